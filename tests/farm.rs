//! `caustic farm`: the Kubernetes manifest parsed as YAML with its fields asserted (no cluster
//! can run here), the Slurm script's directives, and the flags' checks. The Slurm script is
//! run on a real Slurm by tests/slurm.rs.

use yaml_rust2::{Yaml, YamlLoader};

mod common;
use common::{caustic, text};

#[test]
fn the_kubernetes_manifest_is_an_indexed_job_and_a_merge_job() {
    let run = caustic(&[
        "farm",
        "kubernetes",
        "/data/scenes/cornell.toml",
        "--shards",
        "8",
        "--passes",
        "1000",
        "--threads",
        "4",
        "--out",
        "/data/out",
        "--image",
        "registry.example.com/caustic:0.1.0",
        "--volume-claim",
        "renders",
        "--",
        "--width",
        "1920",
        "--height",
        "1080",
    ]);
    assert!(run.status.success(), "{}", text(&run));
    let docs = YamlLoader::load_from_str(&String::from_utf8_lossy(&run.stdout)).expect("valid YAML");
    assert_eq!(docs.len(), 2, "the shard Job and the merge Job");
    let (shards, merge) = (&docs[0], &docs[1]);
    for job in [shards, merge] {
        assert_eq!(job["apiVersion"].as_str(), Some("batch/v1"));
        assert_eq!(job["kind"].as_str(), Some("Job"));
        let pod = &job["spec"]["template"]["spec"];
        let container = &pod["containers"][0];
        assert_eq!(
            container["image"].as_str(),
            Some("registry.example.com/caustic:0.1.0")
        );
        assert_eq!(container["volumeMounts"][0]["mountPath"].as_str(), Some("/data"));
        assert_eq!(
            pod["volumes"][0]["persistentVolumeClaim"]["claimName"].as_str(),
            Some("renders")
        );
        assert_eq!(container["command"][0].as_str(), Some("sh"));
    }
    assert_eq!(shards["metadata"]["name"].as_str(), Some("caustic-shards"));
    let spec = &shards["spec"];
    assert_eq!(spec["completionMode"].as_str(), Some("Indexed"));
    assert_eq!(spec["completions"].as_i64(), Some(8));
    assert_eq!(spec["parallelism"].as_i64(), Some(8));
    let pod = &spec["template"]["spec"];
    assert_eq!(pod["restartPolicy"].as_str(), Some("Never"));
    let container = &pod["containers"][0];
    assert_eq!(container["resources"]["requests"]["cpu"].as_str(), Some("4"));
    let command = container["command"][2].as_str().expect("the shard's command");
    for part in [
        "caustic render /data/scenes/cornell.toml",
        "--shard \"$JOB_COMPLETION_INDEX/8\"",
        "--passes 1000",
        "--threads 4",
        "--out /data/out/part_$JOB_COMPLETION_INDEX.exr",
        "--width 1920 --height 1080",
    ] {
        assert!(command.contains(part), "{part:?} in {command}");
    }
    assert_eq!(merge["metadata"]["name"].as_str(), Some("caustic-merge"));
    let command = merge["spec"]["template"]["spec"]["containers"][0]["command"][2]
        .as_str()
        .expect("the merge's command");
    assert!(command.contains("-ge 8 ]"), "waits for the 8 parts: {command}");
    assert!(
        command.contains("caustic merge /data/out/part_*.exr --out /data/out/image.exr"),
        "{command}"
    );
    assert!(
        !matches!(merge["spec"]["completionMode"], Yaml::String(_)),
        "the merge is one pod"
    );
}

#[test]
fn the_slurm_script_is_a_job_array_and_a_dependent_merge() {
    let run = caustic(&[
        "farm",
        "slurm",
        "scenes/cornell.toml",
        "--shards",
        "4",
        "--passes",
        "64",
        "--threads",
        "2",
        "--out",
        "farm-out",
        "--partition",
        "gpu nodes",
    ]);
    assert!(run.status.success(), "{}", text(&run));
    let script = String::from_utf8_lossy(&run.stdout);
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml");
    let scene = scene.canonicalize().expect("exists").display().to_string();
    for line in [
        "#SBATCH --array=0-3",
        "#SBATCH --cpus-per-task=2",
        "#SBATCH --partition='gpu nodes'",
        "K=$SLURM_ARRAY_TASK_ID",
        "--dependency=afterok:$shards",
        &format!("render {scene} --shard \"$K/4\" --passes 64 --threads 2"),
        "/farm-out/image.exr --force",
    ] {
        assert!(script.contains(line), "{line:?} in\n{script}");
    }
    assert!(script.starts_with("#!/bin/bash"));
}

#[test]
fn farm_flags_are_checked() {
    let cases: [(&[&str], &str); 6] = [
        (
            &[
                "slurm",
                "scenes/cornell.toml",
                "--shards",
                "0",
                "--passes",
                "4",
                "--out",
                "x",
            ],
            "--shards must be at least 1",
        ),
        (
            &[
                "slurm",
                "scenes/cornell.toml",
                "--shards",
                "8",
                "--passes",
                "4",
                "--out",
                "x",
            ],
            "some shards would render nothing",
        ),
        (
            &[
                "slurm",
                "scenes/missing.toml",
                "--shards",
                "2",
                "--passes",
                "4",
                "--out",
                "x",
            ],
            "missing.toml: cannot find the scene",
        ),
        (
            &[
                "kubernetes",
                "/data/a.toml",
                "--shards",
                "2",
                "--passes",
                "4",
                "--out",
                "/data/o",
            ],
            "--image is required",
        ),
        // Render flags are checked before the job goes to the queue, not by each task.
        (
            &[
                "slurm",
                "scenes/cornell.toml",
                "--shards",
                "2",
                "--passes",
                "4",
                "--out",
                "x",
                "--",
                "--widht",
                "1920",
            ],
            "unexpected argument '--widht'",
        ),
        (
            &[
                "kubernetes",
                "/data/a.toml",
                "--shards",
                "2",
                "--passes",
                "4",
                "--out",
                "/data/o",
                "--image",
                "caustic:1",
                "--",
                "--passes",
                "8",
            ],
            "'--passes <PASSES>' cannot be used multiple times",
        ),
    ];
    for (args, message) in cases {
        let run = caustic(&[&["farm"], args].concat());
        assert!(!run.status.success(), "{args:?}");
        assert!(text(&run).contains(message), "{args:?}: {}", text(&run));
    }
}
