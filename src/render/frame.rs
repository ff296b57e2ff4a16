//! What a render hands on after each pass: a [`Frame`] (radiance and the per-pixel layers its
//! renderer describes) and what its integrator measured ([`FrameStats`]: the rows the viewer
//! shows, the lines and JSON the command line prints, the metadata an image records). The
//! integrator fills them in; the session, the viewer and the command line only pass them on.

use std::sync::Arc;

use crate::render::error_tracker::Restarts;
use crate::settings::RendererKind;

/// A per-pixel quantity a renderer describes besides radiance (photon mapping: its search
/// radius and photon count): shown in false colour by the viewer and in its probe, written as
/// the EXR layer `NAME.Y`, sent to tev.
#[derive(Clone, Debug)]
pub struct PixelLayer {
    /// Its name in files and tev (`radius`).
    pub name: &'static str,
    /// Its name in the viewer (`Search radius`).
    pub label: &'static str,
    /// What it means.
    pub help: &'static str,
    /// Decimals its values are shown with.
    pub decimals: usize,
    /// One value a pixel, rows from the top.
    pub values: Arc<[f32]>,
}

/// A pixel's radiance and each layer with its value there ([`Frame::pixel`]).
pub type Probed<'a> = ([f32; 3], Vec<(&'a PixelLayer, f32)>);

/// One statistic as the viewer shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct StatRow {
    /// Its name.
    pub label: String,
    /// Its value, formatted.
    pub value: String,
    /// What it means.
    pub tip: String,
}

impl StatRow {
    /// A row.
    pub fn new(label: &str, value: String, tip: &str) -> Self {
        Self {
            label: label.to_owned(),
            value,
            tip: tip.to_owned(),
        }
    }
}

/// What a frame's integrator measured.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameStats {
    /// Which renderer made the frame.
    pub kind: RendererKind,
    /// Seconds the renderer spent (all passes of the epoch for a progressive one).
    pub seconds: f64,
    /// The viewer's statistics rows for this renderer.
    pub rows: Vec<StatRow>,
    /// The command line's closing summary: the first line follows `FILE: WxH`, the others are
    /// printed as they are.
    pub summary: Vec<String>,
    /// Work the scene let the renderer skip, in words.
    pub skipped: Vec<String>,
    /// The statistics as JSON, under the renderer's key (`caustic render --json`).
    pub json: serde_json::Value,
    /// `caustic:*` metadata the saved image records.
    pub metadata: Vec<(String, String)>,
    /// A short line of how fast it goes (`1.23 M photons/s`), for progress bars; may be empty.
    pub progress: String,
}

impl FrameStats {
    /// Seconds the renderer spent on the frame (all passes of the epoch for photon mapping).
    pub fn elapsed_secs(&self) -> f64 {
        self.seconds
    }

    /// Which renderer made the frame.
    pub fn renderer(&self) -> RendererKind {
        self.kind
    }
}

/// One finished pass, as the viewer needs it.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Increases whenever accumulated statistics are discarded.
    pub epoch: u64,
    /// Passes completed in this epoch (1 for a ray-traced frame).
    pub pass: u32,
    /// Photons emitted in this epoch, or paths traced by a renderer without photons: the
    /// sample count that error estimates between two frames scale by (0 for a single frame).
    pub photons: u64,
    /// Where and when estimates started again in this epoch, no longer counting earlier
    /// passes: a frame from before is not part of this one there, and an error estimate
    /// that compares the two must know ([`crate::render::error_tracker`]).
    pub restarts: Restarts,
    /// Seconds since this epoch started.
    pub elapsed_secs: f64,
    /// What the renderer measured (and so which renderer made it).
    pub stats: FrameStats,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Linear RGB radiance, `width × height` pixels, rows from the top.
    pub radiance: Arc<[[f32; 3]]>,
    /// The per-pixel layers the renderer describes (none for some renderers).
    pub layers: Vec<PixelLayer>,
    /// A quick low-resolution preview of a new epoch (pass 0), enlarged to full size.
    pub preview: bool,
    /// Where its error estimate comes from.
    pub error: ErrorSource,
}

/// Where a frame's error estimate comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ErrorSource {
    /// The viewer compares it with the epoch's earlier frames
    /// ([`crate::render::error_tracker`]).
    #[default]
    Frames,
    /// The spread of the independent passes it merges (a watched folder's parts); `None`
    /// before two.
    PassSpread(Option<f64>),
}

impl Frame {
    /// A frame of `radiance` with no per-pixel search statistics.
    pub fn of_radiance(
        (width, height): (u32, u32),
        radiance: Vec<[f32; 3]>,
        pass: u32,
        (epoch, elapsed_secs): (u64, f64),
        stats: FrameStats,
    ) -> Frame {
        Frame {
            epoch,
            pass,
            photons: 0,
            restarts: Restarts::default(),
            elapsed_secs,
            stats,
            width,
            height,
            radiance: radiance.into(),
            layers: Vec::new(),
            preview: false,
            error: ErrorSource::Frames,
        }
    }

    /// Pixel `(x, y)`'s radiance and each layer's label and value, or `None` outside the
    /// frame (a probe taken on an earlier frame of another size).
    pub fn pixel(&self, x: u32, y: u32) -> Option<Probed<'_>> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let i = y as usize * self.width as usize + x as usize;
        let layers = self
            .layers
            .iter()
            .map(|l| Some((l, *l.values.get(i)?)))
            .collect::<Option<_>>()?;
        Some((*self.radiance.get(i)?, layers))
    }

    /// The layer named `name`.
    pub fn layer(&self, name: &str) -> Option<&PixelLayer> {
        self.layers.iter().find(|l| l.name == name)
    }

    /// This frame at a larger size `(w, h)` (nearest neighbour), marked as a preview.
    pub fn enlarged_preview(self, (w, h): (u32, u32)) -> Frame {
        let small = (self.width, self.height);
        Frame {
            pass: 0,
            photons: 0,
            width: w,
            height: h,
            radiance: enlarge(&self.radiance, small, (w, h)),
            layers: self
                .layers
                .iter()
                .map(|l| PixelLayer {
                    values: enlarge(&l.values, small, (w, h)),
                    ..l.clone()
                })
                .collect(),
            preview: true,
            ..self
        }
    }
}

/// Nearest-neighbour enlargement of a `(sw, sh)` image to `(w, h)`.
fn enlarge<T: Copy>(src: &[T], (sw, sh): (u32, u32), (w, h): (u32, u32)) -> Arc<[T]> {
    (0..h)
        .flat_map(|y| {
            let sy = (y as u64 * sh as u64 / h as u64) as usize;
            (0..w).map(move |x| src[sy * sw as usize + (x as u64 * sw as u64 / w as u64) as usize])
        })
        .collect()
}
