//! Renderers and what they render into: progressive photon mapping, the Whitted ray tracer, the film (linear RGB with
//! tonemapping and PNG/EXR output) and deterministic random streams.

pub mod film;
pub mod limits;
pub mod params;
pub mod ppm;
pub mod rng;
pub mod session;
pub mod whitted;

pub use film::{Image, Metadata};
pub use whitted::{render_whitted, render_whitted_until, WhittedStats};

/// Metadata every output image carries (software, scene, renderer, seed, size); callers
/// append renderer-specific pairs.
pub fn image_metadata(scene: &crate::scene::Scene, renderer: &str) -> Metadata {
    vec![
        (
            "Software".into(),
            format!("caustic {}", env!("CARGO_PKG_VERSION")),
        ),
        ("caustic:scene".into(), scene.source.display().to_string()),
        ("caustic:renderer".into(), renderer.into()),
        ("caustic:seed".into(), scene.params.seed.to_string()),
        (
            "caustic:size".into(),
            format!("{}x{}", scene.camera.width, scene.camera.height),
        ),
    ]
}
