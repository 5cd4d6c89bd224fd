//! The Gauss-point loop: strains from displacements, material updates against the
//! committed history (trial states written, never committed here), internal forces
//! `f_int = Σ_e ∫ Bᵀ σ t dA`, the consistent tangent, and the step's stored energy
//! and dissipation summed with the quadrature weights. Parallel by element colours;
//! nothing is allocated per pass (element buffers live on the stack, trial states in
//! the stores).

use super::nonlocal::DRIVERS;
use super::{Assembler, SharedValues};
use crate::energy::Dissipation;
use crate::fe::{
    element, kinematics_from, rule_shapes, stiffness_rule, strain, strain_solid, ElementKind,
    Plane, PointKinematics, MAX_ELEMENT_DOFS, MAX_NODES,
};
use crate::halves::in_halves;
use crate::material::store::{Committed, Layout, StateStore};
use crate::material::{Material, PointResponse, PointStatus, StrainStep, MAX_STATE};
use crate::mesh::Mesh;

/// A material point whose update failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PointFailure {
    /// Element block.
    pub block: usize,
    /// Element within the block.
    pub element: usize,
    /// Point within the block.
    pub point: usize,
}

/// Integrated point quantities of one evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointTotals {
    /// Stored energy `Σ ψ w`.
    pub psi: f64,
    /// Dissipation increments `Σ ΔD w` by mechanism.
    pub dissipation: Dissipation,
    /// The first point (lowest block, element) whose update failed, if any.
    pub failure: Option<PointFailure>,
}

impl PointTotals {
    fn merge(mut self, o: PointTotals) -> PointTotals {
        self.psi += o.psi;
        self.dissipation += o.dissipation;
        self.failure = match (self.failure, o.failure) {
            (Some(a), Some(b)) => Some(if (b.block, b.element) < (a.block, a.element) {
                b
            } else {
                a
            }),
            (a, b) => a.or(b),
        };
        self
    }
}

/// Elements per leaf of the Gauss-point pass over one colour.
const ELEMENT_LEAF: usize = 128;

/// Number of material points of an element kind (bars: one).
pub fn points_per_element(kind: ElementKind) -> usize {
    kind.points()
}

/// The Voigt size of a mesh's points: 3 in the plane, 6 in a solid.
pub fn voigt_of(mesh: &Mesh) -> usize {
    if mesh.dim == 3 {
        6
    } else {
        3
    }
}

/// One store per block, sized for its points and its material's history, in the
/// material's initial state.
pub fn new_stores(mesh: &Mesh, materials: &[Material]) -> Vec<StateStore> {
    let v = voigt_of(mesh);
    mesh.blocks
        .iter()
        .map(|b| {
            let mat = &materials[b.material];
            let n = b.elements.len() * points_per_element(b.elements.kind);
            let ns = mat.n_state_for(v);
            let mut s = StateStore::with_voigt(n, ns, v);
            if ns > 0 {
                for g in 0..n {
                    mat.init_state(s.history_mut(g));
                }
            }
            s.reset_trial();
            s
        })
        .collect()
}

#[derive(Clone, Copy)]
struct Shared(*mut f64);
// SAFETY: each element writes only its own points' slots in the trial buffer, and the
// force entries of its nodes, which no other element of the running colour holds.
unsafe impl Send for Shared {}
unsafe impl Sync for Shared {}

impl Shared {
    /// # Safety
    /// `start..start+len` must be in bounds and written by one thread only.
    unsafe fn slice<'a>(self, start: usize, len: usize) -> &'a mut [f64] {
        std::slice::from_raw_parts_mut(self.0.add(start), len)
    }
}

/// What one element evaluation needs besides its index (`V` the Voigt size).
struct Ctx<'a, const V: usize> {
    mesh: &'a Mesh,
    mat: &'a Material,
    plane: Plane,
    kind: ElementKind,
    section: f64,
    dt: f64,
    /// Also evaluate the stress of the next step at an unchanged strain.
    predict: bool,
    /// Evaluate the state at rest at `u` (the initial state): `ε_n = ε`, no
    /// history evolution, no dissipation.
    at_rest: bool,
    /// Keep every history at its committed value (`Material::update_frozen`).
    frozen: bool,
    /// The material's elasticity matrix in this idealisation.
    c: [[f64; V]; V],
    /// The averaged drivers of the block's points (`nonlocal::DRIVERS` per point)
    /// when its material is nonlocal.
    drivers: Option<&'a [f64]>,
}

impl<'a, const V: usize> Ctx<'a, V> {
    fn new(
        mesh: &'a Mesh,
        mat: &'a Material,
        plane: Plane,
        block: &crate::mesh::Block,
        dt: f64,
        predict: bool,
        at_rest: bool,
    ) -> Self {
        Ctx {
            drivers: None,
            frozen: false,
            mesh,
            mat,
            plane,
            kind: block.elements.kind,
            section: block.section,
            dt,
            predict,
            at_rest,
            c: mat.c_voigt(plane),
        }
    }

    /// The same context with histories frozen (`frozen`).
    fn frozen(mut self, frozen: bool) -> Self {
        self.frozen = frozen;
        self
    }

    /// The same context reading the averaged drivers `d` of a nonlocal block.
    fn with_drivers(mut self, d: Option<&'a [f64]>) -> Self {
        self.drivers = d;
        self
    }
}

/// Where a point writes its trial state, when it does.
#[derive(Clone, Copy)]
struct TrialOut {
    base: Shared,
    layout: Layout,
}

/// Evaluates element `e` at displacements `u` in a mesh of dimension `D` with `V`
/// Voigt components: calls `point(w, &resp, &kin, x, σ_pred)` for each of its
/// points, where `σ_pred` (when `cx.predict`) is the stress of the next step of the
/// same size at an unchanged strain, from the trial history: for constant-tangent
/// materials `f_int` of the next step is then `f_pred + K_t Δu` exactly. With
/// `trial`, the points' trial states are written.
fn element_points<const D: usize, const V: usize, F>(
    cx: &Ctx<V>,
    committed: Committed,
    nodes: &[usize],
    u: &[f64],
    e: usize,
    trial: Option<TrialOut>,
    mut point: F,
) where
    F: FnMut(f64, &PointResponse<V>, Option<&PointKinematics>, &[[f64; 3]], [f64; V]),
{
    let (x, ue, nn) = gather::<D>(cx.mesh, nodes, u);
    if cx.kind == ElementKind::Bar2 {
        let g = e;
        let eps = element::bar_strain(&x[..2], D, &ue[..2 * D]);
        let eps_n = if cx.at_rest {
            eps
        } else {
            committed.eps::<V>(g)[0]
        };
        let de = eps - eps_n;
        let (_, l) = element::bar_axis(&x[..2]);
        let first = |v: f64| -> [f64; V] { std::array::from_fn(|i| if i == 0 { v } else { 0.0 }) };
        let resp = PointResponse {
            sigma: first(cx.mat.e * eps),
            tangent: std::array::from_fn(|i| if i == 0 { first(cx.mat.e) } else { [0.0; V] }),
            psi: 0.5 * cx.mat.e * eps * eps,
            dissipation: Dissipation {
                numerical: 0.5 * cx.mat.e * de * de,
                ..Default::default()
            },
            status: PointStatus::Ok,
        };
        if let Some(t) = trial {
            // SAFETY: point g belongs to element e only.
            unsafe {
                write_v(t.base.slice(t.layout.eps() + V * g, V), &first(eps));
                write_v(t.base.slice(t.layout.sigma() + V * g, V), &resp.sigma);
                t.base.slice(t.layout.dissipated() + g, 1)[0] = committed.dissipated(g);
            }
        }
        point(cx.section * l, &resp, None, &x[..2], resp.sigma);
        return;
    }
    let rule = stiffness_rule(cx.kind);
    let shapes = rule_shapes(cx.kind);
    // Element size for crack-band regularisation: the square root of its area (the
    // cube root of its volume, `Σ w det J` over the points, whose kinematics a
    // solid element evaluates first and keeps).
    let mut solid_points = [PointKinematics::ZERO; 8];
    let length = if D == 3 {
        let mut volume = 0.0;
        for (q, &(_, wq)) in rule.iter().enumerate() {
            solid_points[q] = kinematics_from(cx.kind, &x[..nn], &shapes[q]);
            volume += wq * solid_points[q].det_j;
        }
        volume.abs().cbrt()
    } else {
        crate::mesh::polygon_area(&x[..nn]).abs().sqrt()
    };
    let ns = cx.mat.n_state_for(V);
    let mut scratch = [0.0; MAX_STATE];
    for (q, &(_, wq)) in rule.iter().enumerate() {
        let g = e * rule.len() + q;
        let plane_point;
        let k = if D == 3 {
            &solid_points[q]
        } else {
            plane_point = kinematics_from(cx.kind, &x[..nn], &shapes[q]);
            &plane_point
        };
        let eps = strain_v::<V>(k, nn, &ue);
        let (eps_n, dt) = if cx.at_rest {
            // A vanishing step: rates are zero and history does not evolve.
            (eps, f64::MIN_POSITIVE)
        } else {
            (committed.eps::<V>(g), cx.dt)
        };
        let step = StrainStep {
            eps_n,
            eps,
            dt,
            length,
        };
        let history_n = committed.history(g);
        let averaged = cx.drivers.map(|d| [d[DRIVERS * g], d[DRIVERS * g + 1]]);
        let mut pred = [0.0; V];
        let resp = match trial {
            Some(t) => {
                // SAFETY: point g belongs to element e only; the slots are disjoint
                // parts of the trial buffer (see `Layout`).
                let hist = unsafe { t.base.slice(t.layout.history() + g * ns, ns) };
                let r = if cx.frozen {
                    cx.mat
                        .update_frozen(&cx.c, cx.plane, &step, history_n, hist)
                } else {
                    cx.mat
                        .update_driven(&cx.c, cx.plane, &step, averaged, history_n, hist)
                };
                unsafe {
                    write_v(t.base.slice(t.layout.eps() + V * g, V), &eps);
                    write_v(t.base.slice(t.layout.sigma() + V * g, V), &r.sigma);
                    t.base.slice(t.layout.dissipated() + g, 1)[0] =
                        committed.dissipated(g) + r.dissipation.material();
                }
                if cx.predict {
                    pred = cx
                        .mat
                        .predicted_stress_with(&cx.c, cx.plane, &eps, hist, cx.dt);
                }
                r
            }
            None => cx.mat.update_driven(
                &cx.c,
                cx.plane,
                &step,
                averaged,
                history_n,
                &mut scratch[..ns],
            ),
        };
        point(wq * k.det_j * cx.section, &resp, Some(k), &x[..nn], pred);
    }
}

/// The strain of `V` Voigt components at a point (`V = 3`: the plane's, `6`: a
/// solid's) from the element displacements `ue`.
#[inline(always)]
pub(crate) fn strain_v<const V: usize>(k: &PointKinematics, nn: usize, ue: &[f64]) -> [f64; V] {
    if V == 6 {
        let e = strain_solid(k, nn, ue);
        std::array::from_fn(|i| e[i])
    } else {
        let e = strain(k, nn, ue);
        std::array::from_fn(|i| e[i])
    }
}

/// The coordinates and displacements (`D` per node) of an element's nodes, and
/// their number.
#[inline(always)]
pub(crate) fn gather<const D: usize>(
    mesh: &Mesh,
    nodes: &[usize],
    u: &[f64],
) -> ([[f64; 3]; MAX_NODES], [f64; MAX_ELEMENT_DOFS], usize) {
    (
        super::element_coords(mesh, nodes),
        super::element_values(u, nodes, D),
        nodes.len(),
    )
}

/// Writes a Voigt vector (element by element: no call to `memcpy` on the hot path).
#[inline(always)]
#[allow(clippy::manual_memcpy)]
fn write_v<const V: usize>(out: &mut [f64], v: &[f64; V]) {
    for i in 0..V {
        out[i] = v[i];
    }
}

/// Adds one point's `w Bᵀ D B` (continuum) or sets the bar stiffness `E A / L`
/// (bars have one point) in the element matrix `ke` (mesh dimension `dim`).
#[inline]
fn add_point_tangent<const V: usize>(
    k: Option<&PointKinematics>,
    x: &[[f64; 3]],
    nn: usize,
    dim: usize,
    w: f64,
    d: &[[f64; V]; V],
    ke: &mut [f64],
) {
    match k {
        Some(k) if V == 6 => {
            let d6: [[f64; 6]; 6] = std::array::from_fn(|i| std::array::from_fn(|j| d[i][j]));
            element::add_btdb_solid(k, nn, &d6, w, ke)
        }
        Some(k) => {
            let d3: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| d[i][j]));
            element::add_btdb(k, nn, &d3, w, ke)
        }
        None => element::bar_stiffness(x, dim, d[0][0] * w / element::bar_axis(x).1, ke),
    }
}

/// Adds `w Bᵀ σ` (continuum) or the axial force `σ w / L` along the bar to `fe`, in
/// a mesh of dimension `D`.
#[inline]
fn add_bt_sigma<const D: usize, const V: usize>(
    k: Option<&PointKinematics>,
    x: &[[f64; 3]],
    nn: usize,
    w: f64,
    sigma: &[f64; V],
    fe: &mut [f64; MAX_ELEMENT_DOFS],
) {
    match k {
        Some(k) if D == 3 => {
            for a in 0..nn {
                let [dx, dy, dz] = k.dndx[a];
                fe[3 * a] += w * (dx * sigma[0] + dy * sigma[2] + dz * sigma[5]);
                fe[3 * a + 1] += w * (dy * sigma[1] + dx * sigma[2] + dz * sigma[4]);
                fe[3 * a + 2] += w * (dz * sigma[3] + dy * sigma[4] + dx * sigma[5]);
            }
        }
        Some(k) => {
            for a in 0..nn {
                let (dx, dy) = (k.dndx[a][0], k.dndx[a][1]);
                fe[2 * a] += w * (dx * sigma[0] + dy * sigma[2]);
                fe[2 * a + 1] += w * (dy * sigma[1] + dx * sigma[2]);
            }
        }
        None => {
            let (ax, l) = element::bar_axis(x);
            let n = sigma[0] * w / l;
            for i in 0..D {
                fe[i] -= n * ax[i];
                fe[D + i] += n * ax[i];
            }
        }
    }
}

/// What a pass of [`Assembler::internal_force`] evaluates.
#[derive(Clone, Copy, Debug)]
pub struct PointPass<'a> {
    /// Displacements.
    pub u: &'a [f64],
    /// Step size.
    pub dt: f64,
    /// Evaluate the state at rest at `u` (the initial state: history not evolved).
    pub at_rest: bool,
    /// Keep every history at its committed value where the material has such a
    /// form (`Material::update_frozen`): the first iterate of an implicit step whose
    /// prescribed displacements jump, evaluated with the last step's damage (the
    /// paper's first estimate `D(u_{s−1})`).
    pub frozen: bool,
}

impl Assembler {
    /// Internal forces at `pass.u` into `f` (overwritten), trial states into the
    /// stores, and the integrated stored energy and dissipation of the step. With
    /// `f_pred`, also the internal force of the next step at unchanged `u` (see
    /// `element_points`), in the same pass. With `tangent`, the consistent tangent of
    /// the same updates is assembled into it in the same pass (what
    /// [`Assembler::tangent`] would give at `u`). A failed point update is reported in
    /// the totals, not hidden in the forces.
    ///
    /// With `tangent_base` (the tangent at rest: every point elastic, assembled by
    /// [`Assembler::tangent`] from fresh stores at the same step size), the tangent
    /// is that base plus, element by element, `Σ w Bᵀ(D − C)B` over the points whose
    /// tangent `D` is not their elastic `C`; elements whose points all stay elastic,
    /// and blocks of constant-tangent materials, cost nothing. While every point is
    /// elastic the tangent is the base bit for bit, so a kept factor of it stays.
    #[allow(clippy::too_many_arguments)]
    pub fn internal_force(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        plane: Plane,
        pass: PointPass,
        stores: &mut [StateStore],
        f: &mut [f64],
        f_pred: Option<&mut [f64]>,
        tangent: Option<&mut [f64]>,
        tangent_base: Option<&[f64]>,
    ) -> PointTotals {
        if mesh.dim == 3 {
            self.internal_force_d::<3, 6>(
                mesh,
                materials,
                plane,
                pass,
                stores,
                f,
                f_pred,
                tangent,
                tangent_base,
            )
        } else {
            self.internal_force_d::<2, 3>(
                mesh,
                materials,
                plane,
                pass,
                stores,
                f,
                f_pred,
                tangent,
                tangent_base,
            )
        }
    }

    /// [`Assembler::internal_force`] in dimension `D` with `V` Voigt components.
    #[allow(clippy::too_many_arguments)]
    fn internal_force_d<const D: usize, const V: usize>(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        plane: Plane,
        pass: PointPass,
        stores: &mut [StateStore],
        f: &mut [f64],
        mut f_pred: Option<&mut [f64]>,
        mut tangent: Option<&mut [f64]>,
        tangent_base: Option<&[f64]>,
    ) -> PointTotals {
        let u = pass.u;
        // Nonlocal materials: their drivers averaged at `u` first (one more pass; a
        // frozen pass reads none).
        let nonlocal = (!pass.frozen).then(|| self.nonlocal_at(mesh, materials, plane, u, stores));
        f.fill(0.0);
        let kp = tangent.as_mut().map(|k| {
            match tangent_base {
                Some(base) => k.copy_from_slice(base),
                None => k.fill(0.0),
            }
            SharedValues(k.as_mut_ptr())
        });
        let by_delta = tangent_base.is_some();
        let fp = Shared(f.as_mut_ptr());
        let predict = f_pred.is_some();
        let pp = f_pred.as_mut().map(|v| {
            v.fill(0.0);
            Shared(v.as_mut_ptr())
        });
        let mut totals = PointTotals::default();
        for (bi, block) in mesh.blocks.iter().enumerate() {
            let (committed, trial_buf) = stores[bi].split();
            let layout = committed.layout();
            let trial = TrialOut {
                base: Shared(trial_buf.as_mut_ptr()),
                layout,
            };
            let cx = Ctx::<V>::new(
                mesh,
                &materials[block.material],
                plane,
                block,
                pass.dt,
                predict,
                pass.at_rest,
            )
            .frozen(pass.frozen)
            .with_drivers(
                nonlocal
                    .as_ref()
                    .and_then(|g| g.as_ref())
                    .and_then(|n| n.block(mesh, bi)),
            );
            let ng = points_per_element(block.elements.kind);
            // With a base, a constant-tangent block adds nothing to it.
            let block_tangent =
                kp.is_some() && !(by_delta && materials[block.material].has_constant_tangent());
            let c_el = cx.c;
            for colour in &self.colours[bi] {
                // In halves of a fixed tree (`crate::halves`): the same totals in
                // every run.
                let leaf = |chunk: &[usize]| {
                    let mut acc = PointTotals::default();
                    let mut ke = [0.0; MAX_ELEMENT_DOFS * MAX_ELEMENT_DOFS];
                    for &e in chunk {
                        let nodes = block.elements.element(e);
                        let mut fe = [0.0; MAX_ELEMENT_DOFS];
                        let mut fe_pred = [0.0; MAX_ELEMENT_DOFS];
                        let nd = D * nodes.len();
                        if block_tangent {
                            ke[..nd * nd].fill(0.0);
                        }
                        let mut changed = !by_delta;
                        let mut q = 0;
                        element_points::<D, V, _>(
                            &cx,
                            committed,
                            nodes,
                            u,
                            e,
                            Some(trial),
                            |w, r, k, x, sp| {
                                acc.psi += w * r.psi;
                                acc.dissipation += r.dissipation.scaled(w);
                                if r.status != PointStatus::Ok && acc.failure.is_none() {
                                    acc.failure = Some(PointFailure {
                                        block: bi,
                                        element: e,
                                        point: e * ng + q,
                                    });
                                }
                                q += 1;
                                add_bt_sigma::<D, V>(k, x, nodes.len(), w, &r.sigma, &mut fe);
                                if predict {
                                    add_bt_sigma::<D, V>(k, x, nodes.len(), w, &sp, &mut fe_pred);
                                }
                                if block_tangent {
                                    if !by_delta {
                                        add_point_tangent(
                                            k,
                                            x,
                                            nodes.len(),
                                            D,
                                            w,
                                            &r.tangent,
                                            &mut ke,
                                        );
                                    } else if r.tangent != c_el {
                                        let mut d = r.tangent;
                                        for (di, ci) in d.iter_mut().zip(&c_el) {
                                            for (a, b) in di.iter_mut().zip(ci) {
                                                *a -= b;
                                            }
                                        }
                                        add_point_tangent(k, x, nodes.len(), D, w, &d, &mut ke);
                                        changed = true;
                                    }
                                }
                            },
                        );
                        if let Some(kp) = kp.filter(|_| block_tangent && changed) {
                            self.scatter(nodes, &ke[..nd * nd], kp);
                        }
                        for (a, &n) in nodes.iter().enumerate() {
                            // SAFETY: no two elements of this colour share node n.
                            let fn_ = unsafe { fp.slice(D * n, D) };
                            for i in 0..D {
                                fn_[i] += fe[D * a + i];
                            }
                            if let Some(pp) = pp {
                                // SAFETY: as above, for the predicted force.
                                let pn = unsafe { pp.slice(D * n, D) };
                                for i in 0..D {
                                    pn[i] += fe_pred[D * a + i];
                                }
                            }
                        }
                    }
                    acc
                };
                let (n, split) = (colour.len(), <[usize]>::split_at);
                let part = in_halves(
                    &colour[..],
                    n,
                    ELEMENT_LEAF,
                    &split,
                    &leaf,
                    &PointTotals::merge,
                );
                totals = totals.merge(part);
            }
        }
        totals
    }

    /// Consistent tangent stiffness `Σ_e ∫ Bᵀ (∂σ/∂ε) B t dA` at `u` from the
    /// committed states (material updates are pure, so nothing is written).
    pub fn tangent(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        plane: Plane,
        u: &[f64],
        dt: f64,
        stores: &[StateStore],
    ) -> Vec<f64> {
        if mesh.dim == 3 {
            self.tangent_d::<3, 6>(mesh, materials, plane, u, dt, stores)
        } else {
            self.tangent_d::<2, 3>(mesh, materials, plane, u, dt, stores)
        }
    }

    /// [`Assembler::tangent`] in dimension `D` with `V` Voigt components.
    fn tangent_d<const D: usize, const V: usize>(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        plane: Plane,
        u: &[f64],
        dt: f64,
        stores: &[StateStore],
    ) -> Vec<f64> {
        let nonlocal = self.nonlocal_at(mesh, materials, plane, u, stores);
        self.assemble(mesh, |bi, e, _x, ke| {
            let block = &mesh.blocks[bi];
            let cx = Ctx::<V>::new(
                mesh,
                &materials[block.material],
                plane,
                block,
                dt,
                false,
                false,
            )
            .with_drivers(nonlocal.as_ref().and_then(|n| n.block(mesh, bi)));
            let nodes = block.elements.element(e);
            let nd = D * nodes.len();
            ke[..nd * nd].fill(0.0);
            element_points::<D, V, _>(
                &cx,
                stores[bi].committed(),
                nodes,
                u,
                e,
                None,
                |w, r, k, x, _| add_point_tangent(k, x, nodes.len(), D, w, &r.tangent, ke),
            );
        })
    }
}
