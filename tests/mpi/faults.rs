//! Faults and refusals: a rank killed mid-run and a rank that stops answering end
//! the run as failed, with every row of its history whole and its summary saying
//! why, and no hang; a single-process backend on several ranks is refused; `rothe
//! check` reports MUMPS's estimate for each rank.

use super::*;

/// W3 at 2 x 6 x 6 cells for 2000 steps: long enough to be caught mid-run.
fn long_run(out: &Path) -> Vec<String> {
    let sc = examples("cluster/w3.toml");
    [
        "run",
        sc.to_str().unwrap(),
        "--set",
        "bodies.0.mesh.divisions=[24,6,6]",
        "--set",
        "analysis.t_end=2e-2",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--backend",
        "mumps",
    ]
    .map(String::from)
    .to_vec()
}

/// Starts the long run on two ranks, waits for 20 rows of history, then sends
/// `signal` to rank 1; returns the launcher's exit status and the output directory.
fn interrupt_rank_1(
    signal: &str,
    timeout: Option<&str>,
) -> (std::process::ExitStatus, tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let args = long_run(&out);
    let mut cmd = mpirun(2, &args.iter().map(String::as_str).collect::<Vec<_>>());
    if let Some(t) = timeout {
        cmd.env("ROTHE_MPI_TIMEOUT", t);
    }
    let mut child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    loop {
        let rows = std::fs::read_to_string(out.join("history.csv"))
            .map(|t| t.lines().count())
            .unwrap_or(0);
        // The header and more than 20 steps: the files checked after the fault
        // hold more than 20 rows whatever the machine's load.
        if rows > 21 {
            break;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before it could be interrupted"
        );
        assert!(start.elapsed().as_secs() < 120, "the run never started");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let marker = out.to_str().unwrap();
    let pids = rank_pids(marker, 1);
    assert_eq!(pids.len(), 1, "rank 1's process: {pids:?}");
    let killed = Command::new("kill")
        .args([signal, &pids[0].to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = wait_for(&mut child, 60, "the interrupted run");
    // A stopped rank the launcher could not end would linger: none may.
    let left = rank_pids(marker, 1);
    for pid in &left {
        let _ = Command::new("kill")
            .args(["-KILL", &pid.to_string()])
            .status();
    }
    assert!(left.is_empty(), "rank 1 (pid {left:?}) outlived the run");
    (status, dir, out)
}

/// The files of a run that failed part way: the summary says failed and why, the
/// history's rows are whole and fewer than the run's.
fn failed_with_valid_files(out: &Path, reason: &str) {
    let s = summary(out);
    assert_eq!(s["status"], "failed", "{s}");
    let error = s["error"].as_str().unwrap();
    assert!(error.contains(reason), "{error}");
    let (_, rows) = history(out);
    assert!(rows.len() > 20 && rows.len() < 2001, "{} rows", rows.len());
    // The summary describes the history's last row, not its last refresh.
    assert_eq!(s["steps"].as_u64(), Some(rows.len() as u64 - 1), "{s}");
    assert_eq!(s["t_end"].as_f64(), Some(rows[rows.len() - 1][0]), "{s}");
    // The times are the steps' in order: nothing was cut or repeated.
    for (k, r) in rows.iter().enumerate() {
        assert!(
            (r[0] - k as f64 * 1e-5).abs() < 1e-12,
            "row {k}: t = {}",
            r[0]
        );
    }
}

#[test]
fn a_rank_killed_mid_run_fails_the_run_with_its_files_valid() {
    let _machine = exclusive();
    let (status, _dir, out) = interrupt_rank_1("-KILL", None);
    assert!(!status.success());
    // The launcher ends rank 0 with a signal when rank 1 dies.
    failed_with_valid_files(&out, "ended by signal");
}

#[test]
fn a_rank_that_stops_answering_times_out() {
    let _machine = exclusive();
    let (status, _dir, out) = interrupt_rank_1("-STOP", Some("3"));
    assert!(!status.success());
    failed_with_valid_files(&out, "no answer from the other ranks within 3 s");
}

#[test]
fn a_single_process_backend_on_several_ranks_is_refused() {
    let _machine = exclusive();
    let dir = tempfile::tempdir().unwrap();
    let sc = examples("scenarios/cantilever.toml");
    let out = dir.path().join("run");
    let o = launch(
        2,
        &[
            "run",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ],
    );
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("launched on 2 MPI ranks"), "{e}");
    assert!(e.contains("--backend mumps"), "{e}");
    assert!(!out.join("summary.json").exists(), "no rank may write");
}

#[test]
fn check_gives_mumps_estimates_per_rank() {
    let _machine = exclusive();
    let sc = examples("cluster/w3.toml");
    let args = [
        "check",
        sc.to_str().unwrap(),
        "--set",
        "bodies.0.mesh.divisions=[32,8,8]",
        "--backend",
        "mumps",
    ];
    let o = launch(2, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("on 2 ranks"), "{text}");
    let per_rank = rank_estimates(&text);
    assert_eq!(per_rank.len(), 2, "{text}");
    // Both ranks take a share of a solid's factor.
    assert!(per_rank.iter().all(|&b| b > 1e6), "{text}");
    // On one rank the whole factor is rank 0's, more than either share.
    let one = launch(1, &args);
    assert!(one.status.success(), "{}", stderr(&one));
    let whole = rank_estimates(&String::from_utf8_lossy(&one.stdout));
    assert_eq!(whole.len(), 1);
    assert!(
        per_rank.iter().all(|&b| b < whole[0]),
        "one rank {whole:?}, two ranks {per_rank:?}"
    );
}

/// Each rank's estimate, in bytes, from the `rank K  X GB on NODE` lines of `check`.
fn rank_estimates(text: &str) -> Vec<f64> {
    text.lines()
        .filter(|l| l.starts_with("rank "))
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            let v: f64 = w[2].parse().unwrap();
            v * match w[3] {
                "GB" => 1e9,
                "MB" => 1e6,
                "kB" => 1e3,
                _ => 1.0,
            }
        })
        .collect()
}

#[test]
fn a_watchdog_timeout_out_of_range_is_refused_by_name() {
    // 1.85e19 s overflowed the deadline's arithmetic: the process exited 101 and
    // printed nothing. Every value out of range is refused, naming the variable.
    let _machine = exclusive();
    let sc = examples("scenarios/cantilever.toml");
    for t in ["1.85e19", "1e300", "-1", "0", "nan", "soon"] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_rothe"))
            .args(["check", sc.to_str().unwrap(), "--backend", "mumps"])
            .env("ROTHE_MPI_TIMEOUT", t)
            .output()
            .unwrap();
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{t}: {e}");
        assert!(e.contains("ROTHE_MPI_TIMEOUT") && e.contains(t), "{t}: {e}");
    }
}
