//! Getting a design ready, for `caustic design` and the viewer's Design panel alike: the
//! options and their checks, the surface and receiver found by name and checked, the surface
//! refined, the parameters, the photons, the target on the receiver's grid and the settings of
//! the descent ([`super::optimize`]).

use super::landing::{surface_bounds, DesignParams, Receiver};
use super::optimize::{design, DesignOutcome, DesignSettings, StepReport};
use super::photons::{design_lights, design_photons, DesignPhoton};
use super::refine::refined;
use super::target::Target;
use crate::scene::material::MaterialKind;
use crate::scene::Scene;

/// What a person chooses about a design (the flags of `caustic design`).
#[derive(Clone, Debug, PartialEq)]
pub struct DesignOptions {
    /// Stop after this many seconds.
    pub seconds: f64,
    /// Steps of the descent (the same steps give the same surface on any machine).
    pub steps: usize,
    /// Photons traced at every step (eight times as many are prepared, used in turn).
    pub photons: usize,
    /// How far a control point may move (`None`: a tenth of the surface's size).
    pub max_height: Option<f64>,
    /// Weight of the smoothness term.
    pub smoothness: f64,
    /// Times a surface of Bézier patches is split into four a patch first.
    pub refine: u32,
    /// Cells of the receiver grid along its longer edge.
    pub grid: usize,
}

impl Default for DesignOptions {
    /// The defaults of `caustic design`: a design that ends in under 2 minutes on 2 cores.
    fn default() -> Self {
        Self {
            seconds: 110.0,
            steps: 1500,
            photons: 20_000,
            max_height: None,
            smoothness: 0.01,
            refine: 2,
            grid: 48,
        }
    }
}

/// The photon subsets used in turn, one a step ([`DesignSettings::subsets`]).
const SUBSETS: usize = 8;

impl DesignOptions {
    /// Checks the numbers; the error names the option as `caustic design`'s flag.
    pub fn check(&self) -> Result<(), String> {
        if !(self.seconds.is_finite() && self.seconds > 0.0 && self.seconds <= 86_400.0) {
            return Err(format!(
                "--seconds must be above 0 and at most a day, got {}",
                self.seconds
            ));
        }
        if !(1..=1_000_000).contains(&self.steps) {
            return Err(format!(
                "--steps must be between 1 and 1,000,000, got {}",
                self.steps
            ));
        }
        if !(100..=10_000_000).contains(&self.photons) {
            return Err(format!(
                "--photons must be between 100 and 10,000,000, got {}",
                self.photons
            ));
        }
        if self.refine > 4 {
            return Err(format!("--refine must be between 0 and 4, got {}", self.refine));
        }
        if !(4..=512).contains(&self.grid) {
            return Err(format!("--grid must be between 4 and 512, got {}", self.grid));
        }
        if !(self.smoothness.is_finite() && self.smoothness >= 0.0) {
            return Err(format!(
                "--smoothness must be a number of 0 or more, got {}",
                self.smoothness
            ));
        }
        match self.max_height {
            Some(h) if !(h.is_finite() && h > 0.0) => {
                Err(format!("--max-height must be a positive number, got {h}"))
            }
            _ => Ok(()),
        }
    }
}

/// A design ready to run.
pub struct PreparedDesign {
    /// The scene, its surface refined as asked.
    pub scene: Scene,
    /// The surface's object number.
    pub surface: u32,
    /// The receiver.
    pub receiver: Receiver,
    /// What moves.
    pub params: DesignParams,
    /// The photons, [`DesignSettings::subsets`] interleaved sets of them.
    pub photons: Vec<DesignPhoton>,
    /// How the descent runs.
    pub settings: DesignSettings,
    /// The target on the receiver's grid (row 0 at `corner + edge_v`), summing to 1.
    pub target_grid: Vec<f64>,
}

impl PreparedDesign {
    /// Runs the design ([`super::optimize::design`]): the scene's surface ends moved, and
    /// `report` hears every step (and may end the design).
    pub fn run(
        &mut self,
        report: impl FnMut(&StepReport, &[f64]) -> std::ops::ControlFlow<()>,
    ) -> DesignOutcome {
        design(
            &mut self.scene,
            (&self.params, &self.receiver),
            &self.photons,
            &self.target_grid,
            &self.settings,
            report,
        )
    }
}

/// The object named `name`, or an error naming `role` and listing the names.
fn object_named(scene: &Scene, name: &str, role: &str) -> Result<u32, String> {
    match scene.objects.iter().position(|o| o.name == name) {
        Some(k) => Ok(k as u32),
        None => {
            let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
            Err(format!(
                "{role}: the scene has no object named '{name}' (it has: {})",
                names.join(", ")
            ))
        }
    }
}

/// Whether material `material` of `scene` is smooth glass or a smooth mirror: what sends light
/// in a shape a design can change.
fn smooth_specular(scene: &Scene, material: usize) -> bool {
    match &scene.materials[material].kind {
        MaterialKind::Glass { roughness, .. } | MaterialKind::Mirror { roughness } => *roughness == 0.0,
        _ => false,
    }
}

/// Why object `surface` cannot be designed (`None`: it can): it must be patches of smooth
/// glass or mirror.
fn unsuitable_surface(scene: &Scene, surface: u32, name: &str) -> Option<String> {
    if !scene.geometry.patches().iter().any(|(_, id)| *id == surface) {
        return Some(format!(
            "--surface: '{name}' has no patches (it must be a `patches` object)"
        ));
    }
    (!smooth_specular(scene, scene.objects[surface as usize].material)).then(|| format!("--surface: '{name}' is not smooth glass or a smooth mirror: the light it sends has no shape to design"))
}

/// The names of the objects a design may shape (patches of smooth glass or mirror) and of
/// those it may draw on (quads), in scene order: what the viewer's Design panel offers.
pub fn design_candidates(scene: &Scene) -> (Vec<String>, Vec<String>) {
    let with_patches: std::collections::BTreeSet<u32> =
        scene.geometry.patches().iter().map(|(_, id)| *id).collect();
    let mut surfaces = Vec::new();
    let mut receivers = Vec::new();
    for (k, object) in scene.objects.iter().enumerate() {
        if with_patches.contains(&(k as u32)) && smooth_specular(scene, object.material) {
            surfaces.push(object.name.clone());
        }
        if scene.geometry.quad_of(k as u32).is_some() {
            receivers.push(object.name.clone());
        }
    }
    (surfaces, receivers)
}

/// Gets a design of object `surface` drawing `target` on object `receiver` of `scene` ready:
/// checks the options and objects, refines the surface (`options.refine`), finds the
/// parameters and traces the photons. Errors name the option or object at fault.
pub fn prepare_design(
    mut scene: Scene,
    (surface_name, receiver_name): (&str, &str),
    target: &Target,
    options: &DesignOptions,
) -> Result<PreparedDesign, String> {
    options.check()?;
    let surface = object_named(&scene, surface_name, "--surface")?;
    let receiver = object_named(&scene, receiver_name, "--receiver")?;
    let Some(quad) = scene.geometry.quad_of(receiver) else {
        return Err(format!("--receiver: '{receiver_name}' is not a quad"));
    };
    if let Some(why) = unsuitable_surface(&scene, surface, surface_name) {
        return Err(why);
    }
    if let Some(finer) =
        refined(&scene, (surface, surface_name), options.refine).map_err(|e| format!("--refine: {e}"))?
    {
        scene = finer;
    }
    let bounds = surface_bounds(&scene, surface).ok_or("--surface: the surface has no patches")?;
    let (centre, size) = (
        (bounds.min + bounds.max) * 0.5,
        (bounds.max - bounds.min).length(),
    );
    // The points move along the direction from the first light to the surface.
    let light = design_lights(&scene)?[0].0;
    let params = DesignParams::of_object(&scene, surface, centre - light)
        .map_err(|e| format!("--surface '{surface_name}': {e}"))?;
    let photons = design_photons(&scene, surface, SUBSETS * options.photons)?;
    let (eu, ev) = (quad.edge_u.length(), quad.edge_v.length());
    let grid = if eu >= ev {
        (
            options.grid,
            ((options.grid as f64 * ev / eu).round() as usize).max(4),
        )
    } else {
        (
            ((options.grid as f64 * eu / ev).round() as usize).max(4),
            options.grid,
        )
    };
    let max_height = options.max_height.unwrap_or(0.1 * size);
    Ok(PreparedDesign {
        target_grid: target.resampled(grid.0, grid.1),
        settings: DesignSettings {
            grid,
            sigma: 0.75,
            smoothness: options.smoothness,
            max_height,
            step: max_height / 40.0,
            subsets: SUBSETS,
            seconds: options.seconds,
            max_steps: options.steps,
            bounces: 16,
        },
        scene,
        surface,
        receiver: Receiver {
            object: receiver,
            quad,
        },
        params,
        photons,
    })
}
