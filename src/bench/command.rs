//! `caustic bench`'s subcommands ([`BenchCommand`]) and [`run`], which runs one and hands its
//! figures to a [`BenchOutput`]. Each bench lives in a file of its own in this folder, flags
//! and all; the command line only parses them.

use anyhow::Result;
use clap::Subcommand;

use super::output::BenchOutput;

/// A benchmark: what `caustic bench` runs.
#[derive(Subcommand)]
pub enum BenchCommand {
    /// Ray/teapot intersection: ns per hitting and per missing primary ray, one thread.
    Intersect(super::intersect::IntersectArgs),
    /// Photon mapping: photon paths per core-second at the given thread counts.
    Ppm(super::scaling::PpmArgs),
    /// Photon mapping: error against wall time for several configurations (old and new
    /// defaults, α, initial radius, index) against a long reference render, cached on disk.
    /// Prints a table; writes a CSV and a log-log plot on request.
    Convergence(super::convergence::ConvergenceArgs),
    /// Live editing: the time from moving one control point to relative MSE 1e-2 against a
    /// reference of the edited scene (cached), with the new epoch started warm and cold; the
    /// medians of several runs each.
    Edit(super::edit::EditArgs),
    /// The viewer's error estimate against the truth: scenes rendered as in the viewer, the
    /// estimate after some passes beside the true relative RMS error against a long
    /// reference render (cached).
    Estimate(super::estimate::EstimateArgs),
    /// Photon mapping: resident memory (current and peak) of a long stochastic render (open
    /// aperture), sampled every --every passes.
    Memory(super::memory::MemoryArgs),
    /// Sharded rendering: each shard's time and peak memory, the merge's over all parts, and
    /// the projected wall time of a long render on many machines.
    Shards(super::shards::ShardsArgs),
    /// What exact patches buy: ray-traced renders with exact patches (prepared and per-ray)
    /// and with patches tessellated at several resolutions, timed, with each one's RMSE
    /// against the exact render (CSV and a log-log plot on request).
    Tessellation(super::tessellation::TessellationArgs),
    /// Whitted ray tracer: rays per second on a scene, at the given thread counts.
    Whitted(super::scaling::WhittedArgs),
    /// The README's benchmark table: runs each of its benchmarks, keeps the figures with their
    /// command, date and machine in assets/readme/benchmarks.json, and writes the table.
    All(super::all::AllArgs),
}

impl BenchCommand {
    /// The `--threads N` that sizes the whole command's pool (the benches that measure several
    /// thread counts take a list of their own).
    pub fn threads(&self) -> Option<usize> {
        match self {
            BenchCommand::Convergence(args) => args.threads.threads,
            BenchCommand::Edit(args) => args.threads.threads,
            BenchCommand::Estimate(args) => args.threads.threads,
            BenchCommand::Memory(args) => args.threads.threads,
            BenchCommand::Shards(args) => args.threads.threads,
            BenchCommand::Tessellation(args) => args.threads.threads,
            _ => None,
        }
    }
}

/// Runs a bench command; `json` prints its figures as JSON.
pub fn run(what: BenchCommand, json: bool) -> Result<()> {
    let name = match &what {
        BenchCommand::Intersect(_) => "intersect",
        BenchCommand::Ppm(_) => "ppm",
        BenchCommand::Convergence(_) => "convergence",
        BenchCommand::Edit(_) => "edit",
        BenchCommand::Estimate(_) => "estimate",
        BenchCommand::Memory(_) => "memory",
        BenchCommand::Shards(_) => "shards",
        BenchCommand::Whitted(_) => "whitted",
        BenchCommand::Tessellation(_) => "tessellation",
        BenchCommand::All(_) => "all",
    };
    let mut out = BenchOutput::new(json, name);
    match what {
        BenchCommand::Intersect(args) => super::intersect::bench_intersect(args, &mut out),
        BenchCommand::Whitted(args) => super::scaling::bench_whitted(args, &mut out),
        BenchCommand::Memory(args) => super::memory::bench_memory(args, &mut out),
        BenchCommand::Shards(args) => super::shards::bench_shards(args, &mut out),
        BenchCommand::Tessellation(args) => super::tessellation::bench_tessellation(args, &mut out),
        BenchCommand::All(args) => super::all::bench_all(args, &mut out),
        BenchCommand::Ppm(args) => super::scaling::bench_ppm(args, &mut out),
        BenchCommand::Convergence(args) => super::convergence::bench_convergence(args, &mut out),
        BenchCommand::Edit(args) => super::edit::bench_edit(args, &mut out),
        BenchCommand::Estimate(args) => super::estimate::bench_estimate(args, &mut out),
    }?;
    out.finish();
    Ok(())
}
