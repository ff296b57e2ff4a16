//! The one table of valid render settings: the scene loader, the command line, the render
//! session and the viewer's controls all check values here, so a setting's range is stated
//! once. Each check returns the value, or the end of an error message ("must be …, got …")
//! that the caller prefixes with the name the user knows (`'alpha'` in a scene file,
//! `--alpha` on the command line).

use std::ops::RangeInclusive;

/// Photons per pass.
pub const PHOTONS_PER_PASS: RangeInclusive<u64> = 1..=1_000_000_000;
/// Mirror/glass bounces followed by eye rays and photons.
pub const MAX_DEPTH: RangeInclusive<u32> = 1..=64;
/// Lens and light samples per pixel or shading point.
pub const SAMPLES: RangeInclusive<u32> = 1..=4096;
/// Least photons per pixel of a stochastic pass.
pub const PHOTONS_PER_PIXEL: RangeInclusive<f64> = 0.0..=1000.0;
/// The indirect estimate's initial radius as a multiple of the initial radius.
pub const RADIUS_SCALE: RangeInclusive<f64> = 1.0..=100.0;
/// Image width and height in pixels.
pub const IMAGE_SIDE: RangeInclusive<u32> = 1..=16384;
/// Passes of one render: photon-mapping passes, a sharded render's total and the passes a
/// part file holds. Ten million passes of the smallest image take days; the bound keeps a
/// part's pass list (4 bytes a pass once read) and the global schedule's radius factor
/// (one multiplication a pass) small.
pub const PASSES: RangeInclusive<u32> = 1..=10_000_000;
/// Seeds: what a scene file can hold, whose integers are TOML's (signed 64-bit), so that every
/// render's scene can be saved and recorded in its image.
pub const SEED: RangeInclusive<u64> = 0..=i64::MAX as u64;

/// The largest power (watts) or intensity (watts per steradian) a light may have in any colour
/// channel (`power × color`): a terawatt. Far above any scene's light, and far enough below
/// f32's range (3.4·10³⁸) that no estimate of a finite scene overflows the film.
pub const MAX_LIGHT_POWER: f64 = 1e12;
/// The largest radiance an area light's surface may emit (power over π × area), and the largest
/// ambient radiance: a light too small for its power would make every pixel that sees it
/// infinite.
pub const MAX_RADIANCE: f64 = 1e18;

/// The most Bézier patches a scene may hold, from every source together (inline, `.bpt`, OBJ
/// free-form): prepared, a patch takes at most about 4 KB, so 2 GB at most.
pub const MAX_PATCHES: usize = 500_000;
/// The most knots one `parm` line of an OBJ free-form surface may give.
pub const MAX_KNOTS: usize = 1_000_000;

/// A setting's value outside its range: the end of the message.
pub type Invalid = String;

/// PPM's radius reduction α, in (0, 1] (Hachisuka et al. 2008 use 0.7).
pub fn alpha(a: f64) -> Result<f64, Invalid> {
    if a > 0.0 && a <= 1.0 {
        Ok(a)
    } else {
        Err(format!("must be in (0, 1], got {a}"))
    }
}

/// A microfacet roughness α (a material's, or the near-specular threshold), in [0, 1].
pub fn roughness(a: f64) -> Result<f64, Invalid> {
    if (0.0..=1.0).contains(&a) {
        Ok(a)
    } else {
        Err(format!("must be within 0 and 1, got {a}"))
    }
}

/// Photons per pass.
pub fn photons_per_pass(n: u64) -> Result<u64, Invalid> {
    within(n, PHOTONS_PER_PASS, "")
}

/// Least photons per pixel of a stochastic pass.
pub fn photons_per_pixel(n: f64) -> Result<f64, Invalid> {
    within(n, PHOTONS_PER_PIXEL, "")
}

/// Maximum specular depth.
pub fn max_depth(d: u32) -> Result<u32, Invalid> {
    within(d, MAX_DEPTH, "")
}

/// Lens or light samples.
pub fn samples(n: u32) -> Result<u32, Invalid> {
    within(n, SAMPLES, "")
}

/// Passes of a render.
pub fn passes(n: u32) -> Result<u32, Invalid> {
    within(n, PASSES, "")
}

/// A light's power or intensity in its brightest colour channel.
pub fn light_power(p: f64) -> Result<f64, Invalid> {
    if p.is_finite() && p > 0.0 && p <= MAX_LIGHT_POWER {
        Ok(p)
    } else {
        Err(format!(
            "must be positive and at most {MAX_LIGHT_POWER:e} in every colour channel (with 'color' applied), got {p}"
        ))
    }
}

/// The radiance an area light emits, or ambient light.
pub fn radiance(l: f64) -> Result<f64, Invalid> {
    if (0.0..=MAX_RADIANCE).contains(&l) {
        Ok(l)
    } else {
        Err(format!(
            "makes a radiance of {l:e}; at most {MAX_RADIANCE:e} keeps the image finite"
        ))
    }
}

/// Image width or height.
pub fn image_side(n: u32) -> Result<u32, Invalid> {
    within(n, IMAGE_SIDE, " pixels")
}

/// The seed of every random number.
pub fn seed(s: u64) -> Result<u64, Invalid> {
    within(s, SEED, " (a scene file's integers are signed 64-bit)")
}

/// A PPM initial search radius.
pub fn radius(r: f64) -> Result<f64, Invalid> {
    positive(r, "scene units")
}

/// The indirect estimate's radius scale.
pub fn radius_scale(k: f64) -> Result<f64, Invalid> {
    within(k, RADIUS_SCALE, "")
}

/// The lens radius (0 is a pinhole).
pub fn aperture(a: f64) -> Result<f64, Invalid> {
    if a.is_finite() && a >= 0.0 {
        Ok(a)
    } else {
        Err(format!(
            "must be a finite number of scene units, 0 or more, got {a}"
        ))
    }
}

/// The distance of the plane in focus.
pub fn focal_distance(f: f64) -> Result<f64, Invalid> {
    positive(f, "scene units")
}

fn positive(v: f64, unit: &str) -> Result<f64, Invalid> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("must be a positive number of {unit}, got {v}"))
    }
}

fn within<T: PartialOrd + std::fmt::Display + Copy>(
    v: T,
    range: RangeInclusive<T>,
    unit: &str,
) -> Result<T, Invalid> {
    if range.contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "must be between {} and {}{unit}, got {v}",
            range.start(),
            range.end()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_accept_their_ends_and_reject_what_lies_outside() {
        assert_eq!(alpha(1.0), Ok(1.0));
        assert_eq!(alpha(0.0).expect_err("0 is out"), "must be in (0, 1], got 0");
        assert!(alpha(f64::NAN).is_err());
        assert_eq!(max_depth(64), Ok(64));
        assert_eq!(
            max_depth(65).expect_err("65 is out"),
            "must be between 1 and 64, got 65"
        );
        assert_eq!(
            image_side(0).expect_err("0 is out"),
            "must be between 1 and 16384 pixels, got 0"
        );
        assert_eq!(seed(i64::MAX as u64), Ok(i64::MAX as u64));
        assert_eq!(
            seed(u64::MAX).expect_err("past TOML's integers"),
            "must be between 0 and 9223372036854775807 (a scene file's integers are signed \
             64-bit), got 18446744073709551615"
        );
        assert!(photons_per_pass(0).is_err() && photons_per_pass(1_000_000_001).is_err());
        assert!(radius(f64::INFINITY).is_err() && radius(-1.0).is_err() && radius(1e-9).is_ok());
        assert_eq!(aperture(0.0), Ok(0.0));
        assert!(aperture(-0.1).is_err() && focal_distance(0.0).is_err());
    }
}
