//! `caustic render`: a scene to a PNG or EXR image, ray traced or photon mapped, with a
//! progress bar, the render's figures and provenance in the image's metadata (so `--from`
//! renders it again), per-pixel EXR layers, and optionally a reference comparison per pass,
//! a tev stream and a JSON summary ([`super::render_report`]).

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Result};

use super::render_report::Report;
use caustic::args::{Overwrite, Threads};
use caustic::render::compare::Reference;
use caustic::render::error::pixel_error_estimate;
use caustic::render::provenance::{software, Recorded};
use caustic::render::session::{Frame, FrameStats, SessionOptions};
use caustic::render::shard::sums::passes_text;
use caustic::render::shard::{PartHeader, PassSet};
use caustic::render::{image_metadata, Image, Layer};
use caustic::run::{load_scene, render_session};
use caustic::scene::{RendererKind, Scene};
use caustic::settings::limits;
use caustic::settings::{RadiusSchedule, SettingFlags};
use caustic::tev::TevStream;

/// `caustic render`'s flags.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene file (TOML); the built-in teapot scene when omitted.
    #[arg(conflicts_with = "from")]
    scene: Option<PathBuf>,
    /// Render again what an image written by caustic records (its scene text, overrides,
    /// seed and passes): the same pixels, whatever the thread count. Flags given as well
    /// override what it records.
    #[arg(long, value_name = "IMAGE")]
    from: Option<PathBuf>,
    /// Output image: .png or .exr (EXR adds the layers radius.Y, photons.Y and error.Y).
    #[arg(short, long)]
    out: PathBuf,
    /// Override the scene's image width (the height follows the scene's aspect unless
    /// --height is given too).
    #[arg(long)]
    width: Option<u32>,
    /// Override the scene's image height (the width follows the scene's aspect unless
    /// --width is given too).
    #[arg(long)]
    height: Option<u32>,
    /// PNG exposure in stops (EXR is always linear); default 0, or what --from records.
    #[arg(long, allow_negative_numbers = true)]
    exposure: Option<f32>,
    #[command(flatten)]
    overwrite: Overwrite,
    #[command(flatten)]
    pub threads: Threads,
    /// Compare with a reference image (.exr or .pfm of the same size): RMSE and relative MSE
    /// after every pass and at the end.
    #[arg(long, value_name = "FILE")]
    reference: Option<PathBuf>,
    /// Stream every pass to a running tev (default address 127.0.0.1:14158); if tev cannot
    /// be reached the render goes on without it.
    #[arg(long, value_name = "HOST:PORT", num_args = 0..=1,
          default_missing_value = caustic::tev::DEFAULT_ADDRESS)]
    tev: Option<String>,
    /// Print the summary as JSON on stdout (progress and warnings stay on stderr).
    #[arg(long)]
    json: bool,
    /// Render shard K of N: the passes i ≡ K (mod N) of 0..--passes, into an EXR part file
    /// holding their exact sums, for `caustic merge` (see README, "Rendering on a cluster").
    /// A VCM scene's passes are VCM's; any other scene's are photon mapped with the global
    /// radius schedule (this flag sets both).
    #[arg(long, value_name = "K/N", value_parser = caustic::render::shard::Shard::parse)]
    shard: Option<caustic::render::shard::Shard>,
    #[command(flatten)]
    run: RunArgs,
    #[command(flatten)]
    settings: SettingFlags,
}

/// `render`'s flags for the run itself (how many passes), beside the render settings.
#[derive(clap::Args, Clone, Debug)]
pub struct RunArgs {
    /// Photon mapping and the path tracer: passes to run (default 16, or what --from records;
    /// with --time-limit alone, as many as fit in it); with --shard, the passes of the whole
    /// render, of which the shard renders its own.
    #[arg(long)]
    passes: Option<u32>,
    /// Photon mapping and the path tracer: stop after this many seconds even if passes remain;
    /// without --passes (and not --from an image that records them), render passes until then.
    #[arg(long, allow_negative_numbers = true)]
    time_limit: Option<f64>,
}

/// Renders a scene to an image with the ray tracer or photon mapping.
pub fn render(args: RenderArgs) -> Result<()> {
    let out = args.out.as_path();
    if caustic::render::film::Format::from_path(out).is_none() {
        bail!("{}: unknown image format (use .png or .exr)", out.display());
    }
    args.overwrite.check([out])?;
    let mut report = Report::new(args.json);
    let (mut scene, recorded, exposure) = scene_to_render(&args, &mut report)?;
    let from_part = match &args.from {
        Some(image) => part_header(image)?,
        None => None,
    };
    if args.shard.is_some() || from_part.is_some() {
        check_shard_flags(&args)?;
        let (passes, total) = match (args.shard, &from_part) {
            (Some(shard), part) => {
                // A shard of the render the part belongs to, unless --passes says otherwise.
                let recorded_total = part
                    .as_ref()
                    .map(|p| p.total_passes)
                    .or(recorded.as_ref().and_then(|r| r.passes));
                (
                    PassSet::Shard(shard),
                    args.run.passes.or(recorded_total).unwrap_or(16),
                )
            }
            (None, Some(part)) => {
                if args.run.passes.is_some() {
                    bail!(
                        "--passes cannot be used with --from a part file: it renders the part's own passes ({} of {}) again; give --shard K/N to render a shard of its render instead",
                        passes_text(&part.passes),
                        part.total_passes
                    );
                }
                (PassSet::List(part.passes.clone().into()), part.total_passes)
            }
            (None, None) => unreachable!("one of the two is given"),
        };
        return super::shard::render_shard(&mut scene, passes, total, out, args.overwrite.force);
    }
    let reference = match &args.reference {
        Some(path) => {
            let reference = Reference::open(path)?;
            reference.check_size(scene.camera.width, scene.camera.height)?;
            Some(reference)
        }
        None => None,
    };
    let name = out
        .file_name()
        .map_or_else(|| "caustic".into(), |n| n.to_string_lossy().into_owned());
    let mut tev = args.tev.as_deref().and_then(|address| {
        TevStream::connect(address, &name)
            .map_err(|e| report.warn(format!("{e}; rendering without it")))
            .ok()
    });
    let mut output = Output {
        reference: reference.as_ref(),
        tev: &mut tev,
        report: &mut report,
    };
    let passes = if scene.params.renderer.progressive() {
        let asked = args.run.passes.or(recorded.as_ref().and_then(|r| r.passes));
        match (asked, args.run.time_limit) {
            (Some(n), _) => Passes::Count(n),
            (None, Some(limit)) => Passes::UntilTimeLimit(limit),
            (None, None) => Passes::Count(16),
        }
    } else {
        Passes::Count(1)
    };
    let rendered = render_passes(&mut scene, passes, &args.run, &mut output)?;
    let layers: Vec<Layer> = rendered
        .layers
        .iter()
        .map(|(name, values)| Layer { name, values })
        .collect();
    rendered
        .image
        .save_with_layers(out, exposure, &rendered.metadata, &layers, args.overwrite.force)?;
    report.finish(out, &scene, &rendered.stats, reference.as_ref(), &rendered.image);
    Ok(())
}

/// Refuses the flags that a part (a shard's, or a part's passes rendered again) cannot take:
/// what reports on a whole render, a time limit, and another renderer or radius schedule.
pub fn check_shard_flags(args: &RenderArgs) -> Result<()> {
    if args.reference.is_some() || args.tev.is_some() || args.json {
        bail!("--reference, --tev and --json report on a whole render, not on a part: merge the parts, then compare or view the merged image");
    }
    if args.run.time_limit.is_some() {
        bail!("--time-limit cannot be used for a part: a part holds whole passes, chosen by their number");
    }
    let given = |key: &str| args.settings.get(key).map(|v| v.replace('-', "_"));
    if let Some(kind) =
        given("renderer").filter(|k| k != RendererKind::Ppm.name() && k != RendererKind::Vcm.name())
    {
        bail!("--renderer {kind}: a part's passes must be independent estimates that merge exactly; only photon mapping (with the global radius schedule) and vcm render parts");
    }
    let vcm = given("renderer").is_some_and(|k| k == RendererKind::Vcm.name());
    if let Some(schedule) = given("radius_schedule").filter(|s| !vcm && s != RadiusSchedule::Global.name()) {
        bail!("--radius-schedule {schedule}: a part's passes follow the global radius schedule");
    }
    Ok(())
}

/// The header of `image` when it is a part file (`None` for another image); a part whose
/// header is damaged is an error.
fn part_header(image: &std::path::Path) -> Result<Option<PartHeader>> {
    let metadata = caustic::render::film::read_metadata(image)
        .map_err(|e| anyhow::anyhow!("{}: {e}", image.display()))?;
    if !metadata
        .iter()
        .any(|(k, _)| k == caustic::render::shard::part::PART)
    {
        return Ok(None);
    }
    Ok(Some(PartHeader::read(image)?))
}

/// The scene to render (from its file, or as an image recorded it with `--from`) with the
/// command line's size, seed and renderer laid in; what `--from` recorded; the exposure.
fn scene_to_render(args: &RenderArgs, report: &mut Report) -> Result<(Scene, Option<Recorded>, f32)> {
    let (mut scene, recorded) = match &args.from {
        Some(image) => {
            let recorded = Recorded::read(image)?;
            if recorded.software != software() {
                report.warn(format!(
                    "{} was written by {}, this is {}: the pixels may differ",
                    image.display(),
                    recorded.software,
                    software()
                ));
            }
            (recorded.scene.clone(), Some(recorded))
        }
        None => (load_scene(args.scene.as_deref())?, None),
    };
    for warning in &scene.warnings {
        report.warn(warning.clone());
    }
    let exposure = args
        .exposure
        .or(recorded.as_ref().and_then(|r| r.exposure))
        .unwrap_or(0.0);
    if !exposure.is_finite() || exposure.abs() > 64.0 {
        bail!("--exposure must be a finite number of stops between -64 and 64, got {exposure}");
    }
    for (flag, v) in [("--width", args.width), ("--height", args.height)] {
        if let Some(v) = v {
            flag_check(flag, limits::image_side(v))?;
        }
    }
    scene.camera.resize(args.width, args.height);
    args.settings
        .apply(&mut scene.params)
        .map_err(anyhow::Error::msg)?;
    Ok((scene, recorded, exposure))
}

/// Where each finished pass goes besides the file: the reference comparison, tev, the report.
struct Output<'a> {
    reference: Option<&'a Reference>,
    tev: &'a mut Option<TevStream>,
    report: &'a mut Report,
}

impl Output<'_> {
    /// Compares a pass with the reference and sends it to tev (dropping tev after a failure,
    /// with a warning).
    fn pass(&mut self, pass: u32, secs: f64, image: &Image, layers: &[Layer]) {
        if let Some(errors) = self.reference.and_then(|r| r.errors(&image.pixels)) {
            self.report.pass_error(pass, secs, errors);
        }
        if let Some(stream) = self.tev.as_mut() {
            if let Err(e) = stream.send(image.width, image.height, &image.pixels, layers) {
                self.report.warn(format!("{e}; no more passes are sent"));
                *self.tev = None;
            }
        }
    }
}

/// A finished render: the image, its EXR layers, its metadata and what the report says.
struct Rendered {
    image: Image,
    layers: Vec<(&'static str, Vec<f32>)>,
    metadata: caustic::render::Metadata,
    stats: FrameStats,
}

/// How many passes `render` runs.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Passes {
    /// This many (or fewer, when a time limit ends the render first).
    Count(u32),
    /// As many as the time limit, this many seconds, allows.
    UntilTimeLimit(f64),
}

/// Renders `passes` (one frame for a renderer that makes one) on a headless session.
fn render_passes(scene: &mut Scene, passes: Passes, args: &RunArgs, output: &mut Output) -> Result<Rendered> {
    if let Passes::Count(n) = passes {
        flag_check("--passes", limits::passes(n))?;
    }
    if let Some(t) = args.time_limit {
        if !(t.is_finite() && t > 0.0) {
            bail!("--time-limit must be a positive number of seconds, got {t}");
        }
    }
    let (w, h) = (scene.camera.width, scene.camera.height);
    let kind = scene.params.renderer;
    let what = format!("{} {w}x{h}", kind.label().to_lowercase());
    // Progress in passes, or, rendering until the time limit, in tenths of a second of it.
    let (length, template, max_passes) = match passes {
        Passes::Count(n) => (
            n as u64,
            "{msg} [{bar:40}] pass {pos}/{len}, {elapsed} (eta {eta})",
            Some(n),
        ),
        Passes::UntilTimeLimit(limit) => (
            (limit * 10.0).ceil().max(1.0) as u64,
            "{msg} [{bar:40}] {elapsed} of the time limit (eta {eta})",
            None,
        ),
    };
    let bar = output.report.bar(length, template, what.clone());
    output.report.set_bar(Some(bar.clone()));
    let session = SessionOptions {
        max_passes,
        time_limit: args.time_limit.map(Duration::from_secs_f64),
        ..Default::default()
    };
    let mut previous: Option<Frame> = None;
    let mut last: Option<Frame> = None;
    let frame = render_session(scene.clone(), session, |f| {
        // The bar counts passes, or tenths of a second and then the message names the pass.
        let (progress, pass) = match passes {
            Passes::Count(_) => (f.pass as u64, String::new()),
            Passes::UntilTimeLimit(_) => ((f.elapsed_secs * 10.0) as u64, format!("pass {}, ", f.pass)),
        };
        if !f.stats.progress.is_empty() {
            bar.set_message(format!("{what}, {pass}{}", f.stats.progress));
        }
        bar.set_position(progress);
        let image = frame_image(f);
        output.pass(f.pass, f.elapsed_secs, &image, &frame_layers(f));
        previous = last.replace(f.clone());
    })?;
    bar.finish_and_clear();
    output.report.set_bar(None);
    let mut layers: Vec<(&'static str, Vec<f32>)> =
        frame.layers.iter().map(|l| (l.name, l.values.to_vec())).collect();
    let error = previous
        .as_ref()
        .and_then(|p| pixel_error_estimate(p.photons, &p.radiance, frame.photons, &frame.radiance));
    if let Some(error) = error {
        layers.push(("error", error));
    }
    let mut metadata = image_metadata(scene, kind.name(), None);
    metadata.extend(frame.stats.metadata.iter().cloned());
    Ok(Rendered {
        image: frame_image(&frame),
        layers,
        metadata,
        stats: frame.stats,
    })
}

/// A frame's radiance as an image.
fn frame_image(f: &Frame) -> Image {
    Image {
        width: f.width,
        height: f.height,
        pixels: f.radiance.to_vec(),
    }
}

/// The per-pixel layers a frame carries (what tev shows beside RGB), as its renderer
/// describes them.
fn frame_layers(f: &Frame) -> Vec<Layer<'_>> {
    f.layers
        .iter()
        .map(|l| Layer {
            name: l.name,
            values: &l.values,
        })
        .collect()
}

/// A flag's value checked against [`limits`]: the message names the flag.
fn flag_check<T>(flag: &str, checked: Result<T, limits::Invalid>) -> Result<T> {
    checked.map_err(|e| anyhow::anyhow!("{flag} {e}"))
}
