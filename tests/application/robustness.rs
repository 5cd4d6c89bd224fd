//! No silent wrong result, no panic, bounded memory: one representative of each class
//! of bad input and runaway run, as a user meets it through the `rothe` command (or
//! the library where the command cannot reach the case).

use std::path::Path;
use std::process::Command;

use crate::common::{rothe, scenario};
use std::time::{Duration, Instant};

fn good() -> String {
    crate::workload::cantilever_scenario(
        [8, 2],
        1e-5,
        1e-4,
        "model = \"elastic\"\nE = 30e9\nnu = 0.2\nrho = 2400.0",
        "vtk_every = 5",
    )
}

/// `check` fails on `text` with a message holding every one of `words`, and no panic.
fn refused(text: &str, words: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", text);
    let (ok, out, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(!ok, "accepted: {out}");
    assert!(!err.contains("panicked"), "{err}");
    for w in words {
        assert!(err.contains(w), "`{w}` not in: {err}");
    }
}

/// `check` accepts `text`.
fn accepted(text: &str) {
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", text);
    let (ok, _, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(ok, "{err}");
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn every_number_of_a_scenario_must_be_finite() {
    // Time functions of every kind, loads, probes, gravity: NaN and infinities are
    // refused with the field named.
    let cases: [(&str, &str, &[&str]); 7] = [
        (
            "function = { kind = \"step\", at = 0.0 }",
            "function = { kind = \"step\", at = nan }",
            &["loads[0].function.at", "finite"],
        ),
        (
            "function = { kind = \"step\", at = 0.0 }",
            "function = { kind = \"ramp\", t0 = 0.0, t1 = inf }",
            &["loads[0].function.t1", "finite"],
        ),
        (
            "function = { kind = \"step\", at = 0.0 }",
            "function = { kind = \"table\", points = [[0.0, 1.0], [nan, 2.0]] }",
            &["loads[0].function.points[1][0]", "finite"],
        ),
        (
            "function = { kind = \"step\", at = 0.0 }",
            "function = { kind = \"harmonic\", frequency = 10.0, phase = -inf }",
            &["loads[0].function.phase"],
        ),
        (
            "value = [0.0, -1.0e6]",
            "value = [nan, -1.0e6]",
            &["loads[0].value[0]", "finite"],
        ),
        (
            "at = [2.0, 0.25]",
            "at = [2.0, inf]",
            &["probes[0].at[1]", "finite"],
        ),
        (
            "vtk_every = 5",
            "vtk_every = 5\ngravity = [0.0, nan]",
            &["analysis.gravity[1]"],
        ),
    ];
    for (from, to, words) in cases {
        assert!(good().contains(from), "{from}");
        refused(&good().replace(from, to), words);
    }
    // A table function that does not increase, and an empty one.
    refused(
        &good().replace(
            "function = { kind = \"step\", at = 0.0 }",
            "function = { kind = \"table\", points = [[0.0, 1.0], [0.0, 2.0]] }",
        ),
        &["loads[0].function.points", "increase strictly"],
    );
    refused(
        &good().replace(
            "function = { kind = \"step\", at = 0.0 }",
            "function = { kind = \"table\", points = [] }",
        ),
        &["loads[0].function.points", "at least one"],
    );
}

#[test]
fn a_run_whose_state_stops_being_finite_fails_naming_the_quantity() {
    // A load of 1e300 N is finite, but the stored energy it puts in overflows: the
    // first non-finite value stops the run with the quantity and the time, and
    // summary.json says failed; the rows written before stay.
    let dir = tempfile::tempdir().unwrap();
    let text = good().replace("value = [0.0, -1.0e6]", "value = [0.0, -1.0e300]");
    let sc = scenario(dir.path(), "s.toml", &text);
    let out = dir.path().join("out");
    let (ok, _, err) = rothe(&[
        "run",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok);
    assert!(err.contains("non-finite value at t = "), "{err}");
    assert!(err.contains("is inf") || err.contains("is NaN"), "{err}");
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    assert!(s["error"].as_str().unwrap().contains("non-finite"));
    let rows = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(rows.lines().count() >= 2, "the initial row is kept");
}

#[test]
fn a_panic_inside_a_run_is_an_internal_error_and_a_failed_summary() {
    // A model built in code with a block whose material does not exist: the run
    // panics deep inside the assembly; `run` reports it as an internal error and
    // writes summary.json with status failed (the command does the same for panics
    // outside a run, with the input file named).
    let mut model = rothe::config::from_str(&good(), Path::new(".")).unwrap();
    model.mesh.blocks[0].material = 7;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let e = rothe::run::run(
        &model,
        &rothe::run::RunOptions::new(&out, rothe::linsolve::Backend::Faer),
    )
    .unwrap_err();
    assert!(matches!(e, rothe::Error::Internal(_)), "{e:?}");
    assert!(e.to_string().contains("internal error"), "{e}");
    assert_eq!(summary(&out)["status"], "failed");
}

#[test]
fn memory_is_estimated_before_it_is_taken() {
    // A mistyped division count: refused before the mesh is built, with the estimate
    // and the memory available.
    refused(
        &good().replace("divisions = [8, 2]", "divisions = [200000, 100000]"),
        &["bodies[..].mesh.divisions", "needs about", "available"],
    );
    // Counts whose product overflows.
    refused(
        &good().replace(
            "divisions = [8, 2]",
            "divisions = [9223372036854775807, 9223372036854775807]",
        ),
        &["divisions", "overflows"],
    );
    // A box of hexahedra: 8 000 000 cells (a solid's factor grows as n^{4/3}),
    // refused by the estimate before anything is built; and one whose node count
    // overflows.
    let solid = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/solid/cantilever.toml"),
    )
    .unwrap();
    refused(
        &solid.replace("divisions = [16, 4, 4]", "divisions = [800, 100, 100]"),
        &["bodies[..].mesh.divisions", "needs about", "available"],
    );
    refused(
        &solid.replace(
            "divisions = [16, 4, 4]",
            "divisions = [4294967296, 4294967296, 4294967296]",
        ),
        &["divisions", "overflows"],
    );
    // Through the library with a small limit: the model is refused naming the parts.
    let e = rothe::config::from_str_with(
        &good(),
        Path::new("."),
        &rothe::config::LoadOptions {
            memory_limit: Some(10_000),
            allow_unstable: false,
            distributed_factor: false,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("factor") && e.contains("only 10.0 kB is available"),
        "{e}"
    );
}

#[test]
fn check_reports_steps_and_output_and_refuses_absurd_step_counts() {
    let dir = tempfile::tempdir().unwrap();
    let huge = good().replace("dt = 1.0e-5", "dt = 1.0e-12");
    let sc = scenario(dir.path(), "huge.toml", &huge);
    let (ok, out, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.contains("steps       100000000 of h"), "{out}");
    assert!(out.contains("history.csv 100000001 rows"), "{out}");
    assert!(out.contains("VTK files"), "{out}");
    assert!(
        out.contains("warning") && out.contains("100000000 steps"),
        "{out}"
    );
    refused(
        &good().replace("dt = 1.0e-5", "dt = 1.0e-300"),
        &["analysis.dt", "does not fit a step counter"],
    );
}

#[test]
fn a_killed_run_is_marked_running() {
    // summary.json exists from the first step on with status "running": a run killed
    // part way is never taken for a complete one.
    let dir = tempfile::tempdir().unwrap();
    let text = crate::workload::cantilever_scenario(
        [40, 10],
        1e-6,
        1.0,
        "model = \"elastic\"\nE = 30e9\nnu = 0.2\nrho = 2400.0",
        "vtk_every = 0",
    );
    let sc = scenario(dir.path(), "long.toml", &text);
    let out = dir.path().join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_rothe"))
        .args([
            "run",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ])
        .spawn()
        .unwrap();
    let start = Instant::now();
    let rows = || {
        std::fs::read_to_string(out.join("history.csv"))
            .map(|s| s.lines().count())
            .unwrap_or(0)
    };
    while rows() < 20 && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(rows() >= 20, "the run wrote its rows as it went");
    let s = summary(&out);
    assert_eq!(s["status"], "running", "{s}");
}

#[test]
fn the_model_must_be_consistent() {
    // A bar whose name is an existing set of its body.
    refused(
        &(good()
            + "[materials.steel]\nmodel = \"elastic\"\nE = 200e9\nnu = 0.3\nrho = 7850.0\n[[bars]]\nname = \"top\"\nbody = \"beam\"\nmaterial = \"steel\"\narea = 1e-4\nfrom = [0.0, 0.5]\nto = [2.0, 0.5]\n"),
        &["bars[0].name", "`beam.top` is already a set"],
    );
    // Two probes of one name.
    refused(
        &(good() + "[[probes]]\nname = \"tip\"\nat = [1.0, 0.25]\n"),
        &["probes[1].name", "duplicate probe name `tip`"],
    );
    // A support and a prescribed displacement on the same dof: both are named.
    refused(
        &(good() + "[[prescribed]]\nset = \"beam.left\"\ncomponent = \"y\"\nvalue = 1e-4\n"),
        &["prescribed[0]", "supports[0]", "already holds"],
    );
    // Overlapping supports are fine (both hold the dof at zero).
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(
        dir.path(),
        "ok.toml",
        &(good() + "[[supports]]\nset = \"beam.bottom_left\"\nfix = [\"x\"]\n"),
    );
    assert!(rothe(&["check", sc.to_str().unwrap()]).0);
    // A probe far from every body.
    refused(
        &good().replace("at = [2.0, 0.25]", "at = [5.0, 0.25]"),
        &["probes[0].at", "lies on no body", "from the nearest node"],
    );
}

/// The square of `tests/data/square.msh` (two triangles, physical curves `bottom`
/// and `top`, surface `body`) with an empty physical group `empty` added.
fn gmsh() -> String {
    let square = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/square.msh"),
    )
    .unwrap();
    square
        .replace("$PhysicalNames\n3\n", "$PhysicalNames\n4\n")
        .replace("$EndPhysicalNames", "1 9 \"empty\"\n$EndPhysicalNames")
}

#[test]
fn mesh_errors_name_the_file_the_body_and_the_element() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("sq.msh"), gmsh()).unwrap();
    let text = good().replace(
        "mesh = { kind = \"rectangle\", size = [2.0, 0.5], divisions = [8, 2] }",
        "mesh = { kind = \"gmsh\", file = \"sq.msh\" }",
    );
    // An empty group is reported as empty, not unknown.
    let with_empty = text
        .replace("set = \"beam.left\"", "set = \"beam.empty\"")
        .replace("set = \"beam.top\"", "set = \"beam.bottom\"")
        .replace("at = [2.0, 0.25]", "at = [1.0, 0.0]");
    let sc = scenario(dir.path(), "e.toml", &with_empty);
    let (ok, _, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("supports[0].set") && err.contains("node set `beam.empty` is empty"),
        "{err}"
    );
    // Coordinates of 1e200 m: the square's area overflows, which is said as such
    // (it was called "degenerate").
    let huge = gmsh().replace("\n1 0 0\n", "\n1e200 0 0\n");
    assert_ne!(huge, gmsh());
    std::fs::write(dir.path().join("sq.msh"), huge).unwrap();
    let sc = scenario(dir.path(), "h.toml", &text);
    let (ok, _, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(
        !ok && err.contains("out of range") && !err.contains("degenerate"),
        "{err}"
    );
}

#[test]
fn a_gmsh_node_of_no_element_is_refused_with_its_tag() {
    let part = rothe::mesh::gmsh::parse(gmsh().as_bytes()).unwrap();
    assert!(part.check().is_ok());
    // A fifth node (tag 5, on a point entity) that no element uses.
    let patched = gmsh()
        .replace("$Nodes\n3 4 1 4\n", "$Nodes\n4 5 1 5\n")
        .replace("$EndNodes", "0 1 0 1\n5\n0.5 0.5 0\n$EndNodes");
    let err = rothe::mesh::gmsh::parse(patched.as_bytes())
        .and_then(|p| p.check())
        .unwrap_err();
    assert!(err.contains("node with Gmsh tag 5 at [0.5, 0.5]"), "{err}");
    assert!(err.contains("belongs to no element"), "{err}");
}

#[test]
fn a_singular_static_model_is_traced_to_its_unsupported_body() {
    let dir = tempfile::tempdir().unwrap();
    let text = good()
        .replace("vtk_every = 5", "vtk_every = 5\nkind = \"static\"")
        .replace(
            "[[supports]]\nset = \"beam.left\"\nfix = [\"x\", \"y\"]\n",
            "",
        );
    let sc = scenario(dir.path(), "free.toml", &text);
    let out = dir.path().join("out");
    let (ok, _, err) = rothe(&[
        "run",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok);
    assert!(err.contains("not positive definite"), "{err}");
    assert!(err.contains("body `beam` has no supports"), "{err}");
    assert_eq!(summary(&out)["status"], "failed");
}

#[test]
fn a_material_path_with_bad_numbers_is_refused_and_a_good_one_streams() {
    let dir = tempfile::tempdir().unwrap();
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/materials/mazars_tension.toml");
    let text = std::fs::read_to_string(&file).unwrap();
    for (bad, words) in [
        (
            text.replace("amplitude = 1.0", "amplitude = nan"),
            vec!["path.amplitude", "finite"],
        ),
        (
            text.replace("[1.0, 1.0e-3]", "[1.0, inf]"),
            vec!["path.function.points[1][1]", "finite"],
        ),
        (
            text.replace("dt = 1.0e-3", "dt = 1.0e-300"),
            vec!["path.dt", "steps"],
        ),
        // A uniaxial path given a table: refused, not ignored.
        (
            text.replace("dt = 1.0e-3", "dt = 1.0e-3\ntimes = [0.0, 1.0]"),
            vec!["path.times", "table path only"],
        ),
        (
            text.replace("dt = 1.0e-3", "dt = 1.0e-3\nstrains = [[0.0, 0.0, 0.0]]"),
            vec!["path.strains", "table path only"],
        ),
    ] {
        let f = dir.path().join("bad.toml");
        std::fs::write(&f, bad).unwrap();
        let out = dir.path().join("m");
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

/// A real Gmsh 4.1 mesh of `tests/data` (a 2 x 1 plate with a hole of radius 0.2 at
/// (1, 0.5); physical curves `left`, `right`, `hole`, surface `plate`).
fn plate(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

/// The coordinates of every node of `part` by its Gmsh tag.
fn by_tag(part: &rothe::mesh::Part) -> std::collections::BTreeMap<u64, [f64; 3]> {
    let tags = part.node_tags.as_ref().unwrap();
    tags.iter()
        .copied()
        .zip(part.coords.iter().copied())
        .collect()
}

/// The ASCII plate with its `$Nodes` section rewritten by `edit`, which gets each
/// block's tags and coordinate lines and returns them as the block should list them.
fn with_node_blocks(edit: impl Fn(&mut Vec<String>, &mut Vec<String>)) -> String {
    let text = String::from_utf8(plate("plate_tri.msh")).unwrap();
    let (head, rest) = text.split_once("$Nodes\n").unwrap();
    let (nodes, tail) = rest.split_once("$EndNodes\n").unwrap();
    let mut lines = nodes.lines();
    let mut out = format!("{head}$Nodes\n{}\n", lines.next().unwrap());
    while let Some(header) = lines.next() {
        let n: usize = header.split_whitespace().nth(3).unwrap().parse().unwrap();
        let mut tags: Vec<String> = (0..n).map(|_| lines.next().unwrap().into()).collect();
        let mut xyz: Vec<String> = (0..n).map(|_| lines.next().unwrap().into()).collect();
        edit(&mut tags, &mut xyz);
        out.push_str(header);
        out.push('\n');
        for l in tags.iter().chain(&xyz) {
            out.push_str(l);
            out.push('\n');
        }
    }
    out + "$EndNodes\n" + tail
}

#[test]
fn gmsh_nodes_get_their_own_coordinates_whatever_the_order_of_their_tags() {
    let ascii = rothe::mesh::gmsh::parse(&plate("plate_tri.msh")).unwrap();
    ascii.check().unwrap();
    // The geometry is where the file says it is: every node of `hole` on the circle,
    // of `left` at x = 0, of `right` at x = 2.
    for &n in &ascii.node_sets["hole"] {
        let [x, y, _] = ascii.coords[n];
        assert!(((x - 1.0).hypot(y - 0.5) - 0.2).abs() < 1e-9, "{x}, {y}");
    }
    assert!(ascii.node_sets["left"]
        .iter()
        .all(|&n| ascii.coords[n][0] == 0.0));
    assert!(ascii.node_sets["right"]
        .iter()
        .all(|&n| ascii.coords[n][0] == 2.0));
    let reference = by_tag(&ascii);
    // Gmsh's binary file of the same mesh.
    let binary = rothe::mesh::gmsh::parse(&plate("plate_tri_binary.msh")).unwrap();
    // (The ASCII file has 16 significant digits, the binary all 17.)
    let b = by_tag(&binary);
    assert!(b.keys().eq(reference.keys()));
    for (t, x) in &b {
        let y = reference[t];
        assert!(
            (x[0] - y[0]).abs() < 1e-14 && (x[1] - y[1]).abs() < 1e-14,
            "tag {t}"
        );
    }
    assert_eq!(binary.node_sets, ascii.node_sets);
    assert_eq!(binary.blocks[0].conn.len(), ascii.blocks[0].conn.len());
    // Every block listed in descending order of its tags: the same node, the same
    // place (the defect this guards against rotated the mesh).
    let descending = with_node_blocks(|tags, xyz| {
        tags.reverse();
        xyz.reverse();
    });
    let part = rothe::mesh::gmsh::parse(descending.as_bytes()).unwrap();
    assert_eq!(by_tag(&part), reference);
    let area = |p: &rothe::mesh::Part| -> f64 {
        (0..p.blocks[0].len())
            .map(|e| {
                let c = |k: usize| p.coords[p.blocks[0].element(e)[k]];
                let (a, b, d) = (c(0), c(1), c(2));
                0.5 * ((b[0] - a[0]) * (d[1] - a[1]) - (d[0] - a[0]) * (b[1] - a[1]))
            })
            .sum()
    };
    let plate_area = 2.0 - std::f64::consts::PI * 0.04;
    assert!((area(&part) - area(&ascii)).abs() < 1e-12);
    assert!((area(&ascii) - plate_area).abs() < 0.01, "{}", area(&ascii));
    // Sparse tags (every tag times 10, the elements' references too).
    let text = String::from_utf8(plate("plate_tri.msh")).unwrap();
    let times_ten = |line: &str| -> String {
        line.split_whitespace()
            .map(|w| format!("{}0", w))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let sparse = with_node_blocks(|tags, _| {
        for t in tags.iter_mut() {
            *t = times_ten(t);
        }
    });
    let (head, elements) = sparse.split_once("$Elements\n").unwrap();
    let mut lines = elements.lines();
    let mut rebuilt = format!("{head}$Elements\n{}\n", lines.next().unwrap());
    while let Some(header) = lines.next() {
        if header == "$EndElements" {
            rebuilt += "$EndElements\n";
            break;
        }
        let n: usize = header.split_whitespace().nth(3).unwrap().parse().unwrap();
        rebuilt += &format!("{header}\n");
        for _ in 0..n {
            let l = lines.next().unwrap();
            let (tag, nodes) = l.trim().split_once(' ').unwrap();
            rebuilt += &format!("{tag} {}\n", times_ten(nodes));
        }
    }
    rebuilt += &text[text.find("$EndElements\n").unwrap() + "$EndElements\n".len()..];
    let part = rothe::mesh::gmsh::parse(rebuilt.as_bytes()).unwrap();
    let tens: std::collections::BTreeMap<u64, [f64; 3]> =
        reference.iter().map(|(t, x)| (10 * t, *x)).collect();
    assert_eq!(by_tag(&part), tens);
    assert_eq!(part.node_sets, ascii.node_sets);
    // Quadrilaterals read as well (Gmsh's recombined mesh).
    let quads = rothe::mesh::gmsh::parse(&plate("plate_quad.msh")).unwrap();
    quads.check().unwrap();
    assert_eq!(quads.blocks[0].kind, rothe::mesh::ElementKind::Quad4);
}

#[test]
fn gmsh_files_that_define_a_tag_twice_or_never_are_refused_naming_it() {
    let text = String::from_utf8(plate("plate_tri.msh")).unwrap();
    let parse = |t: &str| {
        rothe::mesh::gmsh::parse(t.as_bytes())
            .err()
            .unwrap_or_default()
    };
    // A node tag repeated: the second block's tag becomes the first block's.
    let repeated = with_node_blocks(|tags, _| {
        if tags.len() > 1 {
            tags[1] = tags[0].clone();
        }
    });
    let e = parse(&repeated);
    assert!(e.contains("is defined twice"), "{e}");
    // The triangles: the lines after the surface block's header `2 <entity> 2 <n>`.
    let (head, els) = text.split_once("$Elements\n").unwrap();
    let lines: Vec<String> = els.lines().map(String::from).collect();
    let header = 1 + lines[1..]
        .iter()
        .position(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            w.len() == 4 && w[0] == "2" && w[2] == "2"
        })
        .unwrap();
    let (first_tri, last) = (header + 1, lines.len() - 2);
    assert_eq!(lines[last + 1], "$EndElements");
    let file = |lines: &[String]| format!("{head}$Elements\n{}\n", lines.join("\n"));
    let fields = |l: &str| -> Vec<String> { l.split_whitespace().map(String::from).collect() };
    // An element using a tag no block defines.
    let mut undefined = lines.clone();
    let mut w = fields(&lines[last]);
    w[1] = "99999".into();
    undefined[last] = w.join(" ");
    let e = parse(&file(&undefined));
    assert!(
        e.contains(&format!(
            "element with Gmsh tag {} refers to node tag 99999",
            w[0]
        )) && e.contains("no node block defines"),
        "{e}"
    );
    // An element tag used twice.
    let mut dup = lines.clone();
    let mut w = fields(&lines[last]);
    let tag0 = fields(&lines[first_tri])[0].clone();
    w[0] = tag0.clone();
    dup[last] = w.join(" ");
    let e = parse(&file(&dup));
    assert!(
        e.contains(&format!("element tag {tag0} is used by two elements")),
        "{e}"
    );
    // The same triangle twice under two tags.
    let mut twice = lines.clone();
    let mut w = fields(&lines[first_tri]);
    w[0] = fields(&lines[last])[0].clone();
    twice[last] = w.join(" ");
    let e = parse(&file(&twice));
    assert!(e.contains("have the same nodes"), "{e}");
    // Two physical groups of one name.
    let e = parse(&text.replace("1 3 \"right\"", "1 3 \"left\""));
    assert!(e.contains("two physical groups are named `left`"), "{e}");
    // A node off the plane z = 0.
    let lifted = with_node_blocks(|_, xyz| {
        if xyz.len() > 2 {
            let w: Vec<&str> = xyz[1].split_whitespace().collect();
            xyz[1] = format!("{} {} 0.01", w[0], w[1]);
        }
    });
    let e = parse(&lifted);
    assert!(e.contains("lies off the plane z = 0"), "{e}");
    // Through `check`: the file and the tag named.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("p.msh"), &repeated).unwrap();
    let sc = good().replace(
        "mesh = { kind = \"rectangle\", size = [2.0, 0.5], divisions = [8, 2] }",
        "mesh = { kind = \"gmsh\", file = \"p.msh\" }",
    );
    let sc = scenario(dir.path(), "p.toml", &sc);
    let (ok, _, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("p.msh") && err.contains("is defined twice"),
        "{err}"
    );
}

/// A block 0.1 x 0.1 m at 1e5 m/s downwards, its bottom 0.05 m above the master: a
/// rigid line at y = 0 (`rigid`: the block is steel), or the top of a fixed steel
/// block 0.4 x 0.2 m (the striker then has steel's stiffness and a density of 1, so
/// that its 5e6 J stay within what the linear elastic target can take). At
/// h = 1 µs the striker travels 0.1 m a step: twice the gap, more than the contact's
/// search radius (an element).
fn tunnelling(rigid: bool, scheme: &str) -> String {
    let master = if rigid {
        "rigid_line = [[-1.0, 0.0], [1.0, 0.0]]".to_string()
    } else {
        "master = \"target.top\"".to_string()
    };
    let target = if rigid {
        ""
    } else {
        "[[bodies]]\nname = \"target\"\nmaterial = \"steel\"\nthickness = 0.1\n\
         mesh = { kind = \"rectangle\", origin = [-0.2, -0.2], size = [0.4, 0.2], divisions = [8, 4] }\n\n\
         [[supports]]\nset = \"target.bottom\"\nfix = [\"x\", \"y\"]\n"
    };
    let step = if scheme == "backward_euler" {
        "dt = 1.0e-6"
    } else {
        ""
    };
    let striker = if rigid { "steel" } else { "light" };
    format!(
        r#"
[analysis]
scheme = "{scheme}"
t_end = 2.0e-5
{step}
vtk_every = 0

[materials.steel]
model = "elastic"
E = 210e9
nu = 0.3
rho = 7850.0

[materials.light]
model = "elastic"
E = 210e9
nu = 0.3
rho = 1.0

[[bodies]]
name = "striker"
material = "{striker}"
thickness = 0.1
velocity = [0.0, -1.0e5]
mesh = {{ kind = "rectangle", origin = [-0.05, 0.05], size = [0.1, 0.1], divisions = [2, 2] }}

{target}
[[contact]]
name = "hit"
slave = "striker.bottom"
{master}
"#
    )
}

#[test]
fn a_body_crossing_a_master_within_one_step_is_caught_by_both_paths() {
    use rothe::time::Integrator;
    for rigid in [true, false] {
        for scheme in ["backward_euler", "central_difference"] {
            let m = rothe::config::from_str(&tunnelling(rigid, scheme), Path::new(".")).unwrap();
            // The slaves: the striker's bottom nodes. (Its other nodes are not
            // contact nodes: at this speed the elastic block is crushed through
            // itself in a step, which the model allows.)
            let striker: Vec<usize> = (0..m.mesh.n_nodes())
                .filter(|&n| m.mesh.node_body[n] == 0 && m.mesh.coords[n][1] == 0.05)
                .collect();
            assert_eq!(striker.len(), 3);
            let top: Vec<usize> = (0..m.mesh.n_nodes())
                .filter(|&n| m.mesh.node_body[n] == 1 && m.mesh.coords[n][1] == 0.0)
                .collect();
            let check = |s: &rothe::time::State, step: usize| {
                // Every slave stays above the master (the rigid line at 0, the lowest
                // node of the target's top) and no tracked slave penetrates.
                let tol = 1e-3;
                let lowest = striker
                    .iter()
                    .map(|&n| m.mesh.coords[n][1] + s.u[2 * n + 1])
                    .fold(f64::INFINITY, f64::min);
                let floor = if rigid {
                    -tol
                } else {
                    top.iter()
                        .map(|&n| m.mesh.coords[n][1] + s.u[2 * n + 1])
                        .fold(f64::INFINITY, f64::min)
                        - tol
                };
                assert!(
                    s.contact.pairs[0].penetration <= m.analysis.contact.tolerance,
                    "rigid {rigid}, {scheme}, step {step}: penetration {}",
                    s.contact.pairs[0].penetration
                );
                assert!(
                    lowest >= floor,
                    "rigid {rigid}, {scheme}, step {step}: a slave at y = {lowest}: it passed through"
                );
            };
            let mean_vy = |s: &rothe::time::State| {
                striker.iter().map(|&n| s.v[2 * n + 1]).sum::<f64>() / striker.len() as f64
            };
            // Marched as `run` does (a step the contact iteration cannot close is cut).
            let mut touched = false;
            let mut steps = 0;
            let mut observe = |s: &rothe::time::State| {
                if s.step > steps {
                    steps = s.step;
                    check(s, s.step);
                    touched |= s.contact.pairs[0].force > 0.0;
                }
            };
            let control = rothe::time::march::StepControl::of(&m);
            let vy = if scheme == "backward_euler" {
                let mut be = rothe::time::backward_euler::BackwardEuler::new(
                    &m,
                    rothe::linsolve::Backend::Faer,
                )
                .unwrap();
                let mut s = be.initial_state();
                rothe::time::march::march(&mut be, &mut s, control, |_, s, _| {
                    observe(s);
                    Ok(())
                })
                .unwrap();
                mean_vy(&s)
            } else {
                let mut cd = rothe::time::central_difference::CentralDifference::new(&m).unwrap();
                let mut s = cd.initial_state().unwrap();
                rothe::time::march::march(&mut cd, &mut s, control, |_, s, _| {
                    observe(s);
                    Ok(())
                })
                .unwrap();
                mean_vy(&s)
            };
            eprintln!("rigid {rigid}, {scheme}: {steps} steps, slaves' mean v_y {vy:.3e} m/s");
            assert!(
                touched,
                "rigid {rigid}, {scheme}: no contact force at any step"
            );
            if scheme == "backward_euler" {
                // Backward Euler stops the contact nodes (the impact is inelastic at
                // them); central differences leave them ringing with the crushed block.
                assert!(
                    vy.abs() < 2e3,
                    "rigid {rigid}: the slaves still move at {vy} m/s"
                );
            }
        }
    }
}

#[test]
fn bodies_overlapping_at_the_start_are_refused_with_the_pair_node_and_depth() {
    // The target moved up 0.06 m, 0.01 m into the striker (rigid line: the striker
    // 0.02 m below it).
    let pair = tunnelling(false, "backward_euler")
        .replace("origin = [-0.2, -0.2]", "origin = [-0.2, -0.14]");
    refused(
        &pair,
        &[
            "contact[0]",
            "pair `hit`",
            "overlap at the start",
            "of body `striker`",
            "1.000e-2 m behind",
        ],
    );
    let rigid = tunnelling(true, "backward_euler")
        .replace("origin = [-0.05, 0.05]", "origin = [-0.05, -0.02]");
    refused(
        &rigid,
        &[
            "contact[0]",
            "overlap at the start",
            "2.000e-2 m behind its rigid line",
        ],
    );
    // Touching is fine.
    accepted(
        &tunnelling(true, "backward_euler")
            .replace("origin = [-0.05, 0.05]", "origin = [-0.05, 0.0]"),
    );
}

#[test]
fn arrays_with_more_or_fewer_entries_than_the_quantity_are_refused() {
    let text = good();
    let cases: [(&str, &str, &str); 3] = [
        (
            "vtk_every = 5",
            "vtk_every = 5\ngravity = [0.0, -9.81, 0.0]",
            "analysis.gravity",
        ),
        (
            "vtk_every = 5",
            "vtk_every = 5\nrayleigh = [1.0]",
            "analysis.rayleigh",
        ),
        ("at = [2.0, 0.25]", "at = [2.0, 0.25, 7.0]", "probes[0].at"),
    ];
    for (from, to, field) in cases {
        assert!(text.contains(from));
        refused(&text.replacen(from, to, 1), &[field, "entries, expected"]);
    }
    let rigid = tunnelling(true, "backward_euler").replace(
        "[[-1.0, 0.0], [1.0, 0.0]]",
        "[[-1.0, 0.0], [1.0, 0.0], [2.0, 0.0]]",
    );
    refused(
        &rigid,
        &["contact[0].rigid_line", "has 3 entries, expected 2"],
    );
    // The same through --set.
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", &good());
    let (ok, _, err) = rothe(&[
        "check",
        sc.to_str().unwrap(),
        "--set",
        "bodies.0.velocity=[1.0, 0.0, 3.0]",
    ]);
    assert!(
        !ok && err.contains("bodies[0].velocity") && err.contains("has 3 entries"),
        "{err}"
    );
}

#[test]
fn overrides_that_would_change_nothing_are_refused_or_warned() {
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", &good());
    let s = sc.to_str().unwrap();
    // --unset of a key the scenario does not have.
    let (ok, _, err) = rothe(&["check", s, "--unset", "analysis.dtt"]);
    assert!(!ok && err.contains("`analysis` has no key `dtt`"), "{err}");
    // meshing.element_size on bodies that give divisions: by --set and by a study.
    let (ok, _, err) = rothe(&["check", s, "--set", "meshing.element_size=0.1"]);
    assert!(
        !ok && err.contains("meshing.element_size") && err.contains("no body takes it"),
        "{err}"
    );
    let out = dir.path().join("study");
    let (ok, _, err) = rothe(&[
        "study",
        "mesh",
        s,
        "--sizes",
        "0.2,0.1",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok && err.contains("no body takes it"), "{err}");
    assert!(
        !out.join("study.md").exists(),
        "a refused plan reports nothing"
    );
    // --variant twice for one group.
    let bench = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/benchmarks/two_blocks.toml");
    let (ok, _, err) = rothe(&[
        "check",
        bench.to_str().unwrap(),
        "--variant",
        "concrete=elastic",
        "--variant",
        "concrete=mazars",
    ]);
    assert!(!ok && err.contains("selected twice"), "{err}");
    // Keys only the other scheme reads: warned of by check and by run (and kept in
    // summary.json).
    let text = tunnelling(true, "central_difference").replace(
        "vtk_every = 0",
        "vtk_every = 0\ncontact_qp = \"full\"\niteration = \"fixed\"\nomega = 0.5\ndt = 1.0e-7",
    );
    let sc = scenario(dir.path(), "x.toml", &text);
    let (ok, out, err) = rothe(&["check", sc.to_str().unwrap()]);
    assert!(ok, "{err}");
    for key in [
        "analysis.contact_qp",
        "analysis.iteration",
        "analysis.omega",
    ] {
        assert!(
            out.contains(&format!("warning     {key}")),
            "{key} not warned of: {out}"
        );
    }
    let run_out = dir.path().join("x");
    let (ok, _, err) = rothe(&[
        "run",
        sc.to_str().unwrap(),
        "--out",
        run_out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains("warning: analysis.contact_qp is not read: central differences"),
        "{err}"
    );
    assert_eq!(summary(&run_out)["warnings"].as_array().unwrap().len(), 3);
}

#[test]
fn messages_name_the_field_the_line_and_the_column() {
    let text = good();
    // A type error in the file: the field's path, line and column.
    let bad = text.replacen("thickness = ", "thickness = \"thin\" #", 1);
    refused(
        &bad,
        &[
            "bodies[0].thickness (line ",
            "column ",
            "invalid type: string \"thin\", expected f64",
        ],
    );
    // Inside a material (read through its `model` tag): the key is still named.
    let e_bad = text.replacen("E = 30e9", "E = \"stiff\"", 1);
    refused(
        &e_bad,
        &[".E (line ", "invalid type: string \"stiff\", expected f64"],
    );
    // A syntax error: line and column.
    let syntax = text.replacen("vtk_every = 5", "vtk_every = 5 5", 1);
    refused(&syntax, &["line ", ", column "]);
    // A type error through --set: the field's path.
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", &text);
    let (ok, _, err) = rothe(&["check", sc.to_str().unwrap(), "--set", "analysis.dt=fast"]);
    assert!(
        !ok && err.contains("analysis.dt (after variants and --set): invalid type"),
        "{err}"
    );
    // A product that overflows: named as such, not as a singular stiffness.
    let thick = text.replacen("thickness = ", "thickness = 1e300 #", 1);
    refused(&thick, &["bodies[0].thickness", "overflow"]);
}

#[test]
fn an_output_directory_never_mixes_two_runs() {
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", &good());
    let s = sc.to_str().unwrap();
    // A file where the directory should be.
    let file = dir.path().join("taken");
    std::fs::write(&file, "x").unwrap();
    let (ok, _, err) = rothe(&["run", s, "--out", file.to_str().unwrap(), "--quiet"]);
    assert!(!ok && err.contains("is a file, not a directory"), "{err}");
    // An earlier run is refused, then replaced with --overwrite: its VTK files go.
    let out = dir.path().join("o");
    let o = out.to_str().unwrap();
    let (ok, _, err) = rothe(&["run", s, "--out", o, "--quiet"]);
    assert!(ok, "{err}");
    let vtk_before = out.join("vtk").read_dir().unwrap().count();
    assert!(vtk_before > 1);
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let (ok, _, err) = rothe(&[
        "run",
        s,
        "--out",
        o,
        "--quiet",
        "--set",
        "analysis.vtk_every=0",
    ]);
    assert!(
        !ok && err.contains("holds an earlier run") && err.contains("--overwrite"),
        "{err}"
    );
    let (ok, _, err) = rothe(&[
        "run",
        s,
        "--out",
        o,
        "--quiet",
        "--set",
        "analysis.vtk_every=0",
        "--overwrite",
    ]);
    assert!(ok, "{err}");
    assert!(!out.join("vtk").exists(), "a stale VTK series stayed");
    assert!(!out.join("result.pvd").exists());
    assert_eq!(summary(&out)["status"], "completed");
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn sweeps_that_lose_runs_fail_and_name_each_one() {
    let dir = tempfile::tempdir().unwrap();
    // compare on a scenario whose runs fail part way (its block is driven into a V
    // of rigid lines: no motion keeps it out of both). Each failure is printed with
    // its own error, quiet or not, and the command fails.
    let vee =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/vee.toml"))
            .unwrap();
    let sc = scenario(dir.path(), "vee.toml", &vee);
    let out = dir.path().join("cmp");
    let (ok, _, err) = rothe(&[
        "compare",
        sc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok, "a sweep with a failed run exits non-zero: {err}");
    for run in ["implicit", "explicit"] {
        assert!(
            err.contains(&format!("run {run} ({run}) failed: time stepping"))
                || (run == "explicit"
                    && err.contains("run explicit (explicit) failed: energy check failed")),
            "{err}"
        );
    }
    assert!(err.contains("Clarabel status DualInfeasible"), "{err}");
    // Bad plans are refused before anything runs.
    let good_sc = scenario(dir.path(), "g.toml", &good());
    let g = good_sc.to_str().unwrap();
    for (args, words) in [
        (vec!["study", "time", g, "--halvings", "40"], "--halvings"),
        (
            vec!["study", "time", g, "--halvings", "2", "--jobs", "0"],
            "--jobs",
        ),
        (
            vec!["study", "time", g, "--h", "1e-5,1e-12"],
            "steps in all",
        ),
    ] {
        let o = dir.path().join("bad");
        let mut a = args.clone();
        a.extend(["--out", o.to_str().unwrap(), "--quiet"]);
        let (ok, _, err) = rothe(&a);
        assert!(!ok && err.contains(words), "{args:?}: {err}");
        assert!(
            !o.join("runs").exists(),
            "{args:?} ran before it was refused"
        );
    }
    // collect of a plan whose runs never ran.
    let emitted = dir.path().join("emitted");
    let (ok, _, err) = rothe(&[
        "study",
        "time",
        g,
        "--h",
        "1e-5,5e-6",
        "--emit",
        emitted.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let (ok, _, err) = rothe(&["study", "collect", emitted.to_str().unwrap()]);
    assert!(!ok && err.contains("run them first"), "{err}");
}

#[test]
fn the_kept_factor_settings_are_checked_and_default_by_the_kind_of_analysis() {
    let with = |lines: &str| good().replace("vtk_every = 5", &format!("vtk_every = 5\n{lines}"));
    for bad in ["0.0", "1.0", "-0.5", "nan", "2.0"] {
        refused(
            &with(&format!("refactor_rate = {bad}")),
            &["analysis.refactor_rate", "between 0 and 1"],
        );
    }
    refused(
        &with("keep_factor = false\nrefactor_rate = 0.2"),
        &["analysis.refactor_rate", "keep_factor = false"],
    );
    // Dynamics keep the factor by default, statics refactorise at every changed
    // tangent unless told otherwise (theory/equilibrium.md says why).
    let load = |text: &str| rothe::config::from_str(text, Path::new(".")).unwrap();
    let dynamic = load(&good());
    assert_eq!(
        dynamic.analysis.iteration.refactor_rate,
        Some(rothe::model::DEFAULT_REFACTOR_RATE)
    );
    assert_eq!(
        load(&with("refactor_rate = 0.3"))
            .analysis
            .iteration
            .refactor_rate,
        Some(0.3)
    );
    assert_eq!(
        load(&with("keep_factor = false"))
            .analysis
            .iteration
            .refactor_rate,
        None
    );
    let statics = good().replace("[analysis]", "[analysis]\nkind = \"static\"");
    assert_eq!(load(&statics).analysis.iteration.refactor_rate, None);
    let kept_statics = statics.replace("vtk_every = 5", "vtk_every = 5\nkeep_factor = true");
    assert!(load(&kept_statics)
        .analysis
        .iteration
        .refactor_rate
        .is_some());
    // `check` says how the steps will iterate.
    let mazars = good().replace(
        "model = \"elastic\"",
        "model = \"mazars\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3",
    );
    let dir = tempfile::tempdir().unwrap();
    for (text, words) in [
        (mazars.clone(), "divides the residual by 10 or more"),
        (
            mazars.replace("vtk_every = 5", "vtk_every = 5\nkeep_factor = false"),
            "refactorised at every changed tangent",
        ),
    ] {
        let sc = scenario(dir.path(), "m.toml", &text);
        let (ok, out, err) = rothe(&["check", sc.to_str().unwrap()]);
        assert!(ok, "{err}");
        let line = out
            .lines()
            .find(|l| l.starts_with("iteration"))
            .unwrap_or_else(|| panic!("no iteration line: {out}"));
        assert!(line.contains(words), "{line}");
    }
    // Central differences do not read them: a warning names each.
    let explicit = with("keep_factor = true\nrefactor_rate = 0.2")
        .replace("[analysis]", "[analysis]\nscheme = \"central_difference\"")
        .replace("dt = 1.0e-5\n", "");
    let m = load(&explicit);
    for key in ["analysis.keep_factor", "analysis.refactor_rate"] {
        assert!(
            m.warnings.iter().any(|w| w.contains(key)),
            "{key} not warned: {:?}",
            m.warnings
        );
    }
}

// --- The classes of the solids, Gmsh solids, 3D contact and identification round.

/// `rothe run SCENARIO --out OUT --quiet`, and its history as columns.
fn run_history(text: &str, extra: &[&str]) -> (bool, String, BTreeColumns) {
    let (ok, err, h, _) = run_history_and_summary(text, extra);
    (ok, err, h)
}

/// [`run_history`] with the run's `summary.json`.
fn run_history_and_summary(
    text: &str,
    extra: &[&str],
) -> (bool, String, BTreeColumns, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", text);
    let out = dir.path().join("out");
    let (ok, err) = crate::common::rothe_quiet("run", &sc, &out, extra);
    let columns = std::fs::read_to_string(out.join("history.csv"))
        .map(|h| columns(&h))
        .unwrap_or_default();
    let s = std::fs::read_to_string(out.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default();
    (ok, err, columns, s)
}

type BTreeColumns = std::collections::BTreeMap<String, Vec<f64>>;

fn columns(csv: &str) -> BTreeColumns {
    let mut lines = csv.lines();
    let names: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let mut out: BTreeColumns = names.iter().map(|n| (n.clone(), Vec::new())).collect();
    for l in lines {
        for (n, v) in names.iter().zip(l.split(',')) {
            out.get_mut(n).unwrap().push(v.parse().unwrap_or(f64::NAN));
        }
    }
    out
}

/// A steel base and a small steel block on it (plane, or a solid with `solid`),
/// the block's bottom at height `y` (0.2 touches), moving at `vx`.
fn block_on_base(solid: bool, y: f64, vx: f64, formulation: &str) -> String {
    let (base, block, g, v, at) = if solid {
        (
            "mesh = { kind = \"box\", size = [1.0, 0.2, 0.2], divisions = [5, 1, 1] }",
            format!("mesh = {{ kind = \"box\", origin = [0.95, {y}, 0.05], size = [0.1, 0.05, 0.1], divisions = [2, 1, 1] }}"),
            "[0.0, -9.81, 0.0]",
            format!("[{vx}, 0.0, 0.0]"),
            format!("[0.95, {y}, 0.05]"),
        )
    } else {
        (
            "thickness = 0.1\nmesh = { kind = \"rectangle\", size = [1.0, 0.2], divisions = [10, 2] }",
            format!("thickness = 0.1\nmesh = {{ kind = \"rectangle\", origin = [0.95, {y}], size = [0.1, 0.05], divisions = [2, 1] }}"),
            "[0.0, -9.81]",
            format!("[{vx}, 0.0]"),
            format!("[0.95, {y}]"),
        )
    };
    let fix = if solid {
        "[\"x\", \"y\", \"z\"]"
    } else {
        "[\"x\", \"y\"]"
    };
    format!(
        "[analysis]\nt_end = 8.0e-3\ndt = 2.0e-5\ngravity = {g}\nvtk_every = 0\n\n\
         [materials.steel]\nmodel = \"elastic\"\nE = 210e9\nnu = 0.3\nrho = 7850.0\n\n\
         [[bodies]]\nname = \"base\"\nmaterial = \"steel\"\n{base}\n\n\
         [[bodies]]\nname = \"block\"\nmaterial = \"steel\"\nvelocity = {v}\n{block}\n\n\
         [[supports]]\nset = \"base.bottom\"\nfix = {fix}\n\n\
         [[probes]]\nname = \"corner\"\nat = {at}\n\n\
         [[contact]]\nname = \"seat\"\nslave = \"block.bottom\"\nmaster = \"base.top\"\n{formulation}\n"
    )
}

#[test]
fn a_plane_analysis_cannot_be_a_solid_nor_a_solid_plane() {
    refused(
        &good().replace("[analysis]", "[analysis]\nplane = \"solid\""),
        &["analysis.plane", "three-dimensional mesh", "`beam`"],
    );
    refused(
        &block_on_base(true, 0.2, 0.0, "").replace("[analysis]", "[analysis]\nplane = \"strain\""),
        &["analysis.plane", "is a solid", "ignored"],
    );
}

#[test]
fn overlaps_deeper_than_an_element_and_cutting_rigid_masters_are_refused() {
    // A block sunk 0.15 m (more than an element) into its base, plane (both
    // formulations) and solid.
    for f in ["", "formulation = \"node_to_segment\""] {
        refused(
            &block_on_base(false, 0.05, 0.0, f),
            &[
                "contact[0]",
                "pair `seat`",
                "overlap at the start",
                "of body `block`",
                "1.500e-1 m inside the master's body",
            ],
        );
    }
    // In a solid, 0.35 m into a base three elements high (detection reaches one).
    let sunk = block_on_base(true, 0.25, 0.0, "").replace(
        "size = [1.0, 0.2, 0.2], divisions = [5, 1, 1]",
        "size = [1.0, 0.6, 0.2], divisions = [5, 3, 1]",
    );
    refused(
        &sunk,
        &[
            "contact[0]",
            "overlap at the start",
            "3.500e-1 m inside the master's body",
        ],
    );
    // A rigid line or plane above the slave body's centroid cuts it (it would be a
    // ceiling that never acts); through the centroid it would fling the body.
    let line = |y: f64| {
        block_on_base(false, 0.2, 0.0, "").replace(
            "master = \"base.top\"",
            &format!("rigid_line = [[-1.0, {y}], [2.0, {y}]]"),
        )
    };
    for (y, depth) in [(0.23, "2.000e-2"), (0.225, "2.500e-2")] {
        refused(
            &line(y),
            &["contact[0]", "overlap at the start", depth, "rigid line"],
        );
    }
    let plane = block_on_base(true, 0.2, 0.0, "").replace(
        "master = \"base.top\"",
        "rigid_plane = { point = [0.0, 0.23, 0.0], normal = [0.0, 1.0, 0.0] }",
    );
    refused(
        &plane,
        &[
            "overlap at the start",
            "2.000e-2 m behind its rigid plane",
            "cuts the slave body",
        ],
    );
    // A normal of any magnitude has a direction.
    let tiny = block_on_base(true, 0.2, 0.0, "").replace(
        "master = \"base.top\"",
        "rigid_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1e-200, 0.0] }",
    );
    accepted(&tiny);
}

#[test]
fn a_slave_past_the_end_of_its_master_is_free_in_the_plane_and_in_a_solid() {
    // A block sliding off the base's end at 10 m/s: its left corner leaves the base
    // at 5 ms; from then on nothing holds it (before, node to segment and node to
    // face carried its weight for 1-2 ms beside the base).
    for (solid, f) in [
        (false, "formulation = \"node_to_segment\""),
        (false, ""),
        (true, ""),
    ] {
        let (ok, err, h) = run_history(&block_on_base(solid, 0.2, 10.0, f), &[]);
        assert!(ok, "{err}");
        let (ux, force) = (&h["corner_ux"], &h["seat_force"]);
        let on = (0..ux.len()).filter(|&i| ux[i] > 0.01 && ux[i] < 0.04);
        assert!(
            on.clone().all(|i| force[i] > 1.0),
            "held while on the base (solid {solid} {f})"
        );
        let off: Vec<usize> = (0..ux.len()).filter(|&i| ux[i] > 0.0502).collect();
        assert!(!off.is_empty());
        for i in off {
            assert_eq!(
                force[i], 0.0,
                "solid {solid} {f}: force {} at u_x = {}",
                force[i], ux[i]
            );
        }
    }
}

/// The two-hexahedron bar of tests/data with its `$Elements` section replaced.
fn bar_with_elements(elements: &str) -> Vec<u8> {
    let text = String::from_utf8(plate("bar_hex.msh")).unwrap();
    let start = text.find("$Elements").unwrap();
    format!("{}$Elements\n{elements}$EndElements\n", &text[..start]).into_bytes()
}

#[test]
fn gmsh_solids_are_read_as_written_or_refused_by_name() {
    use rothe::mesh::gmsh::parse;
    // A hexahedron listed twice (another tag, another order) would double the
    // stiffness.
    let twice = bar_with_elements(
        "4 6 1 6\n0 1 15 1\n5 1\n2 1 3 1\n1 1 4 10 7\n2 2 3 1\n2 3 6 12 9\n3 1 5 3\n3 1 2 5 4 7 8 11 10\n4 2 5 6 3 8 11 12 9\n6 4 5 2 1 10 11 8 7\n",
    );
    let e = parse(&twice).unwrap_err();
    assert!(e.contains("tags 3 and 6 have the same nodes"), "{e}");
    // Only prisms: the type is named (it used to be "lies off the plane z = 0").
    let prisms = bar_with_elements("1 1 1 1\n3 1 6 1\n3 1 2 4 7 8 10\n");
    let e = parse(&prisms).unwrap_err();
    assert!(e.contains("6-node prism"), "{e}");
    assert!(!e.contains("off the plane"), "{e}");
    // The left face as two triangles listed inwards on the hexahedron: turned out.
    let tris = bar_with_elements(
        "4 6 1 6\n0 1 15 1\n5 1\n2 1 2 2\n1 1 10 4\n6 1 7 10\n2 2 3 1\n2 3 6 12 9\n3 1 5 2\n3 1 2 5 4 7 8 11 10\n4 2 5 6 3 8 11 12 9\n",
    );
    let part = parse(&tris).unwrap();
    let left = &part.face_sets["left"];
    assert_eq!(left.len(), 2);
    for f in left {
        let [a, b, c] = [part.coords[f[0]], part.coords[f[1]], part.coords[f[2]]];
        let n_x = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]);
        assert!(n_x < 0.0, "the left face points out of the bar (-x): {f:?}");
    }
    // A triangle on no volume element's face is refused by its tag.
    let floating = bar_with_elements(
        "2 3 1 3\n2 1 2 1\n1 1 5 9\n3 1 5 2\n3 1 2 5 4 7 8 11 10\n4 2 5 6 3 8 11 12 9\n",
    );
    let e = parse(&floating).unwrap_err();
    assert!(
        e.contains("Gmsh tag 1") && e.contains("does not lie on a face"),
        "{e}"
    );
    // A named surface without elements is an empty set, said so where it is used.
    let text = String::from_utf8(plate("bar_hex.msh"))
        .unwrap()
        .replace("$PhysicalNames\n4\n", "$PhysicalNames\n5\n2 9 \"top\"\n");
    let part = parse(text.as_bytes()).unwrap();
    assert!(part.face_sets["top"].is_empty());
}

#[test]
fn the_crack_band_is_measured_as_the_element_measures_it() {
    // One 0.35 m cube of Mazars with G_f = 40 N/m: the band limit is
    // 2 G_f E / f_t² = 0.314 m; the element is 0.35 m across (cube root of its
    // volume), not the 0.21 m of the square root.
    let cube = "[analysis]\nkind = \"static\"\nt_end = 1.0\ndt = 1.0\n\n\
        [materials.concrete]\nmodel = \"mazars\"\nE = 33e9\nnu = 0.2\nrho = 2400.0\n\
        eps_t0 = 8.788e-5\nA_c = 1.2\nB_c = 1500.0\nfracture_energy = 40.0\n\n\
        [[bodies]]\nname = \"cube\"\nmaterial = \"concrete\"\n\
        mesh = { kind = \"box\", size = [0.35, 0.35, 0.35], divisions = [1, 1, 1] }\n\n\
        [[supports]]\nset = \"cube.bottom\"\nfix = [\"x\", \"y\", \"z\"]\n";
    refused(
        cube,
        &[
            "materials.concrete.fracture_energy",
            "0.350 m across",
            "cube root",
        ],
    );
    // Identified Rankine-Hill names the key the file has.
    let rh = good().replace(
        "model = \"elastic\"\nE = 30e9\nnu = 0.2\nrho = 2400.0",
        "model = \"rankine_hill\"\nnu = 0.2\nrho = 2400.0\nidentify = { class = \"C30/37\", fracture_energy = 20.0 }",
    );
    refused(&rh, &["identify.fracture_energy", "identified G_f = 20"]);
}

#[test]
fn every_strength_class_is_identified_and_impossible_data_are_refused() {
    for model in ["mazars", "rankine_hill"] {
        for class in ["C30/37", "C70/85", "C80/95", "C90/105"] {
            let text = good().replace(
                "model = \"elastic\"\nE = 30e9\nnu = 0.2\nrho = 2400.0",
                &format!("model = \"{model}\"\nnu = 0.2\nrho = 2400.0\nidentify = {{ class = \"{class}\" }}"),
            );
            accepted(&text);
        }
    }
    let strong_tension = good().replace(
        "model = \"elastic\"\nE = 30e9\nnu = 0.2\nrho = 2400.0",
        "model = \"rankine_hill\"\nE = 30e9\nnu = 0.2\nrho = 2400.0\nidentify = { f_ct = 50e6, f_cm = 38e6, eps_c1 = 2.2e-3 }",
    );
    refused(
        &strong_tension,
        &["identify.f_ct", "below the compressive strength"],
    );
}

#[test]
fn stored_energy_is_never_negative_under_a_large_rigid_motion() {
    // An elastic cube dropped 1 m onto a rigid plane: ½ uᵀKu lost its digits to the
    // 1 m of rigid motion (E_el = −6e-6 J, both energy checks failed).
    let text = "[analysis]\nt_end = 0.46\ndt = 2.0e-4\ngravity = [0.0, -9.81, 0.0]\nvtk_every = 0\n\n\
        [materials.steel]\nmodel = \"elastic\"\nE = 210e9\nnu = 0.3\nrho = 7850.0\n\n\
        [[bodies]]\nname = \"cube\"\nmaterial = \"steel\"\n\
        mesh = { kind = \"box\", origin = [0.0, 1.0, 0.0], size = [0.1, 0.1, 0.1], divisions = [2, 2, 2] }\n\n\
        [[contact]]\nname = \"floor\"\nslave = \"cube.bottom\"\n\
        rigid_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }\n";
    let (ok, err, h, s) = run_history_and_summary(text, &[]);
    assert!(ok, "{err}");
    assert!(h["E_el"].iter().all(|&e| e >= 0.0));
    assert!(h["floor_force"].iter().any(|&f| f > 0.0), "it lands");
    for c in [
        "dissipation_within_internal_work",
        "dissipation_within_supplied_energy",
    ] {
        assert_eq!(s["checks"][c]["holds"], true, "{c}: {}", s["checks"][c]);
    }
}

#[test]
fn central_differences_close_their_ledger_with_prescribed_motion_and_any_dt() {
    // A prescribed harmonic motion and a step that does not divide t_end: the
    // shortened last step prescribed the half-step velocity over the wrong interval
    // and the ledger missed (5e-7 here, percents on coarser steps); the steps are
    // now equal, and said so.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regression/damped_lumped_gravity.toml"),
    )
    .unwrap()
    .replace("mass = \"lumped\"", "scheme = \"central_difference\"")
    .replace("dt = 2.0e-5", "dt = 1.9e-6")
    .replace("zeta = 20.0", "zeta = 0.0")
    .replace("rayleigh = [5.0, 1.0e-6]", "")
    .replace(
        "function = { kind = \"ramp\", t0 = 0.0, t1 = 4.0e-4 }",
        "function = { kind = \"harmonic\", frequency = 2000.0 }",
    );
    let dir = tempfile::tempdir().unwrap();
    let sc = scenario(dir.path(), "s.toml", &text);
    let out = dir.path().join("out");
    let (ok, _, err) = rothe(&["run", sc.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(err.contains("316 equal steps"), "{err}");
    let s = summary(&out);
    let rel = s["energy"]["balance_residual_rel"].as_f64().unwrap();
    assert!(rel < 1e-12, "relative residual {rel}");
}

#[test]
fn a_run_that_cuts_below_dt_min_stops_as_stalled_and_says_what_to_try() {
    let bar = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/softening_bar.toml"),
    )
    .unwrap();
    let text = bar
        .replace(
            "[analysis]",
            "[analysis]\nkind = \"static\"\niteration = \"fixed\"\ndt_min = 1.0e-6",
        )
        .replace("dt = 4.0e-6", "dt = 1.0e-4")
        .replace("nonlocal = { radius = 0.04 }", "");
    let (ok, err, h) = run_history(&text, &[]);
    assert!(!ok);
    assert!(
        err.contains("stalls") && err.contains("analysis.dt_min") && err.contains("newton"),
        "{err}"
    );
    assert!(h["t"].len() > 2, "the steps before are kept");
    refused(
        &good().replace("[analysis]", "[analysis]\ndt_min = 1.0"),
        &["analysis.dt_min", "exceeds the step"],
    );
    refused(
        &good().replace(
            "[analysis]",
            "[analysis]\nkind = \"static\"\nrefactor_rate = 0.2",
        ),
        &["analysis.refactor_rate", "statics"],
    );
}

#[test]
fn a_nonlocal_radius_far_below_the_mesh_runs_as_the_local_law() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/cracking_cantilever.toml"),
    )
    .unwrap()
    .replace(
        "nonlocal = { radius = 0.1 }",
        "nonlocal = { radius = 1e-20 }",
    );
    let (ok, err, h) = run_history(&text, &["--set", "analysis.t_end=1e-4"]);
    assert!(ok, "{err}");
    assert!(!err.contains("panicked"));
    assert!(h["t"].len() > 2);
}

#[test]
fn a_body_held_by_frictionless_contact_alone_carries_any_pressure() {
    // Statics, the block with no support of its own (its sideways and rotational
    // motions held by the seat's stiffness only), plane and solid, at 3 kPa and
    // 3 MPa: the seat carries the traction's resultant.
    for (file, area) in [
        ("held_by_contact.toml", 0.5 * 0.1),
        ("held_by_contact_solid.toml", 0.4 * 0.2),
    ] {
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/data")
                .join(file),
        )
        .unwrap();
        for q in [3.0e3, 3.0e6] {
            let loaded = text.replace("-3.0e6", &format!("{:e}", -q));
            let (ok, err, h) = run_history(&loaded, &[]);
            assert!(ok, "{file} at {q} Pa: {err}");
            let f = *h["seat_force"].last().unwrap();
            assert!(
                (f - q * area).abs() < 1e-6 * q * area,
                "{file}: {f} N vs {}",
                q * area
            );
        }
    }
}

#[test]
fn a_static_load_that_contact_alone_cannot_hold_names_the_body_and_the_pair() {
    // The seated block pushed sideways as well as down: frictionless contact cannot
    // hold the push, and statics has no equilibrium. The failure says so, with the
    // body, the pair and what to add, not only "no convergence".
    for file in ["held_by_contact.toml", "held_by_contact_solid.toml"] {
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/data")
                .join(file),
        )
        .unwrap();
        let pushed = text.replace("[0.0, -3.0e6", "[1.0e5, -3.0e6");
        assert_ne!(pushed, text);
        let (ok, err, _) = run_history(&pushed, &[]);
        assert!(!ok, "{file}: a frictionless block pushed sideways stood");
        for w in [
            "body `block` has no support against this motion",
            "contact pair(s) `seat` alone",
            "frictionless contact carries only pressure",
            "friction (`mu`)",
        ] {
            assert!(err.contains(w), "{file}: `{w}` not in: {err}");
        }
        // The residuals are summed up, not listed to the last iteration.
        assert!(err.contains("…"), "{err}");
    }
}

#[test]
fn a_static_body_whose_position_contact_leaves_open_is_named_when_its_neighbour_fails() {
    // The plane patch test without its roller: the upper block's sideways position is
    // held by nothing but the seat, the load is carried, and the contact set at the
    // interface's end moves with the block, so the loop stalls with its largest
    // residual on the lower body. The failure names the upper body, its pair and
    // what to add, not only the residual's node.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/contact/patch_test.toml"),
    )
    .unwrap();
    let free = text.replace("[[supports]]\nset = \"upper.left\"\nfix = [\"x\"]\n", "");
    assert_ne!(free, text);
    let (ok, err, _) = run_history(&free, &[]);
    assert!(!ok, "the patch test without its roller converged: {err}");
    for w in [
        "body `upper` has a rigid motion that no support holds",
        "contact pair(s) `interface` alone",
        "a roller",
        "friction (`mu`)",
    ] {
        assert!(err.contains(w), "`{w}` not in: {err}");
    }
}

/// A solid block (0.1 x 0.05 x 0.1 m) over a solid base, no gravity, its bottom at
/// `y` (0.2 touches) and its velocity `v` (x, y), 200 steps of 20 µs.
fn touching_block(y: f64, v: [f64; 2]) -> String {
    format!(
        "[analysis]\nt_end = 4.0e-3\ndt = 2.0e-5\nvtk_every = 0\n\n\
         [materials.steel]\nmodel = \"elastic\"\nE = 210e9\nnu = 0.3\nrho = 7850.0\n\n\
         [[bodies]]\nname = \"base\"\nmaterial = \"steel\"\n\
         mesh = {{ kind = \"box\", size = [1.0, 0.2, 0.2], divisions = [5, 1, 1] }}\n\n\
         [[bodies]]\nname = \"block\"\nmaterial = \"steel\"\nvelocity = [{}, {}, 0.0]\n\
         mesh = {{ kind = \"box\", origin = [0.3, {y}, 0.05], size = [0.1, 0.05, 0.1], divisions = [2, 1, 2] }}\n\n\
         [[supports]]\nset = \"base.bottom\"\nfix = [\"x\", \"y\", \"z\"]\n\n\
         [[contact]]\nname = \"seat\"\nslave = \"block.bottom\"\nmaster = \"base.top\"\n",
        v[0], v[1]
    )
}

#[test]
fn a_solid_resting_or_grazing_at_a_zero_gap_keeps_its_steps() {
    // At rest on the base, sliding over it, and landing exactly at the end of the
    // fifth step: the gaps are zero to round-off, and so are the first forces. A
    // multiplier that closes only a gap of round-off is no active constraint, so
    // the active set does not flip on round-off forces and no step is cut (9, 2 and
    // 2 cut steps before).
    let landing = 0.2 + 0.5 * 2.0e-5 * 5.0;
    for (what, y, v) in [
        ("resting", 0.2, [0.0, 0.0]),
        ("sliding", 0.2, [1.0, 0.0]),
        ("landing", landing, [0.0, -0.5]),
    ] {
        let (ok, err, h, s) = run_history_and_summary(&touching_block(y, v), &[]);
        assert!(ok, "{what}: {err}");
        assert_eq!(h["t"].len(), 201, "{what}: steps were cut");
        let rel = s["energy"]["balance_residual_rel"].as_f64().unwrap();
        assert!(rel.abs() < 1e-8, "{what}: ledger {rel:e}");
    }
}

#[test]
fn a_material_file_type_error_names_the_key_inside_the_material() {
    // The `model` tag hides the key from serde's path; the message names it, as a
    // scenario's `materials.<name>.<key>` does.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/materials/mazars_tension.toml"),
    )
    .unwrap();
    for (from, to, key) in [
        ("nu = 0.2", "nu = \"abc\"", "material.nu"),
        ("E = 33e9", "E = [1, 2]", "material.E"),
    ] {
        let bad = text.replacen(from, to, 1);
        assert_ne!(bad, text);
        let dir = tempfile::tempdir().unwrap();
        let sc = scenario(dir.path(), "m.toml", &bad);
        let out = dir.path().join("out");
        let (ok, _, err) = rothe(&[
            "material",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok && !err.contains("panicked"), "{err}");
        assert!(
            err.contains(&format!("{key} (line")),
            "`{key}` not in: {err}"
        );
    }
}
