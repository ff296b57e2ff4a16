//! What stays fixed for a photon-mapping render: how the caller runs it ([`PpmOptions`]) and
//! what the scene's render parameters chose once ([`Config`]).

use rand::Rng;

use super::streams;
use crate::render::rng::stream_rng;
use crate::scene::Scene;
use crate::settings::IndexKind;

/// Photons per batch unless [`PpmOptions::batch_photons`] says otherwise: the caller's
/// control callback is asked between batches.
pub const DEFAULT_BATCH_PHOTONS: u64 = 65_536;

/// How photon mapping runs, beyond the scene's render parameters (which hold every setting
/// that changes the image or its speed a user chooses: α, photons, index, direct light, …).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PpmOptions {
    /// Force stochastic PPM (a new eye pass every pass) even for a pinhole camera.
    pub force_stochastic: bool,
    /// Photons traced between two calls of the control callback (rounded up to whole
    /// 4096-photon chunks). Smaller batches let a viewer react sooner; the image does not
    /// depend on it.
    pub batch_photons: u64,
    /// Keep, after each stochastic pass, a copy of every pixel's visible point (36 bytes a
    /// pixel), so that an epoch can hand a warm restart its statistics ([`super::warm`]);
    /// classic PPM keeps its points anyway.
    pub warm_restarts: bool,
}

impl Default for PpmOptions {
    fn default() -> Self {
        Self {
            force_stochastic: false,
            batch_photons: DEFAULT_BATCH_PHOTONS,
            warm_restarts: false,
        }
    }
}

/// The choices a render makes once, from its options and the scene's render parameters, that
/// every part of a pass reads.
#[derive(Clone, Copy, Debug)]
pub struct Config {
    /// How the caller runs the render.
    pub options: PpmOptions,
    /// A new eye pass every pass (Hachisuka & Jensen 2009): a lens, anti-aliasing or
    /// [`PpmOptions::force_stochastic`]; otherwise classic PPM's one eye pass.
    pub stochastic: bool,
    /// Direct light by light sampling.
    pub direct_light: bool,
    /// The spatial index over the visible points.
    pub index: IndexKind,
    /// Eye rays placed by low-discrepancy sequences over passes.
    pub stratified_eye_rays: bool,
    /// With stratified photons: the digital shift of the Sobol points that choose their
    /// directions, drawn from the seed.
    pub photon_shift: Option<u64>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The render's seed.
    pub seed: u64,
}

impl Config {
    /// The choices for a render of `scene` run with `options`.
    pub fn new(scene: &Scene, options: PpmOptions) -> Self {
        let (cam, params) = (&scene.camera, &scene.params);
        Self {
            options,
            stochastic: options.force_stochastic || cam.aperture > 0.0 || params.antialias,
            direct_light: params.direct_light,
            index: params.index,
            stratified_eye_rays: params.stratified_eye_rays,
            photon_shift: params
                .stratified_photons
                .then(|| stream_rng(params.seed, streams::PHOTON_SHIFT, 0).random()),
            width: cam.width,
            height: cam.height,
            seed: params.seed,
        }
    }

    /// Pixels in the image.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }
}
