//! What a frame of a photon-mapping render shows per pixel ([`PixelLayers`]), made in one
//! parallel sweep over the statistics slots.

use std::sync::Arc;

use super::estimate::Slot;
use super::estimates::slots_by_pixel;
use super::sweep::SWEEP_BLOCK;

/// A frame's per-pixel layers ([`super::Ppm::pixel_layers`]).
pub struct PixelLayers {
    /// Linear RGB radiance ([`super::Ppm::radiance`]).
    pub radiance: Arc<[[f32; 3]]>,
    /// The largest primary search radius of the pixel's slots (0 without any).
    pub radius: Arc<[f32]>,
    /// Photons the pixel's slots gathered, both estimates (`N`, after the shrinking).
    pub gathered: Arc<[f32]>,
}

impl PixelLayers {
    /// The layers of `pixels` pixels from `slots` (in pixel order): each pixel's radiance is
    /// `radiance(pixel, its slots)`, or when `mean` is given (the global schedule's mean of
    /// its passes), that. Each in one allocation, made in one parallel sweep over the slots,
    /// `SWEEP_BLOCK` pixels a task (each block finds its first slot by a binary search:
    /// they lie in pixel order), rather than three serial ones; each pixel's values depend on
    /// it alone, so they are the same for any number of threads.
    pub fn sweep(
        slots: &[Slot],
        pixels: usize,
        mean: Option<Vec<[f32; 3]>>,
        radiance_of: impl Fn(usize, &[Slot]) -> [f32; 3] + Sync,
    ) -> Self {
        use rayon::prelude::*;
        debug_assert!(slots.is_sorted_by_key(|s| s.pixel), "slots lie in pixel order");
        let per_point = mean.is_none();
        let mut radiance: Arc<[[f32; 3]]> = match mean {
            Some(mean) => mean.into(),
            None => std::iter::repeat_n([0.0; 3], pixels).collect(),
        };
        let mut radius: Arc<[f32]> = std::iter::repeat_n(0.0, pixels).collect();
        let mut gathered: Arc<[f32]> = std::iter::repeat_n(0.0, pixels).collect();
        let unique = "a new Arc has no other owner";
        debug_assert_eq!(radiance.len(), pixels);
        Arc::get_mut(&mut radiance)
            .expect(unique)
            .par_chunks_mut(SWEEP_BLOCK)
            .zip(
                Arc::get_mut(&mut radius)
                    .expect(unique)
                    .par_chunks_mut(SWEEP_BLOCK),
            )
            .zip(
                Arc::get_mut(&mut gathered)
                    .expect(unique)
                    .par_chunks_mut(SWEEP_BLOCK),
            )
            .enumerate()
            .for_each(|(b, ((radiance, radius), gathered))| {
                let first = b * SWEEP_BLOCK;
                let start = slots.partition_point(|s| (s.pixel as usize) < first);
                let pixels = first..first + radiance.len();
                for (k, slots) in slots_by_pixel(&slots[start..], pixels).enumerate() {
                    if per_point {
                        radiance[k] = radiance_of(first + k, slots);
                    }
                    radius[k] = slots
                        .iter()
                        .map(|s| s.primary.radius2().sqrt() as f32)
                        .fold(0.0, f32::max);
                    gathered[k] = slots
                        .iter()
                        .fold(0.0, |sum, s| sum + (s.primary.n() + s.indirect.n()) as f32);
                }
            });
        Self {
            radiance,
            radius,
            gathered,
        }
    }
}
