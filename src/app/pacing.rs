//! Frame pacing for a window painted on the CPU. Where the window's GPU is a software
//! rasteriser (lavapipe, llvmpipe), every UI frame takes the same cores as the render, and the
//! UI repaints as fast as it can while a drag moves the pointer. While an edit waits for its
//! first image, the UI paints at most [`EDIT_FRAME_INTERVAL`] apart, so the render gets the
//! cores it needs to make that image, and a frame without input (the pointer rests after a
//! move) waits for the image, up to [`IDLE_FRAME_INTERVAL`]: it would paint the same picture
//! again. At every other time, and on a real GPU, frames are not paced.
//!
//! Why 50 ms: under Xvfb (lavapipe, 2 cores), `caustic view scenes/teapot.toml --bench`'s
//! median drag step to its new image was 630–700 ms unpaced (the UI at 25 fps while dragging),
//! 510–550 ms at 50 ms between frames (19 fps) and 400 ms at 100 ms (11 fps), with the panels
//! still painting their fills; 50 ms keeps a drag's overlay at about 20 fps. With the panels on
//! the clear colour ([`super::viewer::Viewer::panels_on_clear_colour`]) the step is 330–340 ms
//! at 50 ms, the UI at 21 fps while dragging.
//!
//! Why a frame without input waits: each frame painted while the pointer rests repaints the
//! same picture and takes ~20 ms of the render's cores. Waiting for the image took the same
//! bench's steps from 282–288 ms to 198–199 ms (control point) and from 300–334 ms to
//! 215–220 ms (light); a pointer that moves still paints every 50 ms.

use std::time::{Duration, Instant};

/// The shortest time between two UI frames while an edit waits for its first image, where the
/// window is painted on the CPU.
pub const EDIT_FRAME_INTERVAL: Duration = Duration::from_millis(50);

/// The shortest time between two UI frames while an edit waits for its first image and the
/// frame has no input (the pointer rests): nothing on screen would change but the image, so
/// the frame waits for it, at most this long.
pub const IDLE_FRAME_INTERVAL: Duration = Duration::from_millis(250);

/// How often a paced frame looks whether the image it waits for has come.
pub const POLL_INTERVAL: Duration = Duration::from_millis(4);

/// When the last frame began, and whether frames are paced at all.
#[derive(Clone, Copy, Debug, Default)]
pub struct FramePacer {
    /// Whether the window is painted by a software rasteriser (pacing applies).
    pub software: bool,
    last: Option<Instant>,
}

impl FramePacer {
    /// A pacer for a window painted by a software rasteriser when `software`.
    pub fn new(software: bool) -> Self {
        Self { software, last: None }
    }

    /// How long the frame beginning `now` waits: while `edit_pending` on a software
    /// rasteriser, what is left of [`EDIT_FRAME_INTERVAL`] since the last frame began, or of
    /// [`IDLE_FRAME_INTERVAL`] when the frame has no `input`; else nothing.
    pub fn delay(&self, now: Instant, edit_pending: bool, input: bool) -> Duration {
        let interval = if input {
            EDIT_FRAME_INTERVAL
        } else {
            IDLE_FRAME_INTERVAL
        };
        match self.last {
            Some(last) if self.software && edit_pending => {
                interval.saturating_sub(now.saturating_duration_since(last))
            }
            _ => Duration::ZERO,
        }
    }

    /// Waits as [`FramePacer::delay`] says, or until `arrived()` (checked every
    /// [`POLL_INTERVAL`]: the awaited image is there to show), then notes that a frame begins.
    pub fn wait(&mut self, (edit_pending, input): (bool, bool), arrived: impl Fn() -> bool) {
        let until = Instant::now() + self.delay(Instant::now(), edit_pending, input);
        while !arrived() {
            let left = until.saturating_duration_since(Instant::now());
            if left.is_zero() {
                break;
            }
            std::thread::sleep(left.min(POLL_INTERVAL));
        }
        self.last = Some(Instant::now());
    }
}

/// Whether `render_state`'s adapter is a software rasteriser (it runs on the CPU).
pub fn paints_on_cpu(render_state: &eframe::egui_wgpu::RenderState) -> bool {
    render_state.adapter.get_info().device_type == eframe::wgpu::DeviceType::Cpu
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_wait_only_on_a_software_rasteriser_while_an_edit_is_pending() {
        let start = Instant::now();
        let mut pacer = FramePacer::new(true);
        // The first frame never waits.
        assert_eq!(pacer.delay(start, true, true), Duration::ZERO);
        pacer.last = Some(start);
        let soon = start + Duration::from_millis(20);
        assert_eq!(pacer.delay(soon, true, true), Duration::from_millis(30));
        assert_eq!(pacer.delay(soon, false, true), Duration::ZERO);
        // Without input the frame waits for the image, up to a quarter second.
        assert_eq!(pacer.delay(soon, true, false), Duration::from_millis(230));
        assert_eq!(pacer.delay(soon, false, false), Duration::ZERO);
        assert_eq!(
            pacer.delay(start + Duration::from_millis(80), true, true),
            Duration::ZERO
        );
        let gpu = FramePacer {
            software: false,
            last: Some(start),
        };
        assert_eq!(gpu.delay(soon, true, true), Duration::ZERO);
        assert_eq!(gpu.delay(soon, true, false), Duration::ZERO);
    }
}
