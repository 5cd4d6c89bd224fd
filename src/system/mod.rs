//! The linear system every implicit step solves: the free-dof numbering
//! ([`DofMap`]), the effective matrix restricted to the free dofs ([`ReducedMatrix`])
//! and the factorised solver, owned together by [`EffectiveSystem`].
//!
//! Statics, backward Euler and `rothe check` build their matrices through
//! [`EffectiveSystem::new`]: it orders and analyses once; [`EffectiveSystem::refill`]
//! writes `c_m M + Σ c_i A_i` (a tangent among the `A_i`), [`EffectiveSystem::factorize`]
//! refactorises, and [`EffectiveSystem::solve`] / [`EffectiveSystem::solve_block`] solve
//! one right-hand side or a block of them on the free dofs.

mod reduced;

use std::time::Instant;

pub use reduced::ReducedMatrix;

use crate::assembly::{Mass, Pattern};
use crate::error::{Error, Result};
use crate::linsolve::{Backend, LowerCsc, SymmetricSolver};
use crate::model::Ordering;

/// Marks a constrained dof in [`DofMap::eq`].
pub const CONSTRAINED: usize = usize::MAX;

/// Numbering of the free dofs; constrained dofs get [`CONSTRAINED`].
#[derive(Clone, Debug)]
pub struct DofMap {
    /// Equation number of each dof.
    pub eq: Vec<usize>,
    /// Free dofs in equation order.
    pub free: Vec<usize>,
    /// Constrained dofs, ascending.
    pub constrained: Vec<usize>,
}

impl DofMap {
    /// Numbers the dofs not in `constrained`, keeping their natural order.
    pub fn new(n_dofs: usize, constrained: impl IntoIterator<Item = usize>) -> Self {
        let mut eq = vec![0usize; n_dofs];
        for d in constrained {
            eq[d] = CONSTRAINED;
        }
        let mut free = Vec::with_capacity(n_dofs);
        let mut fixed = Vec::new();
        for (d, e) in eq.iter_mut().enumerate() {
            if *e == CONSTRAINED {
                fixed.push(d);
            } else {
                *e = free.len();
                free.push(d);
            }
        }
        DofMap {
            eq,
            free,
            constrained: fixed,
        }
    }

    /// Number of free dofs.
    pub fn n_free(&self) -> usize {
        self.free.len()
    }

    /// Number of dofs.
    pub fn n_dofs(&self) -> usize {
        self.eq.len()
    }

    /// Whether dof `d` is free.
    #[inline]
    pub fn is_free(&self, d: usize) -> bool {
        self.eq[d] != CONSTRAINED
    }
}

/// Time spent in the system's factorisations and solves.
#[derive(Clone, Copy, Debug, Default)]
pub struct SystemTiming {
    /// Ordering and symbolic analysis.
    pub analysis_s: f64,
    /// Numeric factorisations.
    pub factorization_s: f64,
    /// Triangular solves.
    pub solve_s: f64,
    /// Right-hand sides solved (a block of `k` counts `k`).
    pub solves: usize,
}

/// What a numeric factorisation gave.
#[derive(Clone, Debug, PartialEq)]
pub enum Factored {
    /// The factor is ready.
    Ok,
    /// A non-positive pivot: the matrix is not positive definite.
    NotPositiveDefinite {
        /// The dof (global numbering) whose column broke down, when known.
        dof: Option<usize>,
        /// The solver's message.
        message: String,
    },
}

/// The free-dof effective matrix of a model and its factorised solver.
pub struct EffectiveSystem {
    dofs: DofMap,
    reduced: ReducedMatrix,
    solver: Box<dyn SymmetricSolver>,
    factorizations: usize,
    timing: SystemTiming,
    nested_dissection: bool,
    /// The identity of the current factor (`factor_id`) and its key, when the
    /// factor was labelled as a matrix the caller may ask for again.
    current: (usize, Option<u64>),
    /// Numeric factors kept by key (`keep_factors`), least recently used first.
    kept: Vec<KeptFactor>,
    /// How many factors besides the current one are kept.
    capacity: usize,
}

/// A numeric factor kept aside, with its identity and key.
struct KeptFactor {
    key: u64,
    id: usize,
    values: Vec<f64>,
}

impl EffectiveSystem {
    /// Builds the free-dof pattern of `pattern`, chooses the ordering (`ordering`,
    /// from the node coordinates for nested dissection) and analyses it. Values are
    /// zero until [`EffectiveSystem::refill`].
    pub fn new(
        pattern: &Pattern,
        dofs: DofMap,
        backend: Backend,
        ordering: Ordering,
        coords: &[[f64; 3]],
    ) -> Result<Self> {
        let reduced = ReducedMatrix::new(pattern, &dofs);
        let t = Instant::now();
        let mut solver = backend.solver()?;
        let dim = pattern.dim;
        let nested_dissection = ordering.nested_dissection(dofs.n_free(), dim);
        if nested_dissection {
            solver.set_ordering(reduced.nested_dissection(&dofs, coords));
        }
        solver.analyze(&reduced.csc)?;
        Ok(EffectiveSystem {
            dofs,
            reduced,
            solver,
            factorizations: 0,
            timing: SystemTiming {
                analysis_s: t.elapsed().as_secs_f64(),
                ..Default::default()
            },
            nested_dissection,
            current: (0, None),
            kept: Vec::new(),
            capacity: 0,
        })
    }

    /// Keeps up to `capacity` numeric factors besides the current one, so that
    /// [`EffectiveSystem::switch_factor`] finds a labelled matrix's factor again
    /// instead of refactorising (0, the default: none kept).
    pub fn keep_factors(&mut self, capacity: usize) {
        self.capacity = capacity;
        self.kept.truncate(capacity);
    }

    /// Whether factors are kept ([`EffectiveSystem::keep_factors`] above 0).
    pub fn keeps_factors(&self) -> bool {
        self.capacity > 0
    }

    /// Labels the current factor as the one of the matrix `key` (the caller's name
    /// for it, e.g. a step size's bits).
    pub fn label_factor(&mut self, key: u64) {
        self.current.1 = Some(key);
    }

    /// Makes the factor labelled `key` current if it is kept (the current one, if
    /// labelled, is kept in turn, the least recently used dropped beyond the
    /// capacity), and says whether it was. On `false` the caller refills and
    /// factorises (the solver may be left without a factor).
    pub fn switch_factor(&mut self, key: u64) -> bool {
        if self.capacity == 0 {
            return false;
        }
        if self.current.1 == Some(key) {
            return true;
        }
        // The wanted factor leaves the kept ones before the current one joins them,
        // so that two factors taken in turn at a capacity of one both stay.
        let wanted = self
            .kept
            .iter()
            .position(|k| k.key == key)
            .map(|i| self.kept.remove(i));
        if let Some(old) = self.current.1.take() {
            if let Some(values) = self.solver.take_numeric() {
                self.kept.push(KeptFactor {
                    key: old,
                    id: self.current.0,
                    values,
                });
                if self.kept.len() > self.capacity {
                    self.kept.remove(0);
                }
            }
        }
        match wanted {
            Some(k) => {
                self.solver.put_numeric(k.values);
                self.current = (k.id, Some(key));
                true
            }
            None => false,
        }
    }

    /// The identity of the current numeric factor: a new one at each factorisation,
    /// the same again when [`EffectiveSystem::switch_factor`] brings a kept factor
    /// back (what depends on the factor, the contact compliance, is keyed by it).
    pub fn factor_id(&self) -> usize {
        self.current.0
    }

    /// Writes `c_m M + Σ c_i A_i` (matrices on the shared pattern) on the free dofs.
    pub fn refill(&mut self, c_m: f64, mass: &Mass, terms: &[(f64, &[f64])]) {
        self.reduced.fill(&self.dofs, c_m, mass, terms);
    }

    /// Numeric factorisation of the current values. A non-positive pivot is an
    /// outcome naming the dof; other solver failures are errors.
    pub fn factorize(&mut self) -> Result<Factored> {
        let t = Instant::now();
        let res = self.solver.factorize(&self.reduced.csc);
        self.factorizations += 1;
        self.current = (self.factorizations, None);
        self.timing.factorization_s += t.elapsed().as_secs_f64();
        match res {
            Ok(()) => Ok(Factored::Ok),
            Err(Error::NotPositiveDefinite {
                column, message, ..
            }) => Ok(Factored::NotPositiveDefinite {
                dof: column.and_then(|c| self.dofs.free.get(c).copied()),
                message,
            }),
            Err(e) => Err(e),
        }
    }

    /// Overwrites the free-dof vector `rhs` with `A⁻¹ rhs`.
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<()> {
        let t = Instant::now();
        let r = self.solver.solve_in_place(rhs);
        self.timing.solve_s += t.elapsed().as_secs_f64();
        self.timing.solves += 1;
        r
    }

    /// `out = A⁻¹ b` for the free-dof vector `b` given by its nonzeros `entries`
    /// (free numbering, repeated indices summed): a forward solve over their reach
    /// only where the backend has one.
    pub fn solve_sparse(&mut self, entries: &[(usize, f64)], out: &mut [f64]) -> Result<()> {
        let t = Instant::now();
        let r = self.solver.solve_sparse(entries, out);
        self.timing.solve_s += t.elapsed().as_secs_f64();
        self.timing.solves += 1;
        r
    }

    /// Overwrites the column-major `n_free x ncols` block `rhs` with `A⁻¹ rhs`; the
    /// factor is read once for the whole block.
    pub fn solve_block(&mut self, rhs: &mut [f64], ncols: usize) -> Result<()> {
        let t = Instant::now();
        let r = self.solver.solve_block_in_place(rhs, ncols);
        self.timing.solve_s += t.elapsed().as_secs_f64();
        self.timing.solves += ncols;
        r
    }

    /// The free-dof numbering.
    pub fn dofs(&self) -> &DofMap {
        &self.dofs
    }

    /// The effective matrix handed to the solver (lower triangle, free dofs).
    pub fn matrix(&self) -> &LowerCsc {
        &self.reduced.csc
    }

    /// Backend name.
    pub fn backend(&self) -> &'static str {
        self.solver.name()
    }

    /// Nonzeros of the factor.
    pub fn factor_nnz(&self) -> Option<usize> {
        self.solver.factor_nnz()
    }

    /// A distributed backend's analysis (each rank's share of the memory).
    pub fn distributed(&self) -> Option<&crate::linsolve::distributed::DistributedAnalysis> {
        self.solver.distributed()
    }

    /// Entries of the factor on and below the diagonal (faer's supernodes also store
    /// the upper triangles of their diagonal blocks, which [`Self::factor_nnz`] counts).
    pub fn factor_lower_entries(&self) -> Option<usize> {
        self.solver.factor_lower_entries()
    }

    /// Numeric factorisations so far.
    pub fn factorizations(&self) -> usize {
        self.factorizations
    }

    /// Time in analysis, factorisations and solves.
    pub fn timing(&self) -> SystemTiming {
        self.timing
    }

    /// Whether the ordering is nested dissection (else the backend's AMD).
    pub fn nested_dissection(&self) -> bool {
        self.nested_dissection
    }

    /// The elimination order of the factor (`order[k]` eliminated `k`-th), when the
    /// backend exposes it.
    pub fn ordering(&self) -> Option<Vec<usize>> {
        self.solver.ordering()
    }
}
