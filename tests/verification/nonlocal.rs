//! Nonlocal damage (theory/damage.md, "Nonlocal averaging"): the average of a uniform
//! field is the field, at boundaries and across element kinds, whatever the element
//! numbering; the nonlocal model under a uniform strain is the local one; and the
//! classic softening bar: with averaging the dissipated energy and the width of the
//! damaged zone converge as the mesh is refined, without it they vanish with the
//! element size.
#![allow(clippy::needless_range_loop)]

use rothe::assembly::nonlocal::{NonlocalTable, DRIVERS};
use rothe::linsolve::Backend;
use rothe::material::{Law, Material, MazarsParams, MazarsVariant, Regularisation};
use rothe::mesh::{structured, ElementKind, Elements, Mesh, Part};
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::march::{march, Marched, StepControl};

/// Mazars with a brittle exponential tension law (`A_t = 1`: softening to zero).
const SOFTENING: &str = "model = \"mazars\"\nE = 30e9\nnu = 0.2\nrho = 2400.0\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";

/// A bar `length` × `height` (thickness 0.01 m) of `nx` × 1 Q4 (or, `solid`,
/// `nx` × 1 × 1 Hex8) of material `mat`, its left end held, its right end pulled to
/// `u_end` by a ramp over `t_end`.
#[allow(clippy::too_many_arguments)]
fn bar_text(
    length: f64,
    height: f64,
    nx: usize,
    mat: &str,
    u_end: f64,
    t_end: f64,
    dt: f64,
    solid: bool,
) -> String {
    // The solid bar: a box one hexahedron across, as thick as the plane one, held
    // against rigid motion out of the plane too.
    let body = if solid {
        format!("mesh = {{ kind = \"box\", size = [{length}, {height}, 0.01], divisions = [{nx}, 1, 1] }}\n[[supports]]\nset = \"bar.left_back\"\nfix = [\"z\"]")
    } else {
        format!("thickness = 0.01\nmesh = {{ kind = \"rectangle\", size = [{length}, {height}], divisions = [{nx}, 1] }}")
    };
    format!(
        r#"
[analysis]
t_end = {t_end}
dt = {dt}
vtk_every = 0
max_cuts = 12
max_iterations = 80
[materials.concrete]
{mat}
[[bodies]]
name = "bar"
material = "concrete"
{body}
[[supports]]
set = "bar.left"
fix = ["x"]
[[supports]]
set = "bar.bottom_left"
fix = ["y"]
[[prescribed]]
set = "bar.right"
component = "x"
value = {u_end}
function = {{ kind = "ramp", t0 = 0.0, t1 = {t_end} }}
"#
    )
}

/// What a softening bar run gives.
struct BarResult {
    /// Element size.
    h: f64,
    /// Damage dissipation per unit cross-section (J/m²).
    dissipated: f64,
    /// The length of bar holding 90 % of the dissipated energy (m).
    width: f64,
}

/// The softening bar with `nx` elements along it: 0.24 m long, 0.02 m high, its
/// height narrowed by 5 % at mid-length in a smooth dip 0.04 m wide (the same
/// imperfection on every mesh), pulled over 2 ms to twice its elongation at the
/// peak (about 20 wave transits: slow dynamics), with `radius` for the nonlocal
/// model, in plane stress or as a `solid`. Asserts the ledger's closure at every
/// step.
fn softening_bar(nx: usize, radius: Option<f64>, solid: bool) -> BarResult {
    let (l, b, t) = (0.24, 0.02, 0.01);
    let mat = match radius {
        Some(r) => format!("{SOFTENING}\nnonlocal = {{ radius = {r} }}"),
        None => SOFTENING.to_string(),
    };
    let text = bar_text(l, b, nx, &mat, 2.0e-4 * l, 2e-3, 4e-6, solid);
    let mut model = rothe::config::from_str(&text, std::path::Path::new(".")).unwrap();
    for p in model.mesh.coords.iter_mut() {
        if p[1] > 0.5 * b {
            let s = (p[0] - 0.5 * l) / 0.04;
            p[1] = b * (1.0 - 0.05 * (-s * s).exp());
        }
    }
    let mut be = BackwardEuler::new(&model, Backend::Faer).unwrap();
    let mut s = be.initial_state();
    march(
        &mut be,
        &mut s,
        StepControl::of(&model),
        |_, s: &rothe::time::State, m| {
            if let Marched::Step(_) = m {
                let l = &s.ledger;
                assert!(
                    l.residual().abs() <= 1e-6 * l.scale(),
                    "t = {}: ledger residual {} of {}",
                    s.t,
                    l.residual(),
                    l.scale()
                );
            }
            Ok(())
        },
    )
    .unwrap();
    // The points' cumulative dissipation densities and the lengths of bar they stand
    // for (their share of the element's area over the bar's height, of its volume
    // over the cross-section in a solid).
    let c = s.points[0].committed();
    let block = &model.mesh.blocks[0];
    let ng = c.n_points() / block.elements.len();
    let cross = if solid { b * t } else { b };
    let mut dens: Vec<(f64, f64)> = Vec::new();
    for e in 0..block.elements.len() {
        let share = model.mesh.element_area(0, e) / ng as f64 / cross;
        for q in 0..ng {
            dens.push((c.dissipated(ng * e + q), share));
        }
    }
    let total: f64 = dens.iter().map(|p| p.0 * p.1).sum();
    dens.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (mut acc, mut width) = (0.0, 0.0);
    for p in &dens {
        if acc >= 0.9 * total {
            break;
        }
        acc += p.0 * p.1;
        width += p.1;
    }
    let dissipated = s.ledger.dissipated().damage / (b * t);
    // The densities are what the ledger's damage line sums (to the quadrature of
    // the tapered elements).
    assert!(
        (total - dissipated).abs() <= 0.01 * dissipated,
        "{total} vs {dissipated}"
    );
    BarResult {
        h: l / nx as f64,
        dissipated,
        width,
    }
}

#[test]
fn softening_bar_converges_with_averaging_and_not_without() {
    // R = 0.04 m; element sizes R/2, R/4, R/8, R/16.
    let r = 0.04;
    let meshes = [12usize, 24, 48, 96];
    let nonlocal: Vec<BarResult> = meshes
        .iter()
        .map(|&n| softening_bar(n, Some(r), false))
        .collect();
    let local: Vec<BarResult> = meshes
        .iter()
        .map(|&n| softening_bar(n, None, false))
        .collect();
    for (a, b) in nonlocal.iter().zip(&local) {
        eprintln!(
            "h = R/{:<2.0}: nonlocal {:.3} J/m² over {:.4} m; local {:.3} J/m² over {:.4} m",
            r / a.h,
            a.dissipated,
            a.width,
            b.dissipated,
            b.width
        );
    }
    // Nonlocal: successive differences shrink, the observed order is reported.
    let d: Vec<f64> = nonlocal
        .windows(2)
        .map(|w| (w[1].dissipated - w[0].dissipated).abs())
        .collect();
    let orders: Vec<f64> = d.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!("nonlocal dissipation: differences {d:.3?} J/m², observed orders {orders:.2?}");
    assert!(d[1] < d[0] && d[2] < d[1], "differences must shrink: {d:?}");
    let finest = nonlocal[3].dissipated;
    assert!(
        d[2] < 0.01 * finest,
        "R/8 and R/16 within 1 %: {d:?} of {finest}"
    );
    // The damaged zone keeps its width (within one R/8 element from R/4 on) and is
    // about twice R across (the bell weight's reach).
    for a in &nonlocal[1..] {
        assert!(
            (a.width - nonlocal[3].width).abs() <= r / 8.0 + 1e-12,
            "width {} vs {}",
            a.width,
            nonlocal[3].width
        );
    }
    assert!(
        nonlocal[3].width > 0.5 * r && nonlocal[3].width < 3.0 * r,
        "width {}",
        nonlocal[3].width
    );
    // Local: one element wide, and the dissipation falls with the element size.
    for (a, b) in local.iter().zip(&local[1..]) {
        assert!(
            b.dissipated < 0.8 * a.dissipated,
            "local must fall: {} then {}",
            a.dissipated,
            b.dissipated
        );
    }
    for a in &local {
        assert!(
            a.width <= 1.0 * a.h + 1e-12,
            "local band {} on h = {}",
            a.width,
            a.h
        );
    }
    assert!(
        local[3].dissipated < 0.1 * finest,
        "local {} vs nonlocal {finest}",
        local[3].dissipated
    );
}

/// A Mazars material, nonlocal with `radius`.
fn nonlocal_mazars(radius: f64) -> Material {
    Material {
        name: "c".into(),
        e: 30e9,
        nu: 0.2,
        rho: 2400.0,
        law: Law::Mazars(MazarsParams {
            variant: MazarsVariant::Paper,
            eps_t0: 1e-4,
            eps_c0: 1e-4,
            a_t: 1.0,
            b_t: 1e4,
            a_c: 1.2,
            b_c: 1.5e3,
            beta: 1.06,
            d_max: 0.99999,
            regularisation: Regularisation::Nonlocal { radius },
        }),
        identified_from: None,
    }
}

/// A 0.6 m × 0.3 m body: Q4 on the left half and, on the right half, each cell cut
/// into two T3 (two blocks of one body), its elements listed in reverse when
/// `reversed`.
fn mixed_body(reversed: bool) -> Mesh {
    let q = structured::rectangle([0.0, 0.0], [0.6, 0.3], 12, 6, ElementKind::Quad4);
    let (mut quads, mut tris) = (Vec::new(), Vec::new());
    for e in 0..q.blocks[0].len() {
        let n = q.blocks[0].element(e);
        let cx: f64 = n.iter().map(|&k| q.coords[k][0]).sum::<f64>() / 4.0;
        if cx < 0.3 {
            quads.extend_from_slice(n);
        } else {
            tris.extend_from_slice(&[n[0], n[1], n[2], n[0], n[2], n[3]]);
        }
    }
    let rev = |conn: Vec<usize>, k: usize| -> Vec<usize> {
        if reversed {
            conn.chunks(k).rev().flatten().copied().collect()
        } else {
            conn
        }
    };
    let part = Part {
        coords: q.coords.clone(),
        blocks: vec![
            Elements::new(ElementKind::Quad4, rev(quads, 4)),
            Elements::new(ElementKind::Tri3, rev(tris, 3)),
        ],
        ..Default::default()
    };
    let mut mesh = Mesh::default();
    mesh.add_part(&part, 0, "b", 0, 0.1);
    mesh
}

#[test]
fn averages_keep_uniform_fields_and_ignore_the_numbering() {
    let mats = [nonlocal_mazars(0.1)];
    for reversed in [false, true] {
        let mesh = mixed_body(reversed);
        let t = NonlocalTable::build(&mesh, &mats).unwrap();
        let n = t.n_points();
        assert_eq!(n, 36 * 4 + 72, "every Gauss point of both blocks");
        // Uniform: every point, corners and edges included, to round-off.
        let local: Vec<f64> = (0..n).flat_map(|_| [3.7e-4, -1.3e-4]).collect();
        let mut avg = vec![0.0; DRIVERS * n];
        t.average(&local, &mut avg);
        for i in 0..n {
            for k in 0..DRIVERS {
                let (a, x) = (avg[DRIVERS * i + k], local[k]);
                assert!(
                    (a - x).abs() <= 4.0 * f64::EPSILON * x.abs(),
                    "point {i} at {:?}: {a} vs {x}",
                    t.point(i)
                );
            }
            let (cols, w) = t.neighbours(i);
            assert!(cols.contains(&(i as u32)), "a point is its own neighbour");
            assert!(w.iter().all(|&x| x > 0.0));
        }
        // The neighbourhoods cross from the Q4 block into the T3 block.
        let (lo, hi) = t.neighbour_range();
        assert!(lo >= 5 && hi > lo, "neighbour counts {lo}..{hi}");
    }
    // Numbering: a field of the coordinates averages to the same values at the same
    // points whichever way the elements are listed.
    let field = |p: [f64; 3]| [(7.0 * p[0]).sin() + p[1] * p[1], p[0] * p[1] - 0.2];
    let averaged = |reversed: bool| -> Vec<([f64; 3], [f64; 2])> {
        let mesh = mixed_body(reversed);
        let t = NonlocalTable::build(&mesh, &mats).unwrap();
        let local: Vec<f64> = (0..t.n_points()).flat_map(|i| field(t.point(i))).collect();
        let mut avg = vec![0.0; local.len()];
        t.average(&local, &mut avg);
        let mut v: Vec<_> = (0..t.n_points())
            .map(|i| (t.point(i), [avg[2 * i], avg[2 * i + 1]]))
            .collect();
        v.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]).then(a.0[1].total_cmp(&b.0[1])));
        v
    };
    let (a, b) = (averaged(false), averaged(true));
    let mut changed = 0;
    for (x, y) in a.iter().zip(&b) {
        assert!((x.0[0] - y.0[0]).abs() < 1e-12 && (x.0[1] - y.0[1]).abs() < 1e-12);
        for k in 0..2 {
            assert!(
                (x.1[k] - y.1[k]).abs() <= 1e-14,
                "{:?}: {} vs {}",
                x.0,
                x.1[k],
                y.1[k]
            );
        }
        changed += usize::from((x.1[0] - field(x.0)[0]).abs() > 1e-6);
    }
    assert!(changed > a.len() / 2, "the average smooths a varying field");
}

/// One Gauss-point pass of `mats` on `mesh` at `u` from fresh states: every point's
/// trial damage (block after block), the internal force, the stored energy and the
/// damage dissipation.
fn one_pass(
    mesh: &Mesh,
    mats: &[Material],
    plane: rothe::fe::Idealisation,
    u: &[f64],
) -> (Vec<f64>, Vec<f64>, f64, f64) {
    use rothe::assembly::internal::{new_stores, PointPass};
    use rothe::assembly::Assembler;
    let asm = Assembler::new(mesh);
    let mut stores = new_stores(mesh, mats);
    let mut f = vec![0.0; u.len()];
    let totals = asm.internal_force(
        mesh,
        mats,
        plane,
        PointPass {
            u,
            dt: 1e-5,
            at_rest: false,
            frozen: false,
        },
        &mut stores,
        &mut f,
        None,
        None,
        None,
    );
    let d: Vec<f64> = stores
        .iter()
        .flat_map(|s| {
            let t = s.trial();
            (0..t.n_points())
                .map(move |g| t.history(g)[2])
                .collect::<Vec<_>>()
        })
        .collect();
    (d, f, totals.psi, totals.dissipation.damage)
}

#[test]
fn under_a_uniform_strain_nonlocal_is_local() {
    // A uniform strain past the tensile peak (and one in compression with shear) on
    // the two-block body: every point has the same drivers, so the averages are the
    // points' own values, and the nonlocal pass gives the local one's damage, forces
    // and energies to round-off, for both variants.
    let mesh = mixed_body(false);
    for variant in [MazarsVariant::Paper, MazarsVariant::Classic] {
        for eps in [[3e-4, -0.5e-4, 0.4e-4], [-2.5e-3, 0.4e-3, 0.6e-3]] {
            let evaluate = |radius: Option<f64>| {
                let mut m = nonlocal_mazars(0.1);
                if let Law::Mazars(p) = &mut m.law {
                    p.variant = variant;
                    if radius.is_none() {
                        p.regularisation = Regularisation::Local;
                    }
                }
                // u = ε x: ε_xx = e0, ε_yy = e1, γ_xy = e2.
                let u: Vec<f64> = mesh
                    .coords
                    .iter()
                    .flat_map(|p| [eps[0] * p[0] + eps[2] * p[1], eps[1] * p[1]])
                    .collect();
                one_pass(&mesh, &[m], rothe::fe::Idealisation::PlaneStress, &u)
            };
            let (dl, fl, psil, wl) = evaluate(None);
            let (dn, fnl, psin, wn) = evaluate(Some(0.1));
            assert!(
                dl.iter().all(|&d| d > 0.05),
                "{variant:?} {eps:?}: damaged everywhere: {:?}",
                &dl[..4]
            );
            for (a, b) in dl.iter().zip(&dn) {
                assert!(
                    (a - b).abs() <= 1e-13,
                    "{variant:?} {eps:?}: damage {a} vs {b}"
                );
            }
            let scale = fl.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (a, b) in fl.iter().zip(&fnl) {
                assert!((a - b).abs() <= 1e-12 * scale, "force {a} vs {b}");
            }
            assert!((psil - psin).abs() <= 1e-12 * psil && (wl - wn).abs() <= 1e-12 * wl);
        }
    }
}

#[test]
fn a_solid_softening_bar_dissipates_as_the_plane_one() {
    // Reference: the plane-stress bar above as a solid one hexahedron across, its
    // height narrowed alike. Both carry uniaxial stress; the averages differ only by
    // the Gauss points' offsets across the thickness (±0.003 m against R = 0.04 m,
    // a weight change below 1 %), so the dissipated energy per cross-section agrees
    // with the plane bar's and the damaged zone has its width, at R/4 and R/8.
    let r = 0.04;
    for nx in [24usize, 48] {
        let plane = softening_bar(nx, Some(r), false);
        let solid = softening_bar(nx, Some(r), true);
        eprintln!(
            "h = R/{:.0}: plane {:.3} J/m² over {:.4} m, solid {:.3} J/m² over {:.4} m",
            r / plane.h,
            plane.dissipated,
            plane.width,
            solid.dissipated,
            solid.width
        );
        assert!(
            (solid.dissipated - plane.dissipated).abs() < 0.01 * plane.dissipated,
            "R/{}: solid {} vs plane {}",
            r / plane.h,
            solid.dissipated,
            plane.dissipated
        );
        assert!(
            (solid.width - plane.width).abs() <= plane.h + 1e-12,
            "width {} vs {}",
            solid.width,
            plane.width
        );
    }
}

/// A 0.3 × 0.2 × 0.2 m box of `kind` cut into 6 × 4 × 4 cells, one body.
fn solid_body(kind: ElementKind) -> Mesh {
    let part = rothe::mesh::solid::uniform([0.0; 3], [0.3, 0.2, 0.2], [6, 4, 4], kind);
    let mut mesh = Mesh::default();
    mesh.add_part(&part, 0, "b", 0, 1.0);
    mesh
}

#[test]
fn solid_averages_weigh_by_distance_in_space_and_keep_uniform_fields() {
    // Reference: α_ij = w(r_ij) V_j / Σ_k w(r_ik) V_k with r the distance in space;
    // on these boxes every point has the same integration volume (cubes with 2x2x2
    // points; Kuhn tetrahedra, a sixth of a cube each), so α_ij is w(r_ij)
    // normalised, computed here over all pairs. The table's neighbours and weights
    // are those, and a uniform field averages to itself at faces, edges and corners.
    let radius = 0.1;
    let mats = [nonlocal_mazars(radius)];
    for kind in [ElementKind::Hex8, ElementKind::Tet4] {
        let mesh = solid_body(kind);
        let t = NonlocalTable::build(&mesh, &mats).unwrap();
        let n = t.n_points();
        let per = if kind == ElementKind::Hex8 { 8 } else { 6 };
        assert_eq!(n, 96 * per, "{kind:?}: every Gauss point");
        for i in 0..n {
            let p = t.point(i);
            let mut want: Vec<(u32, f64)> = (0..n)
                .filter_map(|j| {
                    let q = t.point(j);
                    let r2: f64 = (0..3).map(|d| (q[d] - p[d]).powi(2)).sum();
                    let s = 1.0 - r2 / (radius * radius);
                    (s > 0.0).then_some((j as u32, s * s))
                })
                .collect();
            let total: f64 = want.iter().map(|x| x.1).sum();
            for x in want.iter_mut() {
                x.1 /= total;
            }
            let (cols, w) = t.neighbours(i);
            assert_eq!(
                cols,
                want.iter().map(|x| x.0).collect::<Vec<_>>(),
                "{kind:?} point {i}: neighbours"
            );
            for (a, b) in w.iter().zip(&want) {
                assert!(
                    (a - b.1).abs() < 1e-14,
                    "{kind:?} point {i}: {a} vs {}",
                    b.1
                );
            }
        }
        let local: Vec<f64> = (0..n).flat_map(|_| [3.7e-4, -1.3e-4]).collect();
        let mut avg = vec![0.0; DRIVERS * n];
        t.average(&local, &mut avg);
        for i in 0..n {
            for k in 0..DRIVERS {
                let (a, x) = (avg[DRIVERS * i + k], local[k]);
                assert!(
                    (a - x).abs() <= 1e-13 * x.abs(),
                    "{kind:?} point {i}: {a} vs {x}"
                );
            }
        }
        // An interior point reaches across cells in all three directions.
        let (lo, hi) = t.neighbour_range();
        assert!(
            hi > 4 * lo / 3 && hi > 100,
            "{kind:?}: neighbour counts {lo}..{hi}"
        );
    }
}

#[test]
fn under_a_uniform_strain_a_nonlocal_solid_is_local() {
    // The solid counterpart of `under_a_uniform_strain_nonlocal_is_local`: a uniform
    // strain with all six components, past the tensile peak and in compression, on
    // a hexahedral box: the nonlocal pass gives the local one's damage, forces and
    // energies to round-off, for both variants.
    let mesh = solid_body(ElementKind::Hex8);
    for variant in [MazarsVariant::Paper, MazarsVariant::Classic] {
        for eps in [
            [3e-4, -0.5e-4, 0.4e-4, -0.3e-4, 0.2e-4, -0.1e-4],
            [-2.5e-3, 0.4e-3, 0.6e-3, 0.5e-3, -0.3e-3, 0.2e-3],
        ] {
            // Tensor ε_ij from the Voigt strain (engineering shears).
            let e = [
                [eps[0], 0.5 * eps[2], 0.5 * eps[5]],
                [0.5 * eps[2], eps[1], 0.5 * eps[4]],
                [0.5 * eps[5], 0.5 * eps[4], eps[3]],
            ];
            let u: Vec<f64> = mesh
                .coords
                .iter()
                .flat_map(|p| (0..3).map(move |i| (0..3).map(|j| e[i][j] * p[j]).sum::<f64>()))
                .collect();
            let evaluate = |nonlocal: bool| {
                let mut m = nonlocal_mazars(0.1);
                if let Law::Mazars(p) = &mut m.law {
                    p.variant = variant;
                    if !nonlocal {
                        p.regularisation = Regularisation::Local;
                    }
                }
                one_pass(&mesh, &[m], rothe::fe::Idealisation::Solid, &u)
            };
            let (dl, fl, psil, wl) = evaluate(false);
            let (dn, fnl, psin, wn) = evaluate(true);
            assert!(dl.iter().all(|&d| d > 0.05), "{variant:?} {eps:?}: damaged");
            for (a, b) in dl.iter().zip(&dn) {
                assert!(
                    (a - b).abs() <= 1e-13,
                    "{variant:?} {eps:?}: damage {a} vs {b}"
                );
            }
            let scale = fl.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (a, b) in fl.iter().zip(&fnl) {
                assert!((a - b).abs() <= 1e-12 * scale, "force {a} vs {b}");
            }
            assert!((psil - psin).abs() <= 1e-12 * psil && (wl - wn).abs() <= 1e-12 * wl);
        }
    }
}
