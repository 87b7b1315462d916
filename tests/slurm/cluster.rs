//! A Slurm cluster for the test: the one that is up (`scontrol ping` answers), or a one-node
//! cluster of the test's own in a temporary folder, stopped when the [`Cluster`] is dropped.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::binary::text;
use crate::{JOB_DEADLINE, on_path, path_with_examples, runs, runtime_dir};

/// The cluster the test submits to. Dropping it stops the daemons the test started.
pub(crate) struct Cluster {
    /// The test's own cluster's folder (configuration, munge key and socket, state, logs, pid
    /// files); None for a cluster that was already up.
    pub(crate) own: Option<tempfile::TempDir>,
}

impl Cluster {
    pub(crate) fn conf(&self) -> Option<PathBuf> {
        self.own.as_ref().map(|d| d.path().join("slurm.conf"))
    }

    /// A Slurm command that talks to this cluster, with the examples on PATH and lavapipe's
    /// runtime folder (sbatch hands its environment to the job).
    pub(crate) fn command(&self, program: &str) -> Command {
        let mut command = Command::new(program);
        if let Some(conf) = self.conf() {
            command.env("SLURM_CONF", conf);
        }
        command.env("PATH", path_with_examples()).env("XDG_RUNTIME_DIR", runtime_dir());
        command
    }

    pub(crate) fn run(&self, program: &str, args: &[&str]) -> Output {
        self.command(program).args(args).output().unwrap_or_else(|e| panic!("{program}: {e}"))
    }

    /// What the cluster's logs and queue say, for a failure message.
    pub(crate) fn diagnostics(&self) -> String {
        let mut text = format!("squeue:\n{}", text(&self.run("squeue", &[]).stdout));
        if let Some(dir) = &self.own {
            for log in ["slurmctld.log", "slurmd.log"] {
                let content = std::fs::read_to_string(dir.path().join("log").join(log)).unwrap_or_default();
                let tail: Vec<&str> = content.lines().rev().take(15).collect();
                text += &format!(
                    "\n{log} (last lines):\n{}",
                    tail.into_iter().rev().collect::<Vec<_>>().join("\n")
                );
            }
        }
        text
    }

    /// Waits until the jobs `ids` have left the queue, then returns each job's (or array task's)
    /// state, as `scontrol show job` gives it: `COMPLETED`, `FAILED`, `CANCELLED`... A job
    /// pending on a dependency that can never be met ends the wait too (the README's merge,
    /// submitted without --kill-on-invalid-dep, would wait forever after a failed task).
    pub(crate) fn wait(&self, ids: &[&str]) -> Vec<(String, String)> {
        let start = Instant::now();
        let list = ids.join(",");
        loop {
            let queue = self.run("squeue", &["-h", "-j", &list, "-o", "%i %r"]);
            let queued = text(&queue.stdout);
            let waiting_forever = queued.lines().any(|l| l.ends_with("DependencyNeverSatisfied"));
            if queued.trim().is_empty() || waiting_forever {
                break;
            }
            assert!(
                start.elapsed() < JOB_DEADLINE,
                "jobs {list} still queued after {} s:\n{}",
                JOB_DEADLINE.as_secs(),
                self.diagnostics()
            );
            std::thread::sleep(Duration::from_millis(500));
        }
        let mut states = Vec::new();
        for id in ids {
            let shown = text(&self.run("scontrol", &["show", "job", "-o", id]).stdout);
            for line in shown.lines() {
                let field = |key: &str| {
                    line.split_whitespace().find_map(|w| w.strip_prefix(key)).unwrap_or("?").to_owned()
                };
                let task = match field("ArrayTaskId=") {
                    t if t == "?" => id.to_string(),
                    t => format!("{}_{t}", field("ArrayJobId=")),
                };
                states.push((task, field("JobState=")));
            }
        }
        states
    }

    /// Waits for `ids` and asserts that every job and task completed.
    pub(crate) fn wait_completed(&self, ids: &[&str], logs: &Path) {
        let states = self.wait(ids);
        let failed: Vec<_> = states.iter().filter(|(_, s)| s != "COMPLETED").collect();
        assert!(
            !states.is_empty() && failed.is_empty(),
            "jobs not completed: {failed:?} (all: {states:?})\nlogs in {}:\n{}\n{}",
            logs.display(),
            read_logs(logs),
            self.diagnostics()
        );
    }
}

/// Every `.log` file in `dir`, named, for a failure message.
pub(crate) fn read_logs(dir: &Path) -> String {
    let mut logs: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|e| e == "log")).collect()
        })
        .unwrap_or_default();
    logs.sort();
    logs.iter()
        .map(|p| format!("== {}\n{}", p.display(), std::fs::read_to_string(p).unwrap_or_default()))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The pid in a daemon's pid file, if it names a running process.
fn running_pid(pid_file: &Path) -> Option<u32> {
    let pid: u32 = std::fs::read_to_string(pid_file).ok()?.trim().parse().ok()?;
    Path::new(&format!("/proc/{pid}")).exists().then_some(pid)
}

impl Drop for Cluster {
    /// Stops the daemons this test started, by their pid files: SIGTERM, then SIGKILL for one
    /// that has not ended within 10 s.
    fn drop(&mut self) {
        let Some(dir) = &self.own else { return };
        for daemon in ["slurmd", "slurmctld", "munged"] {
            let pid_file = dir.path().join("run").join(format!("{daemon}.pid"));
            let Some(pid) = running_pid(&pid_file) else { continue };
            let _ = Command::new("kill").arg(pid.to_string()).status();
            // Until the process is gone, not its pid file: a daemon removes that file before it
            // has finished shutting down.
            let alive = || Path::new(&format!("/proc/{pid}")).exists();
            let start = Instant::now();
            while alive() && start.elapsed() < Duration::from_secs(10) {
                std::thread::sleep(Duration::from_millis(100));
            }
            if alive() {
                let _ = Command::new("kill").args(["-KILL", &pid.to_string()]).status();
            }
        }
    }
}

/// Whether a cluster answers with the caller's configuration.
fn cluster_is_up() -> bool {
    Command::new("scontrol")
        .arg("ping")
        .output()
        .is_ok_and(|o| o.status.success() && text(&o.stdout).contains("UP"))
}

/// What is missing to run the Slurm test, with the command that installs each piece.
pub(crate) fn missing_for_slurm() -> Vec<String> {
    let mut missing = Vec::new();
    // `sbatch --version` fails without a configuration, so look for the programs instead.
    if !["sbatch", "squeue", "scontrol", "scancel", "sinfo"].iter().all(|p| on_path(p)) {
        missing.push("Slurm's commands (apt-get install slurm-wlm munge)".to_owned());
        return missing;
    }
    if cluster_is_up() {
        return missing;
    }
    for daemon in ["slurmctld", "slurmd", "munged"] {
        if !runs(daemon, &["-V"]) {
            missing.push(format!("{daemon}, to start a one-node cluster (apt-get install slurm-wlm munge)"));
        }
    }
    if !runs("id", &["-u"]) || text(&Command::new("id").arg("-u").output().expect("id").stdout).trim() != "0"
    {
        missing.push("root, to start slurmd (or a running cluster: scontrol ping answers)".to_owned());
    }
    missing
}

/// A free TCP port (bound then released: another program may take it in between, and the
/// daemon's start then fails, naming it).
fn free_port() -> u16 {
    std::net::TcpListener::bind("0.0.0.0:0")
        .expect("binding a port")
        .local_addr()
        .expect("its address")
        .port()
}

/// The cluster that is up, or a one-node cluster started in a temporary folder.
pub(crate) fn start_cluster() -> Cluster {
    if cluster_is_up() {
        println!("using the Slurm cluster that is up (scontrol ping answers)");
        return Cluster { own: None };
    }
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::Builder::new().prefix("illum-slurm").tempdir().expect("a temporary folder");
    let d = dir.path().to_path_buf();
    let d = d.as_path();
    let cluster = Cluster { own: Some(dir) };
    // munged requires its socket's folder and every folder above it to be searchable by all,
    // and its key readable by its user only.
    for (sub, mode) in
        [("", 0o755), ("munge", 0o700), ("run", 0o755), ("state", 0o700), ("spool", 0o700), ("log", 0o755)]
    {
        let path = d.join(sub);
        std::fs::create_dir_all(&path).expect("creating the cluster's folders");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(mode)).expect("setting permissions");
    }
    let mut key = vec![0u8; 1024];
    std::fs::File::open("/dev/urandom")
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut key))
        .expect("reading /dev/urandom");
    let key_file = d.join("munge/munge.key");
    std::fs::write(&key_file, key).expect("writing the munge key");
    std::fs::set_permissions(&key_file, std::fs::Permissions::from_mode(0o400)).expect("setting permissions");
    let socket = d.join("run/munge.socket");
    let at = |p: &str| d.join(p).display().to_string();
    let munged = Command::new("munged")
        .arg(format!("--socket={}", socket.display()))
        .arg(format!("--key-file={}", key_file.display()))
        .arg(format!("--pid-file={}", at("run/munged.pid")))
        .arg(format!("--log-file={}", at("log/munged.log")))
        .arg(format!("--seed-file={}", at("munge/munged.seed")))
        .output()
        .expect("munged starts");
    assert!(munged.status.success(), "munged failed: {}", text(&munged.stderr));

    let host =
        text(&Command::new("hostname").arg("-s").output().expect("hostname runs").stdout).trim().to_owned();
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap_or_default();
    let mem_kib: u64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemTotal:"))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or(1024 * 1024);
    // 90% of the memory, as the node's to give: slurmd refuses a node configured with more
    // than it has.
    let real_memory = mem_kib / 1024 * 9 / 10;
    let conf = format!(
        "ClusterName=illumtest\nSlurmctldHost={host}\nSlurmctldPort={}\nSlurmdPort={}\nSlurmUser=root\n\
         SlurmdUser=root\nAuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket={socket}\n\
         ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\nSelectType=select/cons_tres\n\
         SelectTypeParameters=CR_Core\nMpiDefault=none\nReturnToService=2\nStateSaveLocation={state}\n\
         SlurmdSpoolDir={spool}\nSlurmctldPidFile={ctld_pid}\nSlurmdPidFile={d_pid}\n\
         SlurmctldLogFile={ctld_log}\nSlurmdLogFile={d_log}\nJobCompType=jobcomp/none\n\
         AccountingStorageType=accounting_storage/none\n\
         NodeName={host} CPUs={cpus} RealMemory={real_memory} State=UNKNOWN\n\
         PartitionName=debug Nodes={host} Default=YES MaxTime=INFINITE State=UP\n",
        free_port(),
        free_port(),
        socket = socket.display(),
        state = at("state"),
        spool = at("spool"),
        ctld_pid = at("run/slurmctld.pid"),
        d_pid = at("run/slurmd.pid"),
        ctld_log = at("log/slurmctld.log"),
        d_log = at("log/slurmd.log"),
    );
    std::fs::write(d.join("slurm.conf"), conf).expect("writing slurm.conf");
    for daemon in ["slurmctld", "slurmd"] {
        let out = cluster.run(daemon, &[]);
        assert!(out.status.success(), "{daemon} failed: {}\n{}", text(&out.stderr), cluster.diagnostics());
    }
    let start = Instant::now();
    loop {
        let state = text(&cluster.run("sinfo", &["-h", "-o", "%t"]).stdout);
        if state.trim() == "idle" {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the one-node cluster did not come up (sinfo: {state:?}):\n{}",
            cluster.diagnostics()
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    println!("started a one-node Slurm cluster in {}", d.display());
    cluster
}
