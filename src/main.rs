//! The `caustic` command line.

use anyhow::{bail, Result};
use clap::{Parser, Subcommand, ValueEnum};

use caustic::bench::{teapot_geometry, teapot_view, time_intersect};
use caustic::geometry::{PatchMethod, SubdivisionParams};

#[derive(Parser)]
#[command(
    name = "caustic",
    version,
    about = "Progressive photon mapping of exact Bézier patches"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Measure performance; prints figures (nothing is asserted).
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
    },
}

#[derive(Subcommand)]
enum BenchCommand {
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
        /// Prepared leaves: subdivision depth limit.
        #[arg(long, default_value_t = SubdivisionParams::default().max_depth)]
        max_depth: u32,
    },
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MethodChoice {
    Prepared,
    PerRay,
    Both,
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Bench {
            what:
                BenchCommand::Intersect {
                    size,
                    repeat,
                    method,
                    per_ray_depth,
                    flatness,
                    max_size,
                    max_depth,
                },
        } => {
            let params = SubdivisionParams {
                flatness,
                max_size,
                max_depth,
            };
            bench_intersect(size, repeat, method, per_ray_depth, params)
        }
    }
}

fn bench_intersect(
    size: usize,
    repeat: usize,
    method: MethodChoice,
    per_ray_depth: u32,
    params: SubdivisionParams,
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
    if !(params.flatness > 0.0 && params.max_size > 0.0 && params.max_depth <= 12) {
        bail!("--flatness and --max-size must be positive and --max-depth at most 12");
    }
    let rays = teapot_view(size, size);
    println!("Utah teapot (32 patches), {size}x{size} primary rays, 1 thread, {repeat} repeats");
    println!(
        "{:<22} {:>9} {:>9} {:>12} {:>13}",
        "intersector", "hit rays", "miss rays", "ns/hit ray", "ns/miss ray"
    );
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
        println!(
            "{:<22} {:>9} {:>9} {:>12.1} {:>13.1}",
            t.method, t.hit_rays, t.miss_rays, t.ns_per_hit, t.ns_per_miss
        );
        let s = geometry.stats();
        println!(
            "    prepare {prep_ms:.2} ms; {} BVH primitives ({} patch leaves), {} nodes, depth {}",
            s.primitives, s.patch_leaves, s.bvh_nodes, s.bvh_depth
        );
    }
    Ok(())
}
