//! Render settings, below both the scene and the renderers: the one parameter set
//! ([`RenderParams`], a scene file's `[render]` table), which renderer makes the image
//! ([`RendererKind`]), the photon mapper's spatial index ([`IndexKind`]) and radius schedule ([`RadiusSchedule`]) and the one table of
//! ranges every setting is checked against ([`limits`]). `scene` reads them from files and
//! `render` runs with them; this module imports neither.

mod index;
pub mod limits;
mod params;
mod renderer;
mod schedule;

pub use index::IndexKind;
pub use params::RenderParams;
pub use renderer::RendererKind;
pub use schedule::RadiusSchedule;
