//! The `rothe` command as a user meets it: a run writes its files; bad input gives a
//! clear message naming the field and a non-zero exit, never a panic.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use std::path::Path;

use crate::common::{rothe, scenario};

fn good() -> String {
    crate::workload::cantilever_scenario(
        [8, 2],
        1e-5,
        1e-4,
        "model = \"elastic\"\nE = 30e9\nnu = 0.2\nrho = 2400.0",
        "vtk_every = 5",
    )
}

#[test]
fn run_writes_history_summary_and_vtk() {
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", &good());
    let out = dir.path().join("out");
    let (ok, _, err) = rothe(&[
        "run",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let header = hist.lines().next().unwrap();
    assert!(header.starts_with(
        "t,E_kin,E_int,W_ext,E_el,D_viscous,D_damage,D_plastic,D_contact,D_friction,D_predictor,D_mass,D_num,E_alg,residual"
    ));
    assert!(header.ends_with("tip_ux,tip_uy"));
    assert_eq!(hist.lines().count(), 12, "header, t = 0 and 10 steps");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["steps"], 10);
    assert_eq!(summary["dofs"], 54);
    assert_eq!(summary["solver"]["backend"], "faer");
    assert!(summary["probes"]["tip"]["max_abs_uy"].as_f64().unwrap() > 0.0);
    assert!(summary["energy"]["balance_residual_rel"].as_f64().unwrap() < 1e-10);
    for key in [
        "kinetic_0",
        "kinetic",
        "internal",
        "external_work",
        "elastic",
        "balance_residual",
    ] {
        assert!(summary["energy"][key].is_number(), "energy.{key}");
    }
    for key in [
        "viscous",
        "damage",
        "plastic",
        "contact",
        "mass",
        "numerical",
    ] {
        assert!(
            summary["energy"]["dissipated"][key].is_number(),
            "dissipated.{key}"
        );
    }
    for key in ["assembly_s", "factorization_s", "solve_s", "total_s"] {
        assert!(summary["timing"][key].is_number(), "timing.{key}");
    }
    let pvd = std::fs::read_to_string(out.join("result.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 3, "steps 0, 5, 10");
    assert!(out.join("vtk/step_0000010.vtu").exists());
}

#[test]
fn check_prints_size_and_cfl() {
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", &good());
    let (ok, out, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.contains("dofs        54 (48 free)"), "{out}");
    assert!(out.contains("CFL step"), "{out}");
    assert!(out.contains("memory"), "{out}");
}

/// Each bad input with the words its message must contain.
#[test]
fn bad_input_gives_clear_errors() {
    let cases: Vec<(String, Vec<&str>)> = vec![
        (
            good().replace("vtk_every = 5", "vtk_every = 5\ncolour = 3"),
            vec!["unknown field `colour`"],
        ),
        (
            good().replace("E = 30e9", "E = -1.0"),
            vec!["materials.concrete.E", "positive"],
        ),
        (
            good().replace("nu = 0.2", "nu = 0.5"),
            vec!["materials.concrete.nu", "(-1, 0.5)"],
        ),
        (
            good().replace("rho = 2400.0", "rho = 0.0"),
            vec!["materials.concrete.rho"],
        ),
        (
            good().replace("dt = 1.0e-5", "dt = 0.0"),
            vec!["analysis.dt"],
        ),
        (
            good().replace("set = \"beam.left\"", "set = \"beam.west\""),
            vec!["supports[0].set", "unknown node set `beam.west`"],
        ),
        (
            good().replace("set = \"beam.top\"", "set = \"beam.roof\""),
            vec!["loads[0].set", "unknown edge set"],
        ),
        (
            good().replace("material = \"concrete\"", "material = \"steel\""),
            vec!["bodies[0].material", "unknown material `steel`"],
        ),
        (
            good().replace("thickness = 0.2", "thickness = -0.2"),
            vec!["bodies[0].thickness"],
        ),
        (
            good().replace(
                "mesh = { kind = \"rectangle\", size = [2.0, 0.5], divisions = [8, 2] }",
                "mesh = { kind = \"gmsh\", file = \"missing.msh\" }",
            ),
            vec!["bodies[0].mesh.file", "does not exist"],
        ),
        (
            good().replace(
                "mesh = { kind = \"rectangle\", size = [2.0, 0.5], divisions = [8, 2] }",
                "mesh = { kind = \"gmsh\", file = \"broken.msh\" }",
            ),
            vec!["bodies[0].mesh.file", "not a valid MSH"],
        ),
        (
            good().replace(
                "mesh = { kind = \"rectangle\", size = [2.0, 0.5], divisions = [8, 2] }",
                "mesh = { kind = \"gmsh\", file = \"flat.msh\" }",
            ),
            vec!["flat.msh", "element with Gmsh tag 4", "degenerate"],
        ),
    ];
    let rh_soft = good().replace("model = \"elastic\"", "model = \"rankine_hill\"\ntension = { law = \"linear_softening\", strength = 2.9e6, fracture_energy = 10.0 }\ncompression = { law = \"bilinear\", strength = 30e6, post_yield_modulus = 1e9 }");
    let rh_ec2 = good().replace("model = \"elastic\"", "model = \"rankine_hill\"\ntension = { law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1e9 }\ncompression = { law = \"ec2\", f_cm = 38e6, eps_c1 = 0.0022, eps_cu1 = 0.02 }");
    let more: Vec<(String, Vec<&str>)> = vec![
        (rh_soft, vec!["tension.fracture_energy", "crack-band limit"]),
        (rh_ec2, vec!["compression.eps_cu1", "zero strength"]),
        (good().replace("model = \"elastic\"", "model = \"sls\"\nbeta = 1e-3"), vec!["missing field `alpha`"]),
        (
            good().replace("model = \"elastic\"", "model = \"mazars\"\neps_t0 = 1e-4\nA_t = 1.0\nB_t = 1e4\nA_c = 1.2\nB_c = 1.5e3\nd_max = 1.0"),
            vec!["d_max"],
        ),
    ];
    let cases: Vec<(String, Vec<&str>)> = cases.into_iter().chain(more).collect();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("broken.msh"),
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2\n",
    )
    .unwrap();
    // A triangle with all three nodes on a line: zero area.
    let square = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/square.msh"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("flat.msh"),
        square.replace("1 1 0\n0 1 0\n", "1 1 0\n0.5 0.5 0\n"),
    )
    .unwrap();
    for (i, (text, words)) in cases.iter().enumerate() {
        let sc = scenario(dir.path(), &format!("bad{i}.toml"), text);
        let (ok, _, err) = rothe(&["check", sc.to_str().unwrap()]);
        assert!(!ok, "case {i} should fail");
        assert!(!err.contains("panicked"), "case {i} panicked: {err}");
        for w in words {
            assert!(err.contains(w), "case {i}: `{w}` not in: {err}");
        }
    }
}

#[test]
fn gmsh_physical_groups_become_sets() {
    let part = rothe::mesh::gmsh::read(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/square.msh"),
    )
    .unwrap();
    assert_eq!(part.coords.len(), 4);
    assert_eq!(part.blocks[0].kind, rothe::mesh::ElementKind::Tri3);
    assert_eq!(part.blocks[0].len(), 2);
    assert_eq!(part.node_sets["bottom"], vec![0, 1]);
    assert_eq!(part.edge_sets["top"], vec![[2, 3]]);
    assert_eq!(part.node_sets["body"].len(), 4);
    // The clockwise triangle was turned counter-clockwise.
    let x = |n: usize| part.coords[part.blocks[0].conn[n]];
    let (a, b, c) = (x(3), x(4), x(5));
    assert!((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]) > 0.0);
    // A curve listed against its body's sense is turned: every edge has its element
    // on the left (contact takes the outward normal from the direction).
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/square.msh"),
    )
    .unwrap()
    .replace("2 3 4\n", "2 4 3\n")
    .replace("1 1 2\n", "1 2 1\n");
    let turned = rothe::mesh::gmsh::parse(text.as_bytes()).unwrap();
    assert_eq!(turned.edge_sets["top"], vec![[2, 3]]);
    assert_eq!(turned.edge_sets["bottom"], vec![[0, 1]]);
}

#[test]
fn material_driver_writes_curves_and_rejects_bad_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/materials/sls_relaxation.toml");
    let out = dir.path().join("m");
    let (ok, _, err) = rothe(&[
        "material",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let csv = std::fs::read_to_string(out.join("material.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert_eq!(
        header,
        "t,eps_xx,eps_yy,gamma_xy,sig_xx,sig_yy,sig_xy,psi,eps_d_xx,eps_d_yy,gamma_d_xy,D_viscous,D_damage,D_plastic,D_num,work"
    );
    assert_eq!(csv.lines().count(), 1002);
    let text = std::fs::read_to_string(&file).unwrap();
    for (bad, words) in [
        (
            text.replace("beta = 1.0e-3", "beta = -1.0"),
            vec!["material.beta", "positive"],
        ),
        (
            text.replace("alpha = 0.5\n", ""),
            vec!["missing field `alpha`"],
        ),
        (
            text.replace("kind = \"uniaxial_stress\"", "kind = \"twisted\""),
            vec!["unknown variant `twisted`"],
        ),
    ] {
        let f = dir.path().join("bad.toml");
        std::fs::write(&f, bad).unwrap();
        let (ok, _, err) = rothe(&[
            "material",
            f.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok);
        assert!(!err.contains("panicked"), "{err}");
        for w in words {
            assert!(err.contains(w), "`{w}` not in {err}");
        }
    }
}

#[test]
fn check_and_material_print_the_identified_concrete() {
    // `rothe check` on the cracking cantilever (identified, nonlocal) and `rothe
    // material` on a class: both print the data the parameters came from and the
    // parameters; `summary.json` says which regularisation ran.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sc = root.join("examples/scenarios/cracking_cantilever.toml");
    let (ok, out, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(ok, "{err}");
    for s in [
        "identified from the concrete's data",
        "f_cm = 3.800e7",
        "eps_c0 = 3.107e-4",
        "A_c = 1.353",
        "regularisation = nonlocal",
        "nonlocal    ",
    ] {
        assert!(out.contains(s), "{s} missing:\n{out}");
    }
    let dir = tempfile::tempdir().unwrap();
    let m = root.join("examples/materials/mazars_compression.toml");
    let (ok, _, err) = rothe(&[
        "material",
        m.to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("C30/37 (EN 1992-1-1 Table 3.1") && err.contains("E = E_cm"),
        "{err}"
    );
    let out = dir.path().join("run");
    let (ok, _, err) = rothe(&[
        "run",
        sc.to_str().unwrap(),
        "--set",
        "analysis.t_end=5e-5",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(v["materials"]["concrete"]["regularisation"], "nonlocal");
    assert_eq!(v["materials"]["concrete"]["radius"], 0.1);
}

#[test]
fn a_frictional_run_reports_friction_in_every_output() {
    // examples/contact/incline.toml: the block slides 11.9 mm in 0.1 s against
    // μ m g cos 30° = 20.0 N of friction.
    let dir = tempfile::tempdir().unwrap();
    let sc = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/contact/incline.toml");
    let out = dir.path().join("out");
    let (ok, _, err) = rothe(&["run", sc.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(ok, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let floor = &summary["contact"]["floor"];
    let friction = 0.3 * 7.85 * 9.81 * 30f64.to_radians().cos();
    let f = floor["max_tangential_force"].as_f64().unwrap();
    assert!((f - friction).abs() < 1e-3 * friction, "{floor}");
    let slip = floor["slip"].as_f64().unwrap();
    assert!((slip - 0.0119).abs() < 1e-4, "{floor}");
    let d = summary["energy"]["dissipated"]["friction"]
        .as_f64()
        .unwrap();
    assert!(
        (d - friction * slip).abs() < 0.01 * d,
        "D_friction {d} against {}",
        friction * slip
    );
    // history.csv: the friction line and the pair's stick and slip counts.
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let header: Vec<&str> = history.lines().next().unwrap().split(',').collect();
    let last: Vec<&str> = history.lines().last().unwrap().split(',').collect();
    let col = |name: &str| {
        let i = header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("{name}"));
        last[i].parse::<f64>().unwrap()
    };
    assert!((col("D_friction") - d).abs() < 1e-9 * d);
    assert_eq!((col("floor_stick"), col("floor_slip")), (0.0, 5.0));
    assert!((col("floor_tangential_force") + friction).abs() < 1e-3 * friction);
    // VTK point data: the tangential traction and the slip path.
    let vtu: Vec<_> = std::fs::read_dir(out.join("vtk"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    let last_vtu = vtu.iter().max().unwrap();
    let text = std::fs::read_to_string(last_vtu).unwrap();
    assert!(text.contains("contact_traction") && text.contains("contact_slip"));
    // check names the pair's formulation and friction.
    let (ok, report, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        report.contains("floor: against a rigid line, node to segment, Coulomb mu = 0.3"),
        "{report}"
    );
}

#[test]
fn a_solid_runs_end_to_end_and_what_it_cannot_hold_is_refused() {
    // examples/solid/cantilever.toml for 40 steps: hexahedra in the VTK files with
    // six stress components, the ledger closing to round-off (a linear model, so
    // the balance is exact); then the same box with a contact pair (contact between
    // solids is not built yet), a thickness, and a z support on a plane body are
    // refused, each naming its field.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let (ok, _, err) = rothe(&[
        "run",
        "examples/solid/cantilever.toml",
        "--set",
        "analysis.t_end=4e-4",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(v["dofs"], 17 * 5 * 5 * 3);
    let rel = v["energy"]["balance_residual_rel"].as_f64().unwrap();
    assert!(rel.abs() < 1e-12, "balance {rel}");
    assert!(v["energy"]["external_work"].as_f64().unwrap() > 0.0);
    let vtu = std::fs::read_to_string(out.join("vtk/step_0000020.vtu")).unwrap();
    assert!(
        vtu.contains("NumberOfComponents=\"6\""),
        "six stress components"
    );
    let base = std::fs::read_to_string("examples/solid/cantilever.toml").unwrap();
    for (from, to, field) in [
        (
            "[[probes]]",
            "[[contact]]\nname = \"floor\"\nslave = \"beam.bottom\"\nrigid_line = [[0.0, -0.1], [2.0, -0.1]]\n\n[[probes]]",
            "contact[0]",
        ),
        (
            "material = \"steel\"",
            "material = \"steel\"\nthickness = 0.5",
            "bodies[0].thickness",
        ),
    ] {
        let sc = dir.path().join("bad.toml");
        std::fs::write(&sc, base.replace(from, to)).unwrap();
        let (ok, _, err) = rothe(&["check", sc.to_str().unwrap()]);
        assert!(!ok && err.contains(field), "{field}: {err}");
    }
    let plane = std::fs::read_to_string("tests/regression/elastic_cantilever.toml")
        .unwrap()
        .replace("fix = [\"x\", \"y\"]", "fix = [\"x\", \"z\"]");
    let sc = dir.path().join("plane.toml");
    std::fs::write(&sc, plane).unwrap();
    let (ok, _, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(!ok && err.contains("supports[0].fix"), "{err}");
    // A z velocity or gravity in a plane model.
    let plane = std::fs::read_to_string("tests/regression/elastic_cantilever.toml").unwrap();
    for (from, to, field) in [
        (
            "thickness = 0.2",
            "thickness = 0.2\nvelocity = [0.0, 0.0, 1.0]",
            "bodies[0].velocity",
        ),
        (
            "dt = 2.0e-5",
            "dt = 2.0e-5\ngravity = [0.0, -9.81, 1.0]",
            "analysis.gravity",
        ),
    ] {
        std::fs::write(&sc, plane.replace(from, to)).unwrap();
        let (ok, _, err) = rothe(&["check", sc.to_str().unwrap()]);
        assert!(!ok && err.contains(field), "{field}: {err}");
    }
}
