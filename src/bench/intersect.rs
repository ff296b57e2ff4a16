//! `caustic bench intersect`: ray/patch intersection on the Utah teapot, nanoseconds per
//! hitting and per missing primary ray, one thread, for the prepared and the per-ray
//! intersectors.

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

use super::output::BenchOutput;
use super::{teapot_geometry, teapot_view, time_intersect};
use crate::geometry::{PatchMethod, SubdivisionParams};

/// `caustic bench intersect`'s flags.
#[derive(Args)]
pub struct IntersectArgs {
    /// Image side in pixels (rays = size²).
    #[arg(long, default_value_t = 512)]
    pub size: usize,
    /// Times each ray set is traced (more = steadier figures).
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Which intersectors to time.
    #[arg(long, value_enum, default_value_t = MethodChoice::Both)]
    pub method: MethodChoice,
    /// Subdivision depth of the per-ray (seed) intersector.
    #[arg(long, default_value_t = 5)]
    pub per_ray_depth: u32,
    /// Prepared leaves: flatness (control-point deviation / leaf diagonal).
    #[arg(long, default_value_t = SubdivisionParams::default().flatness)]
    pub flatness: f64,
    /// Prepared leaves: largest leaf diagonal / patch diagonal.
    #[arg(long, default_value_t = SubdivisionParams::default().max_size)]
    pub max_size: f64,
    /// Prepared leaves: subdivision depth limit, at most 8 (up to 4^8 leaves a patch: 2.1
    /// million for the teapot, 1.6 GB).
    #[arg(long, default_value_t = SubdivisionParams::default().max_depth)]
    pub max_depth: u32,
    /// The order the rays are traced in.
    #[arg(long, value_enum, default_value_t = RayOrder::Image)]
    pub order: RayOrder,
}

/// The order `bench intersect` traces its rays in.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RayOrder {
    /// Row by row through the image, as a camera's rays come: each ray walks the part of
    /// the tree its neighbour just walked, in cache, and takes the same branches.
    Image,
    /// A fixed random permutation of the same rays, as incoherent as a renderer's photons
    /// and secondary rays: the tree and the leaves come from further down the memory
    /// hierarchy and the walk's branches are harder to predict.
    Shuffled,
}

impl RayOrder {
    /// The flag's value, for the report.
    fn name(self) -> &'static str {
        match self {
            RayOrder::Image => "image",
            RayOrder::Shuffled => "shuffled",
        }
    }
}

/// Which intersectors `bench intersect` times.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodChoice {
    /// The prepared leaves (subdivided once, in the BVH).
    Prepared,
    /// Subdivision per ray.
    PerRay,
    /// Both.
    Both,
}

/// The deepest subdivision `bench intersect` prepares: the teapot's 32 patches may become
/// 4^8 leaves each (2.1 million, 1.6 GB and 6 s measured).
const MAX_LEAF_DEPTH: u32 = 8;

/// `bench intersect`'s flags, checked before anything is prepared.
fn check_intersect_args(
    size: usize,
    repeat: usize,
    per_ray_depth: u32,
    params: &SubdivisionParams,
) -> Result<()> {
    if size == 0 || size > 8192 {
        bail!("--size must be between 1 and 8192, got {size}");
    }
    if repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    if !(1..=30).contains(&per_ray_depth) {
        bail!("--per-ray-depth must be between 1 and 30, got {per_ray_depth}");
    }
    if !(params.flatness > 0.0 && params.max_size > 0.0) {
        bail!(
            "--flatness and --max-size must be positive, got {} and {}",
            params.flatness,
            params.max_size
        );
    }
    if params.max_depth > MAX_LEAF_DEPTH {
        // Each level may quarter every leaf: depth 9 could take 6 GB, 12 far more than memory.
        bail!(
            "--max-depth must be at most {MAX_LEAF_DEPTH} (up to 4^{MAX_LEAF_DEPTH} leaves a patch), got {}",
            params.max_depth
        );
    }
    Ok(())
}

/// Seed of [`RayOrder::Shuffled`]'s permutation: every run traces the rays in one order.
const SHUFFLE_SEED: u64 = 0x5EED_0F0D_3E00;

/// Runs `bench intersect`.
pub fn bench_intersect(args: IntersectArgs, out: &mut BenchOutput) -> Result<()> {
    let IntersectArgs {
        size,
        repeat,
        method,
        per_ray_depth,
        flatness,
        max_size,
        max_depth,
        order,
    } = args;
    let params = SubdivisionParams {
        flatness,
        max_size,
        max_depth,
        ..Default::default()
    };
    check_intersect_args(size, repeat, per_ray_depth, &params)?;
    let mut rays = teapot_view(size, size);
    if order == RayOrder::Shuffled {
        rays.shuffle(&mut Pcg64Mcg::seed_from_u64(SHUFFLE_SEED));
    }
    out.say(format!(
        "Utah teapot (32 patches), {size}x{size} primary rays in {} order, 1 thread, {repeat} repeats",
        order.name()
    ));
    out.set("size", size);
    out.set("repeat", repeat);
    out.set("order", order.name());
    out.say(format!(
        "{:<22} {:>9} {:>9} {:>12} {:>13}",
        "intersector", "hit rays", "miss rays", "ns/hit ray", "ns/miss ray"
    ));
    let mut methods = Vec::new();
    if method != MethodChoice::PerRay {
        methods.push(("prepared".to_owned(), PatchMethod::Prepared(params)));
    }
    if method != MethodChoice::Prepared {
        methods.push((
            format!("per-ray (depth {per_ray_depth})"),
            PatchMethod::PerRay { depth: per_ray_depth },
        ));
    }
    for (name, m) in methods {
        let start = std::time::Instant::now();
        let geometry = teapot_geometry(m);
        let prep_ms = start.elapsed().as_secs_f64() * 1e3;
        let t = time_intersect(&name, &geometry, &rays, repeat);
        out.say(format!(
            "{:<22} {:>9} {:>9} {:>12.1} {:>13.1}",
            t.method, t.hit_rays, t.miss_rays, t.ns_per_hit, t.ns_per_miss
        ));
        let s = geometry.stats();
        out.say(format!(
            "    prepare {prep_ms:.2} ms; {} BVH primitives ({} patch leaves), {} nodes, depth {}",
            s.primitives, s.patch_leaves, s.bvh_nodes, s.bvh_depth
        ));
        out.push(
            "intersectors",
            serde_json::json!({
                "method": t.method,
                "hit_rays": t.hit_rays,
                "miss_rays": t.miss_rays,
                "ns_per_hit": t.ns_per_hit,
                "ns_per_miss": t.ns_per_miss,
                "prepare_ms": prep_ms,
                "bvh_primitives": s.primitives,
                "patch_leaves": s.patch_leaves,
                "bvh_nodes": s.bvh_nodes,
                "bvh_depth": s.bvh_depth,
            }),
        );
    }
    Ok(())
}
