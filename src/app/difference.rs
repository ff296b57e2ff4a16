//! The difference views against a reference, in false colour with a legend: signed
//! (`render − reference`, blue below, red above, black equal) and relative
//! (`|render − reference| / (reference + 0.01)`, pbrt's guard against dark pixels, on the
//! sequential ramp). Values are the mean over the colour channels; each view's scale is the
//! 99th percentile of its magnitudes, so a few fireflies do not wash the picture out.

use egui::Rect;

use super::false_colour::false_colour;

/// Which difference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DifferenceKind {
    /// `render − reference`.
    Signed,
    /// `|render − reference| / (reference + 0.01)`.
    Relative,
}

/// What the colours of a difference view mean.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Legend {
    /// Which difference.
    pub kind: DifferenceKind,
    /// The value at the ends of the scale (`±scale` signed, `0..scale` relative).
    pub scale: f32,
}

/// Blue (negative) through black (zero) to red (positive), for `t` in `[-1, 1]`.
pub fn diverging(t: f32) -> [u8; 3] {
    let t = if t.is_finite() { t.clamp(-1.0, 1.0) } else { 0.0 };
    let a = t.abs().sqrt(); // perceptually steadier near zero
    let (r, g, b) = if t >= 0.0 {
        (1.0, 0.35 * a, 0.15 * a)
    } else {
        (0.2 * a, 0.55 * a, 1.0)
    };
    let c = |v: f32| (v * a * 255.0 + 0.5) as u8;
    [c(r), c(g), c(b)]
}

/// The 99th percentile of `values`' magnitudes (at least a tiny positive number).
fn scale_of(values: &[f32]) -> f32 {
    let mut mags: Vec<f32> = values.iter().map(|v| v.abs()).filter(|v| v.is_finite()).collect();
    if mags.is_empty() {
        return 1e-6;
    }
    let k = ((mags.len() - 1) as f64 * 0.99) as usize;
    let (_, at, _) = mags.select_nth_unstable_by(k, f32::total_cmp);
    at.max(1e-6)
}

/// Per pixel, the chosen difference of `render` against `reference` (same size).
pub fn differences(render: &[[f32; 3]], reference: &[[f32; 3]], kind: DifferenceKind) -> Vec<f32> {
    render
        .iter()
        .zip(reference)
        .map(|(x, r)| {
            let mean = |p: &[f32; 3]| (p[0] + p[1] + p[2]) / 3.0;
            let d = mean(x) - mean(r);
            match kind {
                DifferenceKind::Signed => d,
                DifferenceKind::Relative => d.abs() / (mean(r).abs() + 0.01),
            }
        })
        .collect()
}

/// The 8-bit RGB picture of a difference view and its legend.
pub fn difference_bytes(
    render: &[[f32; 3]],
    reference: &[[f32; 3]],
    kind: DifferenceKind,
) -> (Vec<u8>, Legend) {
    let values = differences(render, reference, kind);
    let scale = scale_of(&values);
    let bytes = values
        .iter()
        .flat_map(|&v| match kind {
            DifferenceKind::Signed => diverging(v / scale),
            DifferenceKind::Relative => false_colour(v / scale),
        })
        .collect();
    (bytes, Legend { kind, scale })
}

/// Draws the legend in the lower left corner of `view`: a colour bar and its values.
pub fn legend_ui(ui: &mut egui::Ui, view: Rect, legend: Legend) {
    match legend.kind {
        DifferenceKind::Signed => super::false_colour::colour_bar_ui(
            ui,
            view,
            "render − reference",
            &[
                format!("−{:.3e}", legend.scale),
                "0".to_owned(),
                format!("+{:.3e}", legend.scale),
            ],
            |t| diverging(2.0 * t - 1.0),
        ),
        DifferenceKind::Relative => super::false_colour::colour_bar_ui(
            ui,
            view,
            "|render − reference| / (reference + 0.01)",
            &["0".to_owned(), format!("{:.3e}", legend.scale)],
            false_colour,
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_and_relative_differences_and_their_scale() {
        let reference = vec![[1.0f32; 3]; 100];
        let mut render = reference.clone();
        render[0] = [1.5; 3];
        render[1] = [0.5; 3];
        let signed = differences(&render, &reference, DifferenceKind::Signed);
        assert_eq!((signed[0], signed[1], signed[2]), (0.5, -0.5, 0.0));
        let relative = differences(&render, &reference, DifferenceKind::Relative);
        assert!((relative[1] - 0.5 / 1.01).abs() < 1e-6);
        let (bytes, legend) = difference_bytes(&render, &reference, DifferenceKind::Signed);
        assert_eq!(bytes.len(), 300);
        assert!((legend.scale - 0.5).abs() < 1e-6, "{legend:?}");
        assert!(bytes[0] > 200 && bytes[2] < 100, "above: red");
        assert!(bytes[5] > 200 && bytes[3] < 100, "below: blue");
        assert_eq!(&bytes[6..9], &[0, 0, 0], "equal: black");
        assert_eq!(diverging(f32::NAN), [0, 0, 0]);
    }
}
