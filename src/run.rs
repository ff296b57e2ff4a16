//! What several commands share: the scene a command names (or a built-in one), a headless
//! render session run to its end, a progress bar.

use std::path::Path;

use anyhow::{bail, Context, Result};

use crate::render::session::{Frame, RenderSession, SessionOptions};
use crate::scene::Scene;

/// A progress bar over `len` steps (drawn only on a terminal).
pub fn progress_bar(len: u64, template: &str, message: String) -> Result<indicatif::ProgressBar> {
    let bar = indicatif::ProgressBar::new(len).with_style(
        indicatif::ProgressStyle::with_template(template)
            .context("progress bar template")?
            .progress_chars("=> "),
    );
    bar.set_message(message);
    Ok(bar)
}

/// The scene a photon-mapping bench measures: the file, or smallppm's built-in scene.
pub fn photon_scene(path: Option<&Path>) -> Result<Scene> {
    scene_or_built_in(path, crate::assets::SMALLPPM_SCENE, "smallppm")
}

/// The scene file at `path`, or when none is given the scene text `built_in` (a bench's
/// default, built into the binary so it runs from any directory), named `<built-in name>`.
pub fn scene_or_built_in(path: Option<&Path>, built_in: &str, name: &str) -> Result<Scene> {
    Ok(match path {
        Some(p) => Scene::load(p)?,
        None => Scene::from_str(built_in, Path::new(&format!("<built-in {name}>")), None)?,
    })
}

/// The scene file at `path`, or the built-in scene.
pub fn load_scene(path: Option<&Path>) -> Result<Scene> {
    match path {
        Some(p) => Ok(Scene::load(p)?),
        None => Ok(Scene::builtin()),
    }
}

/// Photon-maps `scene` (its renderer must be photon mapping) on a headless render session —
/// the viewer's render loop — until the session's limits end it; `on_frame` sees every
/// completed pass. Returns the last frame.
pub fn render_session(
    scene: Scene,
    options: SessionOptions,
    mut on_frame: impl FnMut(&Frame),
) -> Result<Frame> {
    let options = SessionOptions {
        every_frame: true,
        ..options
    };
    let session = RenderSession::start_with(scene, options, None);
    let mut last = None;
    for frame in session.frames().iter() {
        on_frame(&frame);
        last = Some(frame);
    }
    if let Some(failure) = session.failure() {
        bail!("the renderer failed: {failure}");
    }
    last.context("the renderer stopped before completing a pass")
}
