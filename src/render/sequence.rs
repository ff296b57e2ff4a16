//! Low-discrepancy sequences over passes: the first two dimensions of Sobol's sequence (a
//! (0,2)-sequence in base 2; Sobol 1967, Joe & Kuo 2008) and the Kronecker sequence R4 of
//! Roberts (2018, "The unreasonable effectiveness of quasirandom sequences"), point `n` being
//! `frac(½ + n·(1/φ, 1/φ², 1/φ³, 1/φ⁴))` with φ the positive root of `x⁵ = x + 1`.
//!
//! Progressive renders take sample `n` of a pixel (or of a light at a visible point) in pass
//! `n`, randomised by a value fixed for that pixel — a digital shift (XOR) for Sobol's points,
//! a Cranley–Patterson rotation ([`rotated`]) for R4's — so every pixel's samples cover their
//! domain evenly over passes, and the error of an integral with an edge in it (a bright
//! light's outline, a shadow, a lens's blur) falls nearly as 1/n instead of the 1/√n of
//! independent samples. Sobol's points stratify every dyadic box, which suits pixels: edges
//! along the image's rows and columns are common (measured: half R2's error for them).
//!
//! Uses that meet in one pixel must not share a sequence (two uses shifted by constant
//! offsets would be tied together, and their joint integral would converge to the wrong
//! value): the eye ray's pixel position takes Sobol's pair, its lens position R4's first two
//! coordinates, its first choice at glass (reflect or refract) the golden-ratio sequence,
//! area-light samples R4's last two. R4's generators, 1/φ_golden and 1 are linearly
//! independent over ℚ (their fields have degrees 5 and 2), so those Kronecker coordinates are
//! jointly equidistributed, and a hybrid of a digital (0,2)-sequence and a Kronecker sequence
//! is equidistributed too.
//!
//! Photons are stratified the same way over the whole render rather than per pixel: photon
//! `n` (counted over all passes) takes point `n` of Sobol's pair, digitally shifted by a value
//! fixed for the render, for the two numbers that choose where its light sends it ([`sobol_any`];
//! quasi-Monte Carlo progressive photon mapping, Keller, Grünschloß & Droske 2012). Each pass's
//! photons are then a stratified share of the light's directions and the passes together
//! keep filling the gaps, so a caustic's density, estimated from photons spread evenly rather
//! than at random, is less noisy. With several lights the first number picks the light as
//! well and, rescaled within the light's share of the power, still places the photon, so each
//! light's photons are stratified rather than a random subset of the points. The photon's
//! later choices stay random.

use glam::DVec2;

use crate::geometry::Ray;
use crate::scene::Camera;

/// The golden ratio (1 + √5)/2.
const GOLDEN: f64 = 1.618_033_988_749_895;
/// φ₄: the real root of x⁵ = x + 1.
const PHI4: f64 = 1.167_303_978_261_418_7;

/// Coordinate `n` of the Kronecker sequence with generator `a` in (0, 1): frac(½ + n·a), in
/// 64-bit fixed point so that it stays exact for any pass number.
fn kronecker(n: u64, a: f64) -> f64 {
    let step = (a * 2f64.powi(64)) as u64;
    let x = (1u64 << 63).wrapping_add(n.wrapping_mul(step));
    (x >> 11) as f64 * 2f64.powi(-53)
}

/// Direction numbers of Sobol's second dimension (primitive polynomial x + 1): v₀ = ½ and
/// vₖ = vₖ₋₁ ⊕ vₖ₋₁/2, as 32-bit fractions.
const SOBOL_DIM1: [u32; 32] = {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    let mut k = 1;
    while k < 32 {
        v[k] = v[k - 1] ^ (v[k - 1] >> 1);
        k += 1;
    }
    v
};

/// Point `n` of Sobol's sequence's first two dimensions in the unit square, digitally shifted
/// by `shift` (its low 32 bits XOR the first coordinate's binary digits, its high 32 bits the
/// second's). Unshifted, any 2ᵏ consecutive points from a multiple of 2ᵏ put one point in
/// each of the 2ᵏ dyadic boxes of any shape; the shift keeps that. Periodic after 2³² points.
pub fn sobol(n: u64, shift: u64) -> DVec2 {
    let n = n as u32;
    let x = n.reverse_bits();
    let mut y = 0u32;
    let mut bits = n;
    let mut k = 0;
    while bits != 0 {
        if bits & 1 == 1 {
            y ^= SOBOL_DIM1[k];
        }
        bits >>= 1;
        k += 1;
    }
    let unit = |v: u32| v as f64 * 2f64.powi(-32);
    DVec2::new(unit(x ^ shift as u32), unit(y ^ (shift >> 32) as u32))
}

/// Point `n` of Sobol's first two dimensions for any 64-bit `n`: [`sobol`] within each block
/// of 2³² points, the block `n >> 32` digitally shifted by `shift` mixed with its number
/// (block 0 by `shift` itself, as the mix of 0 is 0). So an index past 2³² — or one whose high
/// bits name a stream, as the global radius schedule's passes do — starts another independent
/// randomisation of the sequence instead of repeating its points.
pub fn sobol_any(n: u64, shift: u64) -> DVec2 {
    sobol(n, shift ^ crate::render::rng::mix64(n >> 32))
}

/// The R4 sequence's point `n` in the unit 4-cube, as two pairs: the first for the lens, the
/// second for area lights.
pub fn r4(n: u64) -> [DVec2; 2] {
    let a = 1.0 / PHI4;
    let x = [a, a * a, a * a * a, a * a * a * a].map(|a| kronecker(n, a));
    [DVec2::new(x[0], x[1]), DVec2::new(x[2], x[3])]
}

/// The golden-ratio (Kronecker) sequence's point `n` in [0, 1): frac(½ + n/φ), φ = (1 + √5)/2,
/// the best spread of the one-dimensional Kronecker sequences (used for the eye path's first
/// choice at glass).
pub fn golden(n: u64) -> f64 {
    kronecker(n, 1.0 / GOLDEN)
}

/// `x` shifted by `offset` on the unit circle (Cranley–Patterson rotation): still in [0, 1).
pub fn rotated_1d(x: f64, offset: f64) -> f64 {
    (x + offset).fract().min(1.0 - f64::EPSILON / 2.0)
}

/// `point` shifted by `offset` on the unit torus (Cranley–Patterson rotation): still in
/// [0, 1)², and uniformly distributed there when `offset` is.
pub fn rotated(point: DVec2, offset: DVec2) -> DVec2 {
    let p = (point + offset).fract();
    // `fract` of a value just below an integer can round up to 1.0.
    p.min(DVec2::splat(1.0 - f64::EPSILON / 2.0))
}

/// The eye ray of pixel `i` (row-major) in pass `pass` of a renderer that traces one a pixel a
/// pass (the path tracer, VCM): its place in the pixel from Sobol's points, its lens point
/// from R4's, each randomised by numbers drawn once for the pixel from `offsets` (a generator
/// seeded by the pixel alone, the same every pass).
pub fn pixel_ray(camera: &Camera, pass: u64, i: u64, offsets: &mut impl rand::Rng) -> Ray {
    let w = camera.width as u64;
    let jitter = sobol(pass, offsets.random());
    let lens = rotated(r4(pass)[0], DVec2::new(offsets.random(), offsets.random()));
    let pixel = DVec2::new((i % w) as f64, (i / w) as f64) + jitter;
    camera.eye_rays().ray_with_lens_sample(pixel, lens)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The root-mean-square error, over 320 straight edges through the unit square, of the
    /// share of `points` on one side of the edge: how well they estimate the coverage of a
    /// pixel crossed by an outline.
    fn edge_error(points: &[DVec2]) -> f64 {
        let mut sum = 0.0;
        let mut edges = 0;
        for k in 0..64 {
            let angle = k as f64 * std::f64::consts::TAU / 64.0;
            let d = DVec2::new(angle.cos(), angle.sin());
            for c in [-0.3, -0.1, 0.0, 0.15, 0.35] {
                let inside = points.iter().filter(|p| (**p - 0.5).dot(d) < c).count();
                // The exact area of {(p − ½)·d < c} in the square, by a fine grid.
                let m = 400;
                let mut area = 0usize;
                for i in 0..m {
                    for j in 0..m {
                        let p = DVec2::new((i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64);
                        area += usize::from((p - 0.5).dot(d) < c);
                    }
                }
                let exact = area as f64 / (m * m) as f64;
                sum += (inside as f64 / points.len() as f64 - exact).powi(2);
                edges += 1;
            }
        }
        (sum / edges as f64).sqrt()
    }

    #[test]
    fn points_stay_in_the_unit_square() {
        for n in (0..2000).chain([1 << 20, 1 << 40, u64::MAX / 3]) {
            let [lens, light] = r4(n);
            let shifted = sobol(n, u64::MAX);
            for p in [
                sobol(n, 0),
                shifted,
                lens,
                light,
                rotated(lens, DVec2::new(0.999_999_999, 0.5)),
            ] {
                assert!(
                    p.cmpge(DVec2::ZERO).all() && p.cmplt(DVec2::ONE).all(),
                    "{n}: {p}"
                );
            }
            for x in [golden(n), rotated_1d(golden(n), 0.999_999_999)] {
                assert!((0.0..1.0).contains(&x), "{n}: {x}");
            }
        }
        assert!(rotated(DVec2::splat(0.5), DVec2::splat(0.5 - 1e-17))
            .cmplt(DVec2::ONE)
            .all());
    }

    #[test]
    fn sobol_any_is_sobol_in_the_first_block_and_shifts_each_later_block_anew() {
        let shift = 0x0123_4567_89ab_cdef;
        for n in [0, 1, 77, (1 << 32) - 1] {
            assert_eq!(sobol_any(n, shift), sobol(n, shift));
        }
        // Blocks 1 and 2 hold the same unshifted points, each with a shift of its own.
        let (a, b) = (sobol_any((1 << 32) + 5, shift), sobol_any((2 << 32) + 5, shift));
        assert_ne!(a, sobol(5, shift));
        assert_ne!(a, b);
        // Still a (0,2)-sequence within a block: 16 points fill the 4×4 boxes once.
        let mut seen = [0; 16];
        for n in 0..16u64 {
            let p = sobol_any((7 << 32) + 32 + n, shift);
            assert!(p.cmpge(DVec2::ZERO).all() && p.cmplt(DVec2::ONE).all());
            seen[(p.x * 4.0) as usize * 4 + (p.y * 4.0) as usize] += 1;
        }
        assert_eq!(seen, [1; 16]);
    }

    #[test]
    fn sobol_points_fill_every_dyadic_box_once() {
        // 64 points from pass 128 on, shifted: one in each box of every shape 2⁻ᵃ × 2⁻⁽⁶⁻ᵃ⁾.
        let shift = 0x9e37_79b9_7f4a_7c15;
        let points: Vec<DVec2> = (128..192).map(|n| sobol(n, shift)).collect();
        for a in 0..=6 {
            let (cols, rows) = (1u32 << a, 1u32 << (6 - a));
            let mut seen = vec![0; 64];
            for p in &points {
                let (i, j) = ((p.x * cols as f64) as u32, (p.y * rows as f64) as u32);
                seen[(i * rows + j) as usize] += 1;
            }
            assert!(seen.iter().all(|&c| c == 1), "boxes {cols}x{rows}: {seen:?}");
        }
    }

    #[test]
    fn edges_are_covered_nearly_as_one_over_n() {
        // The first 64 passes' points of each sequence, randomised, estimate edges' coverage
        // with an RMS error near 1/64 (Sobol, measured 0.016) and 1.3/64 (R4's pairs); 64
        // independent uniform points miss by 2.5 times as much (0.039 here; ~0.5/√64 = 1/16
        // expected for an edge halving the pixel).
        let offset = DVec2::new(0.291, 0.771);
        let take = |f: &dyn Fn(u64) -> DVec2| (0..64).map(f).collect::<Vec<_>>();
        let sobol_error = edge_error(&take(&|n| sobol(n, 0x1234_5678_9abc_def0)));
        let lens_error = edge_error(&take(&|n| rotated(r4(n)[0], offset)));
        let light_error = edge_error(&take(&|n| rotated(r4(n)[1], offset)));
        let mut rng = crate::render::rng::stream_rng(1, 0, 0);
        let random: Vec<DVec2> = (0..64)
            .map(|_| DVec2::new(rand::Rng::random(&mut rng), rand::Rng::random(&mut rng)))
            .collect();
        let random_error = edge_error(&random);
        assert!(sobol_error < 1.5 / 64.0, "Sobol {sobol_error}");
        assert!(
            lens_error < 2.0 / 64.0 && light_error < 2.0 / 64.0,
            "R4 {lens_error} {light_error}"
        );
        assert!(
            random_error > 2.0 * sobol_error,
            "random {random_error} vs Sobol {sobol_error}"
        );
    }
}
