//! `caustic bench`: measurement commands that print figures (nothing is asserted): ray/patch
//! intersection, the ray tracer, photon throughput and error against time. Each bench beyond
//! `intersect` lives in a file of its own (`bench_*.rs`, `memory.rs`, `tessellation.rs`).

use anyhow::{bail, Result};
use clap::{Subcommand, ValueEnum};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

use super::bench_output::BenchOutput;
use caustic::bench::{teapot_geometry, teapot_view, time_intersect};
use caustic::geometry::{PatchMethod, SubdivisionParams};

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Ray/teapot intersection: ns per hitting and per missing primary ray, one thread.
    Intersect {
        /// Image side in pixels (rays = size²).
        #[arg(long, default_value_t = 512)]
        size: usize,
        /// Times each ray set is traced (more = steadier figures).
        #[arg(long, default_value_t = 3)]
        repeat: usize,
        /// Which intersectors to time.
        #[arg(long, value_enum, default_value_t = MethodChoice::Both)]
        method: MethodChoice,
        /// Subdivision depth of the per-ray (seed) intersector.
        #[arg(long, default_value_t = 5)]
        per_ray_depth: u32,
        /// Prepared leaves: flatness (control-point deviation / leaf diagonal).
        #[arg(long, default_value_t = SubdivisionParams::default().flatness)]
        flatness: f64,
        /// Prepared leaves: largest leaf diagonal / patch diagonal.
        #[arg(long, default_value_t = SubdivisionParams::default().max_size)]
        max_size: f64,
        /// Prepared leaves: subdivision depth limit, at most 8 (up to 4^8 leaves a patch: 2.1
        /// million for the teapot, 1.6 GB).
        #[arg(long, default_value_t = SubdivisionParams::default().max_depth)]
        max_depth: u32,
        /// The order the rays are traced in.
        #[arg(long, value_enum, default_value_t = RayOrder::Image)]
        order: RayOrder,
    },
    /// Photon mapping: photon paths per core-second at the given thread counts.
    Ppm(super::bench_scaling::PpmArgs),
    /// Photon mapping: error against wall time for several configurations (old and new
    /// defaults, α, initial radius, index) against a long reference render, cached on disk.
    /// Prints a table; writes a CSV and a log-log plot on request.
    Convergence(super::bench_convergence::ConvergenceArgs),
    /// Live editing: the time from moving one control point to relative MSE 1e-2 against a
    /// reference of the edited scene (cached), with the new epoch started warm and cold; the
    /// medians of several runs each.
    Edit(super::bench_edit::EditArgs),
    /// Photon mapping: resident memory (current and peak) of a long stochastic render (open
    /// aperture), sampled every --every passes.
    Memory(super::memory::MemoryArgs),
    /// Sharded rendering: each shard's time and peak memory, the merge's over all parts, and
    /// the projected wall time of a long render on many machines.
    Shards(super::bench_shards::ShardsArgs),
    /// What exact patches buy: ray-traced renders with exact patches (prepared and per-ray)
    /// and with patches tessellated at several resolutions, timed, with each one's RMSE
    /// against the exact render (CSV and a log-log plot on request).
    Tessellation(super::tessellation::TessellationArgs),
    /// Whitted ray tracer: rays per second on a scene, at the given thread counts.
    Whitted(super::bench_scaling::WhittedArgs),
    /// The README's benchmark table: runs each of its benchmarks, keeps the figures with their
    /// command, date and machine in assets/readme/benchmarks.json, and writes the table.
    All(super::bench_all::AllArgs),
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

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodChoice {
    Prepared,
    PerRay,
    Both,
}

impl BenchCommand {
    /// The `--threads N` that sizes the whole command's pool (the benches that measure several
    /// thread counts take a list of their own).
    pub fn threads(&self) -> Option<usize> {
        match self {
            BenchCommand::Convergence(args) => args.threads.threads,
            BenchCommand::Edit(args) => args.threads.threads,
            BenchCommand::Memory(args) => args.threads.threads,
            BenchCommand::Shards(args) => args.threads.threads,
            BenchCommand::Tessellation(args) => args.threads.threads,
            _ => None,
        }
    }
}

/// Runs a bench command; `json` prints its figures as JSON.
pub fn bench(what: BenchCommand, json: bool) -> Result<()> {
    let name = match &what {
        BenchCommand::Intersect { .. } => "intersect",
        BenchCommand::Ppm(_) => "ppm",
        BenchCommand::Convergence(_) => "convergence",
        BenchCommand::Edit(_) => "edit",
        BenchCommand::Memory(_) => "memory",
        BenchCommand::Shards(_) => "shards",
        BenchCommand::Whitted(_) => "whitted",
        BenchCommand::Tessellation(_) => "tessellation",
        BenchCommand::All(_) => "all",
    };
    let mut out = BenchOutput::new(json, name);
    match what {
        BenchCommand::Intersect {
            size,
            repeat,
            method,
            per_ray_depth,
            flatness,
            max_size,
            max_depth,
            order,
        } => {
            let params = SubdivisionParams {
                flatness,
                max_size,
                max_depth,
                ..Default::default()
            };
            let rays = IntersectRays { size, repeat, order };
            bench_intersect(rays, method, per_ray_depth, params, &mut out)
        }
        BenchCommand::Whitted(args) => super::bench_scaling::bench_whitted(args, &mut out),
        BenchCommand::Memory(args) => super::memory::bench_memory(args, &mut out),
        BenchCommand::Shards(args) => super::bench_shards::bench_shards(args, &mut out),
        BenchCommand::Tessellation(args) => super::tessellation::bench_tessellation(args, &mut out),
        BenchCommand::All(args) => super::bench_all::bench_all(args, &mut out),
        BenchCommand::Ppm(args) => super::bench_scaling::bench_ppm(args, &mut out),
        BenchCommand::Convergence(args) => super::bench_convergence::bench_convergence(args, &mut out),
        BenchCommand::Edit(args) => super::bench_edit::bench_edit(args, &mut out),
    }?;
    out.finish();
    Ok(())
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

/// Which rays `bench intersect` traces, how often and in what order.
struct IntersectRays {
    /// Image side in pixels.
    size: usize,
    /// Times each ray set is traced.
    repeat: usize,
    order: RayOrder,
}

/// Seed of [`RayOrder::Shuffled`]'s permutation: every run traces the rays in one order.
const SHUFFLE_SEED: u64 = 0x5EED_0F0D_3E00;

fn bench_intersect(
    IntersectRays { size, repeat, order }: IntersectRays,
    method: MethodChoice,
    per_ray_depth: u32,
    params: SubdivisionParams,
    out: &mut BenchOutput,
) -> Result<()> {
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
