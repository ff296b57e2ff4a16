//! The Kubernetes manifest: an Indexed Job (`completionMode: Indexed`, `JOB_COMPLETION_INDEX`
//! picks the shard) whose pods write parts to a shared volume, and a merge Job that waits
//! until every part is there and merges them.
//!
//! The two Jobs are typed values serialized by a YAML serializer (libyaml's emitter, through
//! `serde_yaml_ng`), which quotes and escapes whatever a string holds, so no value can end a
//! document or add a field. The containers' shell commands are made of words quoted by
//! [`super::quote::shell_word`].

use std::ffi::OsStr;

use serde::Serialize;

use super::quote::comment;
use super::{FarmError, Job};

/// The scheduler's variable holding a pod's index in the Indexed Job.
const INDEX_VAR: &str = "JOB_COMPLETION_INDEX";

/// Where every pod mounts the PersistentVolumeClaim.
pub const MOUNT: &str = "/data";

/// A `batch/v1` Job.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct K8sJob {
    api_version: &'static str,
    kind: &'static str,
    metadata: Metadata,
    spec: JobSpec,
}

#[derive(Serialize)]
struct Metadata {
    name: String,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct JobSpec {
    #[serde(skip_serializing_if = "Option::is_none")]
    completions: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    parallelism: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    completion_mode: Option<&'static str>,
    backoff_limit: u32,
    template: Template,
}

#[derive(Serialize)]
struct Template {
    spec: PodSpec,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PodSpec {
    restart_policy: &'static str,
    containers: Vec<Container>,
    volumes: Vec<Volume>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Container {
    name: &'static str,
    image: String,
    command: Vec<String>,
    resources: Resources,
    volume_mounts: Vec<VolumeMount>,
}

#[derive(Serialize)]
struct Resources {
    requests: Requests,
}

#[derive(Serialize)]
struct Requests {
    cpu: String,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct VolumeMount {
    name: &'static str,
    mount_path: &'static str,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Volume {
    name: &'static str,
    persistent_volume_claim: Claim,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Claim {
    claim_name: String,
}

/// Whether `name` is a DNS-1123 label of at most `max` characters (what Kubernetes takes as
/// a Job's name): lower-case letters, digits and `-`, starting and ending alphanumeric.
fn dns_label(name: &str, max: usize) -> bool {
    let edge = |c: Option<char>| c.is_some_and(|c| c.is_ascii_lowercase() || c.is_ascii_digit());
    name.len() <= max
        && edge(name.chars().next())
        && edge(name.chars().last())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
}

/// Whether `name` is a DNS-1123 subdomain (a PersistentVolumeClaim's name): dot-separated
/// labels, at most 253 characters.
fn dns_subdomain(name: &str) -> bool {
    name.len() <= 253 && name.split('.').all(|label| dns_label(label, 63))
}

/// The Kubernetes manifest for `job` (checked by [`Job::check`]; `--image` required).
pub fn kubernetes_manifest(job: &Job) -> Result<String, FarmError> {
    job.check()?;
    let Some(image) = job.image.clone() else {
        return Err(FarmError::new(
            "--image",
            "is required for Kubernetes: the container image the pods run",
        ));
    };
    // A Job's name is a label; its pods' names add a suffix of up to 6 characters and the index.
    let longest = 63 - "-shards".len() - 11;
    if !dns_label(&job.name, longest) {
        return Err(FarmError::new(
            "--name",
            format!(
                "{} must be lower-case letters, digits and '-', start and end with a letter or \
                 digit, at most {longest} characters (Kubernetes' rule for a Job's name)",
                comment(OsStr::new(&job.name))
            ),
        ));
    }
    if !dns_subdomain(&job.volume_claim) {
        return Err(FarmError::new(
            "--volume-claim",
            format!(
                "{} is not a PersistentVolumeClaim name (lower-case letters, digits, '-' and '.')",
                comment(OsStr::new(&job.volume_claim))
            ),
        ));
    }
    let quoted = |e: super::QuoteError| FarmError::new("SCENE, --out or --program", e.to_string());
    let program = job.runner(false).map_err(quoted)?;
    let shard_command = format!("exec {program} {}", job.shard_line(INDEX_VAR).map_err(quoted)?);
    let out = super::quote::shell_word(job.out.join("").as_os_str()).map_err(quoted)?;
    let merge_command = format!(
        "until [ \"$(ls {out}part_*.exr 2>/dev/null | wc -l)\" -ge {n} ]; do sleep 10; done; exec {program} {}",
        job.merge_line().map_err(quoted)?,
        n = job.shards,
    );
    let pod = |container: &'static str, restart: &'static str, command: String, cpu: u32| PodSpec {
        restart_policy: restart,
        containers: vec![Container {
            name: container,
            image: image.clone(),
            command: vec!["sh".into(), "-c".into(), command],
            resources: Resources {
                requests: Requests { cpu: cpu.to_string() },
            },
            volume_mounts: vec![VolumeMount {
                name: "data",
                mount_path: MOUNT,
            }],
        }],
        volumes: vec![Volume {
            name: "data",
            persistent_volume_claim: Claim {
                claim_name: job.volume_claim.clone(),
            },
        }],
    };
    let shards = K8sJob {
        api_version: "batch/v1",
        kind: "Job",
        metadata: Metadata {
            name: format!("{}-shards", job.name),
        },
        spec: JobSpec {
            completions: Some(job.shards),
            parallelism: Some(job.shards),
            completion_mode: Some("Indexed"),
            backoff_limit: 3 * job.shards,
            template: Template {
                spec: pod("shard", "Never", shard_command, job.threads),
            },
        },
    };
    let merge = K8sJob {
        api_version: "batch/v1",
        kind: "Job",
        metadata: Metadata {
            name: format!("{}-merge", job.name),
        },
        spec: JobSpec {
            completions: None,
            parallelism: None,
            completion_mode: None,
            backoff_limit: 3,
            template: Template {
                spec: pod("merge", "OnFailure", merge_command, 1),
            },
        },
    };
    let yaml =
        |j: &K8sJob| serde_yaml_ng::to_string(j).map_err(|e| FarmError::new("the manifest", e.to_string()));
    Ok(format!(
        "# Renders {scene} in {n} shards of {passes} passes on Kubernetes, then merges them.\n\
         # Written by `caustic farm kubernetes`; apply with `kubectl apply -f`. The scene and the\n\
         # output folder {out_c} are paths on the PersistentVolumeClaim {claim}, mounted at\n\
         # {MOUNT} in every pod. Parts are written under a hidden name and renamed when complete, so\n\
         # the merge Job counts only whole parts; it merges once all {n} are there.\n\
         {}---\n{}",
        yaml(&shards)?,
        yaml(&merge)?,
        scene = comment(job.scene.as_os_str()),
        n = job.shards,
        passes = job.passes,
        out_c = comment(job.out.as_os_str()),
        claim = comment(OsStr::new(&job.volume_claim)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_kubernetes_rules() {
        assert!(dns_label("caustic", 45) && dns_label("a-1", 45));
        for bad in ["", "-a", "a-", "A", "a_b", "a\n---", &"a".repeat(46)] {
            assert!(!dns_label(bad, 45), "{bad:?}");
        }
        assert!(dns_subdomain("caustic-data") && dns_subdomain("a.b-c"));
        assert!(!dns_subdomain("a..b") && !dns_subdomain("a b"));
    }
}
