//! The MPI session behind the `mumps` backend: one per process, started by
//! [`start`] before any solver is made.
//!
//! Rank 0 runs everything of a run (the time loop, the assembly, the materials, the
//! contact QP, the output) and is the MUMPS host, which holds the assembled matrix
//! and the right-hand sides (MUMPS's centralised input, `ICNTL(5) = ICNTL(18) =
//! ICNTL(20) = ICNTL(21) = 0`). The other ranks call [`Session::serve`]: they wait
//! for a command broadcast by rank 0 and take their part in the same MUMPS call
//! (analysis, factorisation, solve), until rank 0 says the run is over. Rank 0's
//! commands are serialised by one lock, so solvers on several threads of rank 0
//! (the runs of a study) share the ranks safely, one call at a time.
//!
//! No hang: every collective (the command broadcast and the MUMPS call after it) is
//! timed by a watchdog thread on every rank. When one takes longer than the timeout
//! (`ROTHE_MPI_TIMEOUT` seconds, default 600), the watchdog marks the runs in
//! progress failed ([`crate::output::interrupt`]) and ends the process, and the MPI
//! launcher then ends the others. A rank that dies makes the launcher end the others
//! with `SIGTERM`; rank 0 catches it and marks its runs failed the same way. A
//! worker waiting for its next command is not timed: rank 0 may legitimately work
//! for hours between two solves (an explicit run never solves), and its death ends
//! the job through the launcher.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::traits::*;

use super::ffi::{self, Handle};
use crate::error::{Error, Result};

/// The default timeout of one collective, in seconds.
pub const DEFAULT_TIMEOUT_S: u64 = 600;

/// The environment variable that sets the timeout of one collective, in seconds.
pub const TIMEOUT_ENV: &str = "ROTHE_MPI_TIMEOUT";

/// A command from rank 0 to the others: `[op, instance, argument, argument]`.
type Command = [i64; 4];

/// What a command asks.
mod op {
    /// The run is over: leave the serve loop.
    pub const EXIT: i64 = 0;
    /// Make MUMPS instance `[1]` (`JOB = -1`).
    pub const NEW: i64 = 1;
    /// Run `JOB = [2]` on instance `[1]`.
    pub const JOB: i64 = 2;
    /// Free instance `[1]` (`JOB = -2`).
    pub const FREE: i64 = 3;
    /// Gather each rank's local memory figures of instance `[1]` on rank 0.
    pub const REPORT: i64 = 4;
}

/// The communicator, shared by the threads of rank 0 under the session's lock.
struct World(SimpleCommunicator);

// SAFETY: an MPI communicator handle is a plain value; the session is initialised
// with `MPI_THREAD_SERIALIZED` and every use of the handle on rank 0 happens under
// `Session::lock`, on the workers from their one thread.
unsafe impl Send for World {}
// SAFETY: as above.
unsafe impl Sync for World {}

/// The MPI session of this process.
pub struct Session {
    world: World,
    fortran: i32,
    rank: i32,
    size: i32,
    timeout: Duration,
    lock: Mutex<State>,
    node: String,
}

#[derive(Default)]
struct State {
    next_id: i64,
    finished: bool,
}

static SESSION: OnceLock<std::result::Result<Session, String>> = OnceLock::new();

/// The message that says how to run the backend.
pub const HOW_TO_RUN: &str = "run it as `mpirun -n N rothe run SCENARIO --backend mumps` \
    (as root OpenMPI also needs `--allow-run-as-root`), or without mpirun for one rank";

/// Starts MPI (once per process; later calls return the same session).
pub fn start() -> Result<&'static Session> {
    SESSION
        .get_or_init(Session::init)
        .as_ref()
        .map_err(|message| Error::Solver {
            backend: super::NAME,
            message: message.clone(),
        })
}

/// The session, if [`start`] has made one.
pub fn current() -> Option<&'static Session> {
    SESSION.get().and_then(|s| s.as_ref().ok())
}

/// The longest watchdog timeout `ROTHE_MPI_TIMEOUT` may give (s): a deadline
/// beyond it would overflow the clock's arithmetic.
const MAX_TIMEOUT_S: f64 = 1e9;

impl Session {
    fn init() -> std::result::Result<Session, String> {
        // SAFETY: a function of the shim without arguments.
        let int_size = unsafe { ffi::rothe_mumps_int_size() };
        if int_size != 4 {
            return Err(format!(
                "this MUMPS uses {}-byte indices; rothe's binding needs the 4-byte build \
                 (Debian's libmumps-dev)",
                int_size
            ));
        }
        let timeout = match std::env::var(TIMEOUT_ENV) {
            Ok(v) => match v.trim().parse::<f64>() {
                Ok(s) if s.is_finite() && s > 0.0 && s <= MAX_TIMEOUT_S => {
                    Duration::from_secs_f64(s)
                }
                _ => {
                    return Err(format!(
                        "{TIMEOUT_ENV} = `{v}`: expected a positive number of seconds, at \
                         most {MAX_TIMEOUT_S:e} (about 30 years)"
                    ))
                }
            },
            Err(_) => Duration::from_secs(DEFAULT_TIMEOUT_S),
        };
        let (universe, _threading) = mpi::initialize_with_threading(mpi::Threading::Serialized)
            .ok_or_else(|| {
                format!("MPI could not be initialised (was it initialised already?); {HOW_TO_RUN}")
            })?;
        let world = universe.world();
        // The session lives until the process ends; `finish` finalises MPI.
        std::mem::forget(universe);
        // SAFETY: converts a valid communicator handle to its Fortran handle, which
        // MUMPS's C interface takes.
        let fortran = unsafe { mpi::ffi::RSMPI_Comm_c2f(world.as_raw()) };
        let node = mpi::environment::processor_name().unwrap_or_else(|_| "?".into());
        let session = Session {
            rank: world.rank(),
            size: world.size(),
            world: World(world),
            fortran,
            timeout,
            lock: Mutex::new(State::default()),
            node,
        };
        watchdog::start(session.rank);
        Ok(session)
    }

    /// This process's rank.
    pub fn rank(&self) -> i32 {
        self.rank
    }

    /// The number of ranks.
    pub fn size(&self) -> i32 {
        self.size
    }

    /// Runs `host` on rank 0 after broadcasting `cmd`, so that the other ranks run
    /// their side of the same MUMPS call; the whole is timed by the watchdog.
    fn collective<T>(
        &self,
        cmd: impl FnOnce(&mut State) -> Command,
        what: &str,
        host: impl FnOnce() -> T,
    ) -> Result<T> {
        let mut state = self.lock.lock().unwrap_or_else(|e| e.into_inner());
        if state.finished {
            return Err(Error::Solver {
                backend: super::NAME,
                message: format!("{what} after the MPI session ended"),
            });
        }
        let _armed = watchdog::arm(self.timeout, what);
        let mut cmd = cmd(&mut state);
        self.broadcast(&mut cmd);
        Ok(host())
    }

    /// A new instance id and the MUMPS instance on every rank (`JOB = -1`).
    pub(super) fn create(&self) -> Result<(i64, *mut Handle)> {
        let mut id = 0;
        let h = self.collective(
            |state| {
                state.next_id += 1;
                id = state.next_id;
                [op::NEW, id, 0, 0]
            },
            "the MUMPS initialisation",
            || new_handle(self.fortran),
        )?;
        match h {
            Some(h) => Ok((id, h)),
            None => Err(Error::Solver {
                backend: super::NAME,
                message: "MUMPS could not be initialised (JOB = -1 failed or out of memory)".into(),
            }),
        }
    }

    /// Runs `job` on instance `(id, h)` on every rank; `prepare` sets the host's
    /// inputs first (under the lock). Returns `INFOG(1)`.
    pub(super) fn job(
        &self,
        id: i64,
        h: *mut Handle,
        job: i32,
        what: &str,
        prepare: impl FnOnce(),
    ) -> Result<i32> {
        self.collective(
            |_| [op::JOB, id, job as i64, 0],
            what,
            || {
                prepare();
                // SAFETY: `h` is a live instance made by `create`; its inputs were set by
                // `prepare` and outlive this call (the caller's buffers).
                unsafe { ffi::rothe_mumps_job(h, job) }
            },
        )
    }

    /// Frees instance `(id, h)` on every rank (`JOB = -2`); nothing once the
    /// session has ended (the process is exiting).
    pub(super) fn free(&self, id: i64, h: *mut Handle) {
        let _ = self.collective(
            |_| [op::FREE, id, 0, 0],
            "freeing a MUMPS instance",
            || {
                // SAFETY: `h` is a live instance made by `create`, freed once.
                unsafe { ffi::rothe_mumps_free(h) }
            },
        );
    }

    /// Each rank's memory figures of instance `(id, h)` after its analysis, gathered
    /// on rank 0.
    pub(super) fn report(
        &self,
        id: i64,
        h: *mut Handle,
    ) -> Result<Vec<crate::linsolve::distributed::RankMemory>> {
        let figures = self.collective(
            |_| [op::REPORT, id, 0, 0],
            "gathering MUMPS's estimates",
            || self.gather(local_figures(h, &self.node)),
        )?;
        Ok(figures)
    }

    fn gather(&self, local: Figures) -> Vec<crate::linsolve::distributed::RankMemory> {
        let n = self.size as usize;
        let mut all = vec![Figures::default(); n];
        if n == 1 {
            all[0] = local;
        } else {
            let root = self.world.0.process_at_rank(0);
            let mut numbers = vec![0i64; n * 2];
            let mut names = vec![0u8; n * NODE_NAME];
            if self.rank == 0 {
                root.gather_into_root(&local.numbers[..], &mut numbers[..]);
                root.gather_into_root(&local.name[..], &mut names[..]);
            } else {
                root.gather_into(&local.numbers[..]);
                root.gather_into(&local.name[..]);
            }
            for (r, f) in all.iter_mut().enumerate() {
                f.numbers.copy_from_slice(&numbers[2 * r..2 * r + 2]);
                f.name
                    .copy_from_slice(&names[r * NODE_NAME..(r + 1) * NODE_NAME]);
            }
        }
        all.iter()
            .enumerate()
            .map(|(rank, f)| crate::linsolve::distributed::RankMemory {
                rank,
                node: String::from_utf8_lossy(&f.name)
                    .trim_end_matches('\0')
                    .to_string(),
                estimate: (f.numbers[0].max(0) as u64) * 1_000_000,
                available: (f.numbers[1] >= 0).then_some(f.numbers[1] as u64),
            })
            .collect()
    }

    /// The serve loop of a rank other than 0: takes part in every MUMPS call rank 0
    /// makes, until rank 0 ends the session. Returns the number of commands served.
    pub fn serve(&self) -> Result<usize> {
        let mut instances: HashMap<i64, *mut Handle> = HashMap::new();
        let mut served = 0;
        loop {
            let cmd = self.wait_command();
            served += 1;
            let id = cmd[1];
            match cmd[0] {
                op::EXIT => break,
                op::NEW => {
                    let _armed = watchdog::arm(self.timeout, "the MUMPS initialisation");
                    match new_handle(self.fortran) {
                        Some(h) => {
                            instances.insert(id, h);
                        }
                        None => {
                            return Err(Error::Solver {
                                backend: super::NAME,
                                message: format!(
                                    "rank {}: MUMPS could not be initialised",
                                    self.rank
                                ),
                            })
                        }
                    }
                }
                op::JOB => {
                    let h = self.instance(&instances, id)?;
                    let _armed = watchdog::arm(self.timeout, "a MUMPS call");
                    // SAFETY: a live instance; a worker's inputs are MUMPS's own
                    // (the matrix and right-hand sides are the host's).
                    unsafe { ffi::rothe_mumps_job(h, cmd[2] as i32) };
                }
                op::FREE => {
                    let h = self.instance(&instances, id)?;
                    let _armed = watchdog::arm(self.timeout, "freeing a MUMPS instance");
                    // SAFETY: a live instance, removed from the map below.
                    unsafe { ffi::rothe_mumps_free(h) };
                    instances.remove(&id);
                }
                op::REPORT => {
                    let h = self.instance(&instances, id)?;
                    let _armed = watchdog::arm(self.timeout, "gathering MUMPS's estimates");
                    self.gather(local_figures(h, &self.node));
                }
                other => {
                    return Err(Error::Solver {
                        backend: super::NAME,
                        message: format!("rank {}: unknown command {other} from rank 0", self.rank),
                    })
                }
            }
        }
        Ok(served)
    }

    fn instance(&self, instances: &HashMap<i64, *mut Handle>, id: i64) -> Result<*mut Handle> {
        instances.get(&id).copied().ok_or_else(|| Error::Solver {
            backend: super::NAME,
            message: format!("rank {}: no MUMPS instance {id}", self.rank),
        })
    }

    /// Rank 0's side of the command broadcast: the same non-blocking broadcast the
    /// serving ranks wait on (MPI matches a non-blocking collective only with
    /// non-blocking ones), completed at once.
    fn broadcast(&self, cmd: &mut Command) {
        if self.size < 2 {
            return;
        }
        let root = self.world.0.process_at_rank(0);
        mpi::request::scope(|scope| {
            root.immediate_broadcast_into(scope, &mut cmd[..]).wait();
        });
    }

    /// Waits for rank 0's next command without holding a core: a non-blocking
    /// broadcast tested in a loop that spins for a moment (a solve's command follows
    /// the last one closely), then sleeps longer and longer, up to 2 ms.
    fn wait_command(&self) -> Command {
        let mut cmd: Command = [op::EXIT, 0, 0, 0];
        let root = self.world.0.process_at_rank(0);
        mpi::request::scope(|scope| {
            let mut req = root.immediate_broadcast_into(scope, &mut cmd[..]);
            let start = Instant::now();
            loop {
                match req.test() {
                    Ok(_) => break,
                    Err(r) => req = r,
                }
                let waited = start.elapsed();
                if waited < Duration::from_micros(200) {
                    std::hint::spin_loop();
                } else if waited < Duration::from_millis(20) {
                    std::thread::sleep(Duration::from_micros(50));
                } else {
                    std::thread::sleep(Duration::from_millis(2));
                }
            }
        });
        cmd
    }

    /// Ends the session: rank 0 releases the other ranks from their serve loop;
    /// every rank then finalises MPI. Later collectives are refused.
    pub fn finish(&self) {
        let mut state = self.lock.lock().unwrap_or_else(|e| e.into_inner());
        if state.finished {
            return;
        }
        state.finished = true;
        if self.rank == 0 && self.size > 1 {
            let _armed = watchdog::arm(self.timeout, "ending the MPI session");
            let mut cmd: Command = [op::EXIT, 0, 0, 0];
            self.broadcast(&mut cmd);
        }
        let _armed = watchdog::arm(self.timeout, "finalising MPI");
        // SAFETY: MPI was initialised by `init` and is finalised once, here.
        unsafe { mpi::ffi::MPI_Finalize() };
    }
}

/// A MUMPS instance on the world communicator, configured as every rank needs it.
fn new_handle(fortran: i32) -> Option<*mut Handle> {
    // SAFETY: `fortran` is the world communicator's Fortran handle.
    let h = unsafe { ffi::rothe_mumps_new(fortran) };
    // SAFETY: a non-null handle just made.
    if h.is_null() || unsafe { ffi::rothe_mumps_infog(h, 1) } < 0 {
        return None;
    }
    super::configure(h);
    Some(h)
}

/// The node name's bytes gathered per rank.
const NODE_NAME: usize = 64;

/// One rank's memory figures: MUMPS's estimate in MB (`INFO(15)`), the bytes the
/// node has available (−1 when unknown); and the node's name.
#[derive(Clone)]
struct Figures {
    numbers: [i64; 2],
    name: [u8; NODE_NAME],
}

impl Default for Figures {
    fn default() -> Self {
        Figures {
            numbers: [0; 2],
            name: [0; NODE_NAME],
        }
    }
}

fn local_figures(h: *mut Handle, node: &str) -> Figures {
    let mut f = Figures::default();
    // SAFETY: a live instance after its analysis.
    f.numbers[0] = unsafe { ffi::rothe_mumps_info(h, 15) } as i64;
    f.numbers[1] = crate::memory::available().map_or(-1, |b| b as i64);
    let bytes = node.as_bytes();
    let len = bytes.len().min(NODE_NAME);
    f.name[..len].copy_from_slice(&bytes[..len]);
    f
}

/// The watchdog of the collectives and the handler of the launcher's signals.
mod watchdog {
    use super::*;

    /// Milliseconds since [`EPOCH`] at which the armed collective times out; 0 when
    /// none is armed.
    static DEADLINE: AtomicU64 = AtomicU64::new(0);
    static WHAT: Mutex<String> = Mutex::new(String::new());
    static EPOCH: OnceLock<Instant> = OnceLock::new();
    static TIMEOUT: AtomicU64 = AtomicU64::new(0);

    fn now_ms() -> u64 {
        EPOCH.get_or_init(Instant::now).elapsed().as_millis() as u64 + 1
    }

    /// An armed collective; disarmed when dropped.
    pub struct Armed;

    impl Drop for Armed {
        fn drop(&mut self) {
            DEADLINE.store(0, Ordering::SeqCst);
        }
    }

    /// Arms the watchdog for `what`, to fire after `timeout`.
    pub fn arm(timeout: Duration, what: &str) -> Armed {
        {
            let mut w = WHAT.lock().unwrap_or_else(|e| e.into_inner());
            w.clear();
            w.push_str(what);
        }
        TIMEOUT.store(timeout.as_millis() as u64, Ordering::SeqCst);
        DEADLINE.store(now_ms() + timeout.as_millis() as u64, Ordering::SeqCst);
        Armed
    }

    /// Ends the process after marking the runs in progress failed.
    fn end(rank: i32, message: String) -> ! {
        let message = format!("MPI rank {rank}: {message}");
        crate::output::interrupt::fail_runs(&message);
        eprintln!("error: linear solver (mumps): {message}");
        std::process::exit(1)
    }

    /// Starts the watchdog thread and the signal thread of this rank.
    pub fn start(rank: i32) {
        now_ms();
        let _ = std::thread::Builder::new()
            .name("rothe-mpi-watchdog".into())
            .spawn(move || loop {
                std::thread::sleep(Duration::from_millis(100));
                let d = DEADLINE.load(Ordering::SeqCst);
                if d != 0 && now_ms() > d {
                    let what = WHAT.lock().unwrap_or_else(|e| e.into_inner()).clone();
                    let s = TIMEOUT.load(Ordering::SeqCst) as f64 / 1000.0;
                    end(
                        rank,
                        format!(
                            "{what} got no answer from the other ranks within {s} s \
                             ({TIMEOUT_ENV}); a rank died or hangs"
                        ),
                    );
                }
            });
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        if let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGTERM, SIGINT, SIGHUP]) {
            let _ = std::thread::Builder::new()
                .name("rothe-mpi-signals".into())
                .spawn(move || {
                    if let Some(sig) = signals.forever().next() {
                        if rank != 0 {
                            // A serving rank has no files, and rank 0 says why.
                            std::process::exit(1);
                        }
                        end(
                            rank,
                            format!(
                                "ended by signal {sig} (the MPI launcher ends every rank when \
                                 one of them dies, or the job was cancelled)"
                            ),
                        );
                    }
                });
        }
    }
}
