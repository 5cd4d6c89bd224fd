//! The kinematics of a body: where its dimension and its idealisation enter.
//!
//! A run's bodies are plane stress, plane strain or solid ([`Idealisation`], the
//! runtime choice a scenario makes). Each is a type ([`PlaneStress`],
//! [`PlaneStrain`], [`Solid`]) implementing one trait over the mesh dimension `D`
//! and the Voigt size `V` ([`Kinematics`]): the strain of element displacements,
//! `Bᵀσ` and `BᵀDB`, the crack-band length of an element, and, through its
//! material-point side ([`StrainSpace`]), the elasticity matrix, the principal
//! strains and stresses with their out-of-plane parts and the principal frame of
//! the return mappings. Code above `fe` is written once, generic over
//! `K: Kinematics<D, V>`, and enters it through one dispatch from the runtime
//! choice, [`dispatch_kinematics!`](crate::dispatch_kinematics): no formula of an
//! element or a material point branches on the dimension outside `fe` (the mesh,
//! the output formats and contact still read `Mesh::dim` for their own facts).
//!
//! Voigt order (module `fe`): `[ε_xx, ε_yy, γ_xy]` in the plane,
//! `[ε_xx, ε_yy, γ_xy, ε_zz, γ_yz, γ_zx]` in a solid (engineering shears).
//! Adding an idealisation (axisymmetry, say) is one type here, its two trait
//! impls and one arm of the dispatch (`theory/solids.md`, ARCHITECTURE.md).

use super::frame::{Frame, PlaneFrame, SolidFrame};
use super::principal::{principal_values, principal_voigt6};
use super::{PointKinematics, QuadPoint};

/// The names of the Voigt strain components, in the order of `fe` (a plane
/// vector's are the first three).
pub const STRAIN_NAMES: [&str; 6] = [
    "eps_xx", "eps_yy", "gamma_xy", "eps_zz", "gamma_yz", "gamma_zx",
];

/// The names of the Voigt stress components, in the order of `fe`.
pub const STRESS_NAMES: [&str; 6] = ["sig_xx", "sig_yy", "sig_xy", "sig_zz", "sig_yz", "sig_zx"];

/// The idealisation of a run's bodies: what a scenario's `analysis.plane` chooses
/// (`"stress"`, `"strain"`; a solid mesh is `"solid"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
pub enum Idealisation {
    /// `σ_zz = 0`: thin walls (the paper's "shell" elements); a thickness multiplies.
    #[default]
    #[serde(rename = "stress")]
    PlaneStress,
    /// `ε_zz = 0`: long bodies; the thickness is the length represented.
    #[serde(rename = "strain")]
    PlaneStrain,
    /// No idealisation: a three-dimensional solid (six strain components).
    #[serde(rename = "solid")]
    Solid,
}

impl Idealisation {
    /// The number of Voigt components of strain and stress: 3 in the plane, 6 in a
    /// solid.
    pub fn voigt(self) -> usize {
        match self {
            Idealisation::PlaneStress | Idealisation::PlaneStrain => 3,
            Idealisation::Solid => 6,
        }
    }

    /// The spatial dimension of the mesh: 2 in the plane, 3 in a solid.
    pub fn dim(self) -> usize {
        match self {
            Idealisation::PlaneStress | Idealisation::PlaneStrain => 2,
            Idealisation::Solid => 3,
        }
    }

    /// The name a scenario writes (`analysis.plane`).
    pub fn name(self) -> &'static str {
        match self {
            Idealisation::PlaneStress => "stress",
            Idealisation::PlaneStrain => "strain",
            Idealisation::Solid => "solid",
        }
    }
}

/// Runs `body` with the idealisation's kinematics type bound to `K`, the mesh
/// dimension to the constant `D` and the Voigt size to `V`: the one bridge from the
/// runtime choice ([`Idealisation`]) to code written once over
/// `K: Kinematics<D, V>`.
///
/// ```
/// use rothe::fe::{Idealisation, StrainSpace};
/// let c00 = rothe::dispatch_kinematics!(Idealisation::Solid, <D, V, K> => {
///     K::elasticity(1.0, 0.0)[0][0] * (D * V) as f64
/// });
/// assert_eq!(c00, 18.0);
/// ```
#[macro_export]
macro_rules! dispatch_kinematics {
    ($idealisation:expr, <$d:ident, $v:ident, $k:ident> => $body:expr) => {
        match $idealisation {
            $crate::fe::Idealisation::PlaneStress => {
                #[allow(dead_code)]
                const $d: usize = 2;
                #[allow(dead_code)]
                const $v: usize = 3;
                #[allow(dead_code)]
                type $k = $crate::fe::PlaneStress;
                $body
            }
            $crate::fe::Idealisation::PlaneStrain => {
                #[allow(dead_code)]
                const $d: usize = 2;
                #[allow(dead_code)]
                const $v: usize = 3;
                #[allow(dead_code)]
                type $k = $crate::fe::PlaneStrain;
                $body
            }
            $crate::fe::Idealisation::Solid => {
                #[allow(dead_code)]
                const $d: usize = 3;
                #[allow(dead_code)]
                const $v: usize = 6;
                #[allow(dead_code)]
                type $k = $crate::fe::Solid;
                $body
            }
        }
    };
}

/// What a material point sees of its idealisation (`V` Voigt components): the
/// elasticity, the principal values with their out-of-plane parts, the principal
/// frame of the return mappings. The material layer is written over this trait.
pub trait StrainSpace<const V: usize>: Copy + Default + Send + Sync + 'static {
    /// The runtime value of this idealisation.
    const IDEALISATION: Idealisation;

    /// Isotropic linear elasticity `C(E, ν)` (Voigt, engineering shears).
    fn elasticity(e: f64, nu: f64) -> [[f64; V]; V];

    /// Young's modulus back from this idealisation's `C` (the classic Mazars split
    /// and the crack band read it there).
    fn young(c: &[[f64; V]; V], nu: f64) -> f64;

    /// The three principal strains: in a solid the eigenvalues of the strain
    /// tensor; in the plane the two in-plane ones and the out-of-plane strain
    /// (`−ν/(1−ν)(ε_xx + ε_yy)` in plane stress, `0` in plane strain).
    fn principal_strains(eps: &[f64; V], nu: f64) -> [f64; 3];

    /// The three principal values of an elastic (effective) stress `σ = C ε`: in
    /// the plane the two in-plane ones and `σ_zz` (`0` in plane stress,
    /// `ν(σ_xx + σ_yy)` in plane strain).
    fn principal_stresses(sigma: &[f64; V], nu: f64) -> [f64; 3];

    /// [`StrainSpace::principal_stresses`] of the elastic stress `sigma = c ε` of a
    /// strain whose principal values ([`StrainSpace::principal_strains`]) are `e`.
    /// In the plane, the closed form on `sigma`. In a solid, Hooke's law on the
    /// principal strains, `σ_i = λ tr ε + 2μ ε_i` (isotropic `C` shares the strain's
    /// principal axes), which spares a second 3×3 eigenproblem and pairs each
    /// principal stress with its own strain; equal to the eigenvalues of `sigma` to
    /// round-off.
    #[inline]
    fn principal_elastic_stresses(
        _c: &[[f64; V]; V],
        sigma: &[f64; V],
        _e: &[f64; 3],
        nu: f64,
    ) -> [f64; 3] {
        Self::principal_stresses(sigma, nu)
    }

    /// Hands `user` this space's principal frame (the plane's angle, the solid's
    /// rotation) with its number of principal values.
    fn with_frame<U: FrameUser<V>>(user: U) -> U::Output;
}

/// Code written over a principal frame of `V`-component Voigt tensors and `P`
/// principal values ([`StrainSpace::with_frame`] calls it with its own).
pub trait FrameUser<const V: usize> {
    /// What it returns.
    type Output;
    /// Runs with the frame `F` of `P` principal values.
    fn run<const P: usize, F: Frame<V, P>>(self) -> Self::Output;
}

/// The element side of an idealisation in a mesh of dimension `D` with `V` Voigt
/// components: the operators of the element loops.
pub trait Kinematics<const D: usize, const V: usize>: StrainSpace<V> {
    /// The strain at a point from the element displacements `ue` (`D` per node,
    /// `nn` nodes).
    fn strain(k: &PointKinematics, nn: usize, ue: &[f64]) -> [f64; V];

    /// Adds `w Bᵀ σ` at one point to the element force `fe`.
    fn add_bt_sigma(k: &PointKinematics, nn: usize, w: f64, sigma: &[f64; V], fe: &mut [f64]);

    /// Adds `w Bᵀ D B` at one point to the element matrix `ke` (row-major,
    /// `D nn × D nn`).
    fn add_btdb(k: &PointKinematics, nn: usize, d: &[[f64; V]; V], w: f64, ke: &mut [f64]);

    /// The element's characteristic length for crack-band regularisation, from its
    /// nodes `x` and the kinematics `points` at its rule's points (weights in
    /// `rule`): the square root of a plane element's area, the cube root of a
    /// solid's volume.
    fn band_length(x: &[[f64; 3]], points: &[PointKinematics], rule: &[QuadPoint]) -> f64;
}

/// Plane stress: `σ_zz = 0`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlaneStress;

/// Plane strain: `ε_zz = 0`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlaneStrain;

/// A three-dimensional solid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Solid;

impl StrainSpace<3> for PlaneStress {
    const IDEALISATION: Idealisation = Idealisation::PlaneStress;

    fn elasticity(e: f64, nu: f64) -> [[f64; 3]; 3] {
        let c = e / (1.0 - nu * nu);
        [
            [c, c * nu, 0.0],
            [c * nu, c, 0.0],
            [0.0, 0.0, c * 0.5 * (1.0 - nu)],
        ]
    }

    #[inline]
    fn young(c: &[[f64; 3]; 3], nu: f64) -> f64 {
        c[0][0] * (1.0 - nu * nu)
    }

    #[inline]
    fn principal_strains(eps: &[f64; 3], nu: f64) -> [f64; 3] {
        let (e1, e2) = principal_values(eps[0], eps[1], 0.5 * eps[2]);
        [e1, e2, -nu / (1.0 - nu) * (eps[0] + eps[1])]
    }

    #[inline]
    fn principal_stresses(s: &[f64; 3], _nu: f64) -> [f64; 3] {
        let (s1, s2) = principal_values(s[0], s[1], s[2]);
        [s1, s2, 0.0]
    }

    fn with_frame<U: FrameUser<3>>(user: U) -> U::Output {
        user.run::<2, PlaneFrame>()
    }
}

impl StrainSpace<3> for PlaneStrain {
    const IDEALISATION: Idealisation = Idealisation::PlaneStrain;

    fn elasticity(e: f64, nu: f64) -> [[f64; 3]; 3] {
        let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
        [
            [c * (1.0 - nu), c * nu, 0.0],
            [c * nu, c * (1.0 - nu), 0.0],
            [0.0, 0.0, c * 0.5 * (1.0 - 2.0 * nu)],
        ]
    }

    #[inline]
    fn young(c: &[[f64; 3]; 3], nu: f64) -> f64 {
        young_of_lame(c[0][0], nu)
    }

    #[inline]
    fn principal_strains(eps: &[f64; 3], _nu: f64) -> [f64; 3] {
        let (e1, e2) = principal_values(eps[0], eps[1], 0.5 * eps[2]);
        [e1, e2, 0.0]
    }

    #[inline]
    fn principal_stresses(s: &[f64; 3], nu: f64) -> [f64; 3] {
        let (s1, s2) = principal_values(s[0], s[1], s[2]);
        [s1, s2, nu * (s[0] + s[1])]
    }

    fn with_frame<U: FrameUser<3>>(user: U) -> U::Output {
        user.run::<2, PlaneFrame>()
    }
}

impl StrainSpace<6> for Solid {
    const IDEALISATION: Idealisation = Idealisation::Solid;

    /// `λ` on the normal block, `λ + 2μ` on its diagonal, `μ` on the shears.
    fn elasticity(e: f64, nu: f64) -> [[f64; 6]; 6] {
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = 0.5 * e / (1.0 + nu);
        let mut c = [[0.0; 6]; 6];
        for i in [0, 1, 3] {
            for j in [0, 1, 3] {
                c[i][j] = lambda;
            }
            c[i][i] = lambda + 2.0 * mu;
        }
        for i in [2, 4, 5] {
            c[i][i] = mu;
        }
        c
    }

    /// A solid's `C_xx = λ + 2μ` is the plane-strain one.
    #[inline]
    fn young(c: &[[f64; 6]; 6], nu: f64) -> f64 {
        young_of_lame(c[0][0], nu)
    }

    #[inline]
    fn principal_strains(eps: &[f64; 6], _nu: f64) -> [f64; 3] {
        principal_voigt6(eps, 0.5)
    }

    #[inline]
    fn principal_stresses(s: &[f64; 6], _nu: f64) -> [f64; 3] {
        principal_voigt6(s, 1.0)
    }

    #[inline]
    fn principal_elastic_stresses(
        c: &[[f64; 6]; 6],
        _sigma: &[f64; 6],
        e: &[f64; 3],
        _nu: f64,
    ) -> [f64; 3] {
        let (lambda, two_mu) = (c[0][1], c[0][0] - c[0][1]);
        let trace = e[0] + e[1] + e[2];
        e.map(|ei| lambda * trace + two_mu * ei)
    }

    fn with_frame<U: FrameUser<6>>(user: U) -> U::Output {
        user.run::<3, SolidFrame>()
    }
}

/// `E` from `C_xx = λ + 2μ = E(1 − ν)/((1 + ν)(1 − 2ν))`.
#[inline]
fn young_of_lame(c00: f64, nu: f64) -> f64 {
    c00 * (1.0 + nu) * (1.0 - 2.0 * nu) / (1.0 - nu)
}

/// The plane idealisations, whose element operators are the same.
trait InPlane: StrainSpace<3> {}
impl InPlane for PlaneStress {}
impl InPlane for PlaneStrain {}

impl<K: InPlane> Kinematics<2, 3> for K {
    #[inline(always)]
    fn strain(k: &PointKinematics, nn: usize, ue: &[f64]) -> [f64; 3] {
        let mut eps = [0.0; 3];
        for a in 0..nn {
            let (dx, dy) = (k.dndx[a][0], k.dndx[a][1]);
            let (ux, uy) = (ue[2 * a], ue[2 * a + 1]);
            eps[0] += dx * ux;
            eps[1] += dy * uy;
            eps[2] += dy * ux + dx * uy;
        }
        eps
    }

    #[inline]
    fn add_bt_sigma(k: &PointKinematics, nn: usize, w: f64, sigma: &[f64; 3], fe: &mut [f64]) {
        for a in 0..nn {
            let (dx, dy) = (k.dndx[a][0], k.dndx[a][1]);
            fe[2 * a] += w * (dx * sigma[0] + dy * sigma[2]);
            fe[2 * a + 1] += w * (dy * sigma[1] + dx * sigma[2]);
        }
    }

    #[inline]
    fn add_btdb(k: &PointKinematics, nn: usize, d: &[[f64; 3]; 3], w: f64, ke: &mut [f64]) {
        let nd = 2 * nn;
        for a in 0..nn {
            let (ax, ay) = (k.dndx[a][0], k.dndx[a][1]);
            // Rows of Bᵀ for node a: dof x -> [ax, 0, ay], dof y -> [0, ay, ax];
            // (D B)_b columns: x: D[:,0] bx + D[:,2] by, y: D[:,1] by + D[:,2] bx.
            for b in 0..nn {
                let (bx, by) = (k.dndx[b][0], k.dndx[b][1]);
                let mut dbx = [0.0; 3];
                let mut dby = [0.0; 3];
                for i in 0..3 {
                    dbx[i] = d[i][0] * bx + d[i][2] * by;
                    dby[i] = d[i][1] * by + d[i][2] * bx;
                }
                let kxx = ax * dbx[0] + ay * dbx[2];
                let kxy = ax * dby[0] + ay * dby[2];
                let kyx = ay * dbx[1] + ax * dbx[2];
                let kyy = ay * dby[1] + ax * dby[2];
                let r = 2 * a;
                let c = 2 * b;
                ke[r * nd + c] += w * kxx;
                ke[r * nd + c + 1] += w * kxy;
                ke[(r + 1) * nd + c] += w * kyx;
                ke[(r + 1) * nd + c + 1] += w * kyy;
            }
        }
    }

    /// `√|A|`, the area from the nodes (the shoelace formula).
    #[inline]
    fn band_length(x: &[[f64; 3]], _points: &[PointKinematics], _rule: &[QuadPoint]) -> f64 {
        super::polygon_area(x).abs().sqrt()
    }
}

/// The rows of `B` of node `a` of a solid: `B_a` is 6x3, row `i` the Voigt
/// component `i` (order of `fe`).
#[inline]
fn b_solid(g: [f64; 3]) -> [[f64; 3]; 6] {
    let [x, y, z] = g;
    [
        [x, 0.0, 0.0],
        [0.0, y, 0.0],
        [y, x, 0.0],
        [0.0, 0.0, z],
        [0.0, z, y],
        [z, 0.0, x],
    ]
}

impl Kinematics<3, 6> for Solid {
    #[inline(always)]
    fn strain(k: &PointKinematics, nn: usize, ue: &[f64]) -> [f64; 6] {
        let mut eps = [0.0; 6];
        for a in 0..nn {
            let [dx, dy, dz] = k.dndx[a];
            let (ux, uy, uz) = (ue[3 * a], ue[3 * a + 1], ue[3 * a + 2]);
            eps[0] += dx * ux;
            eps[1] += dy * uy;
            eps[2] += dy * ux + dx * uy;
            eps[3] += dz * uz;
            eps[4] += dz * uy + dy * uz;
            eps[5] += dx * uz + dz * ux;
        }
        eps
    }

    #[inline]
    fn add_bt_sigma(k: &PointKinematics, nn: usize, w: f64, sigma: &[f64; 6], fe: &mut [f64]) {
        for a in 0..nn {
            let [dx, dy, dz] = k.dndx[a];
            fe[3 * a] += w * (dx * sigma[0] + dy * sigma[2] + dz * sigma[5]);
            fe[3 * a + 1] += w * (dy * sigma[1] + dx * sigma[2] + dz * sigma[4]);
            fe[3 * a + 2] += w * (dz * sigma[3] + dy * sigma[4] + dx * sigma[5]);
        }
    }

    #[inline]
    fn add_btdb(k: &PointKinematics, nn: usize, d: &[[f64; 6]; 6], w: f64, ke: &mut [f64]) {
        let nd = 3 * nn;
        for b in 0..nn {
            let bb = b_solid(k.dndx[b]);
            // D B_b (6x3)
            let mut db = [[0.0; 3]; 6];
            for i in 0..6 {
                for j in 0..3 {
                    db[i][j] = (0..6).map(|l| d[i][l] * bb[l][j]).sum();
                }
            }
            for a in 0..nn {
                let ba = b_solid(k.dndx[a]);
                for r in 0..3 {
                    for c in 0..3 {
                        let v: f64 = (0..6).map(|l| ba[l][r] * db[l][c]).sum();
                        ke[(3 * a + r) * nd + 3 * b + c] += w * v;
                    }
                }
            }
        }
    }

    /// `∛|V|`, the volume `Σ w det J` over the rule's points.
    #[inline]
    fn band_length(_x: &[[f64; 3]], points: &[PointKinematics], rule: &[QuadPoint]) -> f64 {
        let mut volume = 0.0;
        for (k, &(_, wq)) in points.iter().zip(rule) {
            volume += wq * k.det_j;
        }
        volume.abs().cbrt()
    }
}
