//! The central image: the render's texture placed by fit / 1:1 / wheel zoom / drag pan, and
//! the pixel under the cursor for the probe.

use std::sync::Arc;

use egui::{Color32, ColorImage, Pos2, Rect, Sense, TextureHandle, TextureOptions, Vec2};

use super::difference::{difference_bytes, DifferenceKind, Legend};
use super::false_colour::false_colour_image;
use super::settings::{DisplayMode, Zoom};
use crate::gpu::image_quad::{ImageCallback, ImagePixels, ImageUniforms};
use crate::render::film::srgb8;
use crate::render::session::Frame;
use crate::render::Image;

/// Zoom limits (screen pixels per image pixel).
pub const MIN_SCALE: f32 = 1.0 / 32.0;
/// See [`MIN_SCALE`].
pub const MAX_SCALE: f32 = 64.0;

/// Texture and placement of the displayed image.
pub struct ImageView {
    /// The image as an egui texture (where the wgpu image pipeline is not installed).
    texture: Option<TextureHandle>,
    /// The image's pixels for the wgpu image pipeline ([`crate::gpu::image_quad`]), with their
    /// generation, once [`ImageView::draw_with_wgpu`] chose it.
    pixels: Option<(Arc<ImagePixels>, u64)>,
    /// Whether the image is drawn by the wgpu image pipeline.
    wgpu: bool,
    /// Offset of the image centre from the view centre, in points (used with [`Zoom::Scale`]).
    pan: Vec2,
    /// Set when the texture must be rebuilt (new frame, exposure or display mode changed).
    dirty: bool,
    /// The legend of the false-colour view shown (a difference or a layer), if one is.
    pub legend: Option<ViewLegend>,
}

/// What [`ImageView::ui`] did this frame.
pub struct ImageResponse {
    /// The view's response (clicks and drags over it).
    pub response: egui::Response,
    /// The view (points).
    pub view: Rect,
    /// Where the image was drawn (points).
    pub image: Rect,
    /// The pixel under the cursor.
    pub probe: Option<Probe>,
    /// The zoom after this frame's wheel, drag and double-click.
    pub zoom: Zoom,
}

/// Where the cursor is over the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// Pixel column.
    pub x: u32,
    /// Pixel row (from the top).
    pub y: u32,
}

impl Default for ImageView {
    fn default() -> Self {
        Self {
            texture: None,
            pixels: None,
            wgpu: false,
            pan: Vec2::ZERO,
            dirty: true,
            legend: None,
        }
    }
}

/// What the colours of a false-colour view mean.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewLegend {
    /// A difference against the reference.
    Difference(Legend),
    /// A per-pixel layer (search radius, photon count) on a log scale: its label and the
    /// values at the two ends.
    Layer {
        /// The layer's label.
        label: &'static str,
        /// The smallest positive value (the dark end).
        low: f32,
        /// The largest value (the bright end).
        high: f32,
    },
}

impl ViewLegend {
    /// Draws it in the lower left corner of `view`.
    pub fn ui(self, ui: &mut egui::Ui, view: egui::Rect) {
        match self {
            ViewLegend::Difference(legend) => super::difference::legend_ui(ui, view, legend),
            ViewLegend::Layer { label, low, high } => super::false_colour::colour_bar_ui(
                ui,
                view,
                &format!("{label} (log scale; black: none)"),
                &[format!("{low:.3e}"), format!("{high:.3e}")],
                super::false_colour::false_colour,
            ),
        }
    }
}

/// What the image view shows besides the frame's own channels.
#[derive(Clone, Copy, Default)]
pub struct Comparison<'a> {
    /// The reference's pixels (same size as the frame; other sizes are ignored).
    pub reference: Option<&'a [[f32; 3]]>,
    /// Show the reference instead of the frame (A/B).
    pub show_reference: bool,
}

/// The 8-bit RGB picture of a frame in a display mode, and the legend of a false-colour view.
/// A difference mode without a (matching) reference shows the radiance.
pub fn display_bytes(
    frame: &Frame,
    mode: DisplayMode,
    exposure_stops: f32,
    comparison: Comparison,
) -> (Vec<u8>, Option<ViewLegend>) {
    let reference = comparison.reference.filter(|r| r.len() == frame.radiance.len());
    if let (Some(r), true) = (reference, comparison.show_reference) {
        return (srgb8(r, exposure_stops), None);
    }
    let kind = match mode {
        DisplayMode::SignedDifference => Some(DifferenceKind::Signed),
        DisplayMode::RelativeDifference => Some(DifferenceKind::Relative),
        _ => None,
    };
    if let (Some(kind), Some(r)) = (kind, reference) {
        let (bytes, legend) = difference_bytes(&frame.radiance, r, kind);
        return (bytes, Some(ViewLegend::Difference(legend)));
    }
    let layer = match mode {
        DisplayMode::Layer(k) => frame.layers.get(k as usize),
        _ => None,
    };
    match layer {
        Some(layer) => {
            let (bytes, range) = false_colour_image(&layer.values);
            let legend = range.map(|(low, high)| ViewLegend::Layer {
                label: layer.label,
                low,
                high,
            });
            (bytes, legend)
        }
        None => (srgb8(&frame.radiance, exposure_stops), None),
    }
}

/// The frame's radiance as an [`Image`] (for display and saving).
pub fn frame_image(frame: &Frame) -> Image {
    Image {
        width: frame.width,
        height: frame.height,
        pixels: frame.radiance.to_vec(),
    }
}

/// The parts of `view` outside `covered`: up to four bands (above, below, left, right).
fn uncovered(view: Rect, covered: Rect) -> Vec<Rect> {
    let inner = view.intersect(covered);
    if !inner.is_positive() {
        return vec![view];
    }
    let bands = [
        Rect::from_min_max(view.min, Pos2::new(view.max.x, inner.min.y)),
        Rect::from_min_max(Pos2::new(view.min.x, inner.max.y), view.max),
        Rect::from_min_max(
            Pos2::new(view.min.x, inner.min.y),
            Pos2::new(inner.min.x, inner.max.y),
        ),
        Rect::from_min_max(
            Pos2::new(inner.max.x, inner.min.y),
            Pos2::new(view.max.x, inner.max.y),
        ),
    ];
    bands.into_iter().filter(|b| b.is_positive()).collect()
}

impl ImageView {
    /// Marks the texture stale (a new frame, another exposure or display mode).
    pub fn invalidate(&mut self) {
        self.dirty = true;
    }

    /// Draws the image with the wgpu image pipeline from now on (once
    /// [`crate::gpu::image_quad::install`] has set it up for the window's renderer).
    pub fn draw_with_wgpu(&mut self) {
        self.wgpu = true;
        self.texture = None;
        self.dirty = true;
    }

    /// Whether there is an image to draw.
    fn has_image(&self) -> bool {
        self.texture.is_some() || self.pixels.is_some()
    }

    /// Rebuilds the texture from `frame` if it is stale.
    pub fn update_texture(
        &mut self,
        ctx: &egui::Context,
        frame: &Frame,
        mode: DisplayMode,
        exposure: f32,
        comparison: Comparison,
    ) {
        if !self.dirty && self.has_image() {
            return;
        }
        let (bytes, legend) = display_bytes(frame, mode, exposure, comparison);
        self.legend = legend;
        self.dirty = false;
        if self.wgpu {
            let rgba = bytes
                .chunks_exact(3)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect();
            let pixels = ImagePixels {
                size: [frame.width, frame.height],
                rgba,
            };
            let generation = self.pixels.as_ref().map_or(0, |(_, g)| g + 1);
            self.pixels = Some((Arc::new(pixels), generation));
            return;
        }
        let image = ColorImage::from_rgb([frame.width as usize, frame.height as usize], &bytes);
        // Nearest when magnified, so zoomed-in pixels stay crisp for the probe.
        let options = TextureOptions {
            magnification: egui::TextureFilter::Nearest,
            ..TextureOptions::LINEAR
        };
        match &mut self.texture {
            Some(t) => t.set(image, options),
            None => self.texture = Some(ctx.load_texture("caustic-render", image, options)),
        }
    }

    /// Image pixels per point for `zoom` in a view of `view` points.
    fn scale(zoom: Zoom, view: Vec2, size: Vec2, pixels_per_point: f32) -> f32 {
        match zoom {
            Zoom::Fit => (view.x / size.x).min(view.y / size.y).max(1e-3),
            // `Scale(s)`: s screen pixels per image pixel.
            Zoom::Scale(s) => s / pixels_per_point,
        }
    }

    /// Shows the image and handles wheel zoom, double-click fit and (when `pan_enabled`) a
    /// left drag that pans; returns where everything went and the zoom it leaves.
    pub fn ui(&mut self, ui: &mut egui::Ui, zoom: Zoom, size: [u32; 2], pan_enabled: bool) -> ImageResponse {
        let mut zoom = zoom;
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        let size_px = Vec2::new(size[0] as f32, size[1] as f32);
        let ppp = ui.ctx().pixels_per_point();
        let mut scale = Self::scale(zoom, rect.size(), size_px, ppp);

        // Wheel (or pinch) zooms about the cursor; dragging pans.
        if let Some(pointer) = response.hover_pos() {
            let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
            let factor = pinch * (scroll / 200.0).exp();
            if (factor - 1.0).abs() > 1e-4 {
                let new_scale = (scale * ppp * factor).clamp(MIN_SCALE, MAX_SCALE) / ppp;
                let centre = rect.center() + self.pan_for(zoom);
                let to_pointer = pointer - centre;
                self.pan = (centre + to_pointer * (1.0 - new_scale / scale)) - rect.center();
                zoom = Zoom::Scale(new_scale * ppp);
                scale = new_scale;
            }
        }
        if pan_enabled && response.dragged_by(egui::PointerButton::Primary) {
            if zoom == Zoom::Fit {
                zoom = Zoom::Scale(scale * ppp);
                self.pan = Vec2::ZERO;
            }
            self.pan += response.drag_delta();
        }
        if response.double_clicked() {
            zoom = Zoom::Fit;
        }

        let centre = rect.center() + self.pan_for(zoom);
        let image_rect =
            Rect::from_center_size(centre, size_px * Self::scale(zoom, rect.size(), size_px, ppp));
        // The backdrop only where the image leaves the view bare: a software rasteriser
        // pays for every covered pixel, and a full backdrop under the image cost as much as
        // the image itself.
        let painter = ui.painter_at(rect);
        let covered = if self.has_image() {
            image_rect
        } else {
            Rect::NOTHING
        };
        for bare in uncovered(rect, covered) {
            painter.rect_filled(bare, 0.0, Color32::from_gray(24));
        }
        if let Some(texture) = &self.texture {
            let uv = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
            painter.image(texture.id(), image_rect, uv, Color32::WHITE);
        }
        if let Some((pixels, generation)) = &self.pixels {
            let callback = ImageCallback {
                uniforms: ImageUniforms::new(image_rect, rect),
                pixels: pixels.clone(),
                generation: *generation,
            };
            painter.add(eframe::egui_wgpu::Callback::new_paint_callback(rect, callback));
        }
        let probe = response
            .hover_pos()
            .filter(|p| image_rect.contains(*p))
            .map(|pointer| {
                let local = (pointer - image_rect.min) / (image_rect.width() / size_px.x);
                Probe {
                    x: (local.x as u32).min(size[0].saturating_sub(1)),
                    y: (local.y as u32).min(size[1].saturating_sub(1)),
                }
            });
        ImageResponse {
            response,
            view: rect,
            image: image_rect,
            probe,
            zoom,
        }
    }

    fn pan_for(&self, zoom: Zoom) -> Vec2 {
        match zoom {
            Zoom::Fit => Vec2::ZERO,
            Zoom::Scale(_) => self.pan,
        }
    }

    /// Centres the image (used by "Fit" and "1:1").
    pub fn recentre(&mut self) {
        self.pan = Vec2::ZERO;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(r: Rect) -> f32 {
        r.width() * r.height()
    }

    #[test]
    fn the_backdrop_covers_exactly_what_the_image_leaves_bare() {
        let view = Rect::from_min_max(Pos2::new(10.0, 20.0), Pos2::new(810.0, 620.0));
        for image in [
            // Inside, letterboxed, overhanging one side, larger than the view, elsewhere.
            Rect::from_min_max(Pos2::new(100.0, 100.0), Pos2::new(500.0, 400.0)),
            Rect::from_min_max(Pos2::new(10.0, 80.0), Pos2::new(810.0, 560.0)),
            Rect::from_min_max(Pos2::new(600.0, -50.0), Pos2::new(1000.0, 300.0)),
            Rect::from_min_max(Pos2::new(-100.0, -100.0), Pos2::new(2000.0, 2000.0)),
            Rect::from_min_max(Pos2::new(900.0, 0.0), Pos2::new(1000.0, 50.0)),
        ] {
            let bands = uncovered(view, image);
            let shown = view.intersect(image);
            let shown_area = if shown.is_positive() { area(shown) } else { 0.0 };
            let total: f32 = bands.iter().map(|b| area(*b)).sum();
            assert!(
                (total + shown_area - area(view)).abs() < 1e-2,
                "{image:?}: {bands:?}"
            );
            for (k, b) in bands.iter().enumerate() {
                assert!(view.contains_rect(*b));
                assert!(!b.intersect(image).is_positive(), "{b:?} overlaps the image");
                for c in &bands[k + 1..] {
                    assert!(!b.intersect(*c).is_positive());
                }
            }
        }
    }
}
