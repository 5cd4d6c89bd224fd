//! Memory: what the machine has available, and the estimate of what a model will
//! take, so a run that would not fit is refused before it allocates (`rothe check`
//! prints the estimate, `rothe run` checks it; `--ignore-memory` overrides). The
//! buffers themselves are made in [`crate::buffers`].

use crate::error::{Error, Result};
use crate::material::Material;
use crate::mesh::Mesh;
use crate::model::Model;

/// Bytes of memory available to this process: the kernel's `MemAvailable`, or a
/// smaller cgroup limit (v2 `memory.max`, v1 `memory.limit_in_bytes`) less what the
/// cgroup uses. `None` where neither can be read (not Linux).
pub fn available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find(|l| l.starts_with("MemAvailable:"))
            .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
            .map(|kb| kb * 1024)
    });
    let read = |p: &str| -> Option<u64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
    let cgroup = read("/sys/fs/cgroup/memory.max")
        .map(|max| max.saturating_sub(read("/sys/fs/cgroup/memory.current").unwrap_or(0)))
        .or_else(|| {
            read("/sys/fs/cgroup/memory/memory.limit_in_bytes").map(|max| {
                max.saturating_sub(read("/sys/fs/cgroup/memory/memory.usage_in_bytes").unwrap_or(0))
            })
        });
    match (meminfo, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// Nonzeros of a sparse Cholesky factor of a finite-element matrix with `dofs`
/// unknowns in dimension `dim`, before the analysis tells the exact figure. In the
/// plane `5 n log₂ n`, from the nested-dissection bound `O(n log n)` fitted to W1 (89
/// per dof at 0.5M dofs, 104 at 2M, both within 10 % of the formula); in a solid
/// `20 n^{4/3}`, the bound `O(n^{4/3})` fitted to W3's hexahedral boxes (97M entries
/// at 107k dofs, 828M at 503k, both within 5 %).
pub fn factor_nnz_estimate(dofs: usize, dim: usize) -> u64 {
    let n = dofs.max(2) as f64;
    if dim == 3 {
        (20.0 * n.powf(4.0 / 3.0)) as u64
    } else {
        (5.0 * n * n.log2()) as u64
    }
}

/// The memory a model takes, by part, in bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    /// Nodes, elements, sets and the node adjacency.
    pub mesh: u64,
    /// `K`, `M` (and a tangent for state-dependent materials) on the shared pattern,
    /// the reduced effective matrix.
    pub matrices: u64,
    /// The Cholesky factor and its workspace.
    pub factor: u64,
    /// State and scratch vectors and the Gauss-point stores.
    pub state: u64,
}

impl Estimate {
    /// The whole estimate.
    pub fn total(&self) -> u64 {
        self.mesh + self.matrices + self.factor + self.state
    }

    /// An estimate for `nodes` nodes of elements of dimension `dim` with `elements`
    /// elements, `points` Gauss points of `history` values each, the factor with
    /// `factor_nnz` entries (the exact figure once analysed, else
    /// [`factor_nnz_estimate`]) and `tangent` when a state-dependent tangent is kept
    /// besides `K` and `M`.
    pub fn of(
        dim: usize,
        nodes: u64,
        elements: u64,
        points: u64,
        history: u64,
        factor_nnz: u64,
        tangent: bool,
    ) -> Estimate {
        // A node of a Q4 or T3 mesh has about 9 neighbours (itself included), of a
        // Hex8 or Tet4 mesh about 27: d² values per neighbour in each full-storage
        // matrix, about half plus a diagonal in the reduced lower triangle (value,
        // row index, source position: 24 bytes); the consistent mass also keeps one
        // value per node pair for its products. A point stores its strain and
        // stress (V each), its dissipation and its history, committed and trial.
        let (neighbours, voigt, corners) = if dim == 3 { (27, 6, 8) } else { (9, 3, 4) };
        let d = dim as u64;
        let per_node_matrix = neighbours * d * d * 8;
        let reduced = (neighbours * d * d / 2 + d) * 24;
        let n_matrices = if tangent { 3 } else { 2 };
        let dofs = d * nodes;
        Estimate {
            mesh: nodes * (24 + 8 + neighbours * 4 + 8) + elements * (corners * 8 + 16),
            matrices: nodes * (n_matrices * per_node_matrix + neighbours * 8 + reduced),
            factor: factor_nnz * 8 + dofs * 64,
            state: dofs * 8 * 30 + points * (2 * voigt + 1 + history) * 8 * 2,
        }
    }

    /// Refuses (an error with the estimate and the memory available) when the
    /// estimate exceeds what the machine has; passes when nothing can be read.
    pub fn check(&self, available: Option<u64>, what: &str) -> Result<()> {
        match available {
            Some(a) if self.total() > a => Err(Error::Memory {
                message: format!(
                    "{what} needs about {} (mesh {}, matrices {}, factor {}, state {}), but \
                     only {} is available; use a coarser mesh, or `--ignore-memory` to try anyway",
                    human(self.total()),
                    human(self.mesh),
                    human(self.matrices),
                    human(self.factor),
                    human(self.state),
                    human(a)
                ),
            }),
            _ => Ok(()),
        }
    }
}

/// A byte count for people: `1.2 GB`.
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.1} MB", b / 1e6)
    } else if b >= 1e3 {
        format!("{:.1} kB", b / 1e3)
    } else {
        format!("{bytes} B")
    }
}

/// The memory estimate of a model (the factor's exact nonzeros when known).
pub fn of_model(model: &Model, factor_nnz: Option<usize>) -> Estimate {
    let mut est = of_mesh(&model.mesh, &model.materials, factor_nnz);
    // An error-controlled run keeps the factors of other rungs of its ladder, and
    // generalized-α with contact the trapezoidal rule's of its impact steps.
    let kept = model
        .analysis
        .time
        .adaptive
        .map_or(0, |a| a.kept_factors() as u64)
        + u64::from(model.takes_impact_steps());
    est.factor *= factorisations(model) + kept;
    est
}

/// The factorisations a run holds at once: the effective matrix's, and the
/// predictor's of the mass (on the same pattern and ordering) when it runs.
fn factorisations(model: &Model) -> u64 {
    1 + u64::from(
        model.analysis.time.contact_predictor == crate::model::ContactPredictor::Stabilised,
    )
}

/// Refuses a factorisation distributed over MPI ranks that will not fit. On each
/// node the need is MUMPS's estimate for the ranks there (once per factorisation
/// the run holds: a distributed backend keeps no factors aside) plus, on rank 0's
/// node, the rest of the model (`rank0` without its factor); it is set against what
/// that node has (rank 0's: `available`, which `--ignore-memory` turns off, and
/// with it the whole check).
pub fn check_distributed(
    model: &Model,
    d: &crate::linsolve::distributed::DistributedAnalysis,
    available: Option<u64>,
    what: &str,
) -> Result<()> {
    let Some(host_available) = available else {
        return Ok(());
    };
    let rank0 = of_model(model, Some(0));
    let model_part = rank0.total() - rank0.factor + d.host_input;
    let factors = factorisations(model);
    for node in d.nodes() {
        let host = node.ranks.contains(&0);
        let need = node.estimate * factors + if host { model_part } else { 0 };
        let have = if host {
            Some(host_available)
        } else {
            node.available
        };
        if let Some(a) = have.filter(|&a| need > a) {
            let ranks: Vec<String> = node.ranks.iter().map(|r| r.to_string()).collect();
            let per_rank: Vec<String> = d
                .per_rank
                .iter()
                .map(|r| format!("{} {}", r.rank, human(r.estimate)))
                .collect();
            return Err(Error::Memory {
                message: format!(
                    "{what} needs about {} on node {} (ranks {}: MUMPS's estimate {}{}), but \
                     only {} is available there; spread the ranks over more nodes, use a \
                     coarser mesh, or `--ignore-memory` to try anyway. MUMPS's estimate per \
                     rank{}: {}",
                    human(need),
                    node.name,
                    ranks.join(", "),
                    human(node.estimate * factors),
                    if host {
                        format!(", and rank 0's model and matrix {}", human(model_part))
                    } else {
                        String::new()
                    },
                    human(a),
                    if factors > 1 {
                        format!(" and factorisation (the run holds {factors})")
                    } else {
                        String::new()
                    },
                    per_rank.join(", ")
                ),
            });
        }
    }
    Ok(())
}

/// The memory estimate of a model, with the factor's exact nonzeros when known.
pub fn of_mesh(mesh: &Mesh, materials: &[Material], factor_nnz: Option<usize>) -> Estimate {
    let points: u64 = mesh
        .blocks
        .iter()
        .map(|b| {
            (b.elements.len() * crate::assembly::internal::points_per_element(b.elements.kind))
                as u64
        })
        .sum();
    let voigt = crate::assembly::internal::voigt_of(mesh);
    let history = materials
        .iter()
        .map(|m| m.n_state(voigt))
        .max()
        .unwrap_or(0) as u64;
    let tangent = materials.iter().any(|m| !m.has_constant_tangent());
    let mut est = Estimate::of(
        mesh.dim,
        mesh.n_nodes() as u64,
        mesh.n_elements() as u64,
        points,
        history,
        factor_nnz.map_or_else(
            || factor_nnz_estimate(mesh.n_dofs(), mesh.dim),
            |n| n as u64,
        ),
        tangent,
    );
    // The nonlocal table (index and weight per entry) and its per-point buffers.
    let (nl_points, nl_entries) = crate::assembly::nonlocal::estimated_entries(mesh, materials);
    est.state += 12 * nl_entries + 64 * nl_points;
    est
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimates_and_refusals() {
        let e = Estimate::of(2, 1000, 900, 3600, 3, 50_000, false);
        assert!(e.total() > 0);
        assert!(e.check(Some(e.total() + 1), "w").is_ok());
        let msg = e.check(Some(10), "the run").unwrap_err().to_string();
        assert!(msg.contains("only 10 B is available"), "{msg}");
        assert!(e.check(None, "w").is_ok());
        assert!(available().is_none_or(|a| a > 0));
        assert_eq!(human(1_500_000), "1.5 MB");
        // The factor estimate is within 15 % of W1's measured factors.
        for (dofs, nnz) in [(503_000usize, 44.6e6), (2_004_000, 208e6)] {
            let est = factor_nnz_estimate(dofs, 2) as f64;
            assert!((est / nnz - 1.0).abs() < 0.15, "{dofs}: {est} vs {nnz}");
        }
        // And of W3's (hexahedral boxes, nested dissection).
        for (dofs, nnz) in [(107_163usize, 97e6), (503_475, 828e6)] {
            let est = factor_nnz_estimate(dofs, 3) as f64;
            assert!((est / nnz - 1.0).abs() < 0.15, "{dofs}: {est} vs {nnz}");
        }
        // A solid node costs more than a plane one: three times the neighbours,
        // 9 values each instead of 4.
        let solid = Estimate::of(3, 1000, 900, 7200, 3, 50_000, false);
        assert!(solid.matrices > 5 * e.matrices && solid.mesh > e.mesh);
    }
}
