//! wgpu for the snapshot tests: the adapter wgpu finds on this machine (Mesa's lavapipe Vulkan,
//! or llvmpipe GL where Vulkan is absent), and one stored snapshot per backend, since the two
//! rasterise thin lines and text a few hundred to a few thousand pixels apart.
#![cfg(feature = "viewer")]

use std::path::{Path, PathBuf};

use eframe::egui_wgpu::{self, wgpu, RenderState};

/// What to install when no adapter can be had.
const NO_ADAPTER: &str = "no wgpu adapter: the viewer's snapshot tests render with wgpu. \
Install Mesa's software drivers: `apt-get install mesa-vulkan-drivers libvulkan1` (lavapipe, \
Vulkan) or `apt-get install libegl1 libgl1-mesa-dri` (llvmpipe, GL); with several, \
WGPU_BACKEND=vulkan or WGPU_BACKEND=gl picks one";

/// A fresh wgpu render state for kittest, on the adapter egui_kittest prefers (a CPU one), and
/// the backend it uses. Fails, saying what to install, when there is none.
pub fn render_state() -> (RenderState, &'static str) {
    let created = std::panic::catch_unwind(|| {
        egui_kittest::wgpu::create_render_state(
            egui_kittest::wgpu::default_wgpu_setup(),
            egui_wgpu::RendererOptions::PREDICTABLE,
        )
    });
    let state = created.unwrap_or_else(|_| panic!("{NO_ADAPTER}"));
    let info = state.adapter.get_info();
    let backend = match info.backend {
        wgpu::Backend::Vulkan => "vulkan",
        wgpu::Backend::Gl => "gl",
        other => panic!(
            "snapshots are kept for Mesa's lavapipe (Vulkan) and llvmpipe (GL); wgpu chose {other:?} \
             ({}): set WGPU_BACKEND=vulkan or WGPU_BACKEND=gl",
            info.name
        ),
    };
    (state, backend)
}

/// A harness renderer on a fresh render state, and the backend it uses.
pub fn renderer() -> (egui_kittest::wgpu::WgpuTestRenderer, &'static str) {
    let (state, backend) = render_state();
    (
        egui_kittest::wgpu::WgpuTestRenderer::from_render_state(state),
        backend,
    )
}

/// The snapshot name for `name` on `backend`: `tests/snapshots/{name}.{backend}.png`.
pub fn snapshot_name(name: &str, backend: &str) -> String {
    format!("{name}.{backend}")
}

/// The stored snapshot file of `name` on `backend`.
pub fn snapshot_path(name: &str, backend: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/snapshots")
        .join(format!("{}.png", snapshot_name(name, backend)))
}

/// How many pixels of `image` fail egui_kittest's comparison with the stored snapshot at the
/// project's tolerance (`kittest.toml`'s defaults: per-pixel threshold 0.6, no failing pixel
/// allowed), computed as `Harness::snapshot` computes it.
pub fn failing_pixels(stored: &Path, image: &image::RgbaImage) -> usize {
    let previous = image::open(stored)
        .unwrap_or_else(|e| panic!("{}: {e}", stored.display()))
        .to_rgba8();
    assert_eq!(previous.dimensions(), image.dimensions());
    let threshold = egui_kittest::SnapshotOptions::default().threshold;
    dify::diff::get_results(previous, image.clone(), threshold, true, None, &None, &None)
        .map_or(0, |(wrong, _)| wrong as usize)
}
