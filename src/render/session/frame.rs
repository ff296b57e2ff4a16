//! What a session sends back after each pass: a [`Frame`] (radiance and per-pixel statistics)
//! and what its renderer measured ([`FrameStats`]).

use std::sync::Arc;

use crate::render::ppm::{Ppm, PpmStats};
use crate::render::whitted::WhittedStats;
use crate::scene::RendererKind;

/// What a frame's renderer measured.
#[derive(Clone, Debug, PartialEq)]
pub enum FrameStats {
    /// Progressive photon mapping's statistics of the epoch so far.
    PhotonMapping(PpmStats),
    /// The ray tracer's statistics of its frame.
    RayTracing(WhittedStats),
}

impl FrameStats {
    /// Seconds the renderer spent on the frame (all passes of the epoch for photon mapping).
    pub fn elapsed_secs(&self) -> f64 {
        match self {
            FrameStats::PhotonMapping(s) => s.elapsed_secs,
            FrameStats::RayTracing(s) => s.elapsed_secs,
        }
    }

    /// Photon mapping's statistics, if the frame was photon mapped.
    pub fn photon_mapping(&self) -> Option<&PpmStats> {
        match self {
            FrameStats::PhotonMapping(s) => Some(s),
            FrameStats::RayTracing(_) => None,
        }
    }

    /// Which renderer made the frame.
    pub fn renderer(&self) -> RendererKind {
        match self {
            FrameStats::PhotonMapping(_) => RendererKind::Ppm,
            FrameStats::RayTracing(_) => RendererKind::Whitted,
        }
    }
}

/// One finished pass, as the viewer needs it.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Increases whenever accumulated statistics are discarded.
    pub epoch: u64,
    /// Passes completed in this epoch (1 for a ray-traced frame).
    pub pass: u32,
    /// Photons emitted in this epoch.
    pub photons: u64,
    /// Seconds since this epoch started.
    pub elapsed_secs: f64,
    /// What the renderer measured (and so which renderer made it).
    pub stats: FrameStats,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Linear RGB radiance, `width × height` pixels, rows from the top.
    pub radiance: Arc<[[f32; 3]]>,
    /// Search radius per pixel (largest of the pixel's slots), for the viewer's probe.
    pub radius: Arc<[f32]>,
    /// Accumulated photon count `N` per pixel (summed over the pixel's slots).
    pub gathered: Arc<[f32]>,
    /// A quick low-resolution preview of a new epoch (pass 0), enlarged to full size.
    pub preview: bool,
}

impl Frame {
    /// The state of a photon-mapping render as a frame of `epoch`, `elapsed_secs` into it.
    pub fn from_ppm(ppm: &Ppm, epoch: u64, elapsed_secs: f64) -> Frame {
        let (width, height) = ppm.size();
        let stats = ppm.stats().clone();
        let (radius, gathered) = pixel_statistics(ppm);
        Frame {
            epoch,
            pass: stats.passes,
            photons: stats.photons,
            elapsed_secs,
            stats: FrameStats::PhotonMapping(stats),
            width,
            height,
            radiance: ppm.radiance().into(),
            radius,
            gathered,
            preview: false,
        }
    }
}

/// Per-pixel search radius (largest of the pixel's slots) and photon count (sum of them).
fn pixel_statistics(ppm: &Ppm) -> (Arc<[f32]>, Arc<[f32]>) {
    let (w, h) = ppm.size();
    let mut radius = vec![0.0f32; w as usize * h as usize];
    let mut gathered = vec![0.0f32; w as usize * h as usize];
    for s in ppm.slots() {
        let px = &mut radius[s.pixel as usize];
        *px = px.max(s.primary.radius2.sqrt() as f32);
        gathered[s.pixel as usize] += (s.primary.n + s.indirect.n) as f32;
    }
    (radius.into(), gathered.into())
}

/// Nearest-neighbour enlargement of a `(sw, sh)` image to `(w, h)`.
pub(super) fn enlarge<T: Copy>(src: &[T], (sw, sh): (u32, u32), (w, h): (u32, u32)) -> Arc<[T]> {
    (0..h)
        .flat_map(|y| {
            let sy = (y as u64 * sh as u64 / h as u64) as usize;
            (0..w).map(move |x| src[sy * sw as usize + (x as u64 * sw as u64 / w as u64) as usize])
        })
        .collect()
}
