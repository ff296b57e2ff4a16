//! The one table of render settings: every key of a scene's `[render]` table, with its type,
//! default, check, unit, help, widget and the renderers that read it, in one entry each
//! ([`render_settings!`] below). From it come the [`RenderParams`] struct (serde reads it from
//! files), its defaults and [`RenderParams::validate`], the list [`SETTINGS`] that the command
//! line's flags ([`super::flags`]), the viewer's widgets, `bench convergence`'s
//! configurations and FORMAT.md's table are made from, and access by key
//! ([`RenderParams::get`], [`RenderParams::set`]).
//!
//! The render session receives the whole set (the session's `Command::SetParams`) and asks
//! [`RenderParams::restarts_from`] whether a change discards the accumulation (every setting
//! not marked live does). Adding a setting is one entry here and the code that reads it.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::limits;
use super::setting::{Field, Setting, Value, Widget};
use super::{IndexKind, RadiusSchedule, RendererKind};

/// The default near-specular threshold (`near_specular`).
pub const NEAR_SPECULAR: f64 = 0.15;

/// The photon mapper alone.
const PPM: &[RendererKind] = &[RendererKind::Ppm];
/// Photon mapping and vertex connection and merging, which merges photons too.
const MERGING: &[RendererKind] = &[RendererKind::Ppm, RendererKind::Vcm];
/// The ray tracer alone.
const WHITTED: &[RendererKind] = &[RendererKind::Whitted];

/// Makes [`RenderParams`], its defaults, checks and access by key, and [`SETTINGS`], from one
/// entry per setting.
macro_rules! render_settings {
    ($(
        $key:ident: $ty:ty = $default:expr;
        check $check:expr;
        flag $flag:literal, label $label:literal, default $default_text:literal, unit $unit:literal,
        renderers $renderers:expr, live $live:literal, widget $widget:expr;
        help $help:literal;
    )*) => {
        /// Every render setting, with the defaults a scene file's `[render]` table starts from.
        /// Camera settings (pose, lens, image size) belong to the scene's camera.
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct RenderParams {
            $(
                #[doc = $help]
                pub $key: $ty,
            )*
        }

        impl Default for RenderParams {
            fn default() -> Self {
                Self { $($key: $default,)* }
            }
        }

        /// Every render setting, in the table's order.
        pub const SETTINGS: &[Setting] = &[$(
            Setting {
                key: stringify!($key),
                flag: $flag,
                label: $label,
                help: $help,
                default: $default_text,
                unit: $unit,
                renderers: $renderers,
                live: $live,
                widget: $widget,
                choices: <$ty as Field>::CHOICES,
                kind: <$ty as Field>::KIND,
            },
        )*];

        impl RenderParams {
            /// Checks every value against [`super::limits`]; the first one out of range is
            /// named.
            pub fn validate(&self) -> Result<(), InvalidParam> {
                $(
                    let check: fn(&$ty) -> Result<(), limits::Invalid> = $check;
                    check(&self.$key).map_err(|problem| InvalidParam {
                        field: stringify!($key),
                        problem,
                    })?;
                )*
                Ok(())
            }

            /// The value of setting `key` (`None`: no such setting).
            pub fn get(&self, key: &str) -> Option<Value> {
                match key {
                    $(stringify!($key) => Some(self.$key.value()),)*
                    _ => None,
                }
            }

            /// Sets `key` to `value` (of its kind; not checked against its range: see
            /// [`RenderParams::validate`]).
            pub fn set(&mut self, key: &str, value: &Value) -> Result<(), String> {
                match key {
                    $(stringify!($key) => {
                        self.$key = <$ty as Field>::from_value(value)
                            .ok_or_else(|| format!("takes {:?} values, not {value:?}", <$ty as Field>::KIND))?;
                        Ok(())
                    })*
                    _ => Err(format!("is not a render setting (the settings: {})", keys())),
                }
            }

            /// Sets `key` from text, as a flag or a bench configuration gives it.
            pub fn set_text(&mut self, key: &str, text: &str) -> Result<(), String> {
                match key {
                    $(stringify!($key) => {
                        self.$key = <$ty as Field>::parse(text)?;
                        Ok(())
                    })*
                    _ => Err(format!("is not a render setting (the settings: {})", keys())),
                }
            }
        }
    };
}

/// Every key, for messages.
fn keys() -> String {
    SETTINGS.iter().map(|s| s.key).collect::<Vec<_>>().join(", ")
}

/// The setting of `key`.
pub fn find_setting(key: &str) -> Option<&'static Setting> {
    SETTINGS.iter().find(|s| s.key == key)
}

/// Checks nothing (choices and switches are valid by their type).
fn any<T>(_: &T) -> Result<(), limits::Invalid> {
    Ok(())
}

render_settings! {
    renderer: RendererKind = RendererKind::Whitted;
    check any;
    flag "renderer", label "Renderer", default "\"whitted\"", unit "",
    renderers RendererKind::ALL, live false, widget Widget::Hidden;
    help "Which renderer makes the image: \"whitted\" (the ray tracer: one fast frame), \"ppm\" (progressive photon mapping), \"path\" (the path tracer: unbiased, one sample per pixel a pass) or \"vcm\" (vertex connection and merging: path tracing, light tracing and photon mapping weighted by multiple importance sampling, one light and one camera subpath per pixel a pass).";

    photons_per_pass: u64 = 200_000;
    check |n| limits::photons_per_pass(*n).map(drop);
    flag "photons", label "Photons per pass", default "200000", unit "photons",
    renderers PPM, live true, widget Widget::Slider { min: 1_000.0, max: 10_000_000.0, log: true, step: 0.0 };
    help "Photons traced per pass (with guided emission, divided by how many times more of them arrive where the camera looks). Applies from the next pass, without restarting.";

    min_photons_per_pixel: f64 = 4.0;
    check |n| limits::photons_per_pixel(*n).map(drop);
    flag "min-photons-per-pixel", label "Min photons per pixel", default "4", unit "photons a pixel",
    renderers PPM, live true, widget Widget::Slider { min: 0.0, max: 32.0, log: false, step: 0.5 };
    help "When the eye pass is traced anew every pass (anti-aliasing or an open aperture), each pass traces at least this many photons per pixel, so the eye pass stays a small share of it: a ratio rather than a timing keeps the image the same on any machine and thread count. 0: exactly the photons per pass. Applies from the next pass, without restarting.";

    alpha: f64 = 0.7;
    check |a| limits::alpha(*a).map(drop);
    flag "alpha", label "Alpha", default "0.7", unit "",
    renderers MERGING, live true, widget Widget::Slider { min: 0.05, max: 1.0, log: false, step: 0.0 };
    help "The radius reduction α in (0, 1]: the fraction of a pass's new photons an estimate keeps (Hachisuka et al. 2008, who use 0.7); the radius shrinks faster when it is smaller (for \"vcm\", the merging radius shrinks as (pass + 1)^((α − 1)/2)). Applies from the next pass, without restarting (with the global radius schedule, it restarts).";

    initial_radius: Option<f64> = None;
    check |r| r.map_or(Ok(()), |r| limits::radius(r).map(drop));
    flag "radius", label "Initial radius", default "automatic", unit "scene units",
    renderers MERGING, live false, widget Widget::Auto { automatic: "Automatic initial radius", min: 1e-5, max: 0.2, scene_length: true, manual: 0.0 };
    help "The search radius photons are gathered over at first, in scene units. Automatic: twice one pixel's footprint at the median distance of the visible points. \"vcm\" merges within it too.";

    indirect_radius_scale: Option<f64> = None;
    check |k| k.map_or(Ok(()), |k| limits::radius_scale(k).map(drop));
    flag "indirect-radius-scale", label "Indirect radius ×", default "automatic", unit "× initial radius",
    renderers PPM, live false, widget Widget::Auto { automatic: "Automatic indirect radius", min: 1.0, max: 16.0, scene_length: false, manual: 2.0 };
    help "The initial radius of the estimate of photons that have bounced off a diffuse surface (indirect light), as a multiple of the initial radius; direct light and caustics keep the narrow radius. Indirect light varies slowly, so where photons are sparse a wider radius gathers many more of them for little blur. Automatic: chosen after the first pass so that a pass hands each point about 32 indirect photons, between 1 and 4 (small closed rooms with dense photons keep 1, sparse scenes widen). 1: one estimate for all photons, as in the paper (1 to 100).";

    adaptive_radius: bool = true;
    check any;
    flag "adaptive-radius", label "Adaptive radius", default "true", unit "",
    renderers PPM, live false, widget Widget::Checkbox;
    help "After the first pass (gathered over twice the initial radius), a point handed more than 64 photons within the initial radius (the inside of a caustic; all light when one estimate is kept) restarts that estimate with the radius that would have handed it about 64, at most 4× narrower, and a point handed fewer than 2, with no pixel within two of its own handed 4 or more, with the radius that would have handed it 2, at most 2× wider and no wider than the indirect estimate's (not at all with one estimate); the first pass's photons no longer count. Sharp light is then not blurred by the initial radius for dozens of passes, and light spread thin is less noisy. Off: every point starts at the initial radius, as in the paper.";

    direct_light: bool = true;
    check any;
    flag "direct-light", label "Direct light by light sampling", default "true", unit "",
    renderers PPM, live false, widget Widget::Checkbox;
    help "Direct light by light sampling at the visible points (point and spot lights exactly by shadow rays, spheres and quads one stratified sample per pass); photons then count only after their first bounce and carry caustics and indirect light. Off: photons carry all the light (classic PPM).";

    near_specular: f64 = NEAR_SPECULAR;
    check |a| limits::roughness(*a).map(drop);
    flag "near-specular", label "Near-specular below", default "0.15", unit "roughness α",
    renderers PPM, live false, widget Widget::Slider { min: 0.0, max: 1.0, log: false, step: 0.01 };
    help "Glossy lobes narrower than this microfacet roughness α, times their share of the surface's reflectance (1 for metals and glass; ρs/(ρs + ρ) for a Phong surface), are followed by the eye paths of stochastic photon mapping, as mirrors are, instead of being gathered at the visible point (a Phong exponent n counts as α = √(2/(n+2))). A narrow lobe gathers few photons and blurs what it reflects by the search radius; a wide one seen by a path is noisy, and a followed lobe costs the surface's diffuse light the passes its path takes the lobe. The path finds the lobes' direct light by light sampling; the photons are still stored on the surface and leave through its lobes, so no caustic is lost either way. 0: every glossy lobe is gathered, as classic photon mapping always does (its one eye pass cannot sample them).";

    guided_emission: bool = true;
    check any;
    flag "guided-emission", label "Photons where the camera looks", default "true", unit "",
    renderers PPM, live false, widget Widget::Checkbox;
    help "Photons are sent where the camera looks: each light learns, pass by pass, which of its emission directions lead photons to a visible point and emits mostly there, with weights that keep the image the same. A pass then traces the photons per pass divided by how many times more photons arrive than unguided (that gain at most 64×), so it lands as many useful photons without the lost ones, and from the 33rd pass on divided by the gain's square root, landing more useful photons in fewer, fuller passes; a light whose map would gain less than 1.5× (a closed room) keeps emitting uniformly. Off: lights emit as they shine.";

    stratified_eye_rays: bool = true;
    check any;
    flag "stratified-eye-rays", label "Stratified eye rays", default "true", unit "",
    renderers PPM, live false, widget Widget::Checkbox;
    help "When eye rays are jittered (anti-aliasing, depth of field), each pixel's rays are placed over passes by low-discrepancy sequences (Sobol's (0,2)-sequence over the pixel, R4 over the lens, each randomised per pixel) instead of independently at random, so the outlines of bright lights, their reflections and the lens blur settle sooner. Off: independent random jitter.";

    stratified_photons: bool = true;
    check any;
    flag "stratified-photons", label "Stratified photons", default "true", unit "",
    renderers PPM, live false, widget Widget::Checkbox;
    help "The two numbers that choose each photon's direction come from Sobol's (0,2)-sequence over the render's photons (photon n takes point n, digitally shifted by a value drawn from the seed; with several lights its first number also picks the light, rescaled within that light's share so that every light's photons stay stratified) instead of independently at random, so each pass's photons cover the light's directions evenly and caustics are less noisy (quasi-Monte Carlo photon mapping, Keller, Grünschloß & Droske 2012). Off: independent random directions.";

    supersample_light_seen: bool = true;
    check any;
    flag "supersample-light-seen", label "Supersampled lamp outlines", default "true", unit "",
    renderers PPM, live false, widget Widget::Checkbox;
    help "When eye rays are jittered: where the light a pixel sees directly (emission seen directly or through mirrors and glass, point and spot lights at its visible point) changes within the pixel by more than 8× the image's mean (a lamp's outline, its images), the pixel traces 16 more eye rays a pass that look only for that light; after 8 passes, the pixels whose light seen varied most between them (more than 8× the image's mean variance: a texture's or a shadow's edge, a floor seen through glass) trace 4 more; at most a quarter more eye rays in all. An outline then settles about 16 times sooner. A chosen pixel's light seen counts only the passes after it was chosen, so the image converges to the same result. Off: one eye ray per pixel a pass.";

    radius_schedule: RadiusSchedule = RadiusSchedule::PerPoint;
    check any;
    flag "radius-schedule", label "Radius", default "\"per_point\"", unit "",
    renderers PPM, live false, widget Widget::Choice;
    help "How the search radius shrinks pass by pass: \"per_point\" (each point's own statistics, Hachisuka et al. 2008) or \"global\" (every pass an independent estimate at the radius of one schedule, Knaus & Zwicker 2011: passes can be rendered on many machines and merged, see README \"Rendering on a cluster\"; α, the initial radii and the emission guide are then fixed by a pilot pass, and changing α restarts).";

    index: IndexKind = IndexKind::HashGrid;
    check any;
    flag "index", label "Index", default "\"grid\"", unit "",
    renderers PPM, live false, widget Widget::Choice;
    help "The spatial index over visible points that photons look up: \"grid\" (a hashed uniform grid) or \"kd\" (the seed report's kd-tree). The image is the same; the speed differs.";

    max_depth: u32 = 8;
    check |d| limits::max_depth(*d).map(drop);
    flag "max-depth", label "Max depth", default "8", unit "bounces",
    renderers RendererKind::ALL, live false, widget Widget::Slider { min: 1.0, max: 64.0, log: false, step: 1.0 };
    help "Most mirror and glass bounces followed by eye rays and photons (1 to 64).";

    seed: u64 = 1;
    check |s| limits::seed(*s).map(drop);
    flag "seed", label "Seed", default "1", unit "",
    renderers RendererKind::ALL, live false, widget Widget::Hidden;
    help "The seed of every random number: the same seed gives the same image, whatever the thread count (0 to 9223372036854775807: TOML's integers are signed 64-bit).";

    antialias: bool = true;
    check any;
    flag "antialias", label "Anti-aliasing", default "true", unit "",
    renderers &[RendererKind::Whitted, RendererKind::Ppm], live false, widget Widget::Checkbox;
    help "The ray tracer's edge-adaptive supersampling; photon mapping jitters each pixel's eye rays, tracing a new eye pass every pass (stochastic PPM). The path tracer always jitters.";

    dof_samples: u32 = 16;
    check |n| limits::samples(*n).map(drop);
    flag "dof-samples", label "Lens samples", default "16", unit "samples a pixel",
    renderers WHITTED, live false, widget Widget::Slider { min: 1.0, max: 256.0, log: true, step: 1.0 };
    help "The ray tracer's lens samples per pixel when the aperture is open (1 to 4096).";

    light_samples: u32 = 16;
    check |n| limits::samples(*n).map(drop);
    flag "light-samples", label "Light samples", default "16", unit "samples a point",
    renderers WHITTED, live false, widget Widget::Slider { min: 1.0, max: 256.0, log: true, step: 1.0 };
    help "The ray tracer's shadow samples per area light per shading point (1 to 4096).";

    ambient: DVec3 = DVec3::ZERO;
    check |a| ambient(*a);
    flag "ambient", label "Ambient", default "[0, 0, 0]", unit "radiance",
    renderers WHITTED, live false, widget Widget::Hidden;
    help "Ambient radiance the ray tracer adds at diffuse surfaces (finite, not negative, at most 1e18).";
}

/// The ambient radiance's check.
fn ambient(a: DVec3) -> Result<(), limits::Invalid> {
    if !(a.is_finite() && a.cmpge(DVec3::ZERO).all()) {
        return Err(format!("must be finite and not negative, got {a}"));
    }
    limits::radiance(a.max_element()).map(drop)
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
    /// Whether going from `old` to these values discards the accumulated image: every change
    /// does but those of the live settings (α and the photon counts), which apply from the next
    /// pass (with the global radius schedule they restart too: every pass must follow one
    /// schedule).
    pub fn restarts_from(&self, old: &RenderParams) -> bool {
        if self.radius_schedule == RadiusSchedule::Global || old.radius_schedule == RadiusSchedule::Global {
            return self != old;
        }
        SETTINGS
            .iter()
            .any(|s| !s.live && self.get(s.key) != old.get(s.key))
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
