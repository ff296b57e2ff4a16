//! Render settings, below both the scene and the renderers: the one parameter set
//! ([`RenderParams`], a scene file's `[render]` table), which renderer makes the image
//! ([`RendererKind`]), the photon mapper's spatial index ([`IndexKind`]) and radius schedule ([`RadiusSchedule`]) and the one table of
//! ranges every setting is checked against ([`limits`]). `scene` reads them from files and
//! `render` runs with them; this module imports neither.

pub mod docs;
pub mod flags;
mod index;
pub mod limits;
mod params;
mod renderer;
mod schedule;
pub mod setting;

pub use flags::SettingFlags;
pub use index::IndexKind;
pub use params::{find_setting, InvalidParam, RenderParams, SETTINGS};
pub(crate) use renderer::with_renderers;
pub use renderer::RendererKind;
pub use schedule::RadiusSchedule;
