//! Linear viscoelasticity on nodal fields: a step of matrix-vector products, no pass
//! over the Gauss points.
//!
//! Every constant-tangent model is linear in the strain history with a viscosity
//! that is a constant matrix, so its global force follows from global matrices and a
//! few nodal vectors (theory/viscoelasticity.md, "Nodal fields"). The materials fall
//! into groups, each with its stiffness `K_g = ∫ Bᵀ C B` over its elements:
//! - elastic (and bars, which are elastic in every model): `f = K_g u`;
//! - Kelvin-Voigt `σ = C ε + η ε̇`: `f = K_g u + V_g Δu / h` with `V_g = α K_g`
//!   (`η = α C`) or `V_g = ∫ Bᵀ η B` (`η = β I`);
//! - standard linear solid (and Maxwell, `p = 0`): the dashpot strain is `B u_d` with
//!   the nodal field `u_d¹ = (u_d⁰ + k u¹)/(1 + k)`, `k = h α/β` (eq. 10's recursion,
//!   linear in `u`, so `ε_d = B u_d` at every point for all time since both start at
//!   zero), and `f = p K_g u + α K_g (u − u_d)`.
//!
//! The stored energy and the dissipation of a step are quadratic forms of these
//! fields: with `y = K_g u` and `y_d = K_g u_d` kept, each is a dot product
//! (`y_d¹ = (y_d⁰ + k y¹)/(1 + k)` needs no product of its own). The Gauss-point
//! state is materialised from the fields for output (`NodalLaws::materialise`).

use rayon::prelude::*;

use crate::assembly::internal::{new_stores, points_per_element};
use crate::assembly::{element_coords, element_values, Assembler, Mass, Pattern};
use crate::energy::Dissipation;
use crate::fe::{element, kinematics, stiffness_rule, ElementKind, Kinematics};
use crate::halves::{add, in_halves, split_slices, Slices, VECTOR_LEAF};
use crate::material::store::StateStore;
use crate::material::{mul3, Law, Sls, Viscosity};
use crate::model::Model;

/// Dofs per parallel chunk of the field passes.
const CHUNK: usize = 8192;

/// How one group of elements responds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum GroupLaw {
    /// `σ = C ε` (bars and elastic materials).
    Elastic,
    /// `σ = C ε + α C ε̇`.
    ProportionalVoigt { alpha: f64 },
    /// `σ = C ε + η ε̇` with the group's viscous matrix `V_g`.
    MatrixVoigt,
    /// `σ = p C ε + α C (ε − ε_d)`, dashpot `β C`.
    Sls { alpha: f64, beta: f64, p: f64 },
}

/// One group: its law and matrices on the shared pattern.
struct Group {
    law: GroupLaw,
    /// The material of the group (`None`: the elastic group, which may hold several).
    material: Option<usize>,
    /// `K_g`; `None` when the group holds every element (then `K_g = K`).
    k: Option<Vec<f64>>,
    /// `V_g` of a Kelvin-Voigt group with `η = β I`.
    v: Vec<f64>,
}

/// The nodal-field representation of a model whose materials all have a constant
/// tangent.
pub(crate) struct NodalLaws {
    groups: Vec<Group>,
    /// Whether some group needs the last increment (Kelvin-Voigt stresses for
    /// output).
    keeps_increment: bool,
}

/// The fields of one group.
#[derive(Clone, Debug, Default)]
pub(crate) struct GroupFields {
    /// `K_g u`.
    ku: Vec<f64>,
    /// The dashpot displacement `u_d` (standard linear solid).
    ud: Vec<f64>,
    /// `K_g u_d` (standard linear solid).
    kud: Vec<f64>,
    /// `V_g u` (Kelvin-Voigt with its own viscous matrix).
    vu: Vec<f64>,
}

/// The nodal state of a run on nodal fields (empty otherwise).
#[derive(Clone, Debug, Default)]
pub struct NodalState {
    groups: Vec<GroupFields>,
    /// The last step's increment `Δu` and size, for the Kelvin-Voigt stress
    /// `C ε + η B Δu / h` of output (empty without Kelvin-Voigt groups).
    du: Vec<f64>,
    h: f64,
}

impl NodalState {
    /// Whether the state holds fields.
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }
}

/// The mass matrix and where `M Δu` goes, for [`NodalLaws::evaluate`] to form in
/// the same pass as the first stiffness product.
pub(crate) struct MassProduct<'a> {
    /// The mass.
    pub m: &'a Mass,
    /// `M Δu`.
    pub out: &'a mut [f64],
}

/// The energy terms of one evaluation.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct NodalTotals {
    /// Stored energy at `u`.
    pub psi: f64,
    /// Viscous and numerical dissipation of the step.
    pub dissipation: Dissipation,
}

impl NodalLaws {
    /// The groups of `model`, or `None` if one of its materials has no nodal-field
    /// form (damage, plasticity: their state is not a linear image of nodal
    /// fields).
    pub fn new(model: &Model, asm: &Assembler) -> Option<Self> {
        let mesh = &model.mesh;
        let law_of = |block: usize| -> Option<(GroupLaw, Option<usize>)> {
            let b = &mesh.blocks[block];
            let m = &model.materials[b.material];
            if b.elements.kind == ElementKind::Bar2 {
                return Some((GroupLaw::Elastic, None));
            }
            let law = match m.law {
                Law::Elastic => return Some((GroupLaw::Elastic, None)),
                Law::KelvinVoigt(Viscosity::Proportional(alpha)) => {
                    GroupLaw::ProportionalVoigt { alpha }
                }
                Law::KelvinVoigt(Viscosity::Identity(_)) => GroupLaw::MatrixVoigt,
                Law::Sls(Sls {
                    alpha,
                    beta,
                    parallel,
                }) => GroupLaw::Sls {
                    alpha,
                    beta,
                    p: if parallel { 1.0 } else { 0.0 },
                },
                Law::Mazars(_) | Law::RankineHill(_) | Law::Custom(_) => return None,
            };
            Some((law, Some(b.material)))
        };
        // One group per viscoelastic material, one for everything elastic.
        let mut keys: Vec<(GroupLaw, Option<usize>)> = Vec::new();
        let mut block_group = Vec::with_capacity(mesh.blocks.len());
        for bi in 0..mesh.blocks.len() {
            let key = law_of(bi)?;
            let g = match keys.iter().position(|k| k.1 == key.1) {
                Some(g) => g,
                None => {
                    keys.push(key);
                    keys.len() - 1
                }
            };
            block_group.push(g);
        }
        let single = keys.len() == 1;
        let groups = keys
            .iter()
            .enumerate()
            .map(|(g, &(law, material))| {
                let in_group = |bi: usize| block_group[bi] == g;
                let (k, v) = crate::dispatch_kinematics!(model.idealisation, <D, V, K> =>
                    group_matrices::<D, V, K>(model, asm, &in_group, law, single));
                Group {
                    law,
                    material,
                    k,
                    v,
                }
            })
            .collect::<Vec<_>>();
        let keeps_increment = groups.iter().any(|g| {
            matches!(
                g.law,
                GroupLaw::ProportionalVoigt { .. } | GroupLaw::MatrixVoigt
            )
        });
        Some(NodalLaws {
            groups,
            keeps_increment,
        })
    }

    fn stiffness<'a>(&'a self, g: &'a Group, k: &'a [f64]) -> &'a [f64] {
        g.k.as_deref().unwrap_or(k)
    }

    /// The state at rest at `u` (no dashpot strain), its internal force into `f` and
    /// its stored energy.
    pub fn initial(&self, p: &Pattern, k: &[f64], u: &[f64], f: &mut [f64]) -> (NodalState, f64) {
        let n = u.len();
        f.fill(0.0);
        let mut psi = 0.0;
        let groups = self
            .groups
            .iter()
            .map(|g| {
                let mut fields = GroupFields {
                    ku: vec![0.0; n],
                    ..Default::default()
                };
                p.matvec(self.stiffness(g, k), u, &mut fields.ku);
                let scale = match g.law {
                    GroupLaw::Sls {
                        alpha, p: parallel, ..
                    } => {
                        fields.ud = vec![0.0; n];
                        fields.kud = vec![0.0; n];
                        parallel + alpha
                    }
                    GroupLaw::MatrixVoigt => {
                        fields.vu = vec![0.0; n];
                        p.matvec(&g.v, u, &mut fields.vu);
                        1.0
                    }
                    _ => 1.0,
                };
                for (fi, y) in f.iter_mut().zip(&fields.ku) {
                    *fi += scale * y;
                }
                psi += 0.5 * scale * crate::time::dot(u, &fields.ku);
                fields
            })
            .collect();
        let state = NodalState {
            groups,
            du: if self.keeps_increment {
                vec![0.0; n]
            } else {
                Vec::new()
            },
            h: 1.0,
        };
        (state, psi)
    }

    /// The internal force of a step of size `h` at the start displacement `u_n`
    /// (`Δu = 0`): `f_int(u) = this + K_t (u − u_n)`.
    pub fn predicted_force(&self, h: f64, s: &NodalState, f: &mut [f64]) {
        for (gi, (g, fields)) in self.groups.iter().zip(&s.groups).enumerate() {
            let first = gi == 0;
            let (a, b) = match g.law {
                GroupLaw::Sls { alpha, beta, p } => {
                    let k = h * alpha / beta;
                    (p + alpha / (1.0 + k), -alpha / (1.0 + k))
                }
                _ => (1.0, 0.0),
            };
            let (ku, kud) = (&fields.ku, &fields.kud);
            f.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
                let lo = c * CHUNK;
                for (i, o) in out.iter_mut().enumerate() {
                    let mut x = a * ku[lo + i];
                    if b != 0.0 {
                        x += b * kud[lo + i];
                    }
                    *o = if first { x } else { *o + x };
                }
            });
        }
    }

    /// Evaluates the step `u_n → u` (`du = u − u_n`, size `h`) from the committed
    /// fields `s`: the trial fields into `trial`, the internal force into `f`, and
    /// the elastic force increment `K Δu` into `kdu` (stiffness-proportional
    /// damping reads it). Returns the stored energy at `u` and the step's dissipation.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &self,
        p: &Pattern,
        k: &[f64],
        h: f64,
        u: &[f64],
        du: &[f64],
        s: &NodalState,
        trial: &mut NodalState,
        f: &mut [f64],
        kdu: &mut [f64],
        mut mass: Option<MassProduct>,
    ) -> NodalTotals {
        let mut totals = NodalTotals::default();
        for (gi, (g, (old, new))) in self
            .groups
            .iter()
            .zip(s.groups.iter().zip(trial.groups.iter_mut()))
            .enumerate()
        {
            match mass.take() {
                // The first group's product and `M Δu` in one pass over the pattern.
                Some(MassProduct { m, out }) => {
                    m.with_product(p, self.stiffness(g, k), u, &mut new.ku, du, out)
                }
                None => p.matvec(self.stiffness(g, k), u, &mut new.ku),
            }
            if g.law == GroupLaw::MatrixVoigt {
                p.matvec(&g.v, u, &mut new.vu);
            }
            let pass = GroupPass {
                law: g.law,
                h,
                first: gi == 0,
                u,
                du,
                old,
            };
            let t = pass.run(new, f, kdu);
            totals.psi += t.psi;
            totals.dissipation += t.dissipation;
        }
        if self.keeps_increment {
            trial.du.copy_from_slice(du);
            trial.h = h;
        }
        totals
    }

    /// The Gauss-point stores of the state `(u, fields)`: strains, stresses and
    /// dashpot strains at every point, as the Gauss-point path would hold them. The
    /// cumulative dissipation density, a sum over every step, is not a function of
    /// the fields: it is NaN (the ledger holds the totals).
    pub fn materialise(&self, model: &Model, u: &[f64], s: &NodalState) -> Vec<StateStore> {
        crate::dispatch_kinematics!(model.idealisation, <D, V, K> => self.materialise_k::<D, V, K>(model, u, s))
    }

    /// [`NodalLaws::materialise`] in the idealisation `K`.
    fn materialise_k<const D: usize, const V: usize, K: Kinematics<D, V>>(
        &self,
        model: &Model,
        u: &[f64],
        s: &NodalState,
    ) -> Vec<StateStore> {
        let mesh = &model.mesh;
        let mut stores = new_stores(mesh, &model.materials);
        for (bi, (block, store)) in mesh.blocks.iter().zip(stores.iter_mut()).enumerate() {
            let mat = &model.materials[block.material];
            let kind = block.elements.kind;
            let nn = kind.nodes();
            let ng = points_per_element(kind);
            let c: [[f64; V]; V] = mat.elasticity::<V, K>();
            let (law, fields) = self.law_of_block(model, bi, s);
            let rule = stiffness_rule(kind);
            let gather = |field: &[f64], nodes: &[usize]| element_values(field, nodes, D);
            for e in 0..block.elements.len() {
                let nodes = block.elements.element(e);
                let x = element_coords(mesh, nodes);
                let ue = gather(u, nodes);
                let de = gather(&s.du, nodes);
                let ude = gather(fields.map_or(&[][..], |f| &f.ud[..]), nodes);
                if kind == ElementKind::Bar2 {
                    let eps = element::bar_strain(&x[..2], D, &ue[..2 * D]);
                    store.set_committed(
                        e,
                        &[eps, 0.0, 0.0, 0.0, 0.0, 0.0],
                        &[mat.e * eps, 0.0, 0.0, 0.0, 0.0, 0.0],
                        f64::NAN,
                        &[],
                    );
                    continue;
                }
                for (q, &(xi, _)) in rule.iter().enumerate() {
                    let kin = kinematics(kind, &x[..nn], xi);
                    let eps = K::strain(&kin, nn, &ue);
                    let ce = mul3(&c, &eps);
                    let g = e * ng + q;
                    match law {
                        GroupLaw::Elastic => store.set_committed(g, &eps, &ce, f64::NAN, &[]),
                        GroupLaw::ProportionalVoigt { .. } | GroupLaw::MatrixVoigt => {
                            let eta: [[f64; V]; V] =
                                mat.viscosity::<V, K>().expect("a Kelvin-Voigt material");
                            let rate = K::strain(&kin, nn, &de).map(|x| x / s.h);
                            let sv = mul3(&eta, &rate);
                            let sigma: [f64; V] = std::array::from_fn(|i| ce[i] + sv[i]);
                            store.set_committed(g, &eps, &sigma, f64::NAN, &[]);
                        }
                        GroupLaw::Sls { alpha, p, .. } => {
                            let ed = K::strain(&kin, nn, &ude);
                            let ced = mul3(&c, &ed);
                            let sigma: [f64; V] =
                                std::array::from_fn(|i| p * ce[i] + alpha * (ce[i] - ced[i]));
                            store.set_committed(g, &eps, &sigma, f64::NAN, &ed);
                        }
                    }
                }
            }
            store.reset_trial();
        }
        stores
    }

    /// The law of block `bi` and its group's fields.
    fn law_of_block<'s>(
        &self,
        model: &Model,
        bi: usize,
        s: &'s NodalState,
    ) -> (GroupLaw, Option<&'s GroupFields>) {
        let b = &model.mesh.blocks[bi];
        let m = &model.materials[b.material];
        if b.elements.kind == ElementKind::Bar2 || m.is_linear_elastic() {
            return (GroupLaw::Elastic, None);
        }
        self.groups
            .iter()
            .zip(&s.groups)
            .find(|(g, _)| g.material == Some(b.material))
            .map(|(g, f)| (g.law, Some(f)))
            .expect("every viscoelastic material has a group")
    }
}

/// A group's stiffness `K_g` (only when there are several groups: one group's is
/// the model's) and, for an identity viscosity, its `V_g = ∫ Bᵀ η B`, in the
/// idealisation `K`.
fn group_matrices<const D: usize, const V: usize, K: Kinematics<D, V>>(
    model: &Model,
    asm: &Assembler,
    in_group: &(impl Fn(usize) -> bool + Sync),
    law: GroupLaw,
    single: bool,
) -> (Option<Vec<f64>>, Vec<f64>) {
    let (mesh, materials) = (&model.mesh, &model.materials[..]);
    let k = (!single).then(|| {
        asm.stiffness_of::<D, V, K>(mesh, materials, in_group, |m| m.elasticity::<V, K>())
    });
    let v = match law {
        GroupLaw::MatrixVoigt => asm.stiffness_of::<D, V, K>(mesh, materials, in_group, |m| {
            m.viscosity::<V, K>().unwrap_or([[0.0; V]; V])
        }),
        _ => Vec::new(),
    };
    (k, v)
}

/// One group's pass over the dofs.
struct GroupPass<'a> {
    law: GroupLaw,
    h: f64,
    /// The first group writes `f` and `kdu`; the others add to them.
    first: bool,
    u: &'a [f64],
    du: &'a [f64],
    old: &'a GroupFields,
}

impl GroupPass<'_> {
    /// Completes the trial fields `new` (whose `ku`, `vu` hold the products at `u`),
    /// adds the group's force to `f` and `K_g Δu` to `kdu`, and sums its energies.
    fn run(&self, new: &mut GroupFields, f: &mut [f64], kdu: &mut [f64]) -> NodalTotals {
        let sums = match self.law {
            GroupLaw::Sls { alpha, beta, p } => self.sls(new, f, kdu, alpha, beta, p),
            law => self.voigt(new, f, kdu, law),
        };
        NodalTotals {
            psi: sums[0],
            dissipation: Dissipation {
                viscous: sums[1],
                numerical: sums[2],
                ..Default::default()
            },
        }
    }

    #[inline]
    fn put(&self, out: &mut f64, x: f64) {
        *out = if self.first { x } else { *out + x };
    }

    /// Elastic and Kelvin-Voigt groups: `f = K_g u + V_g Δu / h`.
    fn voigt(&self, new: &GroupFields, f: &mut [f64], kdu: &mut [f64], law: GroupLaw) -> [f64; 3] {
        let inv_h = 1.0 / self.h;
        let (ku, vu, old) = (&new.ku, &new.vu, self.old);
        let n = f.len();
        let leaf = |(lo, [fc, kc]): Slices<2>| {
            let mut acc = [0.0; 3];
            for (j, (fo, ko)) in fc.iter_mut().zip(kc.iter_mut()).enumerate() {
                let i = lo + j;
                let dy = ku[i] - old.ku[i];
                let visc = match law {
                    GroupLaw::ProportionalVoigt { alpha } => alpha * inv_h * dy,
                    GroupLaw::MatrixVoigt => (vu[i] - old.vu[i]) * inv_h,
                    _ => 0.0,
                };
                self.put(fo, ku[i] + visc);
                self.put(ko, dy);
                acc[0] += 0.5 * self.u[i] * ku[i];
                acc[1] += self.du[i] * visc;
                acc[2] += 0.5 * self.du[i] * dy;
            }
            acc
        };
        in_halves((0, [f, kdu]), n, VECTOR_LEAF, &split_slices, &leaf, &add)
    }

    /// Standard linear solid groups: `u_d`, `K_g u_d` by the recursion, then
    /// `f = p K_g u + α K_g (u − u_d)`.
    #[allow(clippy::too_many_arguments)]
    fn sls(
        &self,
        new: &mut GroupFields,
        f: &mut [f64],
        kdu: &mut [f64],
        alpha: f64,
        beta: f64,
        p: f64,
    ) -> [f64; 3] {
        let k = self.h * alpha / beta;
        let inv = 1.0 / (1.0 + k);
        let visc = beta / self.h;
        let (ku, old) = (&new.ku, self.old);
        let n = f.len();
        let leaf = |(lo, [fc, kc, udc, kudc]): Slices<4>| {
            let mut acc = [0.0; 3];
            for j in 0..fc.len() {
                let i = lo + j;
                let (u, du, y) = (self.u[i], self.du[i], ku[i]);
                let ud = (old.ud[i] + k * u) * inv;
                let yd = (old.kud[i] + k * y) * inv;
                udc[j] = ud;
                kudc[j] = yd;
                let dy = y - old.ku[i];
                let (dud, dyd) = (ud - old.ud[i], yd - old.kud[i]);
                self.put(&mut fc[j], p * y + alpha * (y - yd));
                self.put(&mut kc[j], dy);
                acc[0] += 0.5 * p * u * y + 0.5 * alpha * (u - ud) * (y - yd);
                acc[1] += visc * dud * dyd;
                acc[2] += 0.5 * p * du * dy + 0.5 * alpha * (du - dud) * (dy - dyd);
            }
            acc
        };
        let pieces = (0, [f, kdu, &mut new.ud[..], &mut new.kud[..]]);
        in_halves(pieces, n, VECTOR_LEAF, &split_slices, &leaf, &add)
    }
}
