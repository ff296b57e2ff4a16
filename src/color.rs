//! Colour encodings shared by textures (read) and the film (written): the sRGB transfer pair,
//! and the luminance of a linear colour.

use glam::DVec3;

/// Rec. 709 luminance of a linear RGB colour (the error estimate's measure of a pixel, the
/// designer's of a target and a light).
pub fn luminance(c: DVec3) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The sRGB transfer pair (IEC 61966-2-1): the encoded value of a linear one in [0, 1]...
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// ...and the linear value of an encoded one in [0, 1] (texture images are read with it).
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pair_inverts_and_keeps_the_endpoints() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        for k in 0..=100 {
            let c = k as f64 / 100.0;
            let back = srgb_to_linear(linear_to_srgb(c as f32) as f64);
            assert!((back - c).abs() < 1e-5, "{c} -> {back}");
        }
    }
}
