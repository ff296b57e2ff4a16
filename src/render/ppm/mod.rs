//! Progressive photon mapping (Hachisuka, Ogaki & Jensen 2008) and its stochastic variant
//! (Hachisuka & Jensen 2009), as the seed report §3.2 describes it, physically scaled.
//!
//! Each pass: (1) the eye pass records visible points ([`visible`]) — once for a pinhole
//! camera without anti-aliasing (classic PPM, glass paths split), or every pass with jittered
//! pixel and lens samples (stochastic PPM, one point per pixel, per-pixel statistics); (2) a
//! spatial index over the points is built ([`HashGrid`] or the seed's [`KdTree`]); (3) photons
//! are traced ([`photon`]) and hand flux to points within their radius; (4) every statistics
//! slot is updated with the paper's rule
//!
//! `N' = N + αM`, `R'² = R²·(N + αM)/(N + M)`, `τ' = (τ + φ)·(N + αM)/(N + M)`;
//!
//! and the radiance is `L = τ / (π R² N_emitted)` plus light seen directly (in stochastic
//! passes supersampled where it changes within a pixel, `seen.rs`). No brightness
//! factor: exposure belongs to the viewer. After the first pass, two per-point choices are
//! made from its photon counts: the indirect estimate's radius (`RadiusPolicy::widen_indirect`) and
//! a restart of the primary one, narrower where photons are dense and wider where they are
//! sparse (`RadiusPolicy::adapt_radii`, the adaptive radius: in the spirit of classic photon
//! mapping's k-nearest-neighbour radius, Jensen 2001, chosen once and then shrunk by the
//! paper's rule).
//!
//! Determinism: photon `i` of the render uses the random stream `(seed, photon, i)` (and, when
//! photons are stratified, point `i` of Sobol's sequence under a shift drawn from the seed), pixels
//! `(seed, pass, pixel)`; photons are traced in fixed chunks, their hits sorted by cell
//! with ties in photon order and handed in fixed groups whose deposits are applied in group
//! order (`deposit.rs`), so the image is bit-identical for any number of threads.
//!
//! [`Ppm`] (`progressive.rs`) runs a pass through parts that own their state: the statistics
//! slots (`estimates.rs`, each slot's [`Estimate`]s in `estimate.rs`), the eye pass
//! (`eye_pass.rs`), the photon pass (`photon_pass.rs`, handing flux in `deposit.rs`), the
//! radius policy (`radius.rs`), the emission guide ([`guide`]), the light seen directly
//! (`light.rs`, supersampled by `seen.rs`), warm restarts ([`warm`], whose first pass copies
//! what an edit cannot have changed, `reuse.rs`) and the global radius schedule (`global.rs`). This file only declares them.

mod config;
mod deposit;
mod estimate;
mod estimates;
mod eye_pass;
mod gathered;
mod global;
mod index;
mod layers;
mod light;
mod photon_pass;
mod points;
mod progressive;
mod radius;
mod reuse;
mod seen;
mod stats;
mod streams;
mod sweep;

pub mod direct;
pub mod guide;
pub mod hash_grid;
pub mod kd_tree;
pub mod photon;
pub mod visible;
pub mod warm;

pub use crate::render::control::{Control, Interrupt};
pub use config::{PpmOptions, DEFAULT_BATCH_PHOTONS};
pub use estimate::{Estimate, Restart, Slot};
pub use global::schedule_factor;
pub use hash_grid::HashGrid;
pub use index::SpatialIndex;
pub use kd_tree::KdTree;
pub use layers::PixelLayers;
pub use points::SearchSphere;
pub use progressive::{PassOutcome, Ppm};
pub use radius::footprint_radius;
pub use reuse::Changed;
pub use seen::{SUBSAMPLES, VARIED_SUBSAMPLES};
pub use stats::PpmStats;
pub use warm::{StreamOffset, WarmStart};
