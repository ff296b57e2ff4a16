//! A part rendered in this process ([`shard_part`]: a chosen set of passes of a renderer
//! whose passes are independent — photon mapping with the global schedule, or vertex
//! connection and merging) and parts read back and merged ([`merge_parts`]): what
//! `caustic render --shard`, `caustic merge` and `caustic bench shards` share.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use super::{Part, PassSet, PassSums};
use crate::render::image_metadata;
use crate::render::integrator::vcm::Vcm;
use crate::render::integrator::{Integrator, PassPlan, Setup};
use crate::render::ppm::{Control, PassOutcome, Ppm, PpmOptions};
use crate::scene::{RendererKind, Scene};
use crate::settings::RadiusSchedule;

/// The renderer a shard of `kind`'s render uses: vertex connection and merging for itself
/// (its pass `i` depends on the scene and `i` alone), photon mapping for every other kind
/// (the path tracer's and Whitted's scenes are photon mapped, as the `--shard` flag says).
pub fn shard_renderer(kind: RendererKind) -> RendererKind {
    match kind {
        RendererKind::Vcm => RendererKind::Vcm,
        _ => RendererKind::Ppm,
    }
}

/// Renders the passes `passes` of a `total`-pass render of `scene` ([`shard_renderer`]: photon
/// mapping with the global schedule unless the scene's renderer is VCM), calling `pass_done`
/// after each pass: its part, and the photons (VCM: light subpaths) it emitted.
pub fn shard_part(
    scene: &mut Scene,
    passes: &PassSet,
    total: u32,
    mut pass_done: impl FnMut(),
) -> Result<(Part, u64)> {
    let kind = shard_renderer(scene.params.renderer);
    scene.params.renderer = kind;
    let (sums, photons) = if kind == RendererKind::Vcm {
        vcm_passes(scene, passes, total, &mut pass_done)?
    } else {
        ppm_passes(scene, passes, total, &mut pass_done)?
    };
    let settings = toml::to_string(&scene.params).context("writing the settings")?;
    let mut metadata = image_metadata(scene, kind.name(), None);
    if let PassSet::Shard(shard) = passes {
        metadata.push(("caustic:shard".into(), shard.to_string()));
    }
    Ok((Part::new(sums, total, metadata, settings), photons))
}

/// Photon mapping's passes `passes` (of `total`) with the global schedule: their sums and
/// photons.
fn ppm_passes(
    scene: &mut Scene,
    passes: &PassSet,
    total: u32,
    pass_done: &mut dyn FnMut(),
) -> Result<(PassSums, u64)> {
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
    Ok((sums, ppm.stats().photons))
}

/// Vertex connection and merging's passes `passes` (of `total`): their sums and light
/// subpaths.
fn vcm_passes(
    scene: &Scene,
    passes: &PassSet,
    total: u32,
    pass_done: &mut dyn FnMut(),
) -> Result<(PassSums, u64)> {
    let mut vcm = Vcm::new(scene, &Setup::default());
    vcm.render_only(passes.clone());
    let plan = PassPlan {
        params: scene.params.clone(),
        first_pass_photons: None,
    };
    for _ in 0..passes.passes_of(total) {
        if !vcm.render_pass(scene, &plan, &mut |_| Control::Continue) {
            bail!("pass abandoned");
        }
        pass_done();
    }
    let sums = vcm.pass_sums().cloned().context("a set of passes keeps sums")?;
    let photons = sums.photons();
    Ok((sums, photons))
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
