//! The one set of render parameters. The scene file's `[render]` table, the command line's
//! flags and the viewer's controls overlay their values onto a [`RenderParams`]; the render
//! session receives the whole set (the session's `Command::SetParams`), checks it
//! with [`RenderParams::validate`] (over the ranges in [`super::limits`]) and asks
//! [`RenderParams::restarts_from`] whether the change discards the accumulation; the
//! integrators read it each pass.
//!
//! Adding a setting means a field here (with its default and its check in `validate`), the
//! control that shows it and the code that uses it.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::limits;
use super::{IndexKind, RadiusSchedule, RendererKind};

/// Every render setting, with the defaults a scene file's `[render]` table starts from.
/// Camera settings (pose, lens, image size) belong to the scene's camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderParams {
    /// Renderer.
    pub renderer: RendererKind,
    /// Photons per photon-mapping pass (applies from the next pass, no restart).
    pub photons_per_pass: u64,
    /// Stochastic PPM traces a new eye pass every pass; each pass then traces at least this
    /// many photons per pixel, so the eye pass stays a small share of it (pbrt-v4's SPPM
    /// traces one per pixel by default). A fixed ratio rather than a timing keeps the image
    /// the same on any machine and thread count. 0: exactly `photons_per_pass`. Applies from
    /// the next pass, no restart.
    pub min_photons_per_pixel: f64,
    /// PPM radius reduction α in (0, 1] (applies from the next update, no restart).
    pub alpha: f64,
    /// PPM initial radius in scene units (`None`: from the pixel footprint).
    pub initial_radius: Option<f64>,
    /// Photon mapping: the initial radius of the estimate of photons that have bounced off a
    /// diffuse surface (indirect light), as a multiple of the initial radius. Indirect light
    /// varies slowly, so where photons are sparse a wider radius gathers many more of them
    /// for little blur, while direct light and caustics keep the narrow one. `None`
    /// (default): chosen after the first pass so that a pass hands each point about 32
    /// indirect photons, between 1× and 4×; 1: one estimate for all photons (the paper's
    /// PPM).
    pub indirect_radius_scale: Option<f64>,
    /// Photon mapping: narrow the radius where photons are dense, widen it where they are
    /// sparse. After the first pass (gathered over twice the initial radius), a point that
    /// pass handed many more photons than it needs (the inside of a caustic) restarts its
    /// estimate with a radius that would have handed it about 64, up to 4× narrower, so that
    /// sharp light is not blurred by the initial radius for the first dozens of passes; one
    /// handed fewer than 2 within the initial radius, with no denser light within two pixels,
    /// with a radius that would have handed it 2, up to 2× wider (no wider than the indirect
    /// estimate), so that light spread thin is less noisy. On by default; off, every point
    /// starts at the initial radius (the paper's PPM).
    pub adaptive_radius: bool,
    /// Maximum specular bounces of eye rays and photons.
    pub max_depth: u32,
    /// Seed of every random number.
    pub seed: u64,
    /// Edge-adaptive anti-aliasing in the ray tracer; jittered pixels (stochastic PPM) in
    /// photon mapping.
    pub antialias: bool,
    /// Lens samples per pixel with an open aperture (ray tracer).
    pub dof_samples: u32,
    /// Shadow samples per area light per shading point (ray tracer).
    pub light_samples: u32,
    /// Ambient radiance added at diffuse surfaces by the ray tracer.
    pub ambient: DVec3,
    /// Photon mapping: direct light by light sampling at the visible points — exact shadow
    /// rays for point and spot lights, one stratified sample per area light per pass — with
    /// photons deposited only after their first bounce (caustics and indirect light). On by
    /// default; off, photons carry all the light (classic PPM).
    pub direct_light: bool,
    /// Photon mapping: photons sent where the camera looks — each light's emission density
    /// learned from which of its photons reached a visible point (`ppm::guide`), weighted so
    /// the image converges to the same result. On by default; off, lights emit as they shine.
    pub guided_emission: bool,
    /// Photon mapping: each pixel's eye rays placed over passes by low-discrepancy sequences
    /// (`render::sequence`: Sobol's over the pixel, R4 over the lens, randomised per pixel)
    /// instead of independently at random, so the outlines of bright lights, their
    /// reflections and the lens blur converge nearly as 1/passes rather than 1/√passes. On by
    /// default; matters only when the eye pass is traced every pass (anti-aliasing, depth of
    /// field).
    pub stratified_eye_rays: bool,
    /// Photon mapping: the numbers that choose each photon's direction come from Sobol's
    /// low-discrepancy sequence over the render's photons (`render::sequence`, randomised by
    /// the seed) instead of independently at random (quasi-Monte Carlo photon mapping, Keller,
    /// Grünschloß & Droske 2012), so each pass's photons cover the light's directions evenly
    /// and caustics are less noisy; with several lights the sequence picks the light too. On
    /// by default.
    pub stratified_photons: bool,
    /// Photon mapping: where the light a pixel sees directly changes within the pixel (a
    /// lamp's outline, its images in mirrors and glass), that pixel traces 16 more eye rays a
    /// pass that only look for that light (`ppm::seen`), so the outline converges as if it had
    /// 16 times the passes; after 8 passes, the pixels whose light seen varied most between
    /// them (a texture's or a shadow's edge, a floor seen through glass) trace 4 more. The
    /// pixels are chosen from the passes so far; a chosen pixel's
    /// light seen counts only its later passes, so the image converges to the same result.
    /// On by default; matters only when the eye pass is traced every pass (anti-aliasing,
    /// depth of field).
    pub supersample_light_seen: bool,
    /// Photon mapping: the spatial index over visible points (the image does not depend on it).
    pub index: IndexKind,
    /// Photon mapping: how the radius shrinks pass by pass. Per point (default) keeps each
    /// point's statistics from pass to pass; global (Knaus & Zwicker 2011) makes every pass
    /// an independent estimate at a radius all points follow, so passes can be split across
    /// machines and merged. With the global schedule α, the initial radii and the emission
    /// guide are fixed by a pilot pass every machine repeats.
    pub radius_schedule: RadiusSchedule,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            renderer: RendererKind::Whitted,
            photons_per_pass: 200_000,
            min_photons_per_pixel: 4.0,
            alpha: 0.7,
            initial_radius: None,
            indirect_radius_scale: None,
            adaptive_radius: true,
            max_depth: 8,
            seed: 1,
            antialias: true,
            dof_samples: 16,
            light_samples: 16,
            ambient: DVec3::ZERO,
            direct_light: true,
            guided_emission: true,
            stratified_eye_rays: true,
            stratified_photons: true,
            supersample_light_seen: true,
            index: IndexKind::HashGrid,
            radius_schedule: RadiusSchedule::PerPoint,
        }
    }
}

/// A parameter out of its range: the field's name (as the scene file spells it) and what is
/// wrong ("must be …, got …").
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("'{field}' {problem}")]
pub struct InvalidParam {
    /// The field, as in a scene file's `[render]` table.
    pub field: &'static str,
    /// The end of the message.
    pub problem: limits::Invalid,
}

impl RenderParams {
    /// Checks every value against [`super::limits`]; the first one out of range is named.
    pub fn validate(&self) -> Result<(), InvalidParam> {
        let check = |field: &'static str, result: Result<(), limits::Invalid>| {
            result.map_err(|problem| InvalidParam { field, problem })
        };
        check("alpha", limits::alpha(self.alpha).map(drop))?;
        check(
            "photons_per_pass",
            limits::photons_per_pass(self.photons_per_pass).map(drop),
        )?;
        check(
            "min_photons_per_pixel",
            limits::photons_per_pixel(self.min_photons_per_pixel).map(drop),
        )?;
        if let Some(r) = self.initial_radius {
            check("initial_radius", limits::radius(r).map(drop))?;
        }
        if let Some(k) = self.indirect_radius_scale {
            check("indirect_radius_scale", limits::radius_scale(k).map(drop))?;
        }
        check("max_depth", limits::max_depth(self.max_depth).map(drop))?;
        check("seed", limits::seed(self.seed).map(drop))?;
        check("dof_samples", limits::samples(self.dof_samples).map(drop))?;
        check("light_samples", limits::samples(self.light_samples).map(drop))?;
        let ambient = self.ambient;
        if !(ambient.is_finite() && ambient.cmpge(DVec3::ZERO).all()) {
            check(
                "ambient",
                Err(format!("must be finite and not negative, got {ambient}")),
            )?;
        }
        check("ambient", limits::radiance(ambient.max_element()).map(drop))?;
        Ok(())
    }

    /// Whether going from `old` to these values discards the accumulated image: every change
    /// does except α and the photon counts, which apply from the next pass (with the global
    /// radius schedule α and the photon counts restart too: every pass must follow one
    /// schedule).
    pub fn restarts_from(&self, old: &RenderParams) -> bool {
        if self.radius_schedule == RadiusSchedule::Global || old.radius_schedule == RadiusSchedule::Global {
            return self != old;
        }
        let kept = RenderParams {
            alpha: old.alpha,
            photons_per_pass: old.photons_per_pass,
            min_photons_per_pixel: old.min_photons_per_pixel,
            ..self.clone()
        };
        kept != *old
    }

    /// Photons of a full pass over `pixels` pixels: `photons_per_pass`, raised to
    /// `min_photons_per_pixel × pixels` when the eye pass is `stochastic` (traced anew every
    /// pass).
    pub fn pass_photons(&self, stochastic: bool, pixels: u64) -> u64 {
        let floor = if stochastic {
            (self.min_photons_per_pixel * pixels as f64).ceil() as u64
        } else {
            0
        };
        self.photons_per_pass
            .max(floor)
            .min(*limits::PHOTONS_PER_PASS.end())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validate_names_the_first_field_out_of_range() {
        assert_eq!(RenderParams::default().validate(), Ok(()));
        let bad = RenderParams {
            alpha: 1.5,
            ..Default::default()
        };
        assert_eq!(
            bad.validate().expect_err("α 1.5").to_string(),
            "'alpha' must be in (0, 1], got 1.5"
        );
        let bad = RenderParams {
            initial_radius: Some(f64::NAN),
            ..Default::default()
        };
        assert_eq!(bad.validate().expect_err("NaN").field, "initial_radius");
        let bad = RenderParams {
            ambient: DVec3::new(0.0, -1.0, 0.0),
            ..Default::default()
        };
        assert_eq!(bad.validate().expect_err("negative").field, "ambient");
    }

    #[test]
    fn only_alpha_and_photons_apply_without_restarting() {
        let old = RenderParams::default();
        let gentle = RenderParams {
            alpha: 0.5,
            photons_per_pass: 1000,
            min_photons_per_pixel: 0.0,
            ..old.clone()
        };
        assert!(!gentle.restarts_from(&old));
        for changed in [
            RenderParams {
                max_depth: 3,
                ..gentle.clone()
            },
            RenderParams {
                direct_light: false,
                ..gentle.clone()
            },
            RenderParams {
                renderer: RendererKind::Ppm,
                ..gentle.clone()
            },
        ] {
            assert!(changed.restarts_from(&old), "{changed:?}");
        }
    }

    #[test]
    fn with_the_global_schedule_alpha_and_photons_restart_too() {
        let old = RenderParams {
            radius_schedule: RadiusSchedule::Global,
            ..Default::default()
        };
        for changed in [
            RenderParams {
                alpha: 0.5,
                ..old.clone()
            },
            RenderParams {
                photons_per_pass: 1000,
                ..old.clone()
            },
            RenderParams {
                radius_schedule: RadiusSchedule::PerPoint,
                ..old.clone()
            },
        ] {
            assert!(changed.restarts_from(&old), "{changed:?}");
        }
        assert!(!old.clone().restarts_from(&old));
    }

    #[test]
    fn stochastic_passes_trace_at_least_the_photons_per_pixel() {
        let p = RenderParams::default();
        assert_eq!(p.pass_photons(false, 1_000_000), 200_000, "classic PPM: as set");
        assert_eq!(p.pass_photons(true, 1000), 200_000, "the floor is lower");
        assert_eq!(p.pass_photons(true, 1_000_000), 4_000_000);
        let exact = RenderParams {
            min_photons_per_pixel: 0.0,
            ..p
        };
        assert_eq!(exact.pass_photons(true, 1_000_000), 200_000);
    }

    #[test]
    fn serde_round_trip_with_defaults_for_missing_fields() {
        let p: RenderParams =
            toml::from_str("renderer = \"ppm\"\nalpha = 0.6\nindex = \"kd\"").expect("parses");
        assert_eq!(
            p,
            RenderParams {
                renderer: RendererKind::Ppm,
                alpha: 0.6,
                index: IndexKind::KdTree,
                ..Default::default()
            }
        );
        let text = toml::to_string(&p).expect("serializes");
        assert_eq!(toml::from_str::<RenderParams>(&text).expect("round trip"), p);
        assert!(
            toml::from_str::<RenderParams>("alpah = 0.6").is_err(),
            "unknown field"
        );
    }
}
