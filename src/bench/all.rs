//! `caustic bench all`: runs the benchmarks the README's table shows — each as `caustic bench
//! … --json` of this very program, one after another — keeps their figures in a results file
//! in the repository (each with the command that made it, the date and the machine) and writes
//! the README's table from that file. Figures are never typed: this is how they change.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use super::output::BenchOutput;

/// `bench all`'s flags.
#[derive(clap::Args)]
pub struct AllArgs {
    /// The results file (JSON), read and rewritten.
    #[arg(long, default_value = "assets/readme/benchmarks.json")]
    results: PathBuf,
    /// The README whose benchmark table is written from the results.
    #[arg(long, default_value = "README.md")]
    readme: PathBuf,
    /// Run only these benchmarks (by name: intersect, ppm, whitted, convergence, edit, edit-light,
    /// memory); the others keep their figures in the results file.
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
    /// Write the README's table from the results file without running anything.
    #[arg(long)]
    table_only: bool,
}

/// A figure of a benchmark's JSON document: what it is, where it is, its unit and decimals.
struct Figure {
    what: &'static str,
    pointer: &'static str,
    unit: &'static str,
    decimals: usize,
}

/// A benchmark run for the table: its name, its `caustic bench` arguments, its figures.
struct Bench {
    name: &'static str,
    args: &'static [&'static str],
    figures: &'static [Figure],
}

/// The benchmarks of the README's table, in its order.
const BENCHES: &[Bench] = &[
    Bench {
        name: "intersect",
        args: &["intersect", "--method", "prepared", "--repeat", "5"],
        figures: &[
            Figure {
                what: "Ray/patch intersection, Utah teapot (prepared leaves, one thread): per hitting ray",
                pointer: "/intersectors/0/ns_per_hit",
                unit: "ns",
                decimals: 0,
            },
            Figure {
                what: "… per missing ray",
                pointer: "/intersectors/0/ns_per_miss",
                unit: "ns",
                decimals: 0,
            },
        ],
    },
    Bench {
        name: "ppm",
        args: &["ppm", "--indirect-radius-scale", "1"],
        figures: &[
            Figure {
                what: "Photon mapping, smallppm's scene 1024×768: photon paths per core-second, one thread",
                pointer: "/runs/0/paths_per_core_second",
                unit: "paths/s",
                decimals: 0,
            },
            Figure {
                what: "… speed-up with two threads",
                pointer: "/runs/1/speedup",
                unit: "×",
                decimals: 2,
            },
        ],
    },
    Bench {
        name: "whitted",
        args: &["whitted"],
        figures: &[Figure {
            what: "Ray tracer, built-in scene: camera rays per second, one thread",
            pointer: "/runs/0/camera_rays_per_second",
            unit: "rays/s",
            decimals: 0,
        }],
    },
    Bench {
        name: "convergence",
        args: &[
            "convergence",
            "scenes/glass_teapot.toml",
            "--width",
            "320",
            "--configs",
            "photons-only,default",
            "--seconds",
            "20",
            "--plot",
            "assets/readme/convergence-glass-teapot.png",
            "--force",
        ],
        figures: &[
            Figure {
                what: "Glass teapot 320×240, RMSE after 20 s against a 1000-pass reference: photons only (the paper's PPM)",
                pointer: "/configurations/0/rmse",
                unit: "",
                decimals: 5,
            },
            Figure {
                what: "… the defaults",
                pointer: "/configurations/1/rmse",
                unit: "",
                decimals: 5,
            },
            Figure {
                what: "… the defaults reach the paper's 20-second RMSE in",
                pointer: "/configurations/1/seconds_to_target",
                unit: "s",
                decimals: 2,
            },
        ],
    },
    Bench {
        name: "edit",
        args: &["edit"],
        figures: &[
            Figure {
                what: "Live editing (inline patch): a moved control point to relative MSE 1e-2, warm restart",
                pointer: "/warm_secs",
                unit: "s",
                decimals: 2,
            },
            Figure {
                what: "… cold restart",
                pointer: "/cold_secs",
                unit: "s",
                decimals: 2,
            },
        ],
    },
    Bench {
        name: "edit-light",
        args: &["edit", "scenes/lens.toml", "--light", "0", "--runs", "3"],
        figures: &[
            Figure {
                what: "Live editing (lens): a moved spot light to relative MSE 1e-2, warm restart",
                pointer: "/warm_secs",
                unit: "s",
                decimals: 2,
            },
            Figure {
                what: "… cold restart",
                pointer: "/cold_secs",
                unit: "s",
                decimals: 2,
            },
        ],
    },
    Bench {
        name: "memory",
        args: &["memory", "--passes", "20", "--every", "10"],
        figures: &[Figure {
            what: "Memory, built-in scene 1920×1080 stochastic: peak resident after 20 passes",
            pointer: "/peak_mib",
            unit: "MiB",
            decimals: 0,
        }],
    },
];

/// One figure as the results file keeps it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchResult {
    /// The benchmark that measured it.
    pub bench: String,
    /// What it is.
    pub what: String,
    /// Its value.
    pub value: f64,
    /// Its unit.
    pub unit: String,
    /// Decimals it is shown with.
    pub decimals: usize,
    /// The command that measured it.
    pub command: String,
    /// When (UTC, YYYY-MM-DD).
    pub date: String,
    /// On what.
    pub machine: String,
    /// The program that measured it.
    pub program: String,
}

/// The line before the README's table.
pub const BEGIN: &str =
    "<!-- benchmarks: written by `caustic bench all` from assets/readme/benchmarks.json -->";
/// The line after it.
pub const END: &str = "<!-- end of benchmarks -->";

/// Runs the benchmarks (or some), updates the results file and the README's table.
pub fn bench_all(args: AllArgs, out: &mut BenchOutput) -> Result<()> {
    for name in &args.only {
        if !BENCHES.iter().any(|b| b.name == name) {
            let names: Vec<&str> = BENCHES.iter().map(|b| b.name).collect();
            bail!("--only: no benchmark {name:?} (they are: {})", names.join(", "));
        }
    }
    let mut results = read_results(&args.results)?;
    if !args.table_only {
        let program = std::env::current_exe().context("cannot tell where this program is")?;
        let (date, machine) = (today(), machine());
        for bench in BENCHES
            .iter()
            .filter(|b| args.only.is_empty() || args.only.iter().any(|n| n == b.name))
        {
            out.say(format!("bench {} ...", bench.args.join(" ")));
            let figures = run(&program, bench)?;
            results.retain(|r| r.bench != bench.name);
            for (figure, value) in bench.figures.iter().zip(figures) {
                out.say(format!(
                    "  {} {value:.*} {}",
                    figure.what, figure.decimals, figure.unit
                ));
                results.push(BenchResult {
                    bench: bench.name.into(),
                    what: figure.what.into(),
                    value,
                    unit: figure.unit.into(),
                    decimals: figure.decimals,
                    command: format!("caustic bench {}", bench.args.join(" ")),
                    date: date.clone(),
                    machine: machine.clone(),
                    program: crate::render::provenance::software(),
                });
            }
        }
        // The table's order, whatever order the results were measured in.
        results.sort_by_key(order_of);
        let text = serde_json::to_string_pretty(&results).context("writing the results")?;
        std::fs::write(&args.results, text + "\n")
            .with_context(|| format!("{}: cannot write the results", args.results.display()))?;
        out.say(format!("results written to {}", args.results.display()));
    }
    write_table(&args.readme, &results)?;
    out.say(format!("{}: benchmark table written", args.readme.display()));
    out.set("results", &results);
    Ok(())
}

/// Where a result stands in the table: its benchmark's place, then its figure's.
fn order_of(r: &BenchResult) -> (usize, usize) {
    let bench = BENCHES
        .iter()
        .position(|b| b.name == r.bench)
        .unwrap_or(usize::MAX);
    let figure = BENCHES
        .get(bench)
        .and_then(|b| b.figures.iter().position(|f| f.what == r.what))
        .unwrap_or(usize::MAX);
    (bench, figure)
}

/// The figures `bench`'s JSON document holds, run by `program`.
fn run(program: &Path, bench: &Bench) -> Result<Vec<f64>> {
    let output = std::process::Command::new(program)
        .arg("bench")
        .args(bench.args)
        .arg("--json")
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("cannot run bench {}", bench.name))?;
    if !output.status.success() {
        bail!("bench {} failed", bench.args.join(" "));
    }
    let doc: serde_json::Value = serde_json::from_slice(&output.stdout)
        .with_context(|| format!("bench {} printed no JSON document", bench.name))?;
    bench
        .figures
        .iter()
        .map(|f| {
            doc.pointer(f.pointer)
                .and_then(serde_json::Value::as_f64)
                .with_context(|| format!("bench {}'s JSON has no number at {}", bench.name, f.pointer))
        })
        .collect()
}

/// The results file's figures (none when it does not exist yet).
fn read_results(path: &Path) -> Result<Vec<BenchResult>> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{}: not a results file", path.display()))
}

/// The Markdown table of `results`.
pub fn markdown_table(results: &[BenchResult]) -> String {
    let mut text = String::from("| what | figure | command | date | machine |\n|---|---|---|---|---|\n");
    for r in results {
        text.push_str(&format!(
            "| {} | {:.*} {} | `{}` | {} | {} |\n",
            r.what, r.decimals, r.value, r.unit, r.command, r.date, r.machine
        ));
    }
    text
}

/// Rewrites the README's table between its markers.
fn write_table(readme: &Path, results: &[BenchResult]) -> Result<()> {
    let text =
        std::fs::read_to_string(readme).with_context(|| format!("{}: cannot read", readme.display()))?;
    let (Some((before, rest)), true) = (text.split_once(BEGIN), text.contains(END)) else {
        bail!(
            "{}: no benchmark table (the lines {BEGIN} and {END})",
            readme.display()
        );
    };
    let after = rest.split_once(END).map_or("", |(_, a)| a);
    let new = format!("{before}{BEGIN}\n{}{END}{after}", markdown_table(results));
    if new != text {
        std::fs::write(readme, new).with_context(|| format!("{}: cannot write", readme.display()))?;
    }
    Ok(())
}

/// Today's date (UTC), from the system clock.
fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (year, month, day) = civil((secs / 86_400) as i64);
    format!("{year:04}-{month:02}-{day:02}")
}

/// The date `days` after 1970-01-01: Hinnant's days-to-civil algorithm (proleptic Gregorian).
fn civil(days: i64) -> (i64, i64, i64) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    (yoe + era * 400 + i64::from(month <= 2), month, day)
}

/// The processor and its threads, as /proc/cpuinfo names it.
fn machine() -> String {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, m)| m.trim().to_owned())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_owned());
    format!("{model}, {threads} threads")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn days_become_dates() {
        assert_eq!(civil(0), (1970, 1, 1));
        assert_eq!(civil(11_016), (2000, 2, 29));
        assert_eq!(civil(11_017), (2000, 3, 1));
        assert_eq!(civil(-1), (1969, 12, 31));
    }

    #[test]
    fn the_table_shows_each_figure_with_its_command() {
        let r = BenchResult {
            bench: "ppm".into(),
            what: "paths".into(),
            value: 1234.567,
            unit: "paths/s".into(),
            decimals: 0,
            command: "caustic bench ppm".into(),
            date: "2026-12-06".into(),
            machine: "x, 2 threads".into(),
            program: "caustic".into(),
        };
        let table = markdown_table(&[r]);
        assert!(
            table.ends_with("| paths | 1235 paths/s | `caustic bench ppm` | 2026-12-06 | x, 2 threads |\n"),
            "{table}"
        );
    }
}
