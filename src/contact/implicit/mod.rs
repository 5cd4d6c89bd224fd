//! Impenetrability in the implicit schemes: the constrained correction of the
//! equilibrium loop.
//!
//! At an iterate `u` with residual `r` (without contact forces) and effective matrix
//! `A`, the correction solves the convex QP
//!
//! `min ½ δᵀAδ + rᵀδ   subject to   g + Gδ ≥ 0`,
//!
//! `g` the gaps and `G` their linearisation at `u` (from [`super::detect`]); its
//! multipliers `λ ≥ 0` are the contact forces, `f_c = Gᵀλ`. Condensed (the default):
//! `δ₀ = −A⁻¹r`, `Y = A⁻¹Gᵀ` (one blocked solve on the factor the loop already has),
//! `W = G Y`, the dual `min ½ λᵀWλ + λᵀ(g + Gδ₀)`, `λ ≥ 0`, and `δ = δ₀ + Yλ`. Full
//! (the reference): the primal QP over all free dofs.
//!
//! Rows: the candidates whose predicted gap `g + Gδ₀` closes to within the
//! tolerance, and those active at the last QP (or the last step). At every evaluated
//! iterate the geometry is detected again (new normals, closest segments,
//! candidates: re-linearisation), the forces `Gᵀλ` of the current multipliers enter
//! the residual, and the loop converges when the residual, the penetration, the
//! complementarity (no force across an open gap) and the active set all settle
//! (`theory/contact.md`).

mod held;
mod parts;
mod paths;

use parts::{ActiveSet, RowSelection, Setup, StepStart, Workspace};

use std::time::Instant;

use super::master::rigid;
use super::master::Positions;
use super::rows::Candidate;
use crate::error::Result;
use crate::model::{ContactQp, Model};
use crate::nonlinear::{ConstraintStatus, Corrected, Correction};
use crate::system::EffectiveSystem;

pub use super::state::{ContactState, PairRecord};
use super::state::{Key, Slave, Target};

/// A sparse row of `G` times a vector over the free dofs.
fn row_dot(row: &nalgebra_sparse::csr::CsrRow<'_, f64>, x: &[f64]) -> f64 {
    row.col_indices()
        .iter()
        .zip(row.values())
        .map(|(&e, v)| v * x[e])
        .sum()
}

/// The slaves (pair, side, node) of a sorted list of constraint keys, distinct.
fn slaves(keys: &[Key]) -> impl Iterator<Item = Slave> + '_ {
    let mut last = None;
    keys.iter().filter_map(move |k| {
        let s = k.slave;
        (last.replace(s) != Some(s)).then_some(s)
    })
}

/// The first slave (in key order) pressed in one of two active sets and not in the
/// other.
fn first_change(previous: &[Key], current: &[Key]) -> Option<Slave> {
    let (mut a, mut b) = (slaves(previous).peekable(), slaves(current).peekable());
    loop {
        match (a.peek().copied(), b.peek().copied()) {
            (None, None) => return None,
            (Some(x), None) | (None, Some(x)) => return Some(x),
            (Some(x), Some(y)) if x == y => {
                a.next();
                b.next();
            }
            (Some(x), Some(y)) => return Some(if x < y { x } else { y }),
        }
    }
}

/// How far (relative to the largest predicted gap) a row left out of an active-set
/// guess may end up penetrating for the guess to stand: Clarabel's own tolerance.
const GUESS_GAP_TOLERANCE: f64 = 1e-9;

/// Multipliers below this fraction of the largest count as inactive.
const ACTIVE_FRACTION: f64 = 1e-6;

/// Ulps of the largest coordinate below which a multiplier's own closure of its gap
/// is round-off.
const GAP_ROUNDOFF: f64 = 8.0;

/// Rounds of one correction's QP that may add rows left out and found penetrating.
const MAX_ROW_ROUNDS: usize = 4;

/// A pressed node sticks when its tangential force is below `1 − STICK_MARGIN` of
/// the cone's bound (the cone program ends within its tolerance of the bound).
const STICK_MARGIN: f64 = 1e-6;

/// Whether a pressed node of normal force `normal` and tangential force
/// `tangential` (along its row's tangents) sticks under friction `mu`.
fn sticks(mu: f64, normal: f64, tangential: [f64; 2]) -> bool {
    tangential[0].hypot(tangential[1]) < (1.0 - STICK_MARGIN) * mu * normal
}

/// Time spent in the contact correction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactStats {
    /// QPs solved.
    pub qps: usize,
    /// Rows (constraints) summed over the QPs.
    pub rows: usize,
    /// Forming `W` (the blocked solve and the products), s.
    pub w_s: f64,
    /// Clarabel, s.
    pub qp_s: f64,
    /// Detection, s.
    pub detect_s: f64,
    /// QPs whose `W` came from the kept compliance of the contact dofs.
    pub compliant: usize,
    /// QPs solved by the previous active set (its KKT conditions held).
    pub guessed: usize,
    /// QPs with friction, those solved by the guess of the last statuses, and the
    /// cone programs the others took (De Saxcé's fixed point).
    pub frictional: usize,
    /// Frictional QPs solved by the guess.
    pub friction_guessed: usize,
    /// Cone programs solved.
    pub cone_programs: usize,
}

/// The constrained correction for the contact pairs of a model: its setup, where the
/// step started, the active set, the rows of the QP at hand, the workspace and the
/// record of what it cost.
pub struct ContactCorrection<'m> {
    setup: Setup<'m>,
    start: StepStart,
    active: ActiveSet,
    sel: RowSelection,
    work: Workspace,
    record: ContactStats,
}

impl<'m> ContactCorrection<'m> {
    /// The correction for the contact pairs of `model`.
    pub fn new(model: &'m Model) -> Self {
        let mesh = &model.mesh;
        let n = mesh.n_dofs();
        let largest = mesh
            .coords
            .iter()
            .flat_map(|c| c.iter())
            .fold(0.0f64, |a, x| a.max(x.abs()));
        ContactCorrection {
            setup: Setup {
                model,
                pairs: &model.contacts,
                tol: model.analysis.contact.tolerance,
                gap_floor: GAP_ROUNDOFF * f64::EPSILON * largest,
                qp: model.analysis.contact.qp,
                area: super::tributary_areas(model),
                dofs: crate::system::DofMap::new(n, model.constraints.iter().map(|c| c.dof)),
                dim: mesh.dim,
                frictional: model.contacts.iter().any(|p| p.mu > 0.0),
                friction_guess: model.analysis.contact.friction_guess,
            },
            start: StepStart::default(),
            active: ActiveSet {
                f_c: vec![0.0; n],
                f_t: vec![0.0; n],
                ..Default::default()
            },
            sel: RowSelection::default(),
            work: Workspace {
                x: vec![0.0; n],
                qp_generation: usize::MAX,
                ..Default::default()
            },
            record: ContactStats::default(),
        }
    }

    /// The same correction without friction: impenetrability only (the contact
    /// predictor's projection).
    pub fn frictionless(mut self) -> Self {
        self.setup.frictional = false;
        self
    }

    /// Whether any constraint carries a force at the last iterate.
    pub fn has_forces(&self) -> bool {
        !self.active.lambda.is_empty()
    }

    /// Starts a step from the contact state of the last one: its multipliers are the
    /// first guess of the forces, its active set the reference of the first QP.
    pub fn begin_step(&mut self, committed: &ContactState, u: &[f64], lead: Option<(f64, &[f64])>) {
        // Slaves that came around the end of a rigid line are not its candidates;
        // those it holds stay on it a little beyond its ends.
        let coords = &self.setup.model.mesh.coords;
        // The geometry at the start of the step: a slave's motion from it is swept
        // for crossings ([`super::detect::crossed`]).
        let dim = self.setup.dim;
        self.start.x0.clear();
        self.start.x0.extend(
            coords
                .iter()
                .enumerate()
                .flat_map(|(n, c)| (0..dim).map(move |i| c[i] + u[dim * n + i])),
        );
        if dim == 2 {
            self.start.rigid.beneath = rigid::beneath_rigid(
                self.setup.pairs,
                |n| [coords[n][0] + u[2 * n], coords[n][1] + u[2 * n + 1]],
                rigid::RIGID_DEPTH_TOLERANCES * self.setup.tol,
                &self.start.rigid.beneath,
            );
        } else {
            // A solid's face masters: slaves that came around a master's edge.
            self.start.rigid.beneath = super::master::faces::beneath_faces(
                self.setup.pairs,
                Positions::new(&self.start.x0, dim),
                rigid::RIGID_DEPTH_TOLERANCES * self.setup.tol,
                &self.start.rigid.beneath,
            );
        }
        // The displacement h v the step is expected to make, by which the first
        // correction is linearised ahead (zero on the constrained dofs).
        self.start.lead.clear();
        self.start.lead_all.clear();
        if let Some((h, v)) = lead {
            self.start.lead_all.extend(v.iter().map(|x| h * x));
            for (d, &e) in self.setup.dofs.eq.iter().enumerate() {
                if e == crate::system::CONSTRAINED {
                    self.start.lead_all[d] = 0.0;
                }
            }
            self.start
                .lead
                .extend(self.setup.dofs.free.iter().map(|&d| self.start.lead_all[d]));
        }
        self.active.lambda = committed.active.iter().copied().collect();
        self.active.lambda_t = committed.tangential.iter().copied().collect();
        // Slips are measured from the start of the step (friction only).
        self.start.u0.clear();
        if self.setup.frictional {
            self.start.u0.extend_from_slice(u);
        }
        let values: Vec<f64> = committed.active.iter().map(|(_, l)| *l).collect();
        let threshold = self.active_threshold(&values);
        self.active.current = committed
            .active
            .iter()
            .filter(|(_, l)| *l > threshold)
            .map(|(k, _)| *k)
            .collect();
        self.active.previous = self.active.current.clone();
        self.active.added = false;
        self.start.rigid.held = self
            .active
            .current
            .iter()
            .filter(|k| k.target == Target::Rigid)
            .map(|k| k.slave)
            .collect();
        self.start.rigid.held.sort_unstable();
        self.start.rigid.held.dedup();
        self.start.held = self.held();
    }

    /// The contact forces `Gᵀλ` of the last iterate on every dof, friction
    /// included.
    pub fn contact_force(&self) -> &[f64] {
        &self.active.f_c
    }

    /// Ends an accepted step with increment `du`: writes the contact state and returns
    /// the work `Δu·f` of the normal and of the tangential contact forces of the step
    /// (the ledger books their negatives as `D_contact` and `D_friction`).
    pub fn finish(&mut self, du: &[f64], out: &mut ContactState) -> (f64, f64) {
        let work: f64 = du.iter().zip(&self.active.f_c).map(|(d, f)| d * f).sum();
        let friction: f64 = du.iter().zip(&self.active.f_t).map(|(d, f)| d * f).sum();
        out.active = self.active.lambda.iter().map(|(k, l)| (*k, *l)).collect();
        out.tangential = self.active.lambda_t.iter().map(|(k, l)| (*k, *l)).collect();
        out.pairs.clear();
        out.pairs
            .resize(self.setup.pairs.len(), PairRecord::default());
        let n_nodes = self.setup.model.mesh.n_nodes();
        out.gap.clear();
        out.gap.resize(n_nodes, f64::NAN);
        out.pressure.clear();
        out.pressure.resize(n_nodes, 0.0);
        out.traction.clear();
        out.traction.resize(n_nodes, 0.0);
        out.slip.resize(n_nodes, 0.0);
        let largest = self.active.lambda.values().fold(0.0f64, |a, x| a.max(*x));
        let threshold = self.active_threshold(&[largest]);
        for c in &self.sel.cands {
            let rec = &mut out.pairs[c.pair];
            rec.penetration = rec.penetration.max(-c.gap);
            let g = &mut out.gap[c.slave];
            *g = if g.is_nan() { c.gap } else { g.min(c.gap) };
            let area = self.area_of(c);
            if let Some(&l) = self.active.lambda.get(&c.key()) {
                rec.force += l;
                if area > 0.0 {
                    out.pressure[c.slave] += l / area;
                }
                let mu = self.setup.pairs[c.pair].mu;
                if mu > 0.0 && l > threshold {
                    let lt = self
                        .active
                        .lambda_t
                        .get(&c.key())
                        .copied()
                        .unwrap_or([0.0; 2]);
                    // In the plane the signed force along the tangent; in a solid,
                    // whose rows' tangents differ, its magnitude.
                    let size = lt[0].hypot(lt[1]);
                    let signed = if self.setup.dim == 2 { lt[0] } else { size };
                    rec.tangential_force += signed;
                    rec.tangential_magnitude += size;
                    if area > 0.0 {
                        out.traction[c.slave] += signed / area;
                    }
                    if sticks(mu, l, lt) {
                        rec.sticking += 1;
                    } else {
                        rec.slipping += 1;
                    }
                    let dim = self.setup.dim;
                    let d = c.tangential(|n, i| du[dim * n + i]);
                    out.slip[c.slave] += d[0].hypot(d[1]);
                    rec.max_slip = rec.max_slip.max(out.slip[c.slave]);
                }
            }
        }
        for s in slaves(&self.active.current) {
            out.pairs[s.pair].active += 1;
        }
        (work - friction, friction)
    }

    /// The area (m²) a row's force spreads over: the covered length of a mortar row
    /// times the slave body's thickness (a solid's covered area: its thickness is
    /// 1), else the node's tributary area.
    fn area_of(&self, c: &Candidate) -> f64 {
        if c.length > 0.0 {
            let mesh = &self.setup.model.mesh;
            c.length * self.setup.model.bodies[mesh.node_body[c.slave]].thickness
        } else {
            self.setup.area[c.slave]
        }
    }

    /// Time and counts so far.
    pub fn stats(&self) -> ContactStats {
        self.record
    }

    /// Candidates at `u` into `self.sel.cands`.
    fn detect_at(&mut self, u: &[f64]) {
        let t = Instant::now();
        let coords = &self.setup.model.mesh.coords;
        let dim = self.setup.dim;
        for (n, c) in coords.iter().enumerate() {
            for i in 0..dim {
                self.work.x[dim * n + i] = c[i] + u[dim * n + i];
            }
        }
        let x = Positions::new(&self.work.x, dim);
        super::detect::detect(
            self.setup.pairs,
            x,
            &self.start.rigid,
            Some(&mut self.work.kept),
            &mut self.sel.cands,
        );
        if !self.start.x0.is_empty() {
            let x0 = Positions::new(&self.start.x0, dim);
            super::detect::crossed(
                self.setup.pairs,
                x0,
                x,
                &self.start.rigid,
                &mut self.sel.cands,
            );
        }
        self.record.detect_s += t.elapsed().as_secs_f64();
    }

    /// `Gᵀλ` of the current multipliers at the current candidates, into `f_c` (the
    /// tangential ones' part also into `f_t`).
    fn forces(&mut self) {
        self.active.f_c.fill(0.0);
        self.active.f_t.fill(0.0);
        for c in &self.sel.cands {
            if let Some(&l) = self.active.lambda.get(&c.key()) {
                for (d, v) in c.row() {
                    self.active.f_c[d] += l * v;
                }
            }
            if let Some(&l) = self.active.lambda_t.get(&c.key()) {
                for (j, lj) in l.iter().enumerate().take(c.n_tangents()) {
                    for (d, v) in c.tangent_row(j) {
                        self.active.f_t[d] += lj * v;
                    }
                }
            }
        }
        for (c, t) in self.active.f_c.iter_mut().zip(&self.active.f_t) {
            *c += t;
        }
    }

    /// The relative tangential displacement of a row since the start of the step at
    /// displacements `u`: `t_j · Σ w_k (u_k − u0_k)` along each tangent.
    fn slip(&self, c: &Candidate, u: &[f64]) -> [f64; 2] {
        let dim = self.setup.dim;
        c.tangential(|n, i| u[dim * n + i] - self.start.u0[dim * n + i])
    }

    /// The rows of the QP at an iterate: the candidates predicted (by `δ₀`) to close
    /// to within the tolerance, those active before, and those forced in by an
    /// earlier round of the same correction; then the tangential rows of the
    /// frictional ones. `leading`: the candidates were detected at `u + h v`.
    fn select_rows(&mut self, g: &nalgebra_sparse::CsrMatrix<f64>, u: &[f64], leading: bool) {
        let n_cands = self.sel.cands.len();
        let tdim = self.setup.dim - 1;
        self.sel.rows.clear();
        self.sel.cones.clear();
        self.sel.c.clear();
        self.sel.gaps.clear();
        for (i, c) in self.sel.cands.iter().enumerate() {
            let row = g.row(i);
            let dot = |x: &[f64]| row_dot(&row, x);
            // The gap at u: at u + hv less its linearised change over hv.
            let gap = if leading {
                c.gap - dot(&self.start.lead)
            } else {
                c.gap
            };
            self.sel.gaps.push(gap);
            if row.nnz() == 0 {
                continue;
            }
            let predicted = gap + dot(&self.work.delta0);
            if predicted < self.setup.tol
                || self.active.previous.contains(&c.key())
                || self.sel.forced.binary_search(&i).is_ok()
            {
                self.sel.rows.push(i);
                self.sel.c.push(predicted);
            }
        }
        // The tangential rows of the frictional pairs' rows, after the normal ones
        // (one per tangent, `dim − 1`): the slip since the start of the step,
        // predicted.
        self.sel.normal_rows = self.sel.rows.len();
        self.sel.pressed.clear();
        self.sel.guess_t.clear();
        if self.setup.frictional {
            for &i in &self.sel.rows {
                let key = self.sel.cands[i].key();
                self.sel
                    .pressed
                    .push(self.active.previous.binary_search(&key).is_ok());
            }
            for j in 0..self.sel.normal_rows {
                let i = self.sel.rows[j];
                let c = &self.sel.cands[i];
                let mu = self.setup.pairs[c.pair].mu;
                if mu > 0.0 {
                    let slip = self.slip(c, u);
                    for (t, s) in slip.iter().enumerate().take(tdim) {
                        let moved = row_dot(&g.row(n_cands + tdim * i + t), &self.work.delta0);
                        self.sel.rows.push(n_cands + tdim * i + t);
                        self.sel.c.push(s + moved);
                    }
                    self.sel.cones.push((j, mu));
                    let key = c.key();
                    let ln = self.sel.last_lambda.get(&key).copied().unwrap_or(0.0);
                    let lt = self
                        .sel
                        .last_lambda_t
                        .get(&key)
                        .copied()
                        .unwrap_or([0.0; 2]);
                    self.sel.guess_t.push(if sticks(mu, ln, lt) {
                        super::coulomb::Guess::Stick
                    } else {
                        super::coulomb::Guess::slip_along(&lt[..tdim])
                    });
                }
            }
        }
    }

    /// Whether the correction `δ` now in `delta0` makes a candidate left out of the
    /// QP penetrate (beyond the QP's own accuracy); those that do are added to
    /// `forced` for the next round.
    fn left_out_penetrate(&mut self, g: &nalgebra_sparse::CsrMatrix<f64>) -> bool {
        let inside = &self.sel.rows[..self.sel.normal_rows];
        let floor = GUESS_GAP_TOLERANCE * self.sel.c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let before = self.sel.forced.len();
        for i in 0..self.sel.cands.len() {
            let row = g.row(i);
            if row.nnz() == 0 || inside.binary_search(&i).is_ok() {
                continue;
            }
            if self.sel.gaps[i] + row_dot(&row, &self.work.delta0) < -floor {
                self.sel.forced.push(i);
            }
        }
        self.sel.forced.sort_unstable();
        self.sel.forced.len() > before
    }

    /// The threshold below which a multiplier counts as zero: a millionth of the
    /// largest. A constraint that is only weakly active (its gap and its force both
    /// about zero, as at the instant of a release) would otherwise flip in and out of
    /// the active set from one QP to the next while the step is already in
    /// equilibrium.
    fn active_threshold(&self, lambda: &[f64]) -> f64 {
        ACTIVE_FRACTION * lambda.iter().fold(0.0f64, |a, x| a.max(*x)) + f64::MIN_POSITIVE
    }
}

impl Correction for ContactCorrection<'_> {
    fn constrain(&mut self, u: &[f64], r: &mut [f64]) -> ConstraintStatus {
        self.detect_at(u);
        // A multiplier whose row is no candidate any more (its slave left a notch,
        // or moved on to the next segment) passes to the slave's row that remains:
        // a node's force does not vanish because its linearisation changed. With no
        // row left for the slave (it left the master), it is dropped, and that is
        // an active-set change.
        let mut dropped = false;
        self.active.moved.clear();
        let cands = &self.sel.cands;
        let found = |k: &Key| cands.binary_search_by_key(k, Candidate::key).is_ok();
        let moved = &mut self.active.moved;
        self.active.lambda.retain(|k, l| {
            let keep = found(k);
            if !keep {
                moved.push((*k, *l));
            }
            keep
        });
        // A tangential force follows its normal one to the slave's remaining row.
        let mut moved_t = Vec::new();
        self.active.lambda_t.retain(|k, l| {
            let keep = found(k);
            if !keep {
                moved_t.push((*k, *l));
            }
            keep
        });
        for (k, l) in moved_t {
            let slave = k.slave;
            let at = self.sel.cands.partition_point(|c| c.slave_key() < slave);
            if let Some(c) = self.sel.cands.get(at).filter(|c| c.slave_key() == slave) {
                let e = self.active.lambda_t.entry(c.key()).or_insert([0.0; 2]);
                e[0] += l[0];
                e[1] += l[1];
            }
        }
        for &(k, l) in &self.active.moved {
            let slave = k.slave;
            let at = self.sel.cands.partition_point(|c| c.slave_key() < slave);
            match self.sel.cands.get(at).filter(|c| c.slave_key() == slave) {
                Some(c) => {
                    *self.active.lambda.entry(c.key()).or_insert(0.0) += l;
                    if let Ok(p) = self.active.current.binary_search(&k) {
                        self.active.current.remove(p);
                        if let Err(q) = self.active.current.binary_search(&c.key()) {
                            self.active.current.insert(q, c.key());
                        }
                    }
                }
                None => dropped = true,
            }
        }
        self.forces();
        for (ri, f) in r.iter_mut().zip(&self.active.f_c) {
            *ri -= f;
        }
        self.active.added = true;
        let mut penetration: f64 = 0.0;
        let mut open_under_force: f64 = 0.0;
        for c in &self.sel.cands {
            penetration = penetration.max(-c.gap);
            if self.active.current.binary_search(&c.key()).is_ok() {
                open_under_force = open_under_force.max(c.gap);
            }
        }
        let changed_at =
            first_change(&self.active.previous, &self.active.current).map(|s| (s.pair, s.node));
        ConstraintStatus {
            penetration,
            complementarity: open_under_force,
            active_set_changed: changed_at.is_some() || dropped,
            changed_at,
        }
    }

    fn correct(
        &mut self,
        sys: &mut EffectiveSystem,
        u: &[f64],
        rhs: &mut [f64],
    ) -> Result<Corrected> {
        if !self.active.added {
            // A predicted start: no evaluation, no forces in the right-hand side yet.
            // Linearised about the predicted geometry u + h v (theory/contact.md).
            if self.start.lead.is_empty() {
                self.detect_at(u);
            } else {
                self.work.x_lead.clear();
                self.work
                    .x_lead
                    .extend(u.iter().zip(&self.start.lead_all).map(|(a, b)| a + b));
                let x_lead = std::mem::take(&mut self.work.x_lead);
                self.detect_at(&x_lead);
                self.work.x_lead = x_lead;
            }
            self.active.f_c.fill(0.0);
        }
        let leading = !self.active.added && !self.start.lead.is_empty();
        self.active.added = false;
        let (free, eq) = (&self.setup.dofs.free, &self.setup.dofs.eq);
        debug_assert_eq!(free.len(), sys.dofs().n_free());
        // −r = rhs − f_c on the free dofs; δ₀ = A⁻¹(−r).
        self.work.delta0.clear();
        self.work.delta0.extend(
            free.iter()
                .zip(rhs.iter())
                .map(|(&d, &b)| b - self.active.f_c[d]),
        );
        sys.solve(&mut self.work.delta0)?;
        // G over the free dofs (nalgebra-sparse CSR).
        let n_cands = self.sel.cands.len();
        let g = if self.setup.frictional {
            super::rows::gap_and_tangent_matrix(&self.sel.cands, eq, free.len())
        } else {
            super::rows::gap_matrix(&self.sel.cands, eq, free.len())
        };
        let tdim = self.setup.dim - 1;
        self.active.previous = std::mem::take(&mut self.active.current);
        // The last multipliers, which the guess of a frictional QP reads, make way
        // for the new ones.
        std::mem::swap(&mut self.active.lambda, &mut self.sel.last_lambda);
        std::mem::swap(&mut self.active.lambda_t, &mut self.sel.last_lambda_t);
        self.active.lambda.clear();
        self.active.lambda_t.clear();
        // The QP on the rows predicted to close; a row left out that the QP's
        // correction would make penetrate joins them and the QP is solved again, so
        // no slave is let into its master for want of a row (theory/contact.md,
        // "rows left out").
        self.sel.delta_start.clone_from(&self.work.delta0);
        self.sel.forced.clear();
        let mut rounds = 0;
        let status = loop {
            self.select_rows(&g, u, leading);
            let m = self.sel.rows.len();
            if m == 0 {
                rhs.copy_from_slice(&self.work.delta0);
                return Ok(Corrected::Ok);
            }
            self.record.qps += 1;
            self.record.rows += m;
            let status = match self.setup.qp {
                ContactQp::Condensed => self.condensed(sys, &g, m)?,
                ContactQp::Full => self.full(sys, &g, rhs)?,
            };
            rounds += 1;
            if status.is_err() || rounds > MAX_ROW_ROUNDS || !self.left_out_penetrate(&g) {
                break status;
            }
            self.work.delta0.clone_from(&self.sel.delta_start);
        };

        if let Err(status) = status {
            let worst = self
                .sel
                .cands
                .iter()
                .min_by(|a, b| a.gap.total_cmp(&b.gap))
                .map(|c| {
                    format!(
                        "; worst gap {:.3e} m at {} of pair `{}`",
                        c.gap,
                        self.setup.model.describe_node(c.slave),
                        self.setup.pairs[c.pair].name
                    )
                })
                .unwrap_or_default();
            let pairs: Vec<&str> = {
                let mut p: Vec<usize> = self
                    .sel
                    .rows
                    .iter()
                    .map(|&i| {
                        let c = if i < n_cands { i } else { (i - n_cands) / tdim };
                        self.sel.cands[c].pair
                    })
                    .collect();
                p.sort_unstable();
                p.dedup();
                p.iter()
                    .map(|&i| self.setup.pairs[i].name.as_str())
                    .collect()
            };
            return Ok(Corrected::Failed(format!(
                "contact QP of pair(s) {}: {status}{worst}",
                pairs.join(", ")
            )));
        }
        // Every positive multiplier acts as a force (dropping small ones would leave
        // their force out of the balance); the active set, for the test that it has
        // settled and for complementarity, holds the significant ones.
        let nr = self.sel.normal_rows;
        // A multiplier whose own closure `λ W_jj` is below what the coordinates
        // resolve holds a gap of round-off, not a contact: left out of the active
        // set (its force still acts), or a slave resting or grazing at a gap of
        // exactly zero flips in and out of the set on round-off forces.
        let threshold = self.active_threshold(&self.work.lambda_rows[..nr]);
        let m = self.sel.rows.len();
        let condensed = self.work.w.len() == m * m;
        for (j, &i) in self.sel.rows[..nr].iter().enumerate() {
            let l = self.work.lambda_rows[j];
            let key = self.sel.cands[i].key();
            if l > 0.0 {
                self.active.lambda.insert(key, l);
            }
            let resolved = !condensed || l * self.work.w[j + j * m] > self.setup.gap_floor;
            if l > threshold && resolved {
                self.active.current.push(key);
            }
        }
        for (k, &(j, _)) in self.sel.cones.iter().enumerate() {
            let mut l = [0.0; 2];
            l[..tdim].copy_from_slice(&self.work.lambda_rows[nr + tdim * k..nr + tdim * (k + 1)]);
            if l != [0.0; 2] && self.work.lambda_rows[j] > 0.0 {
                self.active
                    .lambda_t
                    .insert(self.sel.cands[self.sel.rows[j]].key(), l);
            }
        }
        self.active.current.sort_unstable();
        rhs.copy_from_slice(&self.work.delta0);
        Ok(Corrected::Ok)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::state::Target;

    fn key(pair: usize, node: usize, facet: usize) -> Key {
        Key {
            slave: Slave::new(pair, 0, node),
            target: Target::Facet(facet),
        }
    }

    #[test]
    fn the_first_change_of_an_active_set_names_its_slave() {
        let a = [key(0, 3, 1), key(0, 5, 2), key(1, 2, 0)];
        // The same slaves on other facets: no change of membership.
        let moved = [key(0, 3, 2), key(0, 5, 2), key(1, 2, 4)];
        assert_eq!(first_change(&a, &moved), None);
        // Node 5 left; node 4 of pair 0 entered; one added at the end.
        let left = [key(0, 3, 1), key(1, 2, 0)];
        assert_eq!(first_change(&a, &left), Some(Slave::new(0, 0, 5)));
        let entered = [key(0, 3, 1), key(0, 4, 1), key(0, 5, 2), key(1, 2, 0)];
        assert_eq!(first_change(&a, &entered), Some(Slave::new(0, 0, 4)));
        let added = [key(0, 3, 1), key(0, 5, 2), key(1, 2, 0), key(1, 7, 0)];
        assert_eq!(first_change(&a, &added), Some(Slave::new(1, 0, 7)));
    }
}
