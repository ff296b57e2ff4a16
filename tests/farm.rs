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
        "exec caustic render --shard \"$JOB_COMPLETION_INDEX\"/8",
        "--passes=1000",
        "--threads=4",
        "--out=/data/out/part_\"$JOB_COMPLETION_INDEX\".exr",
        "--width 1920 --height 1080 -- /data/scenes/cornell.toml",
    ] {
        assert!(command.contains(part), "{part:?} in {command}");
    }
    assert_eq!(merge["metadata"]["name"].as_str(), Some("caustic-merge"));
    let command = merge["spec"]["template"]["spec"]["containers"][0]["command"][2]
        .as_str()
        .expect("the merge's command");
    assert!(command.contains("-ge 8 ]"), "waits for the 8 parts: {command}");
    assert!(
        command.contains("caustic merge /data/out/part_*.exr --out=/data/out/image.exr --force"),
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
        "--array=0-3 --cpus-per-task=2 '--partition=gpu nodes'",
        "--dependency=afterok:\"$shards\"",
        "render --shard \"$SLURM_ARRAY_TASK_ID\"/4 --passes=64 --threads=2",
        &format!("-- {scene}'"),
        "/farm-out/image.exr --force'",
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

/// Names no script may run or be broken by: quotes, command substitution, backticks, line
/// breaks of every kind, a YAML document marker, globs, `%` (a Slurm pattern), comments.
const HOSTILE: [&str; 8] = [
    "out $(touch CANARY) 'x'",
    "a`touch CANARY`b\"c",
    "line\nbreak\n#SBATCH --wrap=touch CANARY\nSHARDS",
    "---\nkind: Pod\nmetadata: {name: evil}",
    "star * and ? and [a] ~user",
    "100% %a %j; touch CANARY & |",
    "nel\u{85}ls\u{2028}ps\u{2029}cr\rtab\t",
    "ünïcødé 漢字 -dash",
];

/// A folder with a fake `sbatch` that records its arguments and runs each job's `--wrap`
/// command as task 1 would, a fake caustic (`--program`) that records its own, and a canary
/// that an injected command would create.
struct FakeCluster {
    dir: tempfile::TempDir,
}

impl FakeCluster {
    fn new() -> Self {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("temp dir");
        let bin = dir.path().join("bin");
        std::fs::create_dir(&bin).expect("bin");
        let sbatch = "#!/bin/bash\n\
            printf '%s\\0' \"$@\" > \"$FAKE_LOG/sbatch.$RANDOM$RANDOM\"\n\
            for a in \"$@\"; do case \"$a\" in --wrap=*) cmd=\"${a#--wrap=}\";; esac; done\n\
            SLURM_ARRAY_TASK_ID=1 sh -c \"$cmd\"\n\
            echo 42\n";
        let program = "#!/bin/sh\nprintf '%s\\0' \"$@\" > \"$FAKE_LOG/$1.args\"\n";
        for (name, text) in [("sbatch", sbatch), ("fake-caustic", program)] {
            let path = bin.join(name);
            std::fs::write(&path, text).expect("write");
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        }
        std::fs::create_dir(dir.path().join("log")).expect("log");
        Self { dir }
    }

    fn program(&self) -> String {
        self.dir.path().join("bin/fake-caustic").display().to_string()
    }

    /// Runs `script` with bash, the fakes first on the PATH, in a folder of its own.
    fn run_script(&self, script: &[u8]) -> std::process::Output {
        let work = self.dir.path().join("work");
        std::fs::create_dir_all(&work).expect("work");
        let file = self.dir.path().join("job.sh");
        std::fs::write(&file, script).expect("write");
        let path = format!(
            "{}:{}",
            self.dir.path().join("bin").display(),
            std::env::var("PATH").unwrap_or_default()
        );
        std::process::Command::new("bash")
            .arg(&file)
            .current_dir(&work)
            .env("PATH", path)
            .env("FAKE_LOG", self.dir.path().join("log"))
            .output()
            .expect("bash")
    }

    /// What the fake caustic was given as `render` or `merge`.
    fn args(&self, command: &str) -> Vec<String> {
        let bytes = std::fs::read(self.dir.path().join("log").join(format!("{command}.args")))
            .unwrap_or_else(|e| panic!("{command} did not run: {e}"));
        split_nul(&bytes)
    }

    /// Every sbatch call's arguments.
    fn sbatch_calls(&self) -> Vec<Vec<String>> {
        let mut calls: Vec<Vec<String>> = std::fs::read_dir(self.dir.path().join("log"))
            .expect("log")
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with("sbatch."))
            .map(|e| split_nul(&std::fs::read(e.path()).expect("read")))
            .collect();
        calls.sort();
        calls
    }

    /// Whether an injected command ran anywhere under the folder.
    fn canary(&self) -> bool {
        fn walk(dir: &std::path::Path) -> bool {
            std::fs::read_dir(dir)
                .into_iter()
                .flatten()
                .flatten()
                .any(|e| e.file_name() == "CANARY" || (e.path().is_dir() && walk(&e.path())))
        }
        walk(self.dir.path())
    }
}

fn split_nul(bytes: &[u8]) -> Vec<String> {
    bytes
        .split(|&b| b == 0)
        .filter(|s| !s.is_empty())
        .map(|s| String::from_utf8(s.to_vec()).expect("UTF-8"))
        .collect()
}

/// `farm slurm` with a scene and an output folder named `name`, run by bash against the
/// fakes: every value reaches sbatch and the tasks exactly as given, and nothing else runs.
fn slurm_round_trip(name: &str) {
    let cluster = FakeCluster::new();
    let scenes = cluster
        .dir
        .path()
        .join("scenes")
        .join(format!("n{}", name.replace('/', "_")));
    std::fs::create_dir_all(&scenes).expect("scene folder");
    let scene = scenes.join("a.toml");
    std::fs::copy(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml"),
        &scene,
    )
    .expect("scene");
    let out = cluster
        .dir
        .path()
        .join("out")
        .join(format!("n{}", name.replace('/', "_")));
    let (scene_arg, out_arg) = (scene.display().to_string(), out.display().to_string());
    let program = cluster.program();
    let partition = format!("--partition={name}");
    let run = caustic(&[
        "farm",
        "slurm",
        &scene_arg,
        "--shards",
        "4",
        "--passes",
        "64",
        "--threads",
        "2",
        "--out",
        &out_arg,
        &partition,
        "--program",
        &program,
        "--",
        "--width",
        "64",
    ]);
    if name.contains('\\') {
        // Slurm reads a backslash in a log file name as "no patterns": refused, not written.
        assert!(
            !run.status.success() && text(&run).contains("backslash"),
            "{name:?}: {}",
            text(&run)
        );
        return;
    }
    assert!(run.status.success(), "{name:?}: {}", text(&run));
    let check = std::process::Command::new("bash")
        .args(["-n", "-c", &String::from_utf8_lossy(&run.stdout)])
        .output()
        .expect("bash -n");
    assert!(check.status.success(), "{name:?}: bash -n: {}", text(&check));
    let ran = cluster.run_script(&run.stdout);
    assert!(ran.status.success(), "{name:?}: {}", text(&ran));
    let scene = scene.canonicalize().expect("scene").display().to_string();
    let out = out.display().to_string();
    let render = cluster.args("render");
    let expected = [
        "render",
        "--shard",
        "1/4",
        "--passes=64",
        "--threads=2",
        &format!("--out={out}/part_1.exr"),
        "--force",
        "--width",
        "64",
        "--",
        &scene,
    ];
    assert_eq!(render, expected, "{name:?}");
    let merge = cluster.args("merge");
    let parts = format!("{out}/part_*.exr");
    let image = format!("--out={out}/image.exr");
    assert_eq!(
        merge,
        ["merge", parts.as_str(), image.as_str(), "--force"],
        "{name:?}"
    );
    let calls = cluster.sbatch_calls();
    assert_eq!(calls.len(), 2, "{name:?}");
    let log = format!("--output={}/logs/shard_%a.out", out.replace('%', "%%"));
    assert!(
        calls.iter().all(|c| c.contains(&partition)),
        "{name:?}: {calls:?}"
    );
    assert!(calls.iter().any(|c| c.contains(&log)), "{name:?}: {calls:?}");
    assert!(std::path::Path::new(&out).join("logs").is_dir(), "{name:?}");
    assert!(!cluster.canary(), "{name:?}: an injected command ran");
}

#[test]
fn hostile_names_reach_slurm_and_the_tasks_exactly_as_given() {
    for name in HOSTILE {
        slurm_round_trip(name);
    }
}

/// `farm kubernetes` with the scene, output folder and image named after `name`: the manifest
/// parses (libyaml and yaml-rust2) as exactly the two Jobs, and each pod's command, run by sh,
/// gives the program exactly the values given.
fn kubernetes_round_trip(name: &str) {
    let cluster = FakeCluster::new();
    let out = cluster
        .dir
        .path()
        .join("out")
        .join(format!("n{}", name.replace('/', "_")));
    std::fs::create_dir_all(&out).expect("out");
    let scene = format!("/data/n{}/scene.toml", name.replace('/', "_"));
    let out_arg = out.display().to_string();
    let program = cluster.program();
    let image = format!("--image={name}");
    let run = caustic(&[
        "farm",
        "kubernetes",
        &scene,
        "--shards",
        "3",
        "--passes",
        "9",
        "--out",
        &out_arg,
        &image,
        "--program",
        &program,
    ]);
    assert!(run.status.success(), "{name:?}: {}", text(&run));
    let manifest = String::from_utf8(run.stdout.clone()).expect("UTF-8");
    let docs = YamlLoader::load_from_str(&manifest).expect("yaml-rust2 parses it");
    assert_eq!(docs.len(), 2, "{name:?}: {manifest}");
    let jobs: Vec<serde_yaml_ng::Value> = serde_yaml_ng::Deserializer::from_str(&manifest)
        .map(|d| <serde_yaml_ng::Value as serde::Deserialize>::deserialize(d).expect("libyaml parses it"))
        .collect();
    assert_eq!(jobs.len(), 2, "{name:?}: {manifest}");
    let kinds: Vec<_> = jobs.iter().map(|j| j["kind"].as_str()).collect();
    assert_eq!(kinds, [Some("Job"), Some("Job")], "{name:?}");
    for (k, part) in (0..3).map(|k| (k, out.join(format!("part_{k}.exr")))) {
        std::fs::write(&part, [k as u8]).expect("a part for the merge to find");
    }
    for job in &jobs {
        let container = &job["spec"]["template"]["spec"]["containers"][0];
        assert_eq!(container["image"].as_str(), Some(name), "{name:?}");
        assert_eq!(
            container.as_mapping().map(|m| m.len()),
            Some(5),
            "{name:?}: no field added"
        );
        let command = container["command"][2].as_str().expect("a command");
        // A command broken by a name could wait for parts forever: at most 20 s.
        let ran = std::process::Command::new("timeout")
            .args(["20", "sh", "-c", command])
            .current_dir(cluster.dir.path())
            .env("JOB_COMPLETION_INDEX", "2")
            .env("FAKE_LOG", cluster.dir.path().join("log"))
            .output()
            .expect("sh");
        assert!(ran.status.success(), "{name:?}: {}", text(&ran));
    }
    let out = out.display().to_string();
    let render = cluster.args("render");
    let expected = [
        "render",
        "--shard",
        "2/3",
        "--passes=9",
        "--threads=1",
        &format!("--out={out}/part_2.exr"),
        "--force",
        "--",
        &scene,
    ];
    assert_eq!(render, expected, "{name:?}");
    let merge = cluster.args("merge");
    let parts: Vec<String> = (0..3).map(|k| format!("{out}/part_{k}.exr")).collect();
    assert_eq!(merge[1..4], parts, "{name:?}");
    assert_eq!(
        merge[4..],
        [format!("--out={out}/image.exr"), "--force".into()],
        "{name:?}"
    );
    assert!(!cluster.canary(), "{name:?}: an injected command ran");
}

#[test]
fn hostile_names_stay_values_of_the_kubernetes_manifest() {
    for name in HOSTILE {
        kubernetes_round_trip(name);
    }
}

#[test]
fn random_names_round_trip_through_both_systems() {
    use rand::{Rng, SeedableRng};
    let alphabet: Vec<char> = "ab/ '\"$()`\\\n\r\t;&|*?[]~#%!{}-:=,.\u{85}\u{2028}ü漢-"
        .chars()
        .collect();
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(57);
    for _ in 0..40 {
        let len = rng.random_range(1..24);
        let name: String = (0..len)
            .map(|_| alphabet[rng.random_range(0..alphabet.len())])
            .collect();
        let name = if name.trim_matches('/').is_empty() {
            format!("x{name}x")
        } else {
            name
        };
        slurm_round_trip(&name);
        kubernetes_round_trip(&name);
    }
}

#[test]
fn names_no_script_can_carry_are_refused_with_the_flag() {
    use std::os::unix::ffi::OsStrExt;
    let bad = std::ffi::OsStr::from_bytes(b"/data/out\xff");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args([
            "farm",
            "kubernetes",
            "/data/a.toml",
            "--shards",
            "2",
            "--passes",
            "4",
            "--image",
            "i",
            "--out",
        ])
        .arg(bad)
        .output()
        .expect("run");
    assert!(!run.status.success());
    assert!(
        text(&run).contains("--out") && text(&run).contains("not valid UTF-8"),
        "{}",
        text(&run)
    );
    for (args, message) in [
        (&["--name", "Evil\n---"][..], "--name"),
        (&["--volume-claim", "a b"][..], "--volume-claim"),
    ] {
        let mut all = vec![
            "farm",
            "kubernetes",
            "/data/a.toml",
            "--shards",
            "2",
            "--passes",
            "4",
            "--image",
            "i",
            "--out",
            "/data/o",
        ];
        all.extend(args);
        let run = caustic(&all);
        assert!(
            !run.status.success() && text(&run).contains(message),
            "{args:?}: {}",
            text(&run)
        );
    }
}

#[test]
fn shard_counts_are_limited_before_anything_wraps() {
    for system in ["slurm", "kubernetes"] {
        for shards in ["3000000000", "1000000"] {
            let run = caustic(&[
                "farm",
                system,
                "scenes/cornell.toml",
                "--shards",
                shards,
                "--passes",
                "4000000000",
                "--out",
                "/data/o",
                "--image",
                "i",
            ]);
            assert!(!run.status.success(), "{system} {shards}");
            let t = text(&run);
            assert!(
                t.contains("--shards") || t.contains("--passes"),
                "{system} {shards}: {t}"
            );
            assert!(!t.contains("backoffLimit"), "{t}");
        }
    }
    let run = caustic(&[
        "farm",
        "slurm",
        "scenes/cornell.toml",
        "--shards",
        "5000",
        "--passes",
        "5000",
        "--out",
        "/tmp/o",
    ]);
    assert!(run.status.success(), "{}", text(&run));
    assert!(
        String::from_utf8_lossy(&run.stderr).contains("MaxArraySize"),
        "{}",
        text(&run)
    );
}

#[test]
fn flags_every_task_would_refuse_are_refused_before_the_script() {
    for extra in [
        &["--time-limit", "5"][..],
        &["--json"],
        &["--renderer", "path"],
        &["--radius-schedule", "per-point"],
        &["--reference", "r.exr"],
    ] {
        let mut args = vec![
            "farm",
            "slurm",
            "scenes/cornell.toml",
            "--shards",
            "2",
            "--passes",
            "4",
            "--out",
            "x",
            "--",
        ];
        args.extend(extra);
        let run = caustic(&args);
        assert!(!run.status.success(), "{extra:?}");
        assert!(
            text(&run).contains("cannot be given to a shard"),
            "{extra:?}: {}",
            text(&run)
        );
        assert!(run.stdout.is_empty(), "{extra:?}: no script");
    }
}
