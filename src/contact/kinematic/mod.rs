//! The kinematic contact method of the explicit path (the paper's Section 4):
//! impenetrability enforced on the motion of a step, not by forces.
//!
//! Within a step every node moves at its half-step velocity. For each slave node and
//! each master segment (or rigid line) in reach, [`super::collision::node_segment`]
//! gives the earliest time `t_c` at which they meet. The colliding pairs then get a
//! perfectly inelastic normal impact at `t_c`: impulses `p ≥ 0` along the normals,
//! applied as `+p n` on the slave and `−(1−ξ) p n`, `−ξ p n` on the segment's nodes
//! (so the total momentum does not change), with the post-impact normal relative
//! velocities zero where `p > 0` and nonnegative elsewhere. Simultaneous contacts
//! couple through the nodes they share: the impulses solve the small QP
//! `min ½ pᵀWp + pᵀc, p ≥ 0`, `W = G M⁻¹ Gᵀ`, `c = G v` (the same dual QP as the
//! implicit contact, on velocities). Friction follows the paper's interpolation
//! `v× = β v_stick + (1 − β) v_free` between the frictionless impact and the sticking
//! one (zero relative velocity, normal and tangential). The position update over the
//! step is the paper's, `x¹ = x⁰ + t_c (w v + (1 − w) v×) + (h − t_c) v×`, with the
//! weight `w` of the pair. A last pass projects any node still found behind a master
//! at the end of the step back onto it, mass-weighted (positions only, momentum
//! unchanged). See `theory/explicit.md`.

use super::master::{rigid, Positions};
use super::qp::{on_active_set, solve_by_active_set, DualQp};
use super::rows::Candidate;
use super::state::{ContactState, Key, PairRecord, Slave};
use crate::error::{Error, Result};
use crate::model::Model;

/// Sweeps of the end-of-step projection.
const PROJECTION_SWEEPS: usize = 4;

/// The most dofs of a row: the slave and a solid's quadrilateral face, three each.
const ROW_DOFS: usize = 15;

/// The dofs and coefficients of a row, and how many are used.
pub(super) type Dofs = ([(usize, f64); ROW_DOFS], usize);

/// One colliding pair of a step.
#[derive(Clone, Copy, Debug)]
pub(super) struct Row {
    pub(super) key: Key,
    /// Time of impact within the step.
    pub(super) t_c: f64,
    /// Dofs and coefficients of the normal row (slave `+n`, segment `−(1−ξ)n, −ξn`;
    /// a face's corners `−N_k n`).
    pub(super) normal: Dofs,
    /// The same with the tangents: in the plane the one `(n_y, −n_x)` (the implicit
    /// path's, [`Candidate::tangent`]), in a solid two ([`crate::geometry::tangents`]).
    pub(super) tangents: [Dofs; 2],
    /// Tangents used: 1 in the plane, 2 in a solid.
    pub(super) n_tangents: usize,
    /// Friction interpolation, Coulomb coefficient and position weight of the pair.
    pub(super) beta: f64,
    pub(super) mu: f64,
    pub(super) weight: f64,
}

/// A row along `d` in a `dim`-dimensional mesh: `+d` on the slave, `−w d` on each
/// of the master's `corners` `(node, w)`.
fn row_along(dim: usize, slave: usize, corners: &[(usize, f64)], d: [f64; 3]) -> Dofs {
    let mut r = ([(0usize, 0.0f64); ROW_DOFS], 0);
    let mut push = |node: usize, w: f64| {
        for (i, di) in d.iter().enumerate().take(dim) {
            r.0[r.1] = (dim * node + i, w * di);
            r.1 += 1;
        }
    };
    push(slave, 1.0);
    for &(node, w) in corners {
        push(node, -w);
    }
    r
}

/// The rows of an impact along its normal `n`: the normal one and the tangential
/// ones, in the plane the one `(n_y, −n_x)` (the implicit path's,
/// [`Candidate::tangent`]), in a solid the two of [`crate::geometry::tangents`].
fn impact_rows(
    dim: usize,
    slave: usize,
    corners: &[(usize, f64)],
    n: [f64; 3],
) -> (Dofs, [Dofs; 2], usize) {
    let along = |d: [f64; 3]| row_along(dim, slave, corners, d);
    if dim == 2 {
        let empty = ([(0usize, 0.0f64); ROW_DOFS], 0);
        (along(n), [along([n[1], -n[0], 0.0]), empty], 1)
    } else {
        let t = crate::geometry::tangents(n);
        (along(n), [along(t[0]), along(t[1])], 2)
    }
}

fn dot_row(row: &Dofs, x: &[f64]) -> f64 {
    row.0[..row.1].iter().map(|&(d, c)| c * x[d]).sum()
}

/// `Σ_d a_d b_d / m_d` of two rows.
fn coupling(a: &Dofs, b: &Dofs, m_inv: &[f64]) -> f64 {
    let mut w = 0.0;
    for &(da, ca) in &a.0[..a.1] {
        for &(db, cb) in &b.0[..b.1] {
            if da == db {
                w += ca * cb * m_inv[da];
            }
        }
    }
    w
}

/// What the correction of the last step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KinematicStats {
    /// Collisions resolved (rows with a positive impulse).
    pub impacts: usize,
    /// Impulse QPs that needed Clarabel (the active-set start failed).
    pub clarabel: usize,
    /// Nodes moved by the end-of-step projection.
    pub projected: usize,
}

/// The kinematic contact of a model's pairs.
pub struct KinematicContact<'m> {
    model: &'m Model,
    area: Vec<f64>,
    rows: Vec<Row>,
    // Workspace.
    w: Vec<f64>,
    c: Vec<f64>,
    p: Vec<f64>,
    active: Vec<usize>,
    work: Vec<f64>,
    node_tc: Vec<f64>,
    node_weight: Vec<f64>,
    v_pre: Vec<f64>,
    cands: Vec<Candidate>,
    impulses: Vec<(Key, f64)>,
    /// The step's tangential impulses summed per pair (N s).
    tangential: Vec<f64>,
    magnitude: Vec<f64>,
    dual: DualQp,
    step: KinematicStats,
    total: KinematicStats,
    rigid: rigid::EdgeHistory,
    /// Node positions (workspace).
    x: Vec<f64>,
}

impl<'m> KinematicContact<'m> {
    /// The correction for the contact pairs of `model`.
    pub fn new(model: &'m Model) -> Self {
        KinematicContact {
            model,
            area: super::tributary_areas(model),
            rows: Vec::new(),
            w: Vec::new(),
            c: Vec::new(),
            p: Vec::new(),
            active: Vec::new(),
            work: Vec::new(),
            node_tc: vec![f64::INFINITY; model.mesh.n_nodes()],
            node_weight: vec![1.0; model.mesh.n_nodes()],
            v_pre: Vec::new(),
            cands: Vec::new(),
            impulses: Vec::new(),
            tangential: vec![0.0; model.contacts.len()],
            magnitude: vec![0.0; model.contacts.len()],
            dual: DualQp::default(),
            step: KinematicStats::default(),
            total: KinematicStats::default(),
            rigid: Default::default(),
            x: Vec::new(),
        }
    }

    /// Counts of the whole run so far.
    pub fn stats(&self) -> KinematicStats {
        self.total
    }

    /// Corrects the motion of a step of size `h` from the displacements `u` (all
    /// dofs): `v` holds the half-step velocities and becomes the post-impact ones,
    /// `du` holds `h v` and becomes the step's increments. `m_inv` is the inverse
    /// lumped mass per dof, zero on constrained dofs (which no impulse moves).
    pub fn correct(
        &mut self,
        u: &[f64],
        v: &mut [f64],
        du: &mut [f64],
        m_inv: &[f64],
        h: f64,
    ) -> Result<()> {
        self.step = KinematicStats::default();
        self.impulses.clear();
        self.tangential.fill(0.0);
        self.magnitude.fill(0.0);
        // Slaves that came around the end of a rigid line pass beside it (the
        // plane's; a solid's rigid planes are unbounded).
        let coords = &self.model.mesh.coords;
        let plane = self.model.mesh.dim == 2;
        if plane {
            self.rigid.beneath = rigid::beneath_rigid(
                &self.model.contacts,
                |n| [coords[n][0] + u[2 * n], coords[n][1] + u[2 * n + 1]],
                rigid::RIGID_DEPTH_TOLERANCES * self.model.analysis.contact.tolerance,
                &self.rigid.beneath,
            );
            // Slaves on a rigid line stay on it a little past its ends.
            let previous = std::mem::take(&mut self.rigid.held);
            self.rigid.held = rigid::held_rigid(
                &self.model.contacts,
                |n| [coords[n][0] + u[2 * n], coords[n][1] + u[2 * n + 1]],
                rigid::RIGID_DEPTH_TOLERANCES * self.model.analysis.contact.tolerance,
                &previous,
            );
        } else {
            // Slaves that came around a face master's edge pass beside it.
            self.x = super::positions(self.model, u);
            self.rigid.beneath = super::master::faces::beneath_faces(
                &self.model.contacts,
                Positions::new(&self.x, 3),
                rigid::RIGID_DEPTH_TOLERANCES * self.model.analysis.contact.tolerance,
                &self.rigid.beneath,
            );
        }
        self.collisions(u, v, h);
        if !self.rows.is_empty() {
            self.v_pre.clear();
            self.v_pre.extend_from_slice(v);
            self.impacts(v, m_inv)?;
            self.positions(v, du, h);
        }
        self.project(u, du, v, m_inv);
        self.total.impacts += self.step.impacts;
        self.total.clarabel += self.step.clarabel;
        self.total.projected += self.step.projected;
        Ok(())
    }

    /// The earliest collision of every slave node within the step (`u` the
    /// displacements at its start, `v` the velocities).
    fn collisions(&mut self, u: &[f64], v: &[f64], h: f64) {
        self.rows.clear();
        let dim = self.model.mesh.dim;
        self.x = super::positions(self.model, u);
        let (x, v) = (Positions::new(&self.x, dim), Positions::new(v, dim));
        for (pi, pair) in self.model.contacts.iter().enumerate() {
            for (si, side) in pair.sides.iter().enumerate() {
                // Reach: the pair's radius (a segment or element edge) covers the
                // motion of a stable step many times over.
                let surface = super::master::surface(side, x);
                for &s in &side.slaves {
                    let slave = Slave::new(pi, si, s);
                    let Some(hit) = surface.impact(slave, v, h, pair.radius, &self.rigid) else {
                        continue;
                    };
                    let (normal, tangents, n_tangents) =
                        impact_rows(dim, s, hit.corners(), hit.normal);
                    self.rows.push(Row {
                        key: Key {
                            slave,
                            target: hit.target,
                        },
                        t_c: hit.t,
                        normal,
                        tangents,
                        n_tangents,
                        beta: pair.friction,
                        mu: pair.mu,
                        weight: pair.position_weight,
                    });
                }
            }
        }
    }

    /// The impulses of the colliding rows, applied to `v`.
    fn impacts(&mut self, v: &mut [f64], m_inv: &[f64]) -> Result<()> {
        let m = self.rows.len();
        self.w.clear();
        self.w.resize(m * m, 0.0);
        self.c.clear();
        for (i, ri) in self.rows.iter().enumerate() {
            self.c.push(dot_row(&ri.normal, v));
            for (j, rj) in self.rows.iter().enumerate() {
                self.w[i + j * m] = coupling(&ri.normal, &rj.normal, m_inv);
            }
        }
        // Rows whose nodes are all constrained have a zero diagonal: no impulse.
        let movable: Vec<bool> = (0..m).map(|i| self.w[i + i * m] > 0.0).collect();
        for i in 0..m {
            if !movable[i] {
                self.c[i] = self.c[i].max(0.0);
                for j in 0..m {
                    self.w[i + j * m] = if i == j { 1.0 } else { 0.0 };
                    self.w[j + i * m] = if i == j { 1.0 } else { 0.0 };
                }
            }
        }
        if self.rows.iter().any(|r| r.mu > 0.0) {
            return self.coulomb_impacts(v, m_inv, &movable);
        }
        // The frictionless impact: min ½pᵀWp + pᵀc, p ≥ 0.
        self.active.clear();
        self.active.extend((0..m).filter(|&i| self.c[i] < 0.0));
        let tol = 1e-12 * self.c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let guessed = solve_by_active_set(
            &self.w,
            &self.c,
            &mut self.active,
            tol,
            &mut self.p,
            &mut self.work,
        );
        if !guessed {
            self.step.clarabel += 1;
            self.dual
                .solve(&self.w, &self.c, &mut self.p)
                .map_err(|e| {
                    Error::Stepping(format!("the impact impulses of the kinematic contact: {e}"))
                })?;
        }
        let mut normal = self.p.clone();
        let mut tangential = vec![[0.0; 2]; m];
        // Sticking impacts where friction asks for them: the relative velocity of
        // every impacting row (normal and tangential) zero.
        let sticking: Vec<usize> = (0..m)
            .filter(|&i| self.p[i] > 0.0 && self.rows[i].beta > 0.0)
            .collect();
        if !sticking.is_empty() {
            // The sticking rows' normal rows, then their tangential rows (one or two
            // each).
            let rows: Vec<&Dofs> = sticking
                .iter()
                .map(|&i| &self.rows[i].normal)
                .chain(sticking.iter().flat_map(|&i| {
                    let r = &self.rows[i];
                    r.tangents[..r.n_tangents].iter()
                }))
                .collect();
            let k = rows.len();
            // Rows that press without friction stay as they are in both solutions.
            let mut w2 = vec![0.0; k * k];
            let mut c2 = vec![0.0; k];
            // The other impacts' frictionless impulses act in the sticking solve too.
            let mut v_free = v.to_vec();
            for (i, r) in self.rows.iter().enumerate() {
                if self.p[i] > 0.0 && r.beta == 0.0 {
                    for &(d, cf) in &r.normal.0[..r.normal.1] {
                        v_free[d] += m_inv[d] * cf * self.p[i];
                    }
                }
            }
            for (a, ra) in rows.iter().enumerate() {
                c2[a] = dot_row(ra, &v_free);
                for (b, rb) in rows.iter().enumerate() {
                    w2[a + b * k] = coupling(ra, rb, m_inv);
                }
            }
            let all: Vec<usize> = (0..k).collect();
            let mut q = Vec::new();
            let mut work = Vec::new();
            let solved = on_active_set(&w2, &c2, &all, &mut q, &mut work)
                && q[..sticking.len()].iter().all(|&x| x >= 0.0);
            // A sticking impact that would pull is no impact: friction is left out
            // for this step (the frictionless impulses stand).
            if solved {
                let mut next = sticking.len();
                for (a, &i) in sticking.iter().enumerate() {
                    let beta = self.rows[i].beta;
                    normal[i] = (1.0 - beta) * self.p[i] + beta * q[a];
                    for j in 0..self.rows[i].n_tangents {
                        tangential[i][j] = beta * q[next];
                        next += 1;
                    }
                }
            }
        }
        self.apply(v, m_inv, &movable, normal, &tangential);
        Ok(())
    }

    /// The perfectly inelastic impact with Coulomb friction: the normal relative
    /// velocities nonnegative after it (zero where pressed), the tangential ones zero
    /// where the impulse stays inside the cone `|p_T| ≤ μ p_N` and opposite to it on
    /// the cone: the velocity form of the implicit path's cone programs
    /// ([`super::coulomb`]), on `W = G M⁻¹ Gᵀ` with the tangential rows of the pairs
    /// that have friction.
    fn coulomb_impacts(&mut self, v: &mut [f64], m_inv: &[f64], movable: &[bool]) -> Result<()> {
        let m = self.rows.len();
        let frictional: Vec<usize> = (0..m)
            .filter(|&i| movable[i] && self.rows[i].mu > 0.0)
            .collect();
        // The tangents per row: one in the plane, two in a solid (every row alike).
        let tdim = self.rows.first().map_or(1, |r| r.n_tangents);
        let rows: Vec<&Dofs> = self
            .rows
            .iter()
            .map(|r| &r.normal)
            .chain(
                frictional
                    .iter()
                    .flat_map(|&i| self.rows[i].tangents[..tdim].iter()),
            )
            .collect();
        let k = rows.len();
        let mut w = vec![0.0; k * k];
        let mut c = vec![0.0; k];
        for (a, ra) in rows.iter().enumerate() {
            c[a] = dot_row(ra, v);
            for (b, rb) in rows.iter().enumerate() {
                w[a + b * k] = coupling(ra, rb, m_inv);
            }
        }
        // Rows whose nodes are all constrained: no impulse (as the frictionless one).
        for i in (0..m).filter(|&i| !movable[i]) {
            c[i] = c[i].max(0.0);
            for j in 0..k {
                w[i + j * k] = if i == j { 1.0 } else { 0.0 };
                w[j + i * k] = if i == j { 1.0 } else { 0.0 };
            }
        }
        let cones: Vec<(usize, f64)> = frictional.iter().map(|&i| (i, self.rows[i].mu)).collect();
        let mut q = Vec::new();
        self.step.clarabel += 1;
        super::coulomb::solve(&w, &c, (m, tdim), &cones, &mut q).map_err(|e| {
            Error::Stepping(format!(
                "the impact impulses of the kinematic contact with friction: {e}"
            ))
        })?;
        let normal = q[..m].to_vec();
        let mut tangential = vec![[0.0; 2]; m];
        for (a, &i) in frictional.iter().enumerate() {
            for j in 0..tdim {
                tangential[i][j] = q[m + tdim * a + j];
            }
        }
        self.apply(v, m_inv, movable, normal, &tangential);
        Ok(())
    }

    /// Applies the normal and tangential impulses of the rows to `v` and keeps the
    /// normal ones (for the positions and the record).
    fn apply(
        &mut self,
        v: &mut [f64],
        m_inv: &[f64],
        movable: &[bool],
        normal: Vec<f64>,
        tangential: &[[f64; 2]],
    ) {
        for (i, r) in self.rows.iter().enumerate() {
            if !movable[i] {
                continue;
            }
            let along = std::iter::once((&r.normal, normal[i])).chain(
                r.tangents[..r.n_tangents]
                    .iter()
                    .zip(tangential[i].iter().copied()),
            );
            for (row, p) in along {
                if p != 0.0 {
                    for &(d, cf) in &row.0[..row.1] {
                        v[d] += m_inv[d] * cf * p;
                    }
                }
            }
            if normal[i] > 0.0 {
                self.step.impacts += 1;
                self.impulses.push((r.key, normal[i]));
            }
            // In the plane the signed impulse along the tangent; in a solid, whose
            // rows' tangents differ, its magnitude.
            let [a, b] = tangential[i];
            let size = a.hypot(b);
            self.tangential[r.key.slave.pair] += if r.n_tangents == 1 { a } else { size };
            self.magnitude[r.key.slave.pair] += if r.n_tangents == 1 { a.abs() } else { size };
        }
        self.p = normal;
    }

    /// The paper's position update over the step for the nodes of the impacts.
    fn positions(&mut self, v: &[f64], du: &mut [f64], h: f64) {
        let dim = self.model.mesh.dim;
        for (i, r) in self.rows.iter().enumerate() {
            if self.p[i] <= 0.0 {
                continue;
            }
            for &(d, cf) in &r.normal.0[..r.normal.1] {
                let n = d / dim;
                if cf != 0.0 && r.t_c < self.node_tc[n] {
                    self.node_tc[n] = r.t_c;
                    self.node_weight[n] = r.weight;
                }
            }
        }
        for (n, t_c) in self.node_tc.iter_mut().enumerate() {
            if t_c.is_finite() {
                let w = self.node_weight[n];
                for d in dim * n..dim * (n + 1) {
                    du[d] = h * v[d] + w * *t_c * (self.v_pre[d] - v[d]);
                }
                *t_c = f64::INFINITY;
            }
        }
    }

    /// Projects nodes found behind a master at `u + du` back onto it (and leaves the
    /// candidates of the final geometry in `self.cands`): a few
    /// Gauss-Seidel sweeps of mass-weighted position corrections along the normals
    /// (momentum unchanged), and any approach velocity of such a pair removed by an
    /// impulse.
    fn project(&mut self, u: &[f64], du: &mut [f64], v: &mut [f64], m_inv: &[f64]) {
        for sweep in 0..=PROJECTION_SWEEPS {
            self.end_geometry(u, du);
            if sweep == PROJECTION_SWEEPS {
                break;
            }
            let mut moved = false;
            for c in &self.cands {
                if c.gap >= 0.0 {
                    continue;
                }
                // The explicit path's candidates are node to segment (three nodes) or
                // node to face (five at most).
                let mut row: Dofs = ([(0usize, 0.0f64); ROW_DOFS], 0);
                for (e, x) in c.row().take(ROW_DOFS) {
                    row.0[row.1] = (e, x);
                    row.1 += 1;
                }
                let w = coupling(&row, &row, m_inv);
                if w.is_nan() || w <= 0.0 {
                    continue;
                }
                let q = -c.gap / w;
                for &(d, cf) in &row.0[..row.1] {
                    du[d] += m_inv[d] * cf * q;
                }
                let approach = dot_row(&row, v);
                if approach < 0.0 {
                    let p = -approach / w;
                    for &(d, cf) in &row.0[..row.1] {
                        v[d] += m_inv[d] * cf * p;
                    }
                }
                self.step.projected += 1;
                moved = true;
            }
            if !moved {
                break;
            }
        }
    }

    /// Candidates at the geometry `u + du`.
    fn end_geometry(&mut self, u: &[f64], du: &[f64]) {
        let coords = &self.model.mesh.coords;
        let dim = self.model.mesh.dim;
        self.x.clear();
        // (X + u) + du in the plane, X + (u + du) in a solid: the sums each has
        // always made, so that the end geometry keeps its last bits.
        self.x.extend(coords.iter().enumerate().flat_map(|(n, c)| {
            (0..dim).map(move |i| {
                let d = dim * n + i;
                if dim == 2 {
                    c[i] + u[d] + du[d]
                } else {
                    c[i] + (u[d] + du[d])
                }
            })
        }));
        super::detect::detect(
            &self.model.contacts,
            Positions::new(&self.x, dim),
            &self.rigid,
            None,
            &mut self.cands,
        );
    }

    /// Writes the contact state at the end of the step (`u1` the new displacements):
    /// gaps, the mean contact force of each impact over the step (`p/h`), pressures.
    pub fn finish(&mut self, h: f64, out: &mut ContactState) {
        // The candidates of the last projection sweep are those of the step's end.
        let n_nodes = self.model.mesh.n_nodes();
        out.pairs.clear();
        out.pairs
            .resize(self.model.contacts.len(), PairRecord::default());
        out.gap.clear();
        out.gap.resize(n_nodes, f64::NAN);
        out.pressure.clear();
        out.pressure.resize(n_nodes, 0.0);
        for c in &self.cands {
            let rec = &mut out.pairs[c.pair];
            rec.penetration = rec.penetration.max(-c.gap);
            let g = &mut out.gap[c.slave];
            *g = if g.is_nan() { c.gap } else { g.min(c.gap) };
        }
        for ((rec, t), a) in out
            .pairs
            .iter_mut()
            .zip(&self.tangential)
            .zip(&self.magnitude)
        {
            rec.tangential_force = t / h;
            rec.tangential_magnitude = a / h;
        }
        out.active.clear();
        self.impulses.sort_unstable_by_key(|(k, _)| *k);
        let mut last = None;
        for &(key, p) in &self.impulses {
            let f = p / h;
            out.active.push((key, f));
            let rec = &mut out.pairs[key.slave.pair];
            rec.force += f;
            let slave = key.slave;
            if last.replace(slave) != Some(slave) {
                rec.active += 1;
            }
            if self.area[key.slave.node] > 0.0 {
                out.pressure[key.slave.node] += f / self.area[key.slave.node];
            }
        }
    }
}
