//! The files that hand a job to a scheduler: for Slurm a job-array
//! script, a merge script and a submit step that makes the merge wait for
//! every task (`afterok`); for Kubernetes an Indexed Job, a merge Job and
//! a submit step. Each task runs `marbre farm task DIR INDEX`, the array
//! index coming from `SLURM_ARRAY_TASK_ID` or the Indexed Job's
//! `JOB_COMPLETION_INDEX`.

//!
//! Every path and name in a script is one word of [`quoted`]; the
//! manifests are written by serde_json. Both take paths that
//! [`super::carry`] checked: UTF-8 text without control characters.

use super::plan::FarmPlan;
use super::shell::{error_line, quoted};
use serde_json::json;
use std::path::{Path, PathBuf};

/// What a Slurm job asks of the cluster (`marbre farm slurm`'s flags).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SlurmOptions {
    pub partition: Option<String>,
    /// Generic resources, such as `gpu:1`.
    pub gres: Option<String>,
    /// The time limit, as `sbatch --time` takes it.
    pub time: Option<String>,
    pub cpus: Option<u32>,
}

/// `path` as one shell word.
fn quoted_path(path: &Path) -> String {
    quoted(&path.to_string_lossy())
}

impl SlurmOptions {
    /// The flags given, by name, for [`super::carry::slurm_value`].
    pub fn given(&self) -> impl Iterator<Item = (&'static str, &str)> {
        [
            ("--partition", &self.partition),
            ("--gres", &self.gres),
            ("--time", &self.time),
        ]
        .into_iter()
        .filter_map(|(flag, value)| Some((flag, value.as_deref()?)))
    }
}

/// The `#SBATCH` lines both scripts share.
fn sbatch_options(options: &SlurmOptions) -> String {
    let mut lines = String::new();
    for (flag, value) in [
        ("partition", options.partition.clone()),
        ("gres", options.gres.clone()),
        ("time", options.time.clone()),
        ("cpus-per-task", options.cpus.map(|c| c.to_string())),
    ] {
        if let Some(value) = value {
            lines.push_str(&format!("#SBATCH --{flag}={value}\n"));
        }
    }
    lines
}

/// The Slurm files of the job in `dir` ([`super::carry::slurm_folder`],
/// whose `#SBATCH --output` lines hold it unquoted), by name:
/// `tasks.sbatch` (the array), `merge.sbatch` and `submit.sh`. `marbre`:
/// the binary's path on the nodes.
pub fn slurm(
    plan: &FarmPlan,
    dir: &Path,
    marbre: &Path,
    options: &SlurmOptions,
) -> Vec<(&'static str, String)> {
    let (dir_text, marbre) = (quoted_path(dir), quoted_path(marbre));
    let logs = dir.join("logs");
    let tasks = format!(
        "#!/bin/bash\n\
         #SBATCH --job-name=marbre-tasks\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --output={logs}/task_%a.out\n\
         {options}\
         # lavapipe (Mesa's Vulkan on the CPU) runs as many threads as the\n\
         # task has CPUs, not as many as the node has.\n\
         export LP_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-1}}\"\n\
         exec -- {marbre} farm task {dir_text} \"$SLURM_ARRAY_TASK_ID\"\n",
        last = plan.tasks() - 1,
        logs = logs.display(),
        options = sbatch_options(options),
    );
    let merge = format!(
        "#!/bin/bash\n\
         #SBATCH --job-name=marbre-merge\n\
         #SBATCH --output={logs}/merge.out\n\
         {options}\
         exec -- {marbre} farm merge {dir_text}\n",
        logs = logs.display(),
        options = sbatch_options(&SlurmOptions {
            gres: None,
            ..options.clone()
        }),
    );
    let submit = format!(
        "#!/bin/sh\n\
         # Submits the tasks, then the merge, which starts once every task\n\
         # has succeeded (afterok); if one fails the merge is cancelled, and\n\
         # `marbre farm merge` names the tasks to run again.\n\
         set -eu\n\
         tasks=$(sbatch --parsable {tasks_script})\n\
         tasks=${{tasks%%;*}}\n\
         merge=$(sbatch --parsable --dependency=afterok:\"$tasks\" --kill-on-invalid-dep=yes {merge_script})\n\
         printf 'tasks: job %s (%s tasks); merge: job %s\\n' \"$tasks\" {count} \"${{merge%%;*}}\"\n",
        tasks_script = quoted_path(&dir.join("tasks.sbatch")),
        merge_script = quoted_path(&dir.join("merge.sbatch")),
        count = plan.tasks(),
    );
    vec![
        ("tasks.sbatch", tasks),
        ("merge.sbatch", merge),
        ("submit.sh", submit),
    ]
}

/// What a Kubernetes job asks of the cluster (`marbre farm k8s`'s flags).
#[derive(Debug, Clone, PartialEq)]
pub struct KubernetesOptions {
    /// The container image holding marbre.
    pub image: String,
    /// The persistent volume claim holding the job's folder and the
    /// preset.
    pub claim: String,
    /// Where the claim is mounted in every pod: the path it has on the
    /// machine that wrote the job, so that the plan's paths hold there.
    pub mount: PathBuf,
    /// Tasks running at once.
    pub parallelism: u32,
    pub gpus: u32,
    pub cpus: u32,
}

/// The Kubernetes files of the job in `dir`: `tasks-job.json` (an
/// Indexed Job), `merge-job.json` and `submit-k8s.sh`. JSON, which
/// `kubectl apply` takes as it takes YAML.
pub fn kubernetes(
    plan: &FarmPlan,
    dir: &Path,
    options: &KubernetesOptions,
) -> Vec<(&'static str, String)> {
    let dir_text = dir.to_string_lossy();
    let mount = options.mount.to_string_lossy();
    // Job names are unique in a namespace: two jobs' folders give two.
    let suffix = job_suffix(dir);
    let (tasks_name, merge_name) = (
        format!("marbre-tasks-{suffix}"),
        format!("marbre-merge-{suffix}"),
    );
    let container = |name: &str, args: serde_json::Value, gpus: u32| {
        let mut limits = json!({ "cpu": options.cpus.to_string() });
        if gpus > 0 {
            limits["nvidia.com/gpu"] = json!(gpus.to_string());
        }
        json!({
            "name": name,
            "image": options.image,
            "command": ["marbre"],
            "args": args,
            "env": [{
                // lavapipe's threads follow the CPUs the pod may use.
                "name": "LP_NUM_THREADS",
                "valueFrom": { "resourceFieldRef": { "resource": "limits.cpu", "divisor": "1" } }
            }],
            "resources": { "limits": limits },
            "volumeMounts": [{ "name": "job", "mountPath": mount }]
        })
    };
    let volumes = json!([{
        "name": "job",
        "persistentVolumeClaim": { "claimName": options.claim }
    }]);
    let tasks = json!({
        "apiVersion": "batch/v1",
        "kind": "Job",
        "metadata": { "name": tasks_name },
        "spec": {
            "completionMode": "Indexed",
            "completions": plan.tasks(),
            "parallelism": options.parallelism.min(plan.tasks()),
            // An index that fails is retried on its own, up to twice.
            "backoffLimitPerIndex": 2,
            "template": { "spec": {
                "restartPolicy": "Never",
                "containers": [container(
                    "task",
                    // The index: JOB_COMPLETION_INDEX, which the Job
                    // controller sets in each pod.
                    json!(["farm", "task", dir_text]),
                    options.gpus,
                )],
                "volumes": volumes
            }}
        }
    });
    let merge = json!({
        "apiVersion": "batch/v1",
        "kind": "Job",
        "metadata": { "name": merge_name },
        "spec": {
            "backoffLimit": 0,
            "template": { "spec": {
                "restartPolicy": "Never",
                "containers": [container("merge", json!(["farm", "merge", dir_text]), 0)],
                "volumes": volumes
            }}
        }
    });
    let pretty = |v: &serde_json::Value| {
        serde_json::to_string_pretty(v).expect("a JSON value writes") + "\n"
    };
    let submit = format!(
        "#!/bin/sh\n\
         # Runs the tasks and waits until every index has succeeded, then the\n\
         # merge; stops if the Job fails (an index out of retries): `marbre\n\
         # farm merge` names the tasks, and running this again reruns only\n\
         # them (a finished index does nothing).\n\
         set -eu\n\
         kubectl delete --ignore-not-found {tasks_job} {merge_job}\n\
         kubectl apply -f {tasks}\n\
         while ! kubectl wait --for=condition=complete --timeout=10s {tasks_job} >/dev/null 2>&1; do\n\
         \x20   if kubectl wait --for=condition=failed --timeout=0s {tasks_job} >/dev/null 2>&1; then\n\
         \x20       {failed}\n\
         \x20       exit 1\n\
         \x20   fi\n\
         done\n\
         kubectl apply -f {merge}\n",
        tasks_job = quoted(&format!("job/{tasks_name}")),
        merge_job = quoted(&format!("job/{merge_name}")),
        tasks = quoted_path(&dir.join("tasks-job.json")),
        merge = quoted_path(&dir.join("merge-job.json")),
        failed = error_line(&format!(
            "job/{tasks_name} failed: run marbre farm merge {} to see which tasks",
            quoted(&dir_text)
        )),
    );
    vec![
        ("tasks-job.json", pretty(&tasks)),
        ("merge-job.json", pretty(&merge)),
        ("submit-k8s.sh", submit),
    ]
}

/// A suffix naming the job in `dir` within Kubernetes' name rules (lower
/// case letters, digits and `-`): the folder's name, cut to 30
/// characters, and 8 hex digits of its whole path's hash.
fn job_suffix(dir: &Path) -> String {
    let name: String = dir
        .file_name()
        .map(|n| n.to_string_lossy().to_lowercase())
        .unwrap_or_default()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .take(30)
        .collect();
    let hash = marbre_core::render_record::fnv1a_hex(dir.as_os_str().as_encoded_bytes());
    let name = name.trim_matches('-');
    if name.is_empty() {
        hash[..8].to_owned()
    } else {
        format!("{name}-{}", &hash[..8])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::farm::plan::Split;
    use std::path::PathBuf;

    fn plan() -> FarmPlan {
        FarmPlan {
            preset: PathBuf::from("/shared/p.ron"),
            size: (64, 64),
            spp: 64,
            preset_hash: "0123456789abcdef".into(),
            split: Split::Batches { batches: 4 },
            frames: Some(0..=2),
            fps: 24.0,
            kernel: "auto".into(),
            format: "exr".into(),
            moments: false,
            denoise: false,
            scheduler: crate::farm::plan::Scheduler::Slurm,
        }
    }

    /// The array covers every task, its index reaches the task command,
    /// lavapipe's threads follow the allocation, the flags become
    /// `#SBATCH` lines, and the merge waits for every task.
    #[test]
    fn slurm_scripts_run_every_task_then_the_merge() {
        let options = SlurmOptions {
            partition: Some("gpu".into()),
            gres: Some("gpu:1".into()),
            time: Some("01:00:00".into()),
            cpus: Some(4),
        };
        let files = slurm(
            &plan(),
            Path::new("/jobs/a"),
            Path::new("/opt/o'marbre"),
            &options,
        );
        let text = |name: &str| files.iter().find(|(n, _)| *n == name).unwrap().1.clone();
        let tasks = text("tasks.sbatch");
        assert!(tasks.contains("#SBATCH --array=0-11\n"), "{tasks}");
        assert!(tasks.contains(
            "#SBATCH --gres=gpu:1\n#SBATCH --time=01:00:00\n#SBATCH --cpus-per-task=4\n"
        ));
        assert!(tasks.contains(r#"LP_NUM_THREADS="${SLURM_CPUS_PER_TASK:-1}""#));
        assert!(
            tasks.contains("#SBATCH --output=/jobs/a/logs/task_%a.out\n"),
            "{tasks}"
        );
        assert!(
            tasks.contains(
                r#"exec -- '/opt/o'\''marbre' farm task '/jobs/a' "$SLURM_ARRAY_TASK_ID""#
            ),
            "{tasks}"
        );
        let merge = text("merge.sbatch");
        assert!(
            !merge.contains("gres") && merge.contains("farm merge"),
            "{merge}"
        );
        assert!(text("submit.sh").contains("--dependency=afterok:\"$tasks\""));
    }

    /// The Indexed Job's fields, read back from its JSON.
    #[test]
    fn the_kubernetes_job_is_indexed_over_every_task() {
        let options = KubernetesOptions {
            image: "registry.example/marbre:0.1".into(),
            claim: "renders".into(),
            mount: PathBuf::from("/jobs"),
            parallelism: 64,
            gpus: 1,
            cpus: 8,
        };
        let files = kubernetes(&plan(), Path::new("/jobs/a"), &options);
        let job: serde_json::Value = serde_json::from_str(&files[0].1).unwrap();
        assert_eq!(job["kind"], "Job");
        assert_eq!(job["spec"]["completionMode"], "Indexed");
        assert_eq!(job["spec"]["completions"], 12);
        assert_eq!(job["spec"]["parallelism"], 12);
        let pod = &job["spec"]["template"]["spec"];
        assert_eq!(pod["restartPolicy"], "Never");
        let c = &pod["containers"][0];
        assert_eq!(c["image"], "registry.example/marbre:0.1");
        assert_eq!(
            c["args"],
            serde_json::json!(["farm", "task", "/jobs/a"]),
            "the index comes from JOB_COMPLETION_INDEX"
        );
        assert_eq!(c["resources"]["limits"]["nvidia.com/gpu"], "1");
        assert_eq!(c["env"][0]["name"], "LP_NUM_THREADS");
        assert_eq!(c["volumeMounts"][0]["mountPath"], "/jobs");
        let name = job["metadata"]["name"].as_str().unwrap();
        assert!(name.starts_with("marbre-tasks-a-") && name.len() == "marbre-tasks-a-".len() + 8);
        let other = kubernetes(&plan(), Path::new("/other/a"), &options);
        let other: serde_json::Value = serde_json::from_str(&other[0].1).unwrap();
        assert_ne!(
            other["metadata"]["name"], job["metadata"]["name"],
            "two folders, two names"
        );
        assert_eq!(
            pod["volumes"][0]["persistentVolumeClaim"]["claimName"],
            "renders"
        );
        let merge: serde_json::Value = serde_json::from_str(&files[1].1).unwrap();
        assert_eq!(
            merge["spec"]["template"]["spec"]["containers"][0]["args"][1],
            "merge"
        );
        let submit = &files[2].1;
        assert!(submit.contains(&format!(
            "kubectl wait --for=condition=complete --timeout=10s 'job/{name}'"
        )));
        assert!(
            submit.contains("--for=condition=failed"),
            "a failed Job ends the wait: {submit}"
        );
    }
}
