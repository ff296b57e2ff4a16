//! `caustic render`: a scene to a PNG or EXR image, ray traced or photon mapped, with a
//! progress bar and the render's figures in the image's metadata.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Result};

use super::{load_scene, photon_map, ppm_stats, progress_bar};
use caustic::render::limits;
use caustic::render::params::RenderParams;
use caustic::render::ppm::IndexKind;
use caustic::render::session::SessionOptions;
use caustic::render::{image_metadata, render_whitted};
use caustic::scene::{RendererKind, Scene};

/// `caustic render`'s flags.
#[derive(clap::Args)]
pub struct RenderArgs {
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
    renderer: Option<RendererKind>,
    /// PNG exposure in stops (EXR is always linear).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    /// Replace the output file if it exists.
    #[arg(long)]
    force: bool,
    /// Render with this many threads (default: one per core); the image does not depend on it.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    #[command(flatten)]
    ppm: PpmArgs,
}

/// Photon-mapping flags of `render`.
#[derive(clap::Args, Clone, Debug)]
pub struct PpmArgs {
    /// Photon mapping: passes to run.
    #[arg(long, default_value_t = 16)]
    passes: u32,
    /// Photon mapping: stop after this many seconds even if passes remain.
    #[arg(long, allow_negative_numbers = true)]
    time_limit: Option<f64>,
    /// Photon mapping: photons per pass (default: the scene's).
    #[arg(long)]
    photons: Option<u64>,
    /// Photon mapping: least photons per pixel of a pass when the eye pass is traced every
    /// pass (anti-aliasing, depth of field); 0 for exactly --photons (default: the scene's).
    #[arg(long, allow_negative_numbers = true)]
    min_photons_per_pixel: Option<f64>,
    /// Photon mapping: radius reduction α in (0, 1] (default: the scene's).
    #[arg(long, allow_negative_numbers = true)]
    alpha: Option<f64>,
    /// Photon mapping: initial radius in scene units (default: the scene's, or automatic).
    #[arg(long, allow_negative_numbers = true)]
    radius: Option<f64>,
    /// Photon mapping: spatial index over visible points (default: the scene's, or grid).
    #[arg(long, value_enum)]
    index: Option<IndexKind>,
    /// Photon mapping: direct light by light sampling, photons for caustics and indirect
    /// light only (default: the scene's `direct_light`, on unless it says otherwise).
    #[arg(long, value_name = "on|off", action = clap::ArgAction::Set,
          value_parser = clap::builder::BoolishValueParser::new())]
    direct_light: Option<bool>,
}

impl PpmArgs {
    /// Lays the photon-mapping flags given over the scene's parameters and checks the result
    /// with [`RenderParams::validate`]; an error names the flag.
    fn overlay(&self, params: &mut RenderParams) -> Result<()> {
        if let Some(p) = self.photons {
            params.photons_per_pass = p;
        }
        if let Some(a) = self.alpha {
            params.alpha = a;
        }
        if let Some(n) = self.min_photons_per_pixel {
            params.min_photons_per_pixel = n;
        }
        if let Some(r) = self.radius {
            params.initial_radius = Some(r);
        }
        if let Some(index) = self.index {
            params.index = index;
        }
        if let Some(on) = self.direct_light {
            params.direct_light = on;
        }
        params.validate().map_err(|e| {
            let flag = match e.field {
                "photons_per_pass" => "--photons",
                "alpha" => "--alpha",
                "initial_radius" => "--radius",
                "min_photons_per_pixel" => "--min-photons-per-pixel",
                field => field,
            };
            anyhow::anyhow!("{flag} {}", e.problem)
        })
    }
}

/// Renders a scene to an image with the ray tracer or photon mapping.
pub fn render(args: RenderArgs) -> Result<()> {
    let RenderArgs {
        scene: scene_path,
        out,
        width,
        height,
        seed,
        renderer,
        exposure,
        force,
        ppm,
        threads: _,
    } = args;
    let out = out.as_path();
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
    let mut scene = load_scene(scene_path.as_deref())?;
    for (flag, v) in [("--width", width), ("--height", height)] {
        if let Some(v) = v {
            flag_check(flag, limits::image_side(v))?;
        }
    }
    if let Some(w) = width {
        scene.camera.width = w;
    }
    if let Some(h) = height {
        scene.camera.height = h;
    }
    if let Some(s) = seed {
        scene.params.seed = s;
    }
    let kind = match renderer {
        Some(kind) => kind,
        None => scene.params.renderer,
    };
    if kind == RendererKind::Ppm {
        return render_ppm(scene, out, exposure, force, &ppm);
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
    args.overlay(&mut scene.params)?;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let bar = progress_bar(
        args.passes as u64,
        "{msg} [{bar:40}] pass {pos}/{len}, {elapsed} (eta {eta})",
        format!("photon mapping {w}x{h}"),
    )?;
    scene.params.renderer = RendererKind::Ppm;
    let session = SessionOptions {
        max_passes: Some(args.passes),
        time_limit: args.time_limit.map(Duration::from_secs_f64),
        ..Default::default()
    };
    let frame = photon_map(scene.clone(), session, |f| {
        let Some(s) = f.stats.photon_mapping() else {
            return;
        };
        bar.set_message(format!(
            "photon mapping {w}x{h}, {:.2} M photons/s",
            s.photons as f64 / s.photon_secs.max(1e-9) / 1e6
        ));
        bar.set_position(s.passes as u64);
    })?;
    bar.finish_and_clear();
    let s = ppm_stats(&frame)?.clone();
    let image = caustic::render::Image {
        width: w,
        height: h,
        pixels: frame.radiance.to_vec(),
    };
    let mut metadata = image_metadata(&scene, "ppm");
    metadata.extend([
        ("caustic:passes".into(), s.passes.to_string()),
        ("caustic:photons".into(), s.photons.to_string()),
        ("caustic:alpha".into(), scene.params.alpha.to_string()),
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
        "  time: eye passes {:.3} s ({} of them), area-light sampling {:.3} s, index builds {:.3} s, photons {:.3} s",
        s.eye_secs, s.eye_passes, s.direct_secs, s.index_secs, s.photon_secs
    );
    for skipped in &s.skipped {
        println!("  skipped: {skipped}");
    }
    Ok(())
}

/// A flag's value checked against [`limits`]: the message names the flag.
fn flag_check<T>(flag: &str, checked: Result<T, limits::Invalid>) -> Result<T> {
    checked.map_err(|e| anyhow::anyhow!("{flag} {e}"))
}
