//! The Gauss-point pass's shortcuts change no number: a point asked for no tangent
//! returns the stress, history, energy and dissipation of one asked for it, bit for
//! bit; a solid's principal stresses from its principal strains equal the
//! eigenvalues of `C ε`; and the element loop compiled for AVX2 gives the baseline's
//! forces, tangent, trial states and totals bit for bit
//! (`theory/gauss_point_pass.md`).
#![allow(clippy::needless_range_loop)]

use crate::workload;
use proptest::prelude::*;
use rothe::assembly::internal::{new_stores, PointPass};
use rothe::assembly::Assembler;
use rothe::fe::{PlaneStrain, PlaneStress, Solid, StrainSpace};
use rothe::material::{Material, PointResponse, StrainStep};
use rothe::simd::Simd;

const RANKINE_HILL: &str = "model = \"rankine_hill\"\ntension = { law = \"linear_softening\", strength = 2.9e6, fracture_energy = 140.0 }\ncompression = { law = \"ec2\", f_cm = 38e6, eps_c1 = 0.0022, eps_cu1 = 0.0035 }";
const MAZARS: &str =
    "model = \"mazars\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";
const MAZARS_CLASSIC: &str = "model = \"mazars\"\nvariant = \"classic\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";

fn material(text: &str) -> Material {
    let spec: rothe::config::MaterialSpec =
        toml::from_str(&format!("{text}\nE = 33e9\nnu = 0.2\nrho = 2400.0")).unwrap();
    rothe::config::material("m", "material", &spec).unwrap()
}

/// The update of `m` from `state_n` over `eps_n → eps`, with or without the tangent.
fn update<const V: usize, K: StrainSpace<V>>(
    m: &Material,
    eps_n: [f64; V],
    eps: [f64; V],
    state_n: &[f64],
    tangent: bool,
) -> (PointResponse<V>, Vec<f64>) {
    let mut state = vec![0.0; state_n.len()];
    let step = StrainStep {
        eps_n,
        eps,
        dt: 1e-5,
        length: 0.05,
        tangent,
    };
    let r = m.update::<V, K>(&step, state_n, &mut state);
    (r, state)
}

/// Walks `m` along `path` twice, with and without tangents, and asserts the two
/// walks equal bit for bit in everything but the tangent.
fn same_without_tangent<const V: usize, K: StrainSpace<V>>(m: &Material, path: &[[f64; V]]) {
    let ns = m.n_state(V);
    let mut state = vec![0.0; ns];
    let mut eps_n = [0.0; V];
    for eps in path {
        let (with, s_with) = update::<V, K>(m, eps_n, *eps, &state, true);
        let (without, s_without) = update::<V, K>(m, eps_n, *eps, &state, false);
        let bits = |r: &PointResponse<V>| {
            let mut v: Vec<u64> = r.sigma.iter().map(|x| x.to_bits()).collect();
            v.push(r.psi.to_bits());
            v.push(r.dissipation.plastic.to_bits());
            v.push(r.dissipation.damage.to_bits());
            v.push(r.dissipation.numerical.to_bits());
            v
        };
        assert_eq!(bits(&with), bits(&without), "{} at {eps:?}", m.model_name());
        assert_eq!(with.status, without.status);
        let state_bits = |s: &[f64]| s.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(state_bits(&s_with), state_bits(&s_without));
        state = s_with;
        eps_n = *eps;
    }
}

/// A path of `n` strains that cracks in tension, crushes in compression and
/// shears, scaled by `a` (components cycled through `V`).
fn path<const V: usize>(n: usize, a: f64, seed: u64) -> Vec<[f64; V]> {
    let mut x = seed;
    let mut next = move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let dir: [f64; V] = std::array::from_fn(|_| next());
    (1..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            std::array::from_fn(|i| a * (t * dir[i] * 8.0 + 0.4 * next()))
        })
        .collect()
}

#[test]
fn a_point_asked_for_no_tangent_returns_the_same_state_bit_for_bit() {
    for text in [RANKINE_HILL, MAZARS, MAZARS_CLASSIC] {
        let m = material(text);
        for seed in 1..6 {
            same_without_tangent::<3, PlaneStress>(&m, &path(60, 1e-3, seed));
            same_without_tangent::<3, PlaneStrain>(&m, &path(60, 1e-3, seed));
            same_without_tangent::<6, Solid>(&m, &path(60, 1e-3, seed));
        }
    }
}

proptest! {
    #![proptest_config(crate::common::seeded(256, 0x5eed))]

    /// Hooke's law on the principal strains against the eigenvalues of `C ε`.
    #[test]
    fn a_solids_principal_stresses_from_its_principal_strains_are_those_of_c_eps(
        eps in prop::array::uniform6(-1e-3f64..1e-3),
    ) {
        let c = Solid::elasticity(33e9, 0.2);
        let sigma: [f64; 6] = std::array::from_fn(|i| (0..6).map(|j| c[i][j] * eps[j]).sum());
        let e = Solid::principal_strains(&eps, 0.2);
        let fast = Solid::principal_elastic_stresses(&c, &sigma, &e, 0.2);
        let exact = Solid::principal_stresses(&sigma, 0.2);
        let scale = exact.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for i in 0..3 {
            prop_assert!((fast[i] - exact[i]).abs() <= 1e-12 * scale, "{fast:?} against {exact:?}");
        }
    }
}

/// One pass of `asm` with tangent and prediction at `u`: the force, the predicted
/// force, the tangent, the totals and the trial states, as bits.
fn pass_bits(asm: &Assembler, model: &rothe::model::Model, u: &[f64]) -> Vec<u64> {
    let mut stores = new_stores(&model.mesh, &model.materials);
    let n = u.len();
    let (mut f, mut fp) = (vec![0.0; n], vec![0.0; n]);
    let mut k = vec![0.0; asm.pattern.nnz()];
    let totals = asm.internal_force(
        &model.mesh,
        &model.materials,
        model.idealisation,
        PointPass {
            u,
            dt: 1e-5,
            at_rest: false,
            frozen: false,
        },
        &mut stores,
        &mut f,
        Some(&mut fp),
        Some(&mut k),
        None,
    );
    let mut bits: Vec<u64> = f.iter().chain(&fp).chain(&k).map(|x| x.to_bits()).collect();
    bits.push(totals.psi.to_bits());
    bits.push(totals.dissipation.total().to_bits());
    for s in &stores {
        let t = s.trial();
        for g in 0..t.n_points() {
            let v = t.layout().voigt;
            let sigma = t.sigma6(g);
            bits.extend(sigma[..v].iter().map(|x| x.to_bits()));
            bits.extend(t.history(g).iter().map(|x| x.to_bits()));
            bits.push(t.dissipated(g).to_bits());
        }
    }
    bits
}

#[test]
fn the_avx2_element_loop_gives_the_baselines_bits() {
    if Simd::available() != Simd::Avx2 {
        eprintln!("this CPU has no AVX2: only the baseline loop runs here");
        return;
    }
    for text in ["model = \"elastic\"", RANKINE_HILL, MAZARS] {
        let scenario = workload::w3_scenario(4).replace("model = \"elastic\"", text);
        let model = rothe::config::from_str(&scenario, std::path::Path::new(".")).unwrap();
        // A bending field that cracks the clamped end and crushes its other face.
        let u: Vec<f64> = model
            .mesh
            .coords
            .iter()
            .flat_map(|x| {
                [
                    -4e-3 * x[0] * (x[1] - 0.25),
                    -2e-3 * x[0] * x[0],
                    1e-4 * x[2],
                ]
            })
            .collect();
        let base = Assembler::new(&model.mesh).with_simd(Simd::Baseline);
        let avx2 = Assembler::new(&model.mesh).with_simd(Simd::Avx2);
        assert_eq!(avx2.simd(), Simd::Avx2);
        assert_eq!(
            pass_bits(&base, &model, &u),
            pass_bits(&avx2, &model, &u),
            "{text}"
        );
    }
}
