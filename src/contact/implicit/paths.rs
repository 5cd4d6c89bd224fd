//! The two QP paths of the contact correction: the condensed dual on the factor
//! (the default, with friction's cone programs) and the primal QP over all free
//! dofs (the frictionless reference). Each leaves its `δ` in `delta0` and the
//! multipliers of its rows in `lambda_rows`.

use std::time::Instant;

use super::{ContactCorrection, GUESS_GAP_TOLERANCE};
use crate::contact::qp::{primal_qp, solve_by_active_set, QpStats};
use crate::error::Result;
use crate::system::EffectiveSystem;

impl ContactCorrection<'_> {
    /// The condensed dual on the `m` rows of `g` chosen: `W = G A⁻¹ Gᵀ` (from the kept
    /// compliance or a blocked solve), the QP (on the last active set first, or the
    /// Coulomb cone programs with friction), and `δ = δ₀ + A⁻¹Gᵀλ` into `delta0`.
    /// The inner error is the QP's failure, for the step to be cut.
    pub(super) fn condensed(
        &mut self,
        sys: &mut EffectiveSystem,
        g: &nalgebra_sparse::CsrMatrix<f64>,
        m: usize,
    ) -> Result<std::result::Result<(), String>> {
        let nf = self.setup.dofs.free.len();
        let t = Instant::now();
        // S pays once the factor has outlived a QP (theory/contact.md).
        let generation = sys.factor_id();
        let compliant =
            self.work.compliance.is_current(sys) || self.work.qp_generation == generation;
        self.work.qp_generation = generation;
        if compliant {
            self.work.needed.clear();
            for &i in &self.sel.rows {
                self.work.needed.extend_from_slice(g.row(i).col_indices());
            }
            self.work.compliance.cover(sys, &self.work.needed)?;
            self.record.compliant += 1;
            self.work
                .compliance
                .condense(g, &self.sel.rows, &mut self.work.w);
        } else {
            self.work.y.clear();
            self.work.y.resize(nf * m, 0.0);
            for (j, &i) in self.sel.rows.iter().enumerate() {
                let row = g.row(i);
                for (&e, v) in row.col_indices().iter().zip(row.values()) {
                    self.work.y[j * nf + e] += v;
                }
            }
            sys.solve_block(&mut self.work.y, m)?;
            self.work.w.clear();
            self.work.w.resize(m * m, 0.0);
            for j in 0..m {
                let yj = &self.work.y[j * nf..(j + 1) * nf];
                for (k, &i) in self.sel.rows.iter().enumerate() {
                    let row = g.row(i);
                    self.work.w[k + j * m] = row
                        .col_indices()
                        .iter()
                        .zip(row.values())
                        .map(|(&e, v)| v * yj[e])
                        .sum();
                }
            }
        }
        self.record.w_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        // The previous active set first: accepted only if it satisfies the
        // KKT conditions, so the QP's solution either way.
        self.work.guess.clear();
        for (j, &i) in self.sel.rows[..self.sel.normal_rows].iter().enumerate() {
            if self
                .active
                .previous
                .binary_search(&self.sel.cands[i].key())
                .is_ok()
            {
                self.work.guess.push(j);
            }
        }
        let gap_tol = GUESS_GAP_TOLERANCE * self.sel.c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let slip_tol = GUESS_GAP_TOLERANCE * self.sel.c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        // The guess of the statuses (and in a solid the slip directions) the last QP
        // ended in, accepted only if its result satisfies the whole law.
        let r = if !self.sel.cones.is_empty()
            && self.setup.friction_guess
            && crate::contact::coulomb::solve_by_guess(
                &self.work.w,
                &self.sel.c,
                self.sel.normal_rows,
                &self.sel.cones,
                &self.sel.pressed,
                &self.sel.guess_t,
                slip_tol,
                &mut self.work.lambda_rows,
            ) {
            self.record.guessed += 1;
            self.record.frictional += 1;
            self.record.friction_guessed += 1;
            Ok(QpStats::default())
        } else if !self.sel.cones.is_empty() {
            let r = crate::contact::coulomb::solve(
                &self.work.w,
                &self.sel.c,
                (self.sel.normal_rows, self.setup.dim - 1),
                &self.sel.cones,
                &mut self.work.lambda_rows,
            );
            if let Ok(q) = &r {
                self.record.frictional += 1;
                self.record.cone_programs += q.programs as usize;
            }
            r
        } else if !self.work.guess.is_empty()
            && solve_by_active_set(
                &self.work.w,
                &self.sel.c,
                &mut self.work.guess,
                gap_tol,
                &mut self.work.lambda_rows,
                &mut self.work.guess_work,
            )
        {
            self.record.guessed += 1;
            Ok(QpStats::default())
        } else {
            self.work
                .dual
                .solve(&self.work.w, &self.sel.c, &mut self.work.lambda_rows)
        };
        self.record.qp_s += t.elapsed().as_secs_f64();
        if r.is_ok() {
            if compliant {
                self.push_forces(sys, g)?;
            } else {
                for (j, &l) in self.work.lambda_rows.iter().enumerate() {
                    if l != 0.0 {
                        let yj = &self.work.y[j * nf..(j + 1) * nf];
                        for (d, y) in self.work.delta0.iter_mut().zip(yj) {
                            *d += l * y;
                        }
                    }
                }
            }
        }
        Ok(r.map(|_| ()))
    }

    /// `δ = δ₀ + A⁻¹Gᵀλ` for the multipliers in `lambda_rows`: one solve of a
    /// right-hand side on the contact dofs (its forward sweep over their reach only).
    fn push_forces(
        &mut self,
        sys: &mut EffectiveSystem,
        g: &nalgebra_sparse::CsrMatrix<f64>,
    ) -> Result<()> {
        self.work.push_entries.clear();
        for (j, &i) in self.sel.rows.iter().enumerate() {
            let row = g.row(i);
            for (&e, v) in row.col_indices().iter().zip(row.values()) {
                self.work
                    .push_entries
                    .push((e, self.work.lambda_rows[j] * v));
            }
        }
        self.work.push.clear();
        self.work.push.resize(self.setup.dofs.free.len(), 0.0);
        sys.solve_sparse(&self.work.push_entries, &mut self.work.push)?;
        for (d, p) in self.work.delta0.iter_mut().zip(&self.work.push) {
            *d += p;
        }
        Ok(())
    }

    /// The primal QP over all free dofs (the frictionless reference): its
    /// multipliers, and from them `δ = δ₀ + A⁻¹Gᵀλ` on the factor into `delta0`, as
    /// the condensed path forms it. The QP's own `δ` is as accurate as the interior
    /// point's tolerance on every free dof, which left the equilibrium residual at
    /// that tolerance (7.9e-4 on the bars) and the step cut to nothing; from the
    /// multipliers, the two paths differ only by the multipliers' accuracy.
    pub(super) fn full(
        &mut self,
        sys: &mut EffectiveSystem,
        g: &nalgebra_sparse::CsrMatrix<f64>,
        rhs: &[f64],
    ) -> Result<std::result::Result<(), String>> {
        let free = &self.setup.dofs.free;
        debug_assert!(
            self.sel.cones.is_empty(),
            "validation: friction is condensed"
        );
        let t = Instant::now();
        let r_free: Vec<f64> = free
            .iter()
            .zip(rhs.iter())
            .map(|(&d, &b)| self.active.f_c[d] - b)
            .collect();
        let gaps: Vec<f64> = self.sel.rows.iter().map(|&i| self.sel.gaps[i]).collect();
        let row_entries: Vec<Vec<(usize, f64)>> = self
            .sel
            .rows
            .iter()
            .map(|&i| {
                let row = g.row(i);
                row.col_indices()
                    .iter()
                    .copied()
                    .zip(row.values().iter().copied())
                    .collect()
            })
            .collect();
        let mut delta = Vec::new();
        let sigma = self
            .work
            .delta0
            .iter()
            .fold(self.setup.tol, |a, x| a.max(x.abs()));
        let r = primal_qp(
            sys.matrix(),
            &r_free,
            &gaps,
            &row_entries,
            sigma,
            &mut delta,
            &mut self.work.lambda_rows,
        );
        self.record.qp_s += t.elapsed().as_secs_f64();
        if r.is_ok() {
            self.push_forces(sys, g)?;
        }
        Ok(r.map(|_| ()))
    }
}
