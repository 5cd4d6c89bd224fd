//! What a distributed backend's analysis says of its factorisation: the factor's
//! size and each MPI rank's share of the memory, for `rothe check` and for the
//! memory check before a run factorises (per node: the ranks on one node share its
//! memory).

/// One rank's share of a factorisation, from MUMPS's analysis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RankMemory {
    /// The rank.
    pub rank: usize,
    /// The node it runs on (`MPI_Get_processor_name`).
    pub node: String,
    /// MUMPS's estimate of the memory its in-core factorisation needs on this rank
    /// (`INFO(15)`), in bytes.
    pub estimate: u64,
    /// The memory its node had available when asked, in bytes.
    pub available: Option<u64>,
}

/// What MUMPS's analysis says of a factorisation distributed over the ranks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DistributedAnalysis {
    /// MUMPS's version.
    pub version: String,
    /// The number of ranks.
    pub ranks: usize,
    /// Estimated entries of the factor (`INFOG(20)`).
    pub factor_entries: u64,
    /// Estimated floating-point operations of the factorisation (`RINFOG(1)`).
    pub flops: f64,
    /// Each rank's share.
    pub per_rank: Vec<RankMemory>,
    /// What rank 0 holds besides its share: the matrix as handed to the backend
    /// (indices and values), in bytes.
    pub host_input: u64,
}

impl DistributedAnalysis {
    /// The largest estimate of one rank, in bytes (`INFOG(16)`).
    pub fn max_rank(&self) -> u64 {
        self.per_rank.iter().map(|r| r.estimate).max().unwrap_or(0)
    }

    /// The sum over the ranks, in bytes (`INFOG(17)`).
    pub fn total(&self) -> u64 {
        self.per_rank.iter().map(|r| r.estimate).sum()
    }

    /// The nodes, in the order of their first rank.
    pub fn nodes(&self) -> Vec<Node> {
        let mut nodes: Vec<Node> = Vec::new();
        for r in &self.per_rank {
            match nodes.iter_mut().find(|n| n.name == r.node) {
                Some(n) => {
                    n.ranks.push(r.rank);
                    n.estimate += r.estimate;
                    n.available = match (n.available, r.available) {
                        (Some(a), Some(b)) => Some(a.min(b)),
                        (a, b) => a.or(b),
                    };
                }
                None => nodes.push(Node {
                    name: r.node.clone(),
                    ranks: vec![r.rank],
                    estimate: r.estimate,
                    available: r.available,
                }),
            }
        }
        nodes
    }
}

/// The ranks on one node and what they need together.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// The node's name.
    pub name: String,
    /// The ranks on it.
    pub ranks: Vec<usize>,
    /// The sum of their estimates, in bytes.
    pub estimate: u64,
    /// The memory it has available (the least any of its ranks saw), in bytes.
    pub available: Option<u64>,
}

/// The number of ranks an MPI launcher started this process among (OpenMPI's
/// `OMPI_COMM_WORLD_SIZE`, or the PMI `PMI_SIZE` of MPICH's and Slurm's
/// launchers), read without starting MPI.
pub fn launched_ranks() -> Option<usize> {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"]
        .iter()
        .find_map(|k| std::env::var(k).ok()?.trim().parse().ok())
}

/// What this process does in a command run on `backend`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The whole command, in this process alone.
    Alone,
    /// Rank 0 of an MPI session: the whole command, the other ranks serving its
    /// solves; [`finish`] when done.
    Host,
    /// A rank other than 0 that served rank 0 until it finished.
    Served,
}

/// Starts what `backend` needs: for `mumps`, the MPI session, where a rank other
/// than 0 serves rank 0's solves and returns [`Role::Served`] when rank 0 is done.
/// Refuses `mumps` in a build without it, and a launch on several ranks with a
/// backend that runs in one process (every rank would run the whole scenario and
/// write the same files).
pub fn start(backend: super::Backend) -> crate::Result<Role> {
    if backend != super::Backend::Mumps {
        return match launched_ranks() {
            Some(n) if n > 1 => Err(crate::Error::Solver {
                backend: backend.name(),
                message: format!(
                    "launched on {n} MPI ranks, but this backend runs in one process: every \
                     rank would run the whole scenario and write the same files; add \
                     `--backend mumps` to share the solves over the ranks, or run without mpirun"
                ),
            }),
            _ => Ok(Role::Alone),
        };
    }
    #[cfg(feature = "mumps")]
    {
        let session = super::mumps::start()?;
        if session.rank() == 0 {
            return Ok(Role::Host);
        }
        let served = session.serve();
        session.finish();
        served.map(|_| Role::Served)
    }
    #[cfg(not(feature = "mumps"))]
    Err(crate::Error::Solver {
        backend: "mumps",
        message: super::NO_MUMPS.into(),
    })
}

/// Ends the MPI session, if one was started (rank 0 releases the serving ranks).
pub fn finish() {
    #[cfg(feature = "mumps")]
    if let Some(s) = super::mumps::current() {
        s.finish();
    }
}
