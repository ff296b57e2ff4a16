//! Vertex connection and merging: path-traced and photon-mapped estimates of one image combined
//! by multiple importance sampling (Georgiev, Křivánek, Davidovič & Slusallek 2012, "Light
//! transport simulation with vertex connection and merging"; the same estimator as Hachisuka,
//! Pantaleoni & Jensen 2012, "A path space extension for robust light transport simulation").
//!
//! Each pass traces one light subpath and one camera subpath per pixel. A light subpath's
//! vertices on smooth surfaces are kept ([`light_path`]) and linked to the camera (light
//! tracing). A camera subpath ([`camera_path`]), at each smooth vertex, samples a light (next
//! event estimation), connects to every vertex of the light subpath of its own index (vertex
//! connection, the bidirectional path tracer's techniques) and merges with the light vertices
//! of all the pass's subpaths within the pass's radius (vertex merging, photon mapping's
//! density estimate). Every path is so sampled by several techniques; each is weighted by the
//! power heuristic over all of them. The weights are computed from three quantities each
//! subpath carries and updates at every vertex ([`state::Subpath`]), as Georgiev's technical
//! report "Implementing vertex connection and merging" (2012) derives them, so that no
//! subpath is walked again to weigh a connection.
//!
//! The radius shrinks pass by pass as `r₀ · (pass + 1)^((α − 1)/2)` (Knaus & Zwicker 2011's
//! schedule, which Georgiev et al. use): merging's bias vanishes and its share of the weight
//! with it, while the connections stay unbiased.
//!
//! [`Techniques`] switches either half off: without merging the estimator is a bidirectional
//! path tracer (Veach 1997, ch. 10); without connections it is progressive photon mapping with
//! eye paths that stop at the first smooth surface, every merge weighted 1.

pub mod camera_link;
pub mod camera_path;
pub mod emission;
pub mod light_path;
pub mod radius;
pub mod state;

/// Which of the two halves of the estimator run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Techniques {
    /// Vertex connection: light sampling at camera vertices, connections between the two
    /// subpaths, and light tracing to the camera.
    pub connect: bool,
    /// Vertex merging: photon density estimates at camera vertices.
    pub merge: bool,
}

impl Techniques {
    /// Both halves: the full estimator.
    pub const ALL: Techniques = Techniques {
        connect: true,
        merge: true,
    };
}

/// The power heuristic's weight of a density ratio (exponent 2): what every MIS quantity
/// here is made of.
#[inline]
pub fn mis(x: f64) -> f64 {
    x * x
}

/// What every vertex of one pass reads: the radius and the MIS factors it sets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassConstants {
    /// The techniques on.
    pub techniques: Techniques,
    /// The merging radius of this pass.
    pub radius: f64,
    /// Light subpaths of the pass (one per pixel).
    pub light_paths: f64,
    /// Vertex merging's weight beside a connection: `mis(π r² · light_paths)` (0 without
    /// merging).
    pub mis_vm: f64,
    /// A connection's weight beside merging: `mis(1 / (π r² · light_paths))` (0 without
    /// connections).
    pub mis_vc: f64,
    /// What a merged photon's contribution is divided by: `π r² · light_paths`.
    pub vm_normalization: f64,
    /// The most segments of a path, from the camera to the light.
    pub max_length: u32,
}

impl PassConstants {
    /// The constants of pass `pass` (from 0) of a render with initial radius `r0` and radius
    /// reduction `alpha`, `light_paths` light subpaths a pass.
    pub fn new(
        techniques: Techniques,
        r0: f64,
        alpha: f64,
        pass: u32,
        light_paths: usize,
        max_length: u32,
    ) -> Self {
        let radius = r0 * (pass as f64 + 1.0).powf(0.5 * (alpha - 1.0));
        let light_paths = light_paths.max(1) as f64;
        let eta = std::f64::consts::PI * radius * radius * light_paths;
        Self {
            techniques,
            radius,
            light_paths,
            mis_vm: if techniques.merge { mis(eta) } else { 0.0 },
            mis_vc: if techniques.connect { mis(1.0 / eta) } else { 0.0 },
            vm_normalization: 1.0 / eta,
            max_length,
        }
    }

    /// Whether merges are weighted at all: with connections off, every path a merge finds is
    /// found by that merge alone (the camera subpath stops at its first smooth vertex).
    pub fn weighs_merges(&self) -> bool {
        self.techniques.connect
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_radius_shrinks_with_alpha_and_the_factors_follow_it() {
        let k0 = PassConstants::new(Techniques::ALL, 0.1, 0.75, 0, 100, 10);
        let k3 = PassConstants::new(Techniques::ALL, 0.1, 0.75, 3, 100, 10);
        assert_eq!(k0.radius, 0.1);
        assert!((k3.radius - 0.1 * 4f64.powf(-0.125)).abs() < 1e-15);
        let eta = std::f64::consts::PI * k3.radius * k3.radius * 100.0;
        assert!((k3.mis_vm * k3.mis_vc - 1.0).abs() < 1e-12);
        assert!((k3.vm_normalization * eta - 1.0).abs() < 1e-12);
        let bpt = PassConstants::new(
            Techniques {
                connect: true,
                merge: false,
            },
            0.1,
            0.75,
            0,
            100,
            10,
        );
        assert_eq!(bpt.mis_vm, 0.0);
        assert!(bpt.mis_vc > 0.0);
    }
}
