//! A part rendered in this process ([`shard_part`]: photon mapping with the global schedule,
//! a chosen set of passes) and parts read back and merged ([`merge_parts`]): what
//! `caustic render --shard`, `caustic merge` and `caustic bench shards` share.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use super::{Part, PassSet};
use crate::render::image_metadata;
use crate::render::ppm::{Control, PassOutcome, Ppm, PpmOptions};
use crate::scene::{RendererKind, Scene};
use crate::settings::RadiusSchedule;

/// Renders the passes `passes` of a `total`-pass render of `scene` (photon mapping with the
/// global schedule, whatever the scene says), calling `pass_done` after each pass: its part,
/// and the photons it emitted.
pub fn shard_part(
    scene: &mut Scene,
    passes: &PassSet,
    total: u32,
    mut pass_done: impl FnMut(),
) -> Result<(Part, u64)> {
    // A shard is photon mapping with the global schedule, whatever the scene's renderer.
    scene.params.renderer = RendererKind::Ppm;
    scene.params.radius_schedule = RadiusSchedule::Global;
    let mut ppm = Ppm::new(scene, PpmOptions::default());
    ppm.render_only(passes.clone());
    let (w, h) = ppm.size();
    ppm.photons_per_pass = scene
        .params
        .pass_photons(ppm.is_stochastic(), w as u64 * h as u64);
    for _ in 0..passes.passes_of(total) {
        if ppm.run_pass(scene, &mut |_| Control::Continue) != PassOutcome::Completed {
            bail!("pass abandoned");
        }
        pass_done();
    }
    let sums = ppm
        .pass_sums()
        .cloned()
        .context("the global schedule keeps sums")?;
    let settings = toml::to_string(&scene.params).context("writing the settings")?;
    let mut metadata = image_metadata(scene, RendererKind::Ppm.name(), None);
    if let PassSet::Shard(shard) = passes {
        metadata.push(("caustic:shard".into(), shard.to_string()));
    }
    Ok((Part::new(sums, total, metadata, settings), ppm.stats().photons))
}

/// The parts at `paths` merged (in order), refusing parts of other renders and overlapping
/// passes.
pub fn merge_parts(paths: &[PathBuf]) -> Result<Part> {
    let (first, rest) = paths.split_first().context("no parts given")?;
    let mut merged = Part::read(first)?;
    for path in rest {
        let part = Part::read(path)?;
        merged.merge(first, &part, path)?;
    }
    Ok(merged)
}
