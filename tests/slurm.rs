//! The Slurm script of `caustic farm slurm`, run on a real single-node Slurm: 4 shards as a job
//! array, the merge job after them, and the merged image equal to the one-process render.
//!
//! Needs a running Slurm (`.ci/slurm-up` installs and starts one, as `.ci/run` does), so it is
//! ignored by a plain `cargo test`: run it with `cargo test --test slurm -- --ignored`.

use std::path::Path;
use std::process::Command;

use caustic::render::shard::Part;

mod common;
use common::{caustic, text};

#[test]
#[ignore = "needs a running Slurm: .ci/slurm-up, then cargo test --test slurm -- --ignored"]
fn a_slurm_job_array_renders_the_shards_and_the_merge_job_joins_them() {
    let sinfo = Command::new("sinfo").args(["-h", "-o", "%T"]).output();
    let state = sinfo.map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned());
    assert_eq!(
        state.as_deref().ok(),
        Some("idle"),
        "no idle Slurm node: run .ci/slurm-up first"
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("farm");
    let flags = [
        "--width",
        "32",
        "--photons",
        "20000",
        "--min-photons-per-pixel",
        "0",
    ];
    let mut args = vec![
        "farm",
        "slurm",
        "scenes/inline_patch.toml",
        "--shards",
        "4",
        "--passes",
        "6",
        "--threads",
        "1",
        "--wait",
        "--out",
    ];
    let out_text = out.display().to_string();
    args.push(&out_text);
    args.push("--");
    args.extend(flags);
    let farm = caustic(&args);
    assert!(farm.status.success(), "{}", text(&farm));
    let script = dir.path().join("job.sh");
    std::fs::write(&script, &farm.stdout).expect("write the script");
    // The script submits both jobs and (with --wait) returns when the merge job has ended.
    let run = Command::new("timeout")
        .args(["600", "bash"])
        .arg(&script)
        .current_dir(dir.path())
        .output()
        .expect("run bash");
    let logs = |name: &str| std::fs::read_to_string(out.join("logs").join(name)).unwrap_or_default();
    assert!(
        run.status.success(),
        "{}\nshard 0: {}\nmerge: {}",
        text(&run),
        logs("shard_0.out"),
        logs("merge.out")
    );
    for k in 0..4 {
        assert!(
            out.join(format!("part_{k}.exr")).is_file(),
            "part {k}: {}",
            logs(&format!("shard_{k}.out"))
        );
    }
    let merged = Part::read(&out.join("image.exr")).expect("the merge job wrote image.exr");
    assert!(merged.is_complete(), "{}", logs("merge.out"));
    // The one-process render of the same 6 passes.
    let one = dir.path().join("one.exr");
    let one_text = one.display().to_string();
    let mut single = vec![
        "render",
        "scenes/inline_patch.toml",
        "--shard",
        "0/1",
        "--passes",
        "6",
        "--out",
        &one_text,
    ];
    single.extend(flags);
    let run = caustic(&single);
    assert!(run.status.success(), "{}", text(&run));
    let one = Part::read(Path::new(&one)).expect("reads");
    assert_eq!(merged.sums, one.sums, "4 Slurm shards merged equal one process");
    assert_eq!(merged.sums.mean(), one.sums.mean());
}
