//! Renderers and what they render into: progressive photon mapping, the Whitted ray tracer,
//! the film (linear RGB with tonemapping and PNG/EXR output, extra EXR layers), what an image
//! records of its render ([`provenance`]), error against a reference or estimated
//! ([`compare`], [`error`], [`error_tracker`]), deterministic random streams and low-discrepancy sequences, single
//! wavelengths for dispersion ([`spectrum`], [`wavelength`]), and
//! independent passes split across processes and merged ([`shard`]).

pub mod bsdf;
pub mod compare;
pub mod control;
pub mod error;
pub mod error_tracker;
pub mod film;
pub mod frame;
pub mod integrator;
pub mod mis;
pub mod ppm;
pub mod provenance;
pub mod rng;
pub mod sequence;
pub mod session;
pub mod shard;
pub mod spectrum;
pub mod vcm;
pub mod wavelength;
pub mod whitted;

pub use film::{Image, Layer, Metadata};
pub use provenance::image_metadata;
pub use whitted::{render_whitted, render_whitted_until, WhittedStats};
