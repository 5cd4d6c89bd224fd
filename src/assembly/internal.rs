//! The Gauss-point loop: strains from displacements, material updates against the
//! committed history (trial states written, never committed here), internal forces
//! `f_int = Σ_e ∫ Bᵀ σ t dA`, the consistent tangent, and the step's stored energy
//! and dissipation summed with the quadrature weights. Parallel by element colours;
//! nothing is allocated per pass (element buffers live on the stack, trial states in
//! the stores).

use super::{Assembler, SharedValues};
use crate::energy::Dissipation;
use crate::fe::{
    element, kinematics_from, rule_shapes, stiffness_rule, ElementKind, Idealisation, Kinematics,
    PointKinematics, MAX_ELEMENT_DOFS,
};
use crate::halves::in_halves;
use crate::material::store::{Committed, Layout, StateStore};
use crate::material::{
    Material, PointFailure, PointResponse, PointStatus, StrainStep, MAX_DRIVERS as DRIVERS,
    MAX_STATE,
};
use crate::mesh::Mesh;
use crate::simd::Simd;

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
            let ns = mat.n_state(v);
            let mut s = StateStore::new(n, ns, v);
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
    /// Whether the points' tangents are read (`StrainStep::tangent`).
    tangent: bool,
    /// The material's elasticity matrix in the run's idealisation.
    c: [[f64; V]; V],
    /// The averaged drivers of the block's points (`nonlocal::DRIVERS` per point)
    /// when its material is nonlocal.
    drivers: Option<&'a [f64]>,
}

impl<'a, const V: usize> Ctx<'a, V> {
    /// The context of a block of `mat` in the idealisation `K`.
    fn new<const D: usize, K: Kinematics<D, V>>(
        mesh: &'a Mesh,
        mat: &'a Material,
        block: &crate::mesh::Block,
        dt: f64,
        predict: bool,
        at_rest: bool,
    ) -> Self {
        Ctx {
            drivers: None,
            frozen: false,
            tangent: true,
            mesh,
            mat,
            kind: block.elements.kind,
            section: block.section,
            dt,
            predict,
            at_rest,
            c: mat.elasticity::<V, K>(),
        }
    }

    /// The same context with histories frozen (`frozen`).
    fn frozen(mut self, frozen: bool) -> Self {
        self.frozen = frozen;
        self
    }

    /// The same context asking the points for their tangents or not.
    fn tangent(mut self, tangent: bool) -> Self {
        self.tangent = tangent;
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

/// Evaluates element `e` at displacements `u` in the idealisation `K` (a mesh of
/// dimension `D`, `V` Voigt components): calls `point(w, &resp, &kin, x, σ_pred)` for each of its
/// points, where `σ_pred` (when `cx.predict`) is the stress of the next step of the
/// same size at an unchanged strain, from the trial history: for constant-tangent
/// materials `f_int` of the next step is then `f_pred + K_t Δu` exactly. With
/// `trial`, the points' trial states are written.
#[inline(always)]
fn element_points<const D: usize, const V: usize, K: Kinematics<D, V>, F>(
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
    let (x, ue, nn) = super::gather::<D>(cx.mesh, nodes, u);
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
    let mut points = [PointKinematics::ZERO; 8];
    for (q, shape) in shapes.iter().enumerate() {
        points[q] = kinematics_from(cx.kind, &x[..nn], shape);
    }
    // Element size for crack-band regularisation.
    let length = K::band_length(&x[..nn], &points[..rule.len()], rule);
    let ns = cx.mat.n_state(V);
    let mut scratch = [0.0; MAX_STATE];
    for (q, &(_, wq)) in rule.iter().enumerate() {
        let g = e * rule.len() + q;
        let k = &points[q];
        let eps = K::strain(k, nn, &ue);
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
            tangent: cx.tangent,
        };
        let history_n = committed.history(g);
        let averaged = cx
            .drivers
            .map(|d| std::array::from_fn(|k| d[DRIVERS * g + k]));
        let mut pred = [0.0; V];
        let resp = match trial {
            Some(t) => {
                // SAFETY: point g belongs to element e only; the slots are disjoint
                // parts of the trial buffer (see `Layout`).
                let hist = unsafe { t.base.slice(t.layout.history() + g * ns, ns) };
                let r = if cx.frozen {
                    cx.mat.update_frozen::<V, K>(&cx.c, &step, history_n, hist)
                } else {
                    cx.mat
                        .update_driven::<V, K>(&cx.c, &step, averaged, history_n, hist)
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
                        .predicted_stress_with::<V, K>(&cx.c, &eps, hist, cx.dt);
                }
                r
            }
            None => {
                cx.mat
                    .update_driven::<V, K>(&cx.c, &step, averaged, history_n, &mut scratch[..ns])
            }
        };
        point(wq * k.det_j * cx.section, &resp, Some(k), &x[..nn], pred);
    }
}

/// One colour's leaf of the Gauss-point pass over a block: everything an element's
/// evaluation reads and where it writes.
struct ElementLeaf<'a, const D: usize, const V: usize, K> {
    assembler: &'a Assembler,
    block: &'a crate::mesh::Block,
    bi: usize,
    cx: &'a Ctx<'a, V>,
    committed: Committed<'a>,
    trial: TrialOut,
    u: &'a [f64],
    f: Shared,
    f_pred: Option<Shared>,
    /// The tangent's values when this block assembles into them.
    k: Option<SharedValues>,
    /// The tangent is a base plus each element's `Σ w Bᵀ(D − C)B`.
    by_delta: bool,
    /// Points per element.
    points: usize,
    _space: std::marker::PhantomData<K>,
}

impl<const D: usize, const V: usize, K: Kinematics<D, V>> ElementLeaf<'_, D, V, K> {
    /// [`ElementLeaf::elements`] compiled for the instruction set `simd` names.
    fn run(&self, simd: Simd, chunk: &[usize]) -> PointTotals {
        match simd {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `Simd::detected` names AVX2 only where the CPU has it.
            Simd::Avx2 => unsafe { self.elements_avx2(chunk) },
            _ => self.elements(chunk),
        }
    }

    /// [`ElementLeaf::elements`] with AVX2 (wider registers for the same operations:
    /// no fused multiply-add is written, and Rust never contracts one, so the
    /// results are those of the baseline build bit for bit).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn elements_avx2(&self, chunk: &[usize]) -> PointTotals {
        self.elements(chunk)
    }

    /// Evaluates the elements `chunk` of the colour: their points' updates, forces,
    /// and tangents when asked; returns the totals of their points.
    #[inline(always)]
    fn elements(&self, chunk: &[usize]) -> PointTotals {
        let mut acc = PointTotals::default();
        let mut ke = [0.0; MAX_ELEMENT_DOFS * MAX_ELEMENT_DOFS];
        for &e in chunk {
            let nodes = self.block.elements.element(e);
            let mut fe = [0.0; MAX_ELEMENT_DOFS];
            let mut fe_pred = [0.0; MAX_ELEMENT_DOFS];
            let nd = D * nodes.len();
            if self.k.is_some() {
                ke[..nd * nd].fill(0.0);
            }
            let mut changed = !self.by_delta;
            let mut q = 0;
            element_points::<D, V, K, _>(
                self.cx,
                self.committed,
                nodes,
                self.u,
                e,
                Some(self.trial),
                |w, r, k, x, sp| {
                    acc.psi += w * r.psi;
                    acc.dissipation += r.dissipation.scaled(w);
                    if r.status != PointStatus::Ok && acc.failure.is_none() {
                        acc.failure = Some(PointFailure {
                            block: self.bi,
                            element: e,
                            point: e * self.points + q,
                        });
                    }
                    q += 1;
                    element::add_point_force::<D, V, K>(k, x, nodes.len(), w, &r.sigma, &mut fe);
                    if self.cx.predict {
                        element::add_point_force::<D, V, K>(
                            k,
                            x,
                            nodes.len(),
                            w,
                            &sp,
                            &mut fe_pred,
                        );
                    }
                    if self.k.is_some() {
                        if !self.by_delta {
                            element::add_point_tangent::<D, V, K>(
                                k,
                                x,
                                nodes.len(),
                                w,
                                &r.tangent,
                                &mut ke,
                            );
                        } else if r.tangent != self.cx.c {
                            let mut d = r.tangent;
                            for (di, ci) in d.iter_mut().zip(&self.cx.c) {
                                for (a, b) in di.iter_mut().zip(ci) {
                                    *a -= b;
                                }
                            }
                            element::add_point_tangent::<D, V, K>(
                                k,
                                x,
                                nodes.len(),
                                w,
                                &d,
                                &mut ke,
                            );
                            changed = true;
                        }
                    }
                },
            );
            if let Some(kp) = self.k.filter(|_| changed) {
                self.assembler.scatter(nodes, &ke[..nd * nd], kp);
            }
            for (a, &n) in nodes.iter().enumerate() {
                // SAFETY: no two elements of this colour share node n.
                let fn_ = unsafe { self.f.slice(D * n, D) };
                for i in 0..D {
                    fn_[i] += fe[D * a + i];
                }
                if let Some(pp) = self.f_pred {
                    // SAFETY: as above, for the predicted force.
                    let pn = unsafe { pp.slice(D * n, D) };
                    for i in 0..D {
                        pn[i] += fe_pred[D * a + i];
                    }
                }
            }
        }
        acc
    }
}

/// Writes a Voigt vector (element by element: no call to `memcpy` on the hot path).
#[inline(always)]
#[allow(clippy::manual_memcpy)]
fn write_v<const V: usize>(out: &mut [f64], v: &[f64; V]) {
    for i in 0..V {
        out[i] = v[i];
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
        idealisation: Idealisation,
        pass: PointPass,
        stores: &mut [StateStore],
        f: &mut [f64],
        f_pred: Option<&mut [f64]>,
        tangent: Option<&mut [f64]>,
        tangent_base: Option<&[f64]>,
    ) -> PointTotals {
        crate::dispatch_kinematics!(idealisation, <D, V, K> => self.internal_force_k::<D, V, K>(
            mesh,
            materials,
            pass,
            stores,
            f,
            f_pred,
            tangent,
            tangent_base,
        ))
    }

    /// [`Assembler::internal_force`] in the idealisation `K`.
    #[allow(clippy::too_many_arguments)]
    fn internal_force_k<const D: usize, const V: usize, K: Kinematics<D, V>>(
        &self,
        mesh: &Mesh,
        materials: &[Material],
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
        let nonlocal =
            (!pass.frozen).then(|| self.nonlocal_at_k::<D, V, K>(mesh, materials, u, stores));
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
            let ng = points_per_element(block.elements.kind);
            // With a base, a constant-tangent block adds nothing to it.
            let block_tangent =
                kp.is_some() && !(by_delta && materials[block.material].has_constant_tangent());
            let cx = Ctx::<V>::new::<D, K>(
                mesh,
                &materials[block.material],
                block,
                pass.dt,
                predict,
                pass.at_rest,
            )
            .frozen(pass.frozen)
            .tangent(block_tangent)
            .with_drivers(
                nonlocal
                    .as_ref()
                    .and_then(|g| g.as_ref())
                    .and_then(|n| n.block(mesh, bi)),
            );
            let run = ElementLeaf::<D, V, K> {
                assembler: self,
                block,
                bi,
                cx: &cx,
                committed,
                trial,
                u,
                f: fp,
                f_pred: pp,
                k: kp.filter(|_| block_tangent),
                by_delta,
                points: ng,
                _space: std::marker::PhantomData,
            };
            let simd = self.simd();
            for colour in &self.colours[bi] {
                // In halves of a fixed tree (`crate::halves`): the same totals in
                // every run.
                let leaf = |chunk: &[usize]| run.run(simd, chunk);
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
        idealisation: Idealisation,
        u: &[f64],
        dt: f64,
        stores: &[StateStore],
    ) -> Vec<f64> {
        crate::dispatch_kinematics!(idealisation, <D, V, K> =>
            self.tangent_k::<D, V, K>(mesh, materials, u, dt, stores))
    }

    /// [`Assembler::tangent`] in the idealisation `K`.
    fn tangent_k<const D: usize, const V: usize, K: Kinematics<D, V>>(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        u: &[f64],
        dt: f64,
        stores: &[StateStore],
    ) -> Vec<f64> {
        let nonlocal = self.nonlocal_at_k::<D, V, K>(mesh, materials, u, stores);
        self.assemble(mesh, |bi, e, _x, ke| {
            let block = &mesh.blocks[bi];
            let cx =
                Ctx::<V>::new::<D, K>(mesh, &materials[block.material], block, dt, false, false)
                    .with_drivers(nonlocal.as_ref().and_then(|n| n.block(mesh, bi)));
            let nodes = block.elements.element(e);
            let nd = D * nodes.len();
            ke[..nd * nd].fill(0.0);
            element_points::<D, V, K, _>(
                &cx,
                stores[bi].committed(),
                nodes,
                u,
                e,
                None,
                |w, r, k, x, _| {
                    element::add_point_tangent::<D, V, K>(k, x, nodes.len(), w, &r.tangent, ke)
                },
            );
        })
    }
}
