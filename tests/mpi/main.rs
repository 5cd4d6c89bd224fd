//! The MUMPS backend over MPI, as a user runs it: `mpirun -n N rothe run SCENARIO
//! --backend mumps`. Its histories equal faer's on one and two ranks, a run repeats
//! to the last bit on one rank and to round-off on two, `rothe check` gives MUMPS's
//! estimates per rank, and faults end the run as failed with its files valid: a
//! rank killed mid-run, a rank that stops answering (the collectives' timeout), a
//! single-process backend launched on several ranks.
//!
//! Built with the `mumps` feature only (Debian's libmumps-dev and libopenmpi-dev,
//! and `mpirun` on the path); as root, OpenMPI's `OMPI_ALLOW_RUN_AS_ROOT` pair is
//! set for the launches here.
#![cfg(feature = "mumps")]

mod agreement;
mod faults;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::{Mutex, MutexGuard};

static MACHINE: Mutex<()> = Mutex::new(());

/// Held by each test for its whole length: one MPI job at a time, so that the
/// timeouts and the interrupted runs' timing are the test's own.
fn exclusive() -> MutexGuard<'static, ()> {
    MACHINE.lock().unwrap_or_else(|e| e.into_inner())
}

/// `mpirun -n ranks rothe args…` (not yet started), with the environment root
/// needs and the other ranks allowed on few cores.
fn mpirun(ranks: usize, args: &[&str]) -> Command {
    let mut c = Command::new("mpirun");
    c.args(["-n", &ranks.to_string(), "--oversubscribe"])
        .arg(env!("CARGO_BIN_EXE_rothe"))
        .args(args)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .stdin(Stdio::null());
    c
}

/// Runs `mpirun -n ranks rothe args…` to the end.
fn launch(ranks: usize, args: &[&str]) -> Output {
    mpirun(ranks, args).output().expect("mpirun starts")
}

/// Runs `rothe args…` in this process's way (no MPI launcher).
fn alone(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rothe"))
        .args(args)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

/// Standard error of an output, for messages.
fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A history: the header and the rows as numbers; panics on a cut or unparsable
/// row.
fn history(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| {
            let row: Vec<f64> = l
                .split(',')
                .map(|v| v.trim().parse().unwrap_or_else(|_| panic!("row `{l}`")))
                .collect();
            assert_eq!(row.len(), header.len(), "row `{l}` is cut");
            row
        })
        .collect();
    (header, rows)
}

/// The `summary.json` of a run.
fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

/// The running processes whose command line holds `marker` and whose environment
/// says OpenMPI rank `rank`.
fn rank_pids(marker: &str, rank: usize) -> Vec<u32> {
    let mut pids = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let cmdline = std::fs::read(entry.path().join("cmdline")).unwrap_or_default();
        let environ = std::fs::read(entry.path().join("environ")).unwrap_or_default();
        let cmd = String::from_utf8_lossy(&cmdline);
        let env = String::from_utf8_lossy(&environ);
        if cmd.contains(marker)
            && cmd.contains("rothe")
            && !cmd.starts_with("mpirun")
            && env
                .split('\0')
                .any(|kv| kv == format!("OMPI_COMM_WORLD_RANK={rank}"))
        {
            pids.push(pid);
        }
    }
    pids
}

/// Waits for `child` up to `secs` seconds; kills it and panics on a hang.
fn wait_for(child: &mut Child, secs: u64, what: &str) -> std::process::ExitStatus {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed().as_secs() > secs {
            let _ = child.kill();
            panic!("{what}: still running after {secs} s (a hang)");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

/// The scenario files used here.
fn examples(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}
