//! Modal analysis (`rothe modes`, `rothe::modal`): an axial bar against its closed
//! form and its order, rigid modes of free bodies, a box against its plane-strain
//! section, a dense generalised solve, the backends, and bad input.

use rothe::linsolve::Backend;
use rothe::modal::{modes, ModalOptions, Modes};
use rothe::model::Model;

use crate::common::model;

fn options(count: usize) -> ModalOptions {
    ModalOptions {
        count,
        ..Default::default()
    }
}

/// A short dynamic run's `[analysis]` (with the lines `extra`) and steel of
/// Poisson's ratio `nu`: the head of every scenario here.
fn steel(nu: f64, extra: &str) -> String {
    format!(
        "\n[analysis]\nt_end = 1.0e-4\ndt = 1.0e-6\n{extra}[materials.steel]\n\
         model = \"elastic\"\nE = 210e9\nnu = {nu:?}\nrho = 7850.0\n"
    )
}

/// A steel bar 1 m long (plane stress, ν = 0) of `n` elements along, fixed at its left
/// end, its lateral motion suppressed: an axial bar, `c = √(E/ρ)`.
fn bar(n: usize) -> String {
    format!(
        r#"{head}[[bodies]]
name = "bar"
material = "steel"
thickness = 0.05
mesh = {{ kind = "rectangle", size = [1.0, 0.05], divisions = [{n}, 1] }}
[[supports]]
set = "bar.left"
fix = ["x"]
[[supports]]
set = "bar.all"
fix = ["y"]
"#,
        head = steel(0.0, "")
    )
}

fn hz(m: &Modes, i: usize) -> f64 {
    m.modes[i].omega() / (2.0 * std::f64::consts::PI)
}

#[test]
fn an_axial_bar_has_its_closed_form_frequencies_converging_from_above_at_order_two() {
    // f_n = (2n − 1) c / (4L); consistent mass: the discrete frequencies lie above
    // and their error falls as h².
    let c = (210e9f64 / 7850.0).sqrt();
    let exact = |k: usize| (2 * k - 1) as f64 * c / 4.0;
    let meshes = [20, 40, 80];
    let errors: Vec<Vec<f64>> = meshes
        .iter()
        .map(|&n| {
            let m = modes(&model(&bar(n)), &options(3)).unwrap();
            (0..3)
                .map(|k| {
                    let f = hz(&m, k);
                    assert!(f > exact(k + 1), "{n} elements, mode {}: {f} below", k + 1);
                    (f - exact(k + 1)) / exact(k + 1)
                })
                .collect()
        })
        .collect();
    let by_mode: Vec<Vec<f64>> = (0..3)
        .map(|k| errors.iter().map(|row| row[k]).collect())
        .collect();
    for (k, e) in by_mode.iter().enumerate() {
        let orders: Vec<f64> = (0..2).map(|i| (e[i] / e[i + 1]).log2()).collect();
        eprintln!(
            "axial bar mode {}: errors {:.3e} {:.3e} {:.3e}, observed orders {:.3} {:.3}",
            k + 1,
            e[0],
            e[1],
            e[2],
            orders[0],
            orders[1]
        );
        for o in orders {
            assert!((o - 2.0).abs() < 0.1, "mode {}: order {o}", k + 1);
        }
        assert!(e[2] < 2e-3);
    }
}

/// The block `size` with `divisions`, free (no support).
fn free_body(dim: usize) -> Model {
    let mesh = if dim == 3 {
        "mesh = { kind = \"box\", size = [0.4, 0.1, 0.15], divisions = [6, 2, 2] }"
    } else {
        "thickness = 0.1\nmesh = { kind = \"rectangle\", size = [0.4, 0.1], divisions = [8, 2] }"
    };
    model(&format!(
        r#"{head}[[bodies]]
name = "b"
material = "steel"
{mesh}
"#,
        head = steel(0.3, "")
    ))
}

#[test]
fn a_free_body_has_three_rigid_modes_in_the_plane_and_six_in_space() {
    for (dim, rigid) in [(2, 3), (3, 6)] {
        let m = free_body(dim);
        let found = modes(&m, &options(rigid + 3)).unwrap();
        let flags: Vec<bool> = found.modes.iter().map(|x| x.rigid).collect();
        assert_eq!(
            flags.iter().filter(|&&r| r).count(),
            rigid,
            "{dim}D: {flags:?}"
        );
        assert!(flags[..rigid].iter().all(|&r| r) && !flags[rigid]);
        let scale = found.modes[rigid].lambda;
        for x in &found.modes[..rigid] {
            assert!(x.lambda.abs() < 1e-9 * scale, "{dim}D rigid λ {}", x.lambda);
            assert!(x.residual < 1e-10, "{}", x.residual);
        }
        // The rigid modes carry the whole mass along each axis.
        for r in 0..dim {
            let carried: f64 = found.modes[..rigid]
                .iter()
                .map(|x| x.participation[r].powi(2))
                .sum();
            assert!(
                (carried / found.total_mass[r] - 1.0).abs() < 1e-10,
                "{dim}D axis {r}: {carried} of {}",
                found.total_mass[r]
            );
        }
        orthonormal(&m, &found);
        // A shift of zero is an eigenvalue of a free body: its factor fails, the
        // shift is moved below and the same modes come out.
        let at_zero = modes(
            &m,
            &ModalOptions {
                count: rigid + 3,
                shift: Some(0.0),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(at_zero.shift < 0.0, "{dim}D: shift {}", at_zero.shift);
        for (a, b) in at_zero.modes.iter().zip(&found.modes).skip(rigid) {
            assert!((a.lambda / b.lambda - 1.0).abs() < 1e-9, "{dim}D");
        }
        assert_eq!(at_zero.modes.iter().filter(|x| x.rigid).count(), rigid);
    }
}

/// The modes are `M`-orthonormal to 1e-10.
fn orthonormal(m: &Model, found: &Modes) {
    let asm = rothe::assembly::Assembler::new(&m.mesh);
    let mass = asm.mass(&m.mesh, &m.materials, m.analysis.time.lumped_mass);
    let mut y = vec![0.0; m.mesh.n_dofs()];
    for (i, a) in found.modes.iter().enumerate() {
        mass.matvec(&asm.pattern, &a.shape, &mut y);
        for (j, b) in found.modes.iter().enumerate() {
            let d: f64 = b.shape.iter().zip(&y).map(|(p, q)| p * q).sum();
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((d - want).abs() < 1e-10, "modes {i}, {j}: {d}");
        }
    }
}

#[test]
fn a_dense_generalised_solve_and_both_backends_give_the_same_frequencies() {
    // The clamped bar of 6 x 2 elements (lateral motion free): K and M as dense
    // matrices on the free dofs, M = L Lᵀ, the eigenvalues of L⁻¹ K L⁻ᵀ.
    let m = model(
        &bar(6)
            .replace("[[supports]]\nset = \"bar.all\"\nfix = [\"y\"]\n", "")
            .replace("divisions = [6, 1]", "divisions = [6, 2]")
            .replace("fix = [\"x\"]", "fix = [\"x\", \"y\"]"),
    );
    let asm = rothe::assembly::Assembler::new(&m.mesh);
    let k = asm.stiffness(&m.mesh, &m.materials, m.idealisation);
    let mass = asm.mass(&m.mesh, &m.materials, false);
    let fixed: std::collections::BTreeSet<usize> = m.constraints.iter().map(|c| c.dof).collect();
    let free: Vec<usize> = (0..m.mesh.n_dofs())
        .filter(|d| !fixed.contains(d))
        .collect();
    let n = free.len();
    let (mut kd, mut md) = (
        nalgebra::DMatrix::<f64>::zeros(n, n),
        nalgebra::DMatrix::<f64>::zeros(n, n),
    );
    let mut e = vec![0.0; m.mesh.n_dofs()];
    let (mut ke, mut me) = (e.clone(), e.clone());
    for (j, &dj) in free.iter().enumerate() {
        e.fill(0.0);
        e[dj] = 1.0;
        asm.pattern.matvec(&k, &e, &mut ke);
        mass.matvec(&asm.pattern, &e, &mut me);
        for (i, &di) in free.iter().enumerate() {
            kd[(i, j)] = ke[di];
            md[(i, j)] = me[di];
        }
    }
    let l = md.cholesky().expect("M positive").l();
    let li = l.clone().try_inverse().unwrap();
    let c = &li * kd * li.transpose();
    let mut dense: Vec<f64> = c.symmetric_eigen().eigenvalues.iter().copied().collect();
    dense.sort_by(f64::total_cmp);
    let backends: &[Backend] = if cfg!(feature = "cholmod") {
        &[Backend::Faer, Backend::Cholmod]
    } else {
        &[Backend::Faer]
    };
    for &backend in backends {
        let found = modes(
            &m,
            &ModalOptions {
                count: 8,
                backend,
                ..Default::default()
            },
        )
        .unwrap();
        for (i, x) in found.modes.iter().enumerate() {
            assert!(
                (x.lambda - dense[i]).abs() < 1e-9 * dense[i],
                "{backend:?} mode {i}: {} against {}",
                x.lambda,
                dense[i]
            );
            assert!(x.residual < 1e-8, "{}", x.residual);
        }
        orthonormal(&m, &found);
    }
}

#[test]
fn a_thin_box_with_its_depth_fixed_has_its_plane_strain_sections_modes() {
    // A box 1 x 0.1 x 0.01 m clamped at its left end, every z dof fixed: its lowest
    // modes are those of the plane-strain section of depth 0.01 m (the through-depth
    // ones lie far above).
    let text = |solid: bool| {
        let (mesh, extra, fix) = if solid {
            (
                "mesh = { kind = \"box\", size = [1.0, 0.1, 0.01], divisions = [20, 2, 1] }",
                "[[supports]]\nset = \"b.all\"\nfix = [\"z\"]\n",
                "fix = [\"x\", \"y\", \"z\"]",
            )
        } else {
            (
                "thickness = 0.01\nmesh = { kind = \"rectangle\", size = [1.0, 0.1], divisions = [20, 2] }",
                "",
                "fix = [\"x\", \"y\"]",
            )
        };
        format!(
            r#"{head}[[bodies]]
name = "b"
material = "steel"
{mesh}
[[supports]]
set = "b.left"
{fix}
{extra}"#,
            head = steel(0.3, "plane = \"strain\"\n")
        )
    };
    let plane = modes(&model(&text(false)), &options(4)).unwrap();
    let solid_text = text(true).replace("plane = \"strain\"\n", "");
    let solid = modes(&model(&solid_text), &options(4)).unwrap();
    for i in 0..4 {
        let (a, b) = (hz(&plane, i), hz(&solid, i));
        assert!(
            (a - b).abs() < 1e-9 * a,
            "mode {}: plane strain {a} Hz, box {b} Hz",
            i + 1
        );
    }
}

#[test]
fn modes_refuses_bad_input_and_writes_its_tables_and_shapes() {
    let dir = tempfile::tempdir().unwrap();
    let m = model(&bar(10));
    for (count, shift, words) in [
        (0, None, "--count"),
        (1000, None, "free dofs"),
        (3, Some(1.0e6), "--shift"),
    ] {
        let e = modes(
            &m,
            &ModalOptions {
                count,
                shift,
                ..Default::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains(words), "{e}");
    }
    let held = model(
        &bar(4)
            .replace("fix = [\"x\"]", "fix = [\"x\", \"y\"]")
            .replace(
                "set = \"bar.all\"\nfix = [\"y\"]",
                "set = \"bar.all\"\nfix = [\"x\", \"y\"]",
            ),
    );
    let e = modes(&held, &options(1)).unwrap_err().to_string();
    assert!(e.contains("no free motion"), "{e}");
    // The command: its tables and shapes.
    let path = crate::common::scenario(dir.path(), "bar.toml", &bar(20));
    let out = dir.path().join("modes");
    let (ok, stdout, stderr) = crate::common::rothe(&[
        "modes",
        path.to_str().unwrap(),
        "--count",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}{stderr}");
    let csv = std::fs::read_to_string(out.join("modes.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    assert!(
        header.starts_with("index,omega_rad_s,f_hz,period_s"),
        "{header}"
    );
    assert_eq!(lines.count(), 3);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("modes.json")).unwrap()).unwrap();
    assert_eq!(json["modes"].as_array().unwrap().len(), 3);
    // The axial bar's first mode carries 8/π² of the bar's mass along x (the
    // fractions are of the free dofs' mass, which lacks the fixed end's share).
    let first = json["modes"][0]["effective_mass"][0]["fraction"]
        .as_f64()
        .unwrap();
    let free_mass = json["total_mass_kg"][0].as_f64().unwrap();
    let bar_mass = 7850.0 * 1.0 * 0.05 * 0.05;
    let exact = 8.0 / std::f64::consts::PI.powi(2);
    assert!(
        (first * free_mass / bar_mass - exact).abs() < 2e-3,
        "{first} of {free_mass} kg against {exact} of {bar_mass} kg"
    );
    let pvd = std::fs::read_to_string(out.join("modes.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 3);
    assert!(out.join("vtk/mode_0000001.vtu").exists());
    for chart in [
        "spectrum.png",
        "spectrum.svg",
        "step_effect.png",
        "step_effect.svg",
    ] {
        assert!(out.join(chart).exists(), "{chart}");
    }
    let (ok, _, stderr) = crate::common::rothe(&["modes", path.to_str().unwrap(), "--count", "0"]);
    assert!(!ok && stderr.contains("--count"), "{stderr}");
}

#[test]
fn rayleigh_damping_from_modal_targets_gives_the_ratio_at_both() {
    let with =
        |damping: &str| bar(40).replace("dt = 1.0e-6\n", &format!("dt = 1.0e-6\n{damping}\n"));
    // Given frequencies: the ratio at both to 1e-12.
    let m = model(&with(
        "damping = { ratio = 0.02, frequencies = [100.0, 2500.0] }",
    ));
    let d = &m.analysis.damping;
    for f in [100.0, 2500.0] {
        let r = d.ratio_at(2.0 * std::f64::consts::PI * f);
        assert!((r - 0.02).abs() < 1e-12, "{f} Hz: {r}");
    }
    // Computed modes: the pair gives the ratio at modes 1 and 3 as computed.
    let m = model(&with("damping = { ratio = 0.05, modes = [1, 3] }"));
    let found = modes(&m, &options(3)).unwrap();
    let d = &m.analysis.damping;
    for i in [0, 2] {
        let r = d.ratio_at(found.modes[i].omega());
        assert!((r - 0.05).abs() < 1e-12, "mode {}: {r}", i + 1);
    }
    // Between the targets less, outside more.
    assert!(d.ratio_at(found.modes[1].omega()) < 0.05);
    // `rothe check` prints the pair and the ratio at the first modes.
    let dir = tempfile::tempdir().unwrap();
    let path = crate::common::scenario(
        dir.path(),
        "bar.toml",
        &with("damping = { ratio = 0.05, modes = [1, 3] }"),
    );
    let (ok, stdout, stderr) = crate::common::rothe(&["check", path.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("damping     Rayleigh a_m") && stdout.contains("mode  3"),
        "{stdout}"
    );
    // Bad input, by name.
    for (damping, field) in [
        (
            "rayleigh = [1.0, 0.0]\ndamping = { ratio = 0.02, frequencies = [1.0, 2.0] }",
            "analysis.damping",
        ),
        ("damping = { ratio = 0.02 }", "analysis.damping"),
        (
            "damping = { ratio = 0.02, frequencies = [1.0, 2.0], modes = [1, 2] }",
            "analysis.damping",
        ),
        (
            "damping = { ratio = 1.5, frequencies = [1.0, 2.0] }",
            "analysis.damping.ratio",
        ),
        (
            "damping = { ratio = 0.02, frequencies = [0.0, 2.0] }",
            "analysis.damping.frequencies[0]",
        ),
        (
            "damping = { ratio = 0.02, modes = [0, 2] }",
            "analysis.damping.modes",
        ),
    ] {
        let e = rothe::config::from_str(&with(damping), std::path::Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(e.contains(field), "{damping}: {e}");
    }
    // A free body's rigid modes have no frequency to damp at.
    let free = format!(
        "{}[[bodies]]\nname = \"b\"\nmaterial = \"steel\"\nthickness = 0.1\n\
         mesh = {{ kind = \"rectangle\", size = [0.4, 0.1], divisions = [8, 2] }}\n",
        steel(0.3, "damping = { ratio = 0.02, modes = [1, 4] }\n")
    );
    let e = rothe::config::from_str(&free, std::path::Path::new("."))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("analysis.damping.modes[0]") && e.contains("rigid"),
        "{e}"
    );
}

#[test]
fn the_exact_critical_step_is_the_lumped_chains_and_above_the_element_bound() {
    // The axial bar of 40 lumped elements is a spring-mass chain fixed at one end:
    // ω_max = (2c/h) sin((2n − 1)π/(4n)).
    let n = 40;
    let m = model(&bar(n));
    let w = rothe::modal::highest_frequency(&m).unwrap();
    let c = (210e9f64 / 7850.0).sqrt();
    let h = 1.0 / n as f64;
    let chain = 2.0 * c / h * ((2 * n - 1) as f64 * std::f64::consts::PI / (4 * n) as f64).sin();
    assert!((w / chain - 1.0).abs() < 1e-8, "{w} against {chain}");
    // On any mesh the largest element frequency bounds the mesh's from above, so the
    // exact step is at least the element bound `rothe check` prints.
    let two_blocks = rothe::config::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/explicit/two_blocks_central_difference.toml"),
    )
    .unwrap();
    let exact = 2.0 / rothe::modal::highest_frequency(&two_blocks).unwrap();
    let bound = rothe::time::cfl::stable_step(&two_blocks).unwrap().dt;
    eprintln!("two blocks: exact step {exact:.5e} s, element bound {bound:.5e} s");
    assert!(
        exact >= bound && exact < 1.5 * bound,
        "{exact} against {bound}"
    );
}

/// Two identical plane-stress cantilevers side by side, not connected: every
/// eigenvalue of the pair is double.
fn twin_cantilevers() -> String {
    let body = |name: &str, y: f64| {
        format!(
            r#"
[[bodies]]
name = "{name}"
material = "steel"
thickness = 0.1
mesh = {{ kind = "rectangle", origin = [0.0, {y}], size = [1.0, 0.1], divisions = [20, 2] }}
[[supports]]
set = "{name}.left"
fix = ["x", "y"]
"#
        )
    };
    format!("{}{}{}", steel(0.3, ""), body("a", 0.0), body("b", 0.5))
}

#[test]
fn the_sturm_count_finds_the_copies_of_double_eigenvalues_lanczos_missed() {
    // One start vector meets each distinct eigenvalue once: of the twins' double
    // eigenvalues the first Lanczos run finds one copy, and the inertia of K − μM
    // (twice as many below μ) sends it back for the others. Each frequency comes
    // twice, equal to a single cantilever's, the set M-orthonormal.
    let twins = model(&twin_cantilevers());
    let single_text = twin_cantilevers();
    let cut = single_text.find("\n[[bodies]]\nname = \"b\"").unwrap();
    let single = modes(&model(&single_text[..cut]), &options(3)).unwrap();
    for count in [2, 4, 6] {
        let found = modes(&twins, &options(count)).unwrap();
        for i in 0..count {
            let (f, g) = (hz(&found, i), hz(&single, i / 2));
            assert!(
                (f / g - 1.0).abs() < 1e-9,
                "{count} modes, mode {}: {f} Hz, single {g} Hz",
                i + 1
            );
        }
        assert!(found.sturm.count >= count);
        orthonormal(&twins, &found);
    }
}

#[test]
fn the_modes_around_a_frequency_are_the_nearest_numbered_in_the_spectrum() {
    // The bar's axial spectrum f_k = (2k − 1) c/(4L) (discrete, from the lowest
    // twelve): the three nearest a frequency between f_6 and f_7 are f_5..f_7 or
    // f_6..f_8, numbered so, from an LDLᵀ inside the spectrum whose inertia says how
    // many lie below.
    let m = model(&bar(60));
    let lowest = modes(&m, &options(12)).unwrap();
    let f: Vec<f64> = (0..12).map(|k| hz(&lowest, k)).collect();
    let target = f[5] + 0.4 * (f[6] - f[5]);
    let around = modes(
        &m,
        &ModalOptions {
            count: 3,
            around: Some(target),
            ..Default::default()
        },
    )
    .unwrap();
    let mut expect: Vec<usize> = (0..12).collect();
    expect.sort_by(|&a, &b| (f[a] - target).abs().total_cmp(&(f[b] - target).abs()));
    let mut nearest: Vec<usize> = expect[..3].to_vec();
    nearest.sort();
    for (mode, &k) in around.modes.iter().zip(&nearest) {
        assert_eq!(mode.number, k + 1);
        let got = mode.omega() / (2.0 * std::f64::consts::PI);
        assert!(
            (got / f[k] - 1.0).abs() < 1e-10,
            "mode {}: {got} against {}",
            k + 1,
            f[k]
        );
        assert!(mode.residual < 1e-8, "residual {}", mode.residual);
    }
    orthonormal(&m, &around);
    // Looking around a negative or zero frequency, or with a shift too, is refused.
    for (around, shift) in [(Some(-5.0), None), (Some(100.0), Some(-1.0))] {
        let e = modes(
            &m,
            &ModalOptions {
                count: 3,
                around,
                shift,
                ..Default::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("--around"), "{e}");
    }
}

/// The plane-stress cantilever `L × H` (thickness 0.05 m) clamped on its left edge,
/// `ny` elements through the height and `5 ny` along.
fn stubby_cantilever(ny: usize) -> String {
    format!(
        r#"{head}[[bodies]]
name = "beam"
material = "steel"
thickness = 0.05
mesh = {{ kind = "rectangle", size = [1.0, 0.2], divisions = [{nx}, {ny}] }}
[[supports]]
set = "beam.left"
fix = ["x", "y"]
"#,
        nx = 5 * ny,
        head = steel(0.3, "")
    )
}

/// The lowest `count` circular frequencies of a clamped-free Timoshenko beam
/// (length `l`, bending stiffness `ei`, shear stiffness `kga`, masses per length
/// `rho_a` and rotary `rho_i`), solved to convergence: `n` two-node elements with
/// linear `w, θ`, the shear strain `w' − θ` at the midpoint (free of locking),
/// consistent translational and rotary mass, and a dense generalised solve.
fn timoshenko_cantilever(n: usize, p: [f64; 5], count: usize) -> Vec<f64> {
    use nalgebra::{DMatrix, SymmetricEigen};
    let [l, ei, kga, rho_a, rho_i] = p;
    let h = l / n as f64;
    let size = 2 * n; // (w, θ) of nodes 1..=n; node 0 clamped
    let (mut k, mut m) = (
        DMatrix::<f64>::zeros(size, size),
        DMatrix::<f64>::zeros(size, size),
    );
    for e in 0..n {
        let dofs = [
            2 * e as isize - 2,
            2 * e as isize - 1,
            2 * e as isize,
            2 * e as isize + 1,
        ];
        let bs = [-1.0 / h, -0.5, 1.0 / h, -0.5];
        let bb = [0.0, -1.0 / h, 0.0, 1.0 / h];
        let mw = [
            [2.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [1.0, 0.0, 2.0, 0.0],
            [0.0; 4],
        ];
        let mt = [
            [0.0; 4],
            [0.0, 2.0, 0.0, 1.0],
            [0.0; 4],
            [0.0, 1.0, 0.0, 2.0],
        ];
        for a in 0..4 {
            for b in 0..4 {
                let (i, j) = (dofs[a], dofs[b]);
                if i < 0 || j < 0 {
                    continue;
                }
                let (i, j) = (i as usize, j as usize);
                k[(i, j)] += (ei * bb[a] * bb[b] + kga * bs[a] * bs[b]) * h;
                m[(i, j)] += (rho_a * mw[a][b] + rho_i * mt[a][b]) * h / 6.0;
            }
        }
    }
    let chol = m.cholesky().expect("positive mass");
    let linv = chol.l().try_inverse().expect("invertible");
    let a = &linv * k * linv.transpose();
    let mut lambda: Vec<f64> = SymmetricEigen::new(a).eigenvalues.iter().copied().collect();
    lambda.sort_by(f64::total_cmp);
    lambda[..count].iter().map(|x| x.sqrt()).collect()
}

#[test]
fn a_stubby_cantilevers_bending_frequencies_are_timoshenkos() {
    // L/H = 5: Timoshenko's shear and rotary inertia lower the first two bending
    // frequencies by about 2 % and 12 % from Euler–Bernoulli's. The plane-stress
    // mesh (bilinear quadrilaterals, whose parasitic shear stiffens bending at h²)
    // over three meshes, extrapolated at that order, against Timoshenko's beam with
    // Cowper's shear coefficient κ = 10(1 + ν)/(12 + 11ν) of a rectangle.
    let (e, nu, rho, l, h, b) = (210e9, 0.3, 7850.0, 1.0, 0.2, 0.05);
    let (area, inertia) = (b * h, b * h * h * h / 12.0);
    let kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
    let g = e / (2.0 * (1.0 + nu));
    let p = [l, e * inertia, kappa * g * area, rho * area, rho * inertia];
    let timo = timoshenko_cantilever(400, p, 2);
    let coarse = timoshenko_cantilever(200, p, 2);
    let bernoulli: Vec<f64> = [1.875_104_068_711_961, 4.694_091_132_974_175]
        .iter()
        .map(|bl: &f64| bl * bl * (e * inertia / (rho * area * l.powi(4))).sqrt())
        .collect();
    let bending = |ny: usize| -> Vec<f64> {
        let m = modes(&model(&stubby_cantilever(ny)), &options(4)).unwrap();
        m.modes
            .iter()
            .filter(|x| x.participation[1].abs() > x.participation[0].abs())
            .take(2)
            .map(|x| x.omega())
            .collect()
    };
    let fe: Vec<Vec<f64>> = [4, 8, 16].iter().map(|&ny| bending(ny)).collect();
    for k in 0..2 {
        let (a, bm, c) = (fe[0][k], fe[1][k], fe[2][k]);
        let order = ((a - bm) / (bm - c)).log2();
        let extrapolated = c - (bm - c) / (2f64.powf(order) - 1.0);
        let err = extrapolated / timo[k] - 1.0;
        eprintln!(
            "bending mode {}: FE {:.2} {:.2} {:.2} rad/s (order {order:.2}) -> {extrapolated:.2}; \
             Timoshenko {:.2} (converged to {:.1e}), Euler–Bernoulli {:.2}; error {:+.3} %",
            k + 1,
            a,
            bm,
            c,
            timo[k],
            (coarse[k] / timo[k] - 1.0).abs(),
            bernoulli[k],
            100.0 * err
        );
        assert!(a > bm && bm > c, "mode {}: from above", k + 1);
        assert!((order - 2.0).abs() < 0.3, "mode {}: order {order}", k + 1);
        assert!(
            err.abs() < 0.005,
            "mode {}: {err:+e} from Timoshenko",
            k + 1
        );
        // and far from Euler–Bernoulli: the test tells the theories apart.
        assert!(extrapolated / bernoulli[k] - 1.0 < -0.015, "mode {}", k + 1);
    }
}

/// What a step `h` of a first-order-form scheme does to a mode of frequency `omega`
/// and damping ratio `xi`: the ratio `ξ̄ = −ln|z| / √(ln²|z| + arg² z)` of its
/// amplification `z`, `z = 1/(1 − λh)` (backward Euler) or `(1 + λh/2)/(1 − λh/2)`
/// (trapezoidal), `λ = ω(−ξ + i√(1 − ξ²))`.
fn scheme_ratio(omega: f64, xi: f64, h: f64, trapezoidal: bool) -> f64 {
    use nalgebra::Complex;
    let lambda = Complex::new(-xi * omega, omega * (1.0 - xi * xi).sqrt()) * h;
    let one = Complex::new(1.0, 0.0);
    let z = if trapezoidal {
        (one + lambda * 0.5) / (one - lambda * 0.5)
    } else {
        one / (one - lambda)
    };
    let (ln, arg) = (z.norm().ln(), z.im.atan2(z.re));
    -ln / ln.hypot(arg)
}

#[test]
fn a_free_vibration_of_a_targeted_mode_decays_at_the_targets_ratio() {
    // The axial bar set moving at 1 m/s, Rayleigh damping of ratio 0.02 at modes 1
    // and 3. Rayleigh damping keeps the modes apart, so the projection q₁ = φ₁ᵀMu
    // is a damped oscillator of its own: its logarithmic decrement over ten periods
    // gives the ratio the run damps mode 1 with, 0.02 plus what the scheme adds at
    // ωh = 2π/400 (backward Euler about ωh/2, the trapezoidal rule nothing to first
    // order), to 1 % of the whole.
    let xi = 0.02;
    for (scheme, trapezoidal) in [("trapezoidal", true), ("backward_euler", false)] {
        let probe = model(&bar(40));
        let mode = modes(&probe, &options(1)).unwrap().modes.remove(0);
        let omega = mode.omega();
        let h = 2.0 * std::f64::consts::PI / omega / 400.0;
        let text = bar(40)
            .replace(
                "t_end = 1.0e-4\ndt = 1.0e-6",
                &format!(
                    "t_end = {:e}\ndt = {h:e}\nscheme = \"{scheme}\"\n\
                 damping = {{ ratio = {xi}, modes = [1, 3] }}",
                    4000.0 * h
                ),
            )
            .replace("name = \"bar\"", "name = \"bar\"\nvelocity = [1.0, 0.0]");
        let m = model(&text);
        let asm = rothe::assembly::Assembler::new(&m.mesh);
        let mass = asm.mass(&m.mesh, &m.materials, false);
        let mut m_phi = vec![0.0; mode.shape.len()];
        mass.matvec(&asm.pattern, &mode.shape, &mut m_phi);
        let mut run = rothe::time::backward_euler::BackwardEuler::new(&m, Backend::Faer).unwrap();
        use rothe::time::Integrator;
        let mut s = run.initial_state();
        let mut q = Vec::new();
        for _ in 0..4000 {
            run.step_accepted(&mut s).unwrap();
            q.push(m_phi.iter().zip(&s.u).map(|(a, b)| a * b).sum::<f64>());
        }
        // The peaks of q₁, each refined by the parabola through its three samples.
        let peaks: Vec<f64> = (1..q.len() - 1)
            .filter(|&i| q[i] > q[i - 1] && q[i] >= q[i + 1])
            .map(|i| {
                let (a, b, c) = (q[i - 1], q[i], q[i + 1]);
                b - (a - c).powi(2) / (8.0 * (a - 2.0 * b + c))
            })
            .collect();
        assert!(peaks.len() >= 10, "{scheme}: {} peaks", peaks.len());
        let periods = 9;
        let delta = (peaks[0] / peaks[periods]).ln() / periods as f64;
        let r: f64 = delta / (2.0 * std::f64::consts::PI);
        let measured = r / (1.0 + r * r).sqrt();
        let expected = scheme_ratio(omega, xi, h, trapezoidal);
        eprintln!(
            "{scheme}: measured ξ = {measured:.6}, the scheme's {expected:.6} (target {xi}, \
             the step's own {:.6})",
            rothe::modal::step::backward_euler(omega, h).damping
        );
        assert!(
            (measured / expected - 1.0).abs() < 1e-3,
            "{scheme}: measured {measured} against {expected}"
        );
        if trapezoidal {
            assert!((measured / xi - 1.0).abs() < 0.01, "{measured}");
        } else {
            assert!(measured > xi + 0.5 * rothe::modal::step::backward_euler(omega, h).damping);
        }
    }
}

#[test]
fn the_modes_do_not_depend_on_the_thread_count() {
    // Assembly, products and solves on one thread and on two: the same frequencies
    // and shapes (the parallel loops split work, not sums).
    let m = model(&stubby_cantilever(16));
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| modes(&m, &options(6)).unwrap())
    };
    let (one, two) = (on(1), on(2));
    for (a, b) in one.modes.iter().zip(&two.modes) {
        assert!(
            (a.lambda / b.lambda - 1.0).abs() < 1e-12,
            "{} against {}",
            a.lambda,
            b.lambda
        );
        let diff = a
            .shape
            .iter()
            .zip(&b.shape)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        let size = a.shape.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        assert!(diff <= 1e-9 * size, "shapes differ by {diff} of {size}");
    }
}

#[test]
fn a_count_that_cuts_a_repeated_eigenvalue_keeps_every_copy() {
    // A square-section steel cantilever: its first bending modes in y and z share
    // one frequency (the mesh is symmetric in y and z). Asked for one mode, or for
    // three (cutting the second bending pair), every copy of the last frequency
    // comes back, checked against the inertia count of the pair.
    let m = model(&format!(
        r#"{head}[[bodies]]
name = "b"
material = "steel"
mesh = {{ kind = "box", size = [1.0, 0.1, 0.1], divisions = [10, 2, 2] }}
[[supports]]
set = "b.left"
fix = ["x", "y", "z"]
"#,
        head = steel(0.3, "")
    ));
    let one = modes(&m, &options(1)).unwrap();
    assert_eq!(one.modes.len(), 2, "the two first bending modes");
    let (a, b) = (one.modes[0].omega(), one.modes[1].omega());
    assert!((a - b).abs() <= 1e-8 * a, "{a} {b}");
    let three = modes(&m, &options(3)).unwrap();
    assert_eq!(three.modes.len(), 4, "the second pair whole");
    let (c, d) = (three.modes[2].omega(), three.modes[3].omega());
    assert!(
        (c - d).abs() <= 1e-8 * c && c > 1.5 * a,
        "{c} {d} after {a}"
    );
    // A count that ends on a distinct frequency is kept as asked.
    assert_eq!(modes(&m, &options(2)).unwrap().modes.len(), 2);
}
