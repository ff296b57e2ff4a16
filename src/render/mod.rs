//! Renderers and what they render into: progressive photon mapping, the Whitted ray tracer, the film (linear RGB with
//! tonemapping and PNG/EXR output) and deterministic random streams. DESIGN.md §3.

pub mod film;
pub mod ppm;
pub mod rng;
pub mod session;
pub mod whitted;

pub use film::{Image, Metadata};
pub use whitted::{render_whitted, WhittedStats};
