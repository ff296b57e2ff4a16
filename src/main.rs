//! The `caustic` command line: render scenes to images, export patches as OBJ, benchmark.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};

use caustic::bench::{teapot_geometry, teapot_view, time_intersect};
use caustic::geometry::tessellate::{tessellate, write_obj};
use caustic::geometry::{PatchMethod, SubdivisionParams};
use caustic::render::ppm::{Control, IndexKind, Ppm, PpmOptions};
use caustic::render::{image_metadata, render_whitted};
use caustic::scene::{RendererKind, Scene};

#[derive(Parser)]
#[command(
    name = "caustic",
    version,
    about = "Progressive photon mapping of exact Bézier patches"
)]
struct Cli {
    /// What to do; without one, the viewer opens on the built-in scene.
    #[command(subcommand)]
    command: Option<Command>,
}

/// `caustic view` (also what `caustic` alone runs, with these defaults).
#[derive(Parser)]
struct ViewArgs {
    /// Scene file (TOML).
    scene: Option<PathBuf>,
    /// Save a screenshot of the window (PNG) once the render has reached
    /// --after-passes passes, then close.
    #[arg(long, value_name = "FILE.png")]
    screenshot: Option<PathBuf>,
    /// Passes to wait for before --screenshot.
    #[arg(long, default_value_t = 4, value_name = "N")]
    after_passes: u32,
    /// Replace an existing --screenshot file.
    #[arg(long)]
    force: bool,
    /// Measure launch-to-first-image, UI frame rate while rendering and the latency from
    /// an aperture change to the new image; print them and close.
    #[arg(long)]
    bench: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Open the viewer window on a scene (the built-in teapot scene when omitted).
    View(ViewArgs),
    /// Render a scene to an image (PNG: tonemapped sRGB; EXR: linear float).
    Render {
        /// Scene file (TOML); the built-in teapot scene when omitted.
        scene: Option<PathBuf>,
        /// Output image: .png or .exr.
        #[arg(short, long)]
        out: PathBuf,
        /// Override the scene's image width.
        #[arg(long)]
        width: Option<u32>,
        /// Override the scene's image height.
        #[arg(long)]
        height: Option<u32>,
        /// Override the scene's seed.
        #[arg(long)]
        seed: Option<u64>,
        /// Override the scene's renderer.
        #[arg(long, value_enum)]
        renderer: Option<RendererChoice>,
        /// PNG exposure in stops (EXR is always linear).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        exposure: f32,
        /// Replace the output file if it exists.
        #[arg(long)]
        force: bool,
        #[command(flatten)]
        ppm: PpmArgs,
    },
    /// Write a scene's Bézier patches, tessellated, as a Wavefront OBJ file.
    ExportObj {
        /// Scene file (TOML); the built-in scene when omitted.
        scene: Option<PathBuf>,
        /// Output .obj file.
        #[arg(short, long)]
        out: PathBuf,
        /// Quads per patch side.
        #[arg(long, default_value_t = 16)]
        resolution: usize,
        /// Replace the output file if it exists.
        #[arg(long)]
        force: bool,
    },
    /// Measure performance; prints figures (nothing is asserted).
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
    },
}

/// Photon-mapping flags of `render`.
#[derive(clap::Args, Clone, Debug)]
struct PpmArgs {
    /// Photon mapping: passes to run.
    #[arg(long, default_value_t = 16)]
    passes: u32,
    /// Photon mapping: stop after this many seconds even if passes remain.
    #[arg(long, allow_negative_numbers = true)]
    time_limit: Option<f64>,
    /// Photon mapping: photons per pass (default: the scene's).
    #[arg(long)]
    photons: Option<u64>,
    /// Photon mapping: radius reduction α in (0, 1] (default: the scene's).
    #[arg(long, allow_negative_numbers = true)]
    alpha: Option<f64>,
    /// Photon mapping: initial radius in scene units (default: the scene's, or automatic).
    #[arg(long, allow_negative_numbers = true)]
    radius: Option<f64>,
    /// Photon mapping: spatial index over visible points.
    #[arg(long, value_enum, default_value_t = IndexChoice::Grid)]
    index: IndexChoice,
    /// Photon mapping: direct light from point/spot lights by shadow rays.
    #[arg(long)]
    direct_light: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum IndexChoice {
    Grid,
    Kd,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum RendererChoice {
    Whitted,
    Ppm,
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Ray/teapot intersection: ns per hitting and per missing primary ray, one thread.
    Intersect {
        /// Image side in pixels (rays = size²).
        #[arg(long, default_value_t = 512)]
        size: usize,
        /// Times each ray set is traced (more = steadier figures).
        #[arg(long, default_value_t = 3)]
        repeat: usize,
        /// Which intersectors to time.
        #[arg(long, value_enum, default_value_t = MethodChoice::Both)]
        method: MethodChoice,
        /// Subdivision depth of the per-ray (seed) intersector.
        #[arg(long, default_value_t = 5)]
        per_ray_depth: u32,
        /// Prepared leaves: flatness (control-point deviation / leaf diagonal).
        #[arg(long, default_value_t = SubdivisionParams::default().flatness)]
        flatness: f64,
        /// Prepared leaves: largest leaf diagonal / patch diagonal.
        #[arg(long, default_value_t = SubdivisionParams::default().max_size)]
        max_size: f64,
        /// Prepared leaves: subdivision depth limit.
        #[arg(long, default_value_t = SubdivisionParams::default().max_depth)]
        max_depth: u32,
    },
    /// Photon mapping: photon paths per core-second at the given thread counts.
    Ppm {
        /// Scene file.
        #[arg(default_value = "scenes/smallppm.toml")]
        scene: PathBuf,
        /// Photons per pass.
        #[arg(long, default_value_t = 500_000)]
        photons: u64,
        /// Passes per measurement.
        #[arg(long, default_value_t = 3)]
        passes: u32,
        /// Thread counts to measure.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
    },
    /// Photon mapping: RMSE against a long reference render over time, for the hash grid and
    /// the kd-tree, with and without direct light by shadow rays.
    Convergence {
        /// Scene file.
        #[arg(default_value = "scenes/smallppm.toml")]
        scene: PathBuf,
        /// Image width (height follows the scene's aspect).
        #[arg(long, default_value_t = 256)]
        width: u32,
        /// Photons per pass.
        #[arg(long, default_value_t = 100_000)]
        photons: u64,
        /// Passes of each measured configuration.
        #[arg(long, default_value_t = 32)]
        passes: u32,
        /// Passes of the reference render (grid, no direct light, another seed).
        #[arg(long, default_value_t = 400)]
        reference_passes: u32,
        /// Write every (configuration, pass, seconds, RMSE) row to this CSV file.
        #[arg(long)]
        csv: Option<PathBuf>,
    },
    /// Whitted ray tracer: rays per second on a scene, at the given thread counts.
    Whitted {
        /// Scene file; the built-in scene when omitted.
        scene: Option<PathBuf>,
        /// Image width (height follows the scene's aspect).
        #[arg(long, default_value_t = 640)]
        width: u32,
        /// Thread counts to measure.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
    },
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MethodChoice {
    Prepared,
    PerRay,
    Both,
}

fn main() -> Result<()> {
    let launched = std::time::Instant::now();
    // No subcommand: the viewer with `view`'s own defaults.
    let command = Cli::parse()
        .command
        .unwrap_or_else(|| Command::View(ViewArgs::parse_from(["caustic view"])));
    match command {
        Command::View(args) => view(args, launched),
        Command::Render {
            scene,
            out,
            width,
            height,
            seed,
            renderer,
            exposure,
            force,
            ppm,
        } => render(
            scene.as_deref(),
            &out,
            width,
            height,
            seed,
            renderer,
            exposure,
            force,
            &ppm,
        ),
        Command::ExportObj {
            scene,
            out,
            resolution,
            force,
        } => export_obj(scene.as_deref(), &out, resolution, force),
        Command::Bench { what } => match what {
            BenchCommand::Intersect {
                size,
                repeat,
                method,
                per_ray_depth,
                flatness,
                max_size,
                max_depth,
            } => {
                let params = SubdivisionParams {
                    flatness,
                    max_size,
                    max_depth,
                };
                bench_intersect(size, repeat, method, per_ray_depth, params)
            }
            BenchCommand::Whitted {
                scene,
                width,
                threads,
            } => bench_whitted(scene.as_deref(), width, &threads),
            BenchCommand::Ppm {
                scene,
                photons,
                passes,
                threads,
            } => bench_ppm(&scene, photons, passes, &threads),
            BenchCommand::Convergence {
                scene,
                width,
                photons,
                passes,
                reference_passes,
                csv,
            } => bench_convergence(&scene, width, photons, passes, reference_passes, csv.as_deref()),
        },
    }
}

/// A progress bar over `len` steps (drawn only on a terminal).
fn progress_bar(len: u64, template: &str, message: String) -> Result<indicatif::ProgressBar> {
    let bar = indicatif::ProgressBar::new(len).with_style(
        indicatif::ProgressStyle::with_template(template)
            .context("progress bar template")?
            .progress_chars("=> "),
    );
    bar.set_message(message);
    Ok(bar)
}

/// Opens the viewer (only with the `viewer` feature).
#[cfg(feature = "viewer")]
fn view(args: ViewArgs, launched: std::time::Instant) -> Result<()> {
    let ViewArgs {
        scene,
        screenshot,
        after_passes,
        force,
        bench,
    } = args;
    if let Some(p) = &screenshot {
        if p.extension().is_none_or(|e| !e.eq_ignore_ascii_case("png")) {
            bail!(
                "--screenshot {}: the screenshot is written as PNG; name it .png",
                p.display()
            );
        }
    }
    let launch = caustic::app::LaunchOptions {
        screenshot,
        screenshot_after_passes: after_passes.max(1),
        force,
        bench,
        launched,
    };
    caustic::app::run(scene, launch)
}

/// Without the `viewer` feature there is no window to open.
#[cfg(not(feature = "viewer"))]
fn view(_: ViewArgs, _: std::time::Instant) -> Result<()> {
    bail!("this caustic was built without the viewer (the `viewer` feature); use `caustic render`")
}

fn load_scene(path: Option<&Path>) -> Result<Scene> {
    match path {
        Some(p) => Ok(Scene::load(p)?),
        None => Ok(Scene::builtin()),
    }
}

#[allow(clippy::too_many_arguments)]
fn render(
    scene_path: Option<&Path>,
    out: &Path,
    width: Option<u32>,
    height: Option<u32>,
    seed: Option<u64>,
    renderer: Option<RendererChoice>,
    exposure: f32,
    force: bool,
    ppm: &PpmArgs,
) -> Result<()> {
    if caustic::render::film::Format::from_path(out).is_none() {
        bail!("{}: unknown image format (use .png or .exr)", out.display());
    }
    if out.exists() && !force {
        bail!(
            "{}: the file exists; choose another name or pass --force to overwrite it",
            out.display()
        );
    }
    if !exposure.is_finite() || exposure.abs() > 64.0 {
        bail!("--exposure must be a finite number of stops between -64 and 64, got {exposure}");
    }
    let mut scene = load_scene(scene_path)?;
    for (flag, v) in [("--width", width), ("--height", height)] {
        if let Some(v) = v {
            if !(1..=16384).contains(&v) {
                bail!("{flag} must be between 1 and 16384 pixels, got {v}");
            }
        }
    }
    if let Some(w) = width {
        scene.camera.width = w;
    }
    if let Some(h) = height {
        scene.camera.height = h;
    }
    if let Some(s) = seed {
        scene.settings.seed = s;
    }
    let kind = match renderer {
        Some(RendererChoice::Whitted) => RendererKind::Whitted,
        Some(RendererChoice::Ppm) => RendererKind::Ppm,
        None => scene.settings.renderer,
    };
    if kind == RendererKind::Ppm {
        return render_ppm(scene, out, exposure, force, ppm);
    }
    let (w, h) = (scene.camera.width, scene.camera.height);
    let bar = progress_bar(
        h as u64,
        "{msg} [{bar:40}] {pos}/{len} rows, {elapsed} (eta {eta})",
        format!("ray tracing {w}x{h}"),
    )?;
    let (image, stats) = render_whitted(&scene, &|rows| bar.inc(rows as u64));
    bar.finish_and_clear();
    let mut metadata = image_metadata(&scene, "whitted");
    metadata.push(("caustic:camera_rays".into(), stats.camera_rays.to_string()));
    metadata.push((
        "caustic:elapsed_secs".into(),
        format!("{:.3}", stats.elapsed_secs),
    ));
    image.save(out, exposure, &metadata, force)?;
    println!(
        "{}: {w}x{h} ray traced in {:.2} s ({} camera rays, {} edge pixels re-sampled, {:.0} rays/s)",
        out.display(),
        stats.elapsed_secs,
        stats.camera_rays,
        stats.edge_pixels,
        stats.camera_rays as f64 / stats.elapsed_secs.max(1e-9)
    );
    Ok(())
}

fn render_ppm(mut scene: Scene, out: &Path, exposure: f32, force: bool, args: &PpmArgs) -> Result<()> {
    if args.passes == 0 {
        bail!("--passes must be at least 1");
    }
    if let Some(t) = args.time_limit {
        if !(t.is_finite() && t > 0.0) {
            bail!("--time-limit must be a positive number of seconds, got {t}");
        }
    }
    if let Some(p) = args.photons {
        if p == 0 || p > 1_000_000_000 {
            bail!("--photons must be between 1 and 1000000000, got {p}");
        }
        scene.settings.photons_per_pass = p;
    }
    if let Some(a) = args.alpha {
        if !(a > 0.0 && a <= 1.0) {
            bail!("--alpha must be in (0, 1], got {a}");
        }
        scene.settings.alpha = a;
    }
    if let Some(r) = args.radius {
        if !(r.is_finite() && r > 0.0) {
            bail!("--radius must be a positive number of scene units, got {r}");
        }
        scene.settings.initial_radius = Some(r);
    }
    let options = PpmOptions {
        index: match args.index {
            IndexChoice::Grid => IndexKind::HashGrid,
            IndexChoice::Kd => IndexKind::KdTree,
        },
        direct_light: args.direct_light,
        ..Default::default()
    };
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut ppm = Ppm::new(&scene, options);
    let bar = progress_bar(
        args.passes as u64,
        "{msg} [{bar:40}] pass {pos}/{len}, {elapsed} (eta {eta})",
        format!("photon mapping {w}x{h}"),
    )?;
    let start = std::time::Instant::now();
    for _ in 0..args.passes {
        if args
            .time_limit
            .is_some_and(|t| start.elapsed().as_secs_f64() >= t)
        {
            break;
        }
        ppm.run_pass(&scene, &mut |_| Control::Continue);
        let s = ppm.stats();
        bar.set_message(format!(
            "photon mapping {w}x{h}, {:.2} M photons/s",
            s.photons as f64 / s.photon_secs.max(1e-9) / 1e6
        ));
        bar.inc(1);
    }
    bar.finish_and_clear();
    let s = ppm.stats().clone();
    let image = caustic::render::Image {
        width: w,
        height: h,
        pixels: ppm.radiance(),
    };
    let mut metadata = image_metadata(&scene, "ppm");
    metadata.extend([
        ("caustic:passes".into(), s.passes.to_string()),
        ("caustic:photons".into(), s.photons.to_string()),
        ("caustic:alpha".into(), ppm.alpha.to_string()),
        ("caustic:mean_radius".into(), format!("{:.6}", s.mean_radius)),
        ("caustic:elapsed_secs".into(), format!("{:.3}", s.elapsed_secs)),
    ]);
    image.save(out, exposure, &metadata, force)?;
    println!(
        "{}: {w}x{h}, {} passes, {} photons in {:.2} s ({:.0} photons/s while tracing photons), mean radius {:.4}, {} visible points",
        out.display(),
        s.passes,
        s.photons,
        s.elapsed_secs,
        s.photons as f64 / s.photon_secs.max(1e-9),
        s.mean_radius,
        s.visible_points
    );
    println!(
        "  time: eye passes {:.3} s ({} of them), index builds {:.3} s, photons {:.3} s",
        s.eye_secs, s.eye_passes, s.index_secs, s.photon_secs
    );
    for skipped in &s.skipped {
        println!("  skipped: {skipped}");
    }
    Ok(())
}

fn export_obj(scene_path: Option<&Path>, out: &Path, resolution: usize, force: bool) -> Result<()> {
    if !(1..=256).contains(&resolution) {
        bail!("--resolution must be between 1 and 256, got {resolution}");
    }
    if out.exists() && !force {
        bail!(
            "{}: the file exists; choose another name or pass --force to overwrite it",
            out.display()
        );
    }
    let scene = load_scene(scene_path)?;
    let meshes: Vec<(String, caustic::geometry::TriangleMesh)> = scene
        .geometry
        .patches()
        .iter()
        .enumerate()
        .map(|(k, (p, obj))| {
            let name = format!("{}_patch{k}", scene.objects[*obj as usize].name.replace(' ', "_"));
            (name, tessellate(p, resolution))
        })
        .collect();
    if meshes.is_empty() {
        bail!(
            "{}: the scene has no Bézier patches to export",
            scene.source.display()
        );
    }
    let tmp = out.with_extension("obj.partial");
    let write = || -> std::io::Result<()> {
        let mut file = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        write_obj(&meshes, &mut file)?;
        std::io::Write::flush(&mut file)?;
        std::fs::rename(&tmp, out)
    };
    write().with_context(|| format!("{}: cannot write the OBJ file", out.display()))?;
    let triangles: usize = meshes.iter().map(|(_, m)| m.indices.len()).sum();
    println!(
        "{}: {} patches, {triangles} triangles",
        out.display(),
        meshes.len()
    );
    Ok(())
}

fn bench_ppm(scene_path: &Path, photons: u64, passes: u32, threads: &[usize]) -> Result<()> {
    if photons == 0 || passes == 0 {
        bail!("--photons and --passes must be at least 1");
    }
    let mut scene = Scene::load(scene_path)?;
    scene.settings.photons_per_pass = photons;
    let (w, h) = (scene.camera.width, scene.camera.height);
    println!(
        "Photon mapping on {}, {w}x{h}, {passes} passes of {photons} photons",
        scene.source.display()
    );
    println!(
        "{:>8} {:>12} {:>16} {:>22} {:>10}",
        "threads", "photon s", "photon paths/s", "paths per core-second", "scaling"
    );
    let mut base = None;
    for &n in threads {
        if n == 0 {
            bail!("--threads values must be at least 1");
        }
        let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build()?;
        let stats = pool.install(|| {
            let mut ppm = Ppm::new(&scene, PpmOptions::default());
            for _ in 0..passes {
                ppm.run_pass(&scene, &mut |_| Control::Continue);
            }
            ppm.stats().clone()
        });
        let rate = stats.photons as f64 / stats.photon_secs;
        let scaling = base.map_or(1.0, |b: f64| rate / b);
        base.get_or_insert(rate);
        println!(
            "{n:>8} {:>12.3} {rate:>16.0} {:>22.0} {scaling:>9.2}x",
            stats.photon_secs,
            rate / n as f64
        );
    }
    Ok(())
}

fn rmse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|c| (x[c] as f64 - y[c] as f64).powi(2)).sum::<f64>())
        .sum();
    (sum / (3 * a.len()) as f64).sqrt()
}

fn bench_convergence(
    scene_path: &Path,
    width: u32,
    photons: u64,
    passes: u32,
    reference_passes: u32,
    csv: Option<&Path>,
) -> Result<()> {
    if photons == 0 || passes == 0 || reference_passes == 0 || width == 0 {
        bail!("--width, --photons, --passes and --reference-passes must be at least 1");
    }
    if let Some(p) = csv {
        if p.exists() {
            bail!("{}: the file exists; choose another name", p.display());
        }
    }
    let mut scene = Scene::load(scene_path)?;
    let aspect = scene.camera.height as f64 / scene.camera.width as f64;
    scene.camera.width = width;
    scene.camera.height = ((width as f64 * aspect).round() as u32).max(1);
    scene.settings.photons_per_pass = photons;
    println!(
        "Convergence on {}, {}x{}, {photons} photons per pass; reference: {reference_passes} passes",
        scene.source.display(),
        scene.camera.width,
        scene.camera.height
    );
    let mut reference_scene = scene.clone();
    reference_scene.settings.seed ^= 0x5eed;
    let bar = indicatif::ProgressBar::new(reference_passes as u64);
    let mut reference = Ppm::new(&reference_scene, PpmOptions::default());
    for _ in 0..reference_passes {
        reference.run_pass(&reference_scene, &mut |_| Control::Continue);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let reference = reference.radiance();
    let configs = [
        ("hash grid", IndexKind::HashGrid, false),
        ("kd-tree", IndexKind::KdTree, false),
        ("hash grid + direct", IndexKind::HashGrid, true),
        ("kd-tree + direct", IndexKind::KdTree, true),
    ];
    let mut rows = Vec::new();
    let mut curves = Vec::new();
    for (name, index, direct_light) in configs {
        let options = PpmOptions {
            index,
            direct_light,
            ..Default::default()
        };
        let mut ppm = Ppm::new(&scene, options);
        let mut curve = Vec::new();
        for _ in 0..passes {
            ppm.run_pass(&scene, &mut |_| Control::Continue);
            let s = ppm.stats();
            let e = rmse(&ppm.radiance(), &reference);
            rows.push(format!("{name},{},{:.4},{e:.6e}", s.passes, s.elapsed_secs));
            curve.push((s.elapsed_secs, e));
        }
        curves.push((name, curve));
    }
    // Target: the error the plain hash grid reaches after half its passes.
    let target = curves[0].1[(passes as usize / 2).saturating_sub(1)].1;
    println!(
        "{:<22} {:>12} {:>14} {:>22}",
        "configuration", "final RMSE", "seconds", "seconds to RMSE target"
    );
    for (name, curve) in &curves {
        let (secs, err) = curve[curve.len() - 1];
        let reach = curve
            .iter()
            .find(|(_, e)| *e <= target)
            .map_or("not reached".to_owned(), |(t, _)| format!("{t:.2}"));
        println!("{name:<22} {err:>12.4e} {secs:>14.2} {reach:>22}");
    }
    println!(
        "RMSE target {target:.4e} (the hash grid's error after {} passes)",
        passes / 2
    );
    if let Some(p) = csv {
        let mut text = String::from("configuration,pass,seconds,rmse\n");
        for r in rows {
            text.push_str(&r);
            text.push('\n');
        }
        std::fs::write(p, text).with_context(|| format!("{}: cannot write the CSV file", p.display()))?;
        println!("rows written to {}", p.display());
    }
    Ok(())
}

fn bench_whitted(scene_path: Option<&Path>, width: u32, threads: &[usize]) -> Result<()> {
    let mut scene = load_scene(scene_path)?;
    let aspect = scene.camera.height as f64 / scene.camera.width as f64;
    scene.camera.width = width.clamp(1, 16384);
    scene.camera.height = ((width as f64 * aspect).round() as u32).max(1);
    println!(
        "Whitted ray tracer on {}, {}x{}",
        scene.source.display(),
        scene.camera.width,
        scene.camera.height
    );
    println!(
        "{:>8} {:>10} {:>14} {:>12}",
        "threads", "seconds", "camera rays/s", "speed-up"
    );
    let mut base = None;
    for &n in threads {
        if n == 0 {
            bail!("--threads values must be at least 1");
        }
        let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build()?;
        let (_, stats) = pool.install(|| render_whitted(&scene, &|_| {}));
        let rate = stats.camera_rays as f64 / stats.elapsed_secs;
        let speedup = base.map_or(1.0, |b: f64| stats.elapsed_secs.recip() * b);
        base.get_or_insert(stats.elapsed_secs);
        println!(
            "{n:>8} {:>10.3} {rate:>14.0} {speedup:>11.2}x",
            stats.elapsed_secs
        );
    }
    Ok(())
}

fn bench_intersect(
    size: usize,
    repeat: usize,
    method: MethodChoice,
    per_ray_depth: u32,
    params: SubdivisionParams,
) -> Result<()> {
    if size == 0 || size > 8192 {
        bail!("--size must be between 1 and 8192, got {size}");
    }
    if repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    if !(1..=30).contains(&per_ray_depth) {
        bail!("--per-ray-depth must be between 1 and 30, got {per_ray_depth}");
    }
    if !(params.flatness > 0.0 && params.max_size > 0.0 && params.max_depth <= 12) {
        bail!("--flatness and --max-size must be positive and --max-depth at most 12");
    }
    let rays = teapot_view(size, size);
    println!("Utah teapot (32 patches), {size}x{size} primary rays, 1 thread, {repeat} repeats");
    println!(
        "{:<22} {:>9} {:>9} {:>12} {:>13}",
        "intersector", "hit rays", "miss rays", "ns/hit ray", "ns/miss ray"
    );
    let mut methods = Vec::new();
    if method != MethodChoice::PerRay {
        methods.push(("prepared".to_owned(), PatchMethod::Prepared(params)));
    }
    if method != MethodChoice::Prepared {
        methods.push((
            format!("per-ray (depth {per_ray_depth})"),
            PatchMethod::PerRay { depth: per_ray_depth },
        ));
    }
    for (name, m) in methods {
        let start = std::time::Instant::now();
        let geometry = teapot_geometry(m);
        let prep_ms = start.elapsed().as_secs_f64() * 1e3;
        let t = time_intersect(&name, &geometry, &rays, repeat);
        println!(
            "{:<22} {:>9} {:>9} {:>12.1} {:>13.1}",
            t.method, t.hit_rays, t.miss_rays, t.ns_per_hit, t.ns_per_miss
        );
        let s = geometry.stats();
        println!(
            "    prepare {prep_ms:.2} ms; {} BVH primitives ({} patch leaves), {} nodes, depth {}",
            s.primitives, s.patch_leaves, s.bvh_nodes, s.bvh_depth
        );
    }
    Ok(())
}
