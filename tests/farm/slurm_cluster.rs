//! A real one-node Slurm cluster on 127.0.0.1, owned by one test.
//!
//! Mocking `sbatch` would only test our idea of Slurm; this starts the actual
//! daemons (munged, slurmctld, slurmd) as children of the test, so job arrays,
//! dependencies and exit codes behave as on a real cluster. Everything the
//! daemons read or write lives in one fresh folder under the system temp
//! directory, and they listen on ports picked at start-up, so the machine's own
//! Slurm (if any) is never touched and several clusters can run side by side.
//! Dropping the cluster stops every process it started, job steps included.

use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::fs::{self, DirBuilder, File, OpenOptions};
use std::io::{self, Read, Write};
use std::net::TcpListener;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{DirBuilderExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::thread;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Without any of these there is no cluster to start or talk to; the caller
/// skips rather than fails, since most machines have no Slurm installed.
const TOOLS: [&str; 6] = [
    "munged",
    "slurmctld",
    "slurmd",
    "sbatch",
    "scontrol",
    "squeue",
];

/// The node reaches IDLE in about a second; the rest is headroom for a
/// machine whose cores are all busy (issue 47): a bound that fails loudly,
/// never one a figure depends on.
const START_TIMEOUT: Duration = Duration::from_secs(180);

/// A client command that hangs (controller wedged) must not hang the test
/// with it; generous, as [`START_TIMEOUT`] is.
const COMMAND_TIMEOUT: Duration = Duration::from_secs(120);

/// slurmctld saves its state on SIGTERM (well under a second here); a daemon
/// still alive after this long is stuck and gets SIGKILL.
const STOP_GRACE: Duration = Duration::from_secs(5);

const POLL: Duration = Duration::from_millis(100);

/// Variables through which an enclosing Slurm job (a CI runner that is itself
/// a Slurm job) would steer our clients toward its own cluster or options.
const FOREIGN_ENV_PREFIXES: [&str; 4] = ["SLURM_", "SBATCH_", "SQUEUE_", "SCONTROL_"];

/// A running one-node cluster. Its daemons and job steps die with it.
pub struct SlurmCluster {
    folder: PathBuf,
    conf: PathBuf,
    /// Kept apart from the Slurm daemons because it must outlive them: they
    /// authenticate through it until they have stopped.
    munged: Option<Child>,
    /// slurmctld and slurmd, named for the error when one dies early.
    slurm: Vec<(&'static str, Child)>,
}

impl SlurmCluster {
    /// Starts munged, slurmctld and slurmd and waits until the node is idle.
    ///
    /// Returns `Ok(None)` when a daemon or client is not on `PATH`, so the
    /// caller can print a skip banner instead of failing on machines without
    /// Slurm. Note that `/usr/sbin`, where Debian puts the daemons, is often
    /// missing from a non-root user's `PATH`. Any failure after that is an
    /// error carrying the tail of the daemons' logs, and whatever was already
    /// started is stopped again.
    pub fn start() -> io::Result<Option<Self>> {
        if TOOLS.iter().any(|tool| !on_path(tool)) {
            return Ok(None);
        }
        let folder = make_folder()?;
        // The guard exists before the first process does, so an early return
        // below stops whatever is running and removes the folder.
        let mut cluster = SlurmCluster {
            conf: folder.join("slurm.conf"),
            folder,
            munged: None,
            slurm: Vec::new(),
        };
        match cluster.boot() {
            Ok(()) => Ok(Some(cluster)),
            Err(e) => Err(io::Error::new(
                e.kind(),
                format!(
                    "starting Slurm in {}: {e}\n{}",
                    cluster.folder.display(),
                    cluster.log_tails()
                ),
            )),
        }
    }

    /// Variables a command needs to use this cluster instead of the machine's
    /// own configuration. Jobs inherit `SLURM_CONF` too, which is how `Drop`
    /// recognises their processes.
    pub fn env(&self) -> Vec<(String, String)> {
        vec![(
            "SLURM_CONF".to_owned(),
            self.conf.to_string_lossy().into_owned(),
        )]
    }

    /// Runs `sbatch --parsable ARGS` and returns the job id. For
    /// `--dependency=afterok:ID` on a job that fails, note that Slurm's default
    /// keeps the dependent job PENDING (reason DependencyNeverSatisfied)
    /// forever, so [`wait`](Self::wait) would time out on it; submit it with
    /// `--kill-on-invalid-dep=yes` to have it end CANCELLED instead.
    pub fn sbatch(&self, args: &[impl AsRef<OsStr>]) -> io::Result<u32> {
        let mut cmd = self.command("sbatch");
        cmd.arg("--parsable").args(args);
        let out = checked(run(cmd, COMMAND_TIMEOUT)?, "sbatch")?;
        let stdout = String::from_utf8_lossy(&out.stdout);
        // `--parsable` prints "ID" or, on a federation, "ID;CLUSTER".
        let id = stdout.trim().split(';').next().unwrap_or_default();
        id.parse()
            .map_err(|_| invalid(format!("sbatch printed {stdout:?}, not a job id")))
    }

    /// Returns once none of `ids` is pending, running or completing, polling
    /// `squeue` because there is no accounting daemon to ask for completion.
    /// The error after `timeout` lists what was still queued, with Slurm's
    /// reason, so a stuck dependency is told apart from a slow job.
    pub fn wait(&self, ids: &[u32], timeout: Duration) -> io::Result<()> {
        if ids.is_empty() {
            // `squeue -j ""` would list every job rather than none.
            return Ok(());
        }
        let list = ids.iter().map(u32::to_string).collect::<Vec<_>>().join(",");
        let deadline = Instant::now() + timeout;
        loop {
            let mut cmd = self.command("squeue");
            cmd.args(["--noheader", "--format=%i %T %r", "--jobs"])
                .arg(&list);
            let out = checked(run(cmd, COMMAND_TIMEOUT)?, "squeue")?;
            let queued = String::from_utf8_lossy(&out.stdout).trim().to_owned();
            if queued.is_empty() {
                return Ok(());
            }
            if Instant::now() >= deadline {
                return Err(io::Error::new(
                    io::ErrorKind::TimedOut,
                    format!("after {timeout:?}, still queued:\n{queued}"),
                ));
            }
            thread::sleep(POLL);
        }
    }

    /// The state of each task of job `id` as `scontrol` names it (COMPLETED,
    /// FAILED, CANCELLED, PENDING...), keyed by array index, or by 0 for a job
    /// that is not an array. A pending array prints its unstarted tasks as one
    /// range, which is expanded here. Finished jobs are only visible because
    /// the configuration sets MinJobAge to an hour: without slurmdbd, `sacct`
    /// has nothing to report.
    pub fn states(&self, id: u32) -> io::Result<BTreeMap<u32, String>> {
        let mut cmd = self.command("scontrol");
        cmd.args(["show", "job", "--oneliner"]).arg(id.to_string());
        let out = checked(run(cmd, COMMAND_TIMEOUT)?, "scontrol show job")?;
        let mut states = BTreeMap::new();
        for record in String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter(|l| !l.trim().is_empty())
        {
            let field = |name: &str| record.split_whitespace().find_map(|t| t.strip_prefix(name));
            let state =
                field("JobState=").ok_or_else(|| invalid(format!("no JobState in {record:?}")))?;
            let tasks = match field("ArrayTaskId=") {
                Some(spec) => task_ids(spec)
                    .ok_or_else(|| invalid(format!("odd ArrayTaskId in {record:?}")))?,
                None => vec![0],
            };
            for task in tasks {
                states.insert(task, state.to_owned());
            }
        }
        Ok(states)
    }

    /// The cluster's private folder: configuration, state, spool and the
    /// daemons' logs (`munged.log`, `slurmctld.log`, `slurmd.log`). Tests may
    /// put job scripts and outputs here; it is world-readable because munged
    /// insists on that for the directory of its socket.
    pub fn folder(&self) -> &Path {
        &self.folder
    }

    fn boot(&mut self) -> io::Result<()> {
        let folder = self.folder.clone();
        for sub in ["state", "spool"] {
            fs::create_dir(folder.join(sub))?;
        }
        let mut key = [0u8; 1024];
        File::open("/dev/urandom")?.read_exact(&mut key)?;
        // munged refuses a key that anyone else may read.
        OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o400)
            .open(folder.join("munge.key"))?
            .write_all(&key)?;
        let host = short_hostname()?;
        fs::write(&self.conf, self.config(&host)?)?;

        let socket = folder.join("munge.socket");
        let mut munged = Command::new("munged");
        munged
            .arg("--foreground")
            .arg(flag("--socket=", &socket))
            .arg(flag("--key-file=", &folder.join("munge.key")))
            .arg(flag("--pid-file=", &folder.join("munged.pid")))
            .arg(flag("--log-file=", &folder.join("munged.log")))
            .arg(flag("--seed-file=", &folder.join("munged.seed")));
        self.munged = Some(spawn_logged(munged, &folder.join("munged.log"))?);
        // Waiting for the socket reports a munged that cannot start as such,
        // rather than as authentication errors from the Slurm daemons.
        let deadline = Instant::now() + START_TIMEOUT;
        while !socket.exists() {
            self.check_alive()?;
            if Instant::now() >= deadline {
                return Err(io::Error::new(
                    io::ErrorKind::TimedOut,
                    "munged never created its socket",
                ));
            }
            thread::sleep(Duration::from_millis(10));
        }

        // `-D` keeps the daemons in the foreground as our children, so their
        // PIDs are known for certain and their logs go to our files.
        let mut ctld = self.command("slurmctld");
        ctld.arg("-D").arg("-f").arg(&self.conf);
        self.slurm.push((
            "slurmctld",
            spawn_logged(ctld, &folder.join("slurmctld.log"))?,
        ));
        let mut slurmd = self.command("slurmd");
        // `-N` spares slurmd from guessing its node name from the hostname.
        slurmd
            .arg("-D")
            .arg("-f")
            .arg(&self.conf)
            .arg("-N")
            .arg(&host);
        self.slurm
            .push(("slurmd", spawn_logged(slurmd, &folder.join("slurmd.log"))?));

        let mut last = String::from("no answer yet");
        while Instant::now() < deadline {
            self.check_alive()?;
            let mut cmd = self.command("scontrol");
            cmd.args(["show", "node", "--oneliner"]).arg(&host);
            match run(cmd, deadline.saturating_duration_since(Instant::now())) {
                Ok(out) => {
                    let text = String::from_utf8_lossy(&out.stdout);
                    if text.split_whitespace().any(|t| t == "State=IDLE") {
                        return Ok(());
                    }
                    last = format!(
                        "{}{}",
                        text.trim(),
                        String::from_utf8_lossy(&out.stderr).trim()
                    );
                }
                Err(e) => last = e.to_string(),
            }
            thread::sleep(POLL);
        }
        Err(io::Error::new(
            io::ErrorKind::TimedOut,
            format!("node {host} not idle after {START_TIMEOUT:?}; last scontrol answer: {last}"),
        ))
    }

    /// The whole configuration, so nothing is read from `/etc/slurm`. It has
    /// no cgroups (often unavailable in containers), no accounting daemon, and
    /// keeps finished jobs for an hour so `states` can still see them. The
    /// scheduler also runs a pass every second: left to its events alone it
    /// starts each wave of jobs two or three seconds late, which made a
    /// four-task array on two CPUs take about 8 s instead of 2 to 3 s.
    /// RealMemory is small because slurmd drains a node that claims more
    /// memory than the machine has; CR_Core keeps memory out of scheduling,
    /// so jobs never wait for it. ReturnToService=2 lets the node come back
    /// by itself if a slow start had it marked DOWN.
    fn config(&self, host: &str) -> io::Result<String> {
        let f = self.folder.display();
        // Slurm refuses to run as any user but SlurmUser/SlurmdUser, so both
        // are whoever runs the test; the folder was just created by that user.
        let uid = fs::metadata(&self.folder)?.uid();
        let user = if uid == 0 {
            "root".to_owned()
        } else {
            uid.to_string()
        };
        // Bound together so that the two picks cannot coincide; the daemons
        // bind all addresses, so the check does too.
        let ctld_probe = TcpListener::bind("0.0.0.0:0")?;
        let slurmd_probe = TcpListener::bind("0.0.0.0:0")?;
        let ctld_port = ctld_probe.local_addr()?.port();
        let slurmd_port = slurmd_probe.local_addr()?.port();
        let cpus = thread::available_parallelism().map_or(1, |n| n.get());
        Ok(format!(
            "ClusterName=marbre\n\
             SlurmctldHost={host}(127.0.0.1)\n\
             SlurmctldPort={ctld_port}\n\
             SlurmdPort={slurmd_port}\n\
             SlurmUser={user}\n\
             SlurmdUser={user}\n\
             AuthType=auth/munge\n\
             CredType=cred/munge\n\
             AuthInfo=socket={f}/munge.socket\n\
             StateSaveLocation={f}/state\n\
             SlurmdSpoolDir={f}/spool\n\
             SlurmctldPidFile={f}/slurmctld.pid\n\
             SlurmdPidFile={f}/slurmd.pid\n\
             ProctrackType=proctrack/linuxproc\n\
             TaskPlugin=task/none\n\
             JobAcctGatherType=jobacct_gather/none\n\
             AccountingStorageType=accounting_storage/none\n\
             JobCompType=jobcomp/none\n\
             SelectType=select/cons_tres\n\
             SelectTypeParameters=CR_Core\n\
             MpiDefault=none\n\
             MailProg=/bin/true\n\
             MinJobAge=3600\n\
             SchedulerParameters=sched_interval=1,bf_interval=1\n\
             ReturnToService=2\n\
             NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} RealMemory=512 State=UNKNOWN\n\
             PartitionName=test Nodes={host} Default=YES MaxTime=INFINITE State=UP\n"
        ))
    }

    /// A client or daemon command bound to this cluster, rid of any Slurm
    /// variables the test itself may have inherited.
    fn command(&self, program: &str) -> Command {
        let mut cmd = Command::new(program);
        for (key, _) in std::env::vars_os() {
            if key
                .to_str()
                .is_some_and(|k| FOREIGN_ENV_PREFIXES.iter().any(|p| k.starts_with(p)))
            {
                cmd.env_remove(key);
            }
        }
        cmd.envs(self.env()).stdin(Stdio::null());
        cmd
    }

    /// Fails fast when a daemon died (bad configuration, port taken) instead
    /// of waiting out the start-up timeout.
    fn check_alive(&mut self) -> io::Result<()> {
        let munged = self.munged.iter_mut().map(|child| ("munged", child));
        let slurm = self.slurm.iter_mut().map(|(name, child)| (*name, child));
        for (name, child) in munged.chain(slurm) {
            if let Some(status) = child.try_wait()? {
                return Err(io::Error::other(format!(
                    "{name} exited during start-up ({status})"
                )));
            }
        }
        Ok(())
    }

    fn log_tails(&self) -> String {
        let mut tails = String::new();
        for name in ["munged", "slurmctld", "slurmd"] {
            let path = self.folder.join(format!("{name}.log"));
            let Ok(text) = fs::read_to_string(&path) else {
                continue;
            };
            let lines: Vec<&str> = text.lines().collect();
            tails.push_str(&format!("--- last lines of {name}.log ---\n"));
            for line in &lines[lines.len().saturating_sub(15)..] {
                tails.push_str(line);
                tails.push('\n');
            }
        }
        tails
    }

    /// Job steps are not our children: slurmd forks them off and they survive
    /// it, still running the job. They and the jobs carry our `SLURM_CONF`
    /// in their environment, which identifies them among other clusters'.
    /// Repeats until a pass finds none, since a dying step may still fork.
    fn kill_job_processes(&self) {
        let mut needle = b"SLURM_CONF=".to_vec();
        needle.extend_from_slice(self.conf.as_os_str().as_bytes());
        let spared = [
            Some(std::process::id()),
            self.munged.as_ref().map(Child::id),
        ];
        for _ in 0..100 {
            let pids: Vec<u32> = processes()
                .into_iter()
                .filter(|pid| !spared.contains(&Some(*pid)))
                .filter(|pid| {
                    fs::read(format!("/proc/{pid}/environ"))
                        .is_ok_and(|env| env.split(|b| *b == 0).any(|var| var == needle.as_slice()))
                })
                .collect();
            if pids.is_empty() {
                return;
            }
            signal("KILL", &pids);
            thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for SlurmCluster {
    /// The Slurm daemons go first so that no new job step starts while the
    /// leftovers are killed; munged goes last because they use it until they exit.
    fn drop(&mut self) {
        stop(self.slurm.iter_mut().map(|(_, child)| child));
        self.kill_job_processes();
        stop(self.munged.iter_mut());
        let _ = fs::remove_dir_all(&self.folder);
    }
}

/// SIGTERM first so slurmctld saves its state and munged removes its socket;
/// SIGKILL for whatever is still there after [`STOP_GRACE`]. Signalled
/// together, as each daemon's shutdown is independent of the others'.
fn stop<'a>(children: impl Iterator<Item = &'a mut Child>) {
    let mut children: Vec<&mut Child> = children.collect();
    let pids: Vec<u32> = children.iter().map(|child| child.id()).collect();
    signal("TERM", &pids);
    let deadline = Instant::now() + STOP_GRACE;
    for child in &mut children {
        while matches!(child.try_wait(), Ok(None)) && Instant::now() < deadline {
            thread::sleep(Duration::from_millis(20));
        }
        if matches!(child.try_wait(), Ok(None)) {
            let _ = child.kill();
        }
        let _ = child.wait();
    }
}

/// Through `kill(1)`, as std can only send SIGKILL and only to its own
/// children. Failures are ignored: the process may already be gone, and a
/// missing `kill` still ends with `Child::kill` in [`stop`].
fn signal(name: &str, pids: &[u32]) {
    if pids.is_empty() {
        return;
    }
    let _ = Command::new("kill")
        .args(["-s", name])
        .args(pids.iter().map(u32::to_string))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
}

fn processes() -> Vec<u32> {
    let Ok(entries) = fs::read_dir("/proc") else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse().ok())
        .collect()
}

/// Unique among concurrent tests (counter) and processes (PID), and not
/// reused from a crashed run (time). Mode 0755: munged wants the directory of
/// its socket searchable by everyone.
fn make_folder() -> io::Result<PathBuf> {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let name = format!(
        "marbre-slurm-{}-{nanos}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    );
    let folder = std::env::temp_dir().join(name);
    DirBuilder::new().mode(0o755).create(&folder)?;
    // The umask may have taken bits away.
    fs::set_permissions(&folder, fs::Permissions::from_mode(0o755))?;
    Ok(folder)
}

/// The name slurmctld compares with SlurmctldHost to decide it is the
/// controller: the kernel's hostname up to the first dot, like `hostname -s`.
fn short_hostname() -> io::Result<String> {
    let full = fs::read_to_string("/proc/sys/kernel/hostname")?;
    let short = full.trim().split('.').next().unwrap_or_default();
    if short.is_empty() {
        return Err(invalid("the machine has no hostname".to_owned()));
    }
    Ok(short.to_owned())
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|dir| {
            fs::metadata(dir.join(program))
                .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
        })
    })
}

fn flag(name: &str, path: &Path) -> std::ffi::OsString {
    let mut arg = std::ffi::OsString::from(name);
    arg.push(path);
    arg
}

/// Appends, so munged's own `--log-file` writes and its stderr share one file.
fn spawn_logged(mut cmd: Command, log: &Path) -> io::Result<Child> {
    let file = OpenOptions::new().create(true).append(true).open(log)?;
    cmd.stdin(Stdio::null())
        .stdout(file.try_clone()?)
        .stderr(file)
        .spawn()
}

/// Runs `cmd` to completion, killing it after `timeout`. The pipes are
/// drained on threads so a long `scontrol` answer cannot block the child.
fn run(mut cmd: Command, timeout: Duration) -> io::Result<Output> {
    let mut child = cmd.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn()?;
    let stdout = drain(child.stdout.take());
    let stderr = drain(child.stderr.take());
    let deadline = Instant::now() + timeout;
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if Instant::now() >= deadline {
            let _ = child.kill();
            let _ = child.wait();
            return Err(io::Error::new(
                io::ErrorKind::TimedOut,
                format!("{cmd:?} did not finish within {timeout:?}"),
            ));
        }
        thread::sleep(Duration::from_millis(10));
    };
    Ok(Output {
        status,
        stdout: stdout.join().unwrap_or_default(),
        stderr: stderr.join().unwrap_or_default(),
    })
}

fn drain(pipe: Option<impl Read + Send + 'static>) -> thread::JoinHandle<Vec<u8>> {
    thread::spawn(move || {
        let mut bytes = Vec::new();
        if let Some(mut pipe) = pipe {
            let _ = pipe.read_to_end(&mut bytes);
        }
        bytes
    })
}

fn checked(out: Output, what: &str) -> io::Result<Output> {
    if out.status.success() {
        return Ok(out);
    }
    Err(io::Error::other(format!(
        "{what} failed ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr).trim()
    )))
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, message)
}

/// Expands an `ArrayTaskId` as `scontrol` prints it: `3`, `2-3`, `1,4-6`,
/// `0-9:2` (a step), each possibly followed by `%N` (a limit on tasks running
/// at once, irrelevant here).
fn task_ids(spec: &str) -> Option<Vec<u32>> {
    let spec = spec.split('%').next()?;
    let mut ids = Vec::new();
    for part in spec.split(',') {
        let (range, step): (&str, usize) = match part.split_once(':') {
            Some((range, step)) => (range, step.parse().ok().filter(|s| *s > 0)?),
            None => (part, 1),
        };
        let (first, last): (u32, u32) = match range.split_once('-') {
            Some((first, last)) => (first.parse().ok()?, last.parse().ok()?),
            None => (range.parse().ok()?, range.parse().ok()?),
        };
        ids.extend((first..=last).step_by(step));
    }
    Some(ids)
}

#[cfg(test)]
mod tests {
    use super::task_ids;

    #[test]
    fn array_task_ids_expand_as_scontrol_prints_them() {
        assert_eq!(task_ids("3"), Some(vec![3]));
        assert_eq!(task_ids("2-3"), Some(vec![2, 3]));
        assert_eq!(task_ids("1,4-6%2"), Some(vec![1, 4, 5, 6]));
        assert_eq!(task_ids("0-6:3"), Some(vec![0, 3, 6]));
        assert_eq!(task_ids("x"), None);
        assert_eq!(task_ids("0-4:0"), None);
    }
}
