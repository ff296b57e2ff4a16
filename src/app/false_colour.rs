//! The false-colour ramp of the radius, photon-count and difference views, and the colour
//! bar their legends are drawn with.

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

/// Log-scaled false colour of positive values (zero/non-finite values are black), and the
/// smallest and largest positive value, the ends of the scale (`None` when there is none).
pub fn false_colour_image(values: &[f32]) -> (Vec<u8>, Option<(f32, f32)>) {
    let positive = || values.iter().copied().filter(|v| v.is_finite() && *v > 0.0);
    let low = positive().fold(f32::INFINITY, f32::min);
    let high = positive().fold(f32::NEG_INFINITY, f32::max);
    let (lo, hi) = (low.ln(), high.ln());
    let span = (hi - lo).max(1e-6);
    let bytes = values
        .iter()
        .flat_map(|&v| {
            if v.is_finite() && v > 0.0 {
                false_colour((v.ln() - lo) / span)
            } else {
                [0, 0, 0]
            }
        })
        .collect();
    (bytes, (low <= high).then_some((low, high)))
}

/// Draws a colour bar in the lower left corner of `view`: `title`, the ramp `ramp` over
/// `[0, 1]` from left to right, and `ticks` spread under it (the first at the left end, the
/// last at the right).
pub fn colour_bar_ui(
    ui: &mut egui::Ui,
    view: egui::Rect,
    title: &str,
    ticks: &[String],
    ramp: impl Fn(f32) -> [u8; 3],
) {
    use egui::{Color32, Rect, RichText, Vec2};
    let area = egui::Area::new(egui::Id::unique("caustic-colour-bar"))
        .fixed_pos(view.left_bottom() + Vec2::new(12.0, -78.0))
        .order(egui::Order::Foreground);
    area.show(ui.ctx(), |ui| {
        egui::Frame::popup(ui.style()).show(ui, |ui| {
            ui.label(RichText::new(title).small());
            let (bar, _) = ui.allocate_exact_size(Vec2::new(220.0, 12.0), egui::Sense::hover());
            let steps = 64;
            for k in 0..steps {
                let rgb = ramp((k as f32 + 0.5) / steps as f32);
                let x0 = bar.left() + bar.width() * k as f32 / steps as f32;
                let x1 = bar.left() + bar.width() * (k + 1) as f32 / steps as f32;
                let cell = Rect::from_x_y_ranges(x0..=x1, bar.y_range());
                ui.painter()
                    .rect_filled(cell, 0.0, Color32::from_rgb(rgb[0], rgb[1], rgb[2]));
            }
            ui.horizontal(|ui| {
                let gap = if ticks.len() > 2 { 50.0 } else { 130.0 };
                for (k, tick) in ticks.iter().enumerate() {
                    if k > 0 {
                        ui.add_space(gap);
                    }
                    ui.label(RichText::new(tick).small().monospace());
                }
            });
        });
    });
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
        let (bytes, range) = false_colour_image(&[0.0, f32::NAN, 1.0, 10.0]);
        assert_eq!(&bytes[..6], &[0; 6]);
        assert_eq!(bytes.len(), 12);
        assert_eq!(range, Some((1.0, 10.0)));
        assert_eq!(false_colour_image(&[0.0, f32::NAN]).1, None);
    }
}
