//! The false-colour ramp of the radius, photon-count and difference views.

/// A false-colour ramp (dark blue → cyan → yellow → white) for `t` in `[0, 1]`.
pub fn false_colour(t: f32) -> [u8; 3] {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    const STOPS: [[f32; 3]; 5] = [
        [0.05, 0.03, 0.25],
        [0.10, 0.35, 0.75],
        [0.20, 0.80, 0.70],
        [0.95, 0.85, 0.25],
        [1.00, 1.00, 0.95],
    ];
    let x = t * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let c = |k: usize| ((STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f) * 255.0 + 0.5) as u8;
    [c(0), c(1), c(2)]
}

/// Log-scaled false colour of positive values (zero/non-finite values are black).
pub fn false_colour_image(values: &[f32]) -> Vec<u8> {
    let logs: Vec<f32> = values
        .iter()
        .filter(|v| v.is_finite() && **v > 0.0)
        .map(|v| v.ln())
        .collect();
    let lo = logs.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = logs.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let span = (hi - lo).max(1e-6);
    values
        .iter()
        .flat_map(|&v| {
            if v.is_finite() && v > 0.0 {
                false_colour((v.ln() - lo) / span)
            } else {
                [0, 0, 0]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn false_colour_is_monotone_in_brightness_and_handles_bad_values() {
        let sum = |c: [u8; 3]| c.iter().map(|&v| v as u32).sum::<u32>();
        let mut last = 0;
        for i in 0..=20 {
            let s = sum(false_colour(i as f32 / 20.0));
            assert!(s >= last, "ramp not monotone at {i}");
            last = s;
        }
        assert_eq!(false_colour(f32::NAN), false_colour(0.0));
        let bytes = false_colour_image(&[0.0, f32::NAN, 1.0, 10.0]);
        assert_eq!(&bytes[..6], &[0; 6]);
        assert_eq!(bytes.len(), 12);
    }
}
