//! Single wavelengths as colours: what one wavelength of white light adds to the film's linear
//! sRGB, and how a path picks its wavelength when it meets a dispersive glass.
//!
//! The CIE 1931 2° standard observer is taken from the multi-lobe Gaussian fit of Wyman,
//! Sloan & Shirley 2013, "Simple analytic approximations to the CIE XYZ color matching
//! functions" (JCGT 2(2)), which follows the tabulated curves within about 1 % of their peak,
//! and brought to linear sRGB by IEC 61966-2-1's XYZ → sRGB matrix. Wavelengths whose colour
//! lies outside sRGB's gamut have their negative channels clipped to zero, and each channel is
//! then normalised to integrate to one over the spectrum, so that white light split into its
//! wavelengths and put back together is white again (`(1, 1, 1)`), exactly.
//!
//! A wavelength is drawn with a density proportional to the sum of the three normalised
//! channels, tabulated at 1 nm from 360 to 830 nm; its weight (the channels over the density)
//! then sums to 3 over the channels at every wavelength and no channel exceeds 3, which keeps
//! the colour noise of a dispersed path low.

use std::sync::OnceLock;

use glam::DVec3;

/// The shortest wavelength tabulated, in nm.
pub const FIRST_NM: f64 = 360.0;
/// How many 1-nm bins are tabulated (360 to 830 nm).
const BINS: usize = 470;

/// The CIE 1931 colour matching functions `(x̄, ȳ, z̄)` at `nm` (Wyman, Sloan & Shirley 2013,
/// the multi-lobe fit).
pub fn cie_xyz(nm: f64) -> DVec3 {
    // A Gaussian with different widths left and right of its peak.
    let g = |mu: f64, left: f64, right: f64| {
        let t = (nm - mu) / if nm < mu { left } else { right };
        (-0.5 * t * t).exp()
    };
    DVec3::new(
        1.056 * g(599.8, 37.9, 31.0) + 0.362 * g(442.0, 16.0, 26.7) - 0.065 * g(501.1, 20.4, 26.2),
        0.821 * g(568.8, 46.9, 40.5) + 0.286 * g(530.9, 16.3, 31.1),
        1.217 * g(437.0, 11.8, 36.0) + 0.681 * g(459.0, 26.0, 13.8),
    )
}

/// CIE XYZ to linear sRGB (D65), IEC 61966-2-1.
pub fn xyz_to_linear_srgb(xyz: DVec3) -> DVec3 {
    DVec3::new(
        3.240_454_2 * xyz.x - 1.537_138_5 * xyz.y - 0.498_531_4 * xyz.z,
        -0.969_266_0 * xyz.x + 1.876_010_8 * xyz.y + 0.041_556_0 * xyz.z,
        0.055_643_4 * xyz.x - 0.204_025_9 * xyz.y + 1.057_225_2 * xyz.z,
    )
}

/// The tabulated spectrum: each bin's normalised colour and the cumulative density.
struct Table {
    /// Per 1-nm bin, the clipped linear sRGB of the bin's middle wavelength, each channel
    /// normalised to sum to one over the bins.
    color: [DVec3; BINS],
    /// `cdf[i]`: the chance of a bin below `i` (`cdf[BINS]` is 1).
    cdf: [f64; BINS + 1],
}

/// The table, made on first use.
fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut color = [DVec3::ZERO; BINS];
        for (i, c) in color.iter_mut().enumerate() {
            *c = xyz_to_linear_srgb(cie_xyz(FIRST_NM + i as f64 + 0.5)).max(DVec3::ZERO);
        }
        let total: DVec3 = color.iter().sum();
        let mut cdf = [0.0; BINS + 1];
        for i in 0..BINS {
            color[i] /= total;
            cdf[i + 1] = cdf[i] + color[i].element_sum() / 3.0;
        }
        Table { color, cdf }
    })
}

/// One wavelength drawn for a path, and what it weighs in the film's colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WavelengthSample {
    /// The wavelength in nm.
    pub nm: f64,
    /// The colour it adds over its density: the mean over many draws is `(1, 1, 1)`.
    pub weight: DVec3,
}

/// Draws a wavelength with `u` in [0, 1) (see the module's documentation for the density).
pub fn sample_wavelength(u: f64) -> WavelengthSample {
    let t = table();
    // The last bin whose cumulative chance is at most u.
    let bin = t.cdf.partition_point(|&c| c <= u).clamp(1, BINS) - 1;
    let width = t.cdf[bin + 1] - t.cdf[bin];
    let frac = if width > 0.0 {
        ((u - t.cdf[bin]) / width).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let c = t.color[bin];
    WavelengthSample {
        nm: FIRST_NM + bin as f64 + frac,
        weight: c * (3.0 / c.element_sum()),
    }
}

/// The mean wavelength of each channel (weighted by the channel's share at each wavelength):
/// the wavelengths a tracer that splits rather than samples stands each channel for.
pub fn channel_wavelengths() -> [f64; 3] {
    static MEANS: OnceLock<[f64; 3]> = OnceLock::new();
    *MEANS.get_or_init(|| {
        let t = table();
        let mean = |k: usize| {
            (0..BINS)
                .map(|i| t.color[i][k] * (FIRST_NM + i as f64 + 0.5))
                .sum::<f64>()
        };
        [mean(0), mean(1), mean(2)]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fit against three values of the CIE 1931 table (CIE 018:2019): ȳ peaks at 1 near
    /// 555 nm, x̄(600) = 1.0622, z̄(450) = 1.7471.
    #[test]
    fn observer_matches_the_cie_table() {
        assert!((cie_xyz(555.0).y - 1.0).abs() < 0.02);
        assert!((cie_xyz(600.0).x - 1.0622).abs() < 0.02);
        assert!((cie_xyz(450.0).z - 1.7471).abs() < 0.04);
    }

    /// Drawn over a fine stratification of [0, 1), the weights average to white, every draw's
    /// channels sum to 3, and red is long, blue short.
    #[test]
    fn draws_average_to_white() {
        let n = 100_000;
        let mut sum = DVec3::ZERO;
        for i in 0..n {
            let s = sample_wavelength((i as f64 + 0.5) / n as f64);
            assert!((s.weight.element_sum() - 3.0).abs() < 1e-9);
            assert!((FIRST_NM..FIRST_NM + BINS as f64).contains(&s.nm));
            sum += s.weight;
        }
        let mean = sum / n as f64;
        assert!((mean - DVec3::ONE).abs().max_element() < 1e-3, "{mean}");
        let [r, g, b] = channel_wavelengths();
        assert!(r > g && g > b && b > 430.0 && r < 640.0, "{r} {g} {b}");
        assert!(sample_wavelength(0.0).nm < 420.0 && sample_wavelength(0.999_999).nm > 680.0);
    }
}
