//! Error-controlled steps (`analysis.adaptive`, `theory/adaptive.md`): the global
//! error against the tolerance at each scheme's rate, a rejected step that leaves
//! no trace, the ledger under changing steps with every material model, the first
//! contact found to the ladder's bottom rung, and bad input.

use std::path::Path;

use rothe::linsolve::Backend;
use rothe::model::Model;
use rothe::time::adaptive::{march_adaptive, AdaptiveControl, AdaptiveReport};
use rothe::time::backward_euler::BackwardEuler;
use rothe::time::march::Marched;
use rothe::time::{Integrator, State};

use crate::common::model;
use crate::trapezoidal::cantilever;

/// Runs `m` with error-controlled steps, calling `each` after every step that
/// stands: the last state, the report and the sizes of the steps that stood.
fn adaptive(m: &Model, mut each: impl FnMut(&State)) -> (State, AdaptiveReport, Vec<f64>) {
    let mut i = BackwardEuler::new(m, Backend::Faer).unwrap();
    let mut s = i.initial_state();
    let report = std::cell::Cell::new(AdaptiveReport::default());
    let mut steps = Vec::new();
    let control = AdaptiveControl::of(m).expect("an adaptive scenario");
    march_adaptive(&mut i, &mut s, control, &report, |i, s, marched| {
        if let Marched::Step(_) = marched {
            steps.push(i.h());
            // The report is current at every step.
            assert_eq!(report.get().steps_accepted, steps.len());
            each(s);
        }
        Ok(())
    })
    .unwrap();
    (s, report.get(), steps)
}

/// Runs `m` with fixed steps of `h` (its `analysis.adaptive` removed), calling
/// `each` after every step.
fn fixed(m: &Model, h: f64, mut each: impl FnMut(&State)) -> State {
    let mut m = m.clone();
    m.analysis.time.adaptive = None;
    m.analysis.time.dt = h;
    let mut i = BackwardEuler::new(&m, Backend::Faer).unwrap();
    let mut s = i.initial_state();
    for _ in 0..m.analysis.n_steps() {
        i.step_accepted(&mut s).unwrap();
        each(&s);
    }
    s
}

/// The cantilever of `tests::trapezoidal` under a tip load at 100 Hz from rest,
/// to 4 ms, with error-controlled steps from 2.5e-4 s (bottom rung 2.44e-7 s)
/// landing on every 0.5 ms.
fn forced_cantilever(scheme: &str, tolerance: f64) -> Model {
    model(&forced_cantilever_text(scheme, tolerance))
}

/// The scenario text of [`forced_cantilever`].
fn forced_cantilever_text(scheme: &str, tolerance: f64) -> String {
    let load = "[[loads]]\nkind = \"traction\"\nset = \"beam.right\"\nvalue = [0.0, -1.0e6]\n\
                function = { kind = \"harmonic\", frequency = 100.0 }\n";
    let extra = format!(
        "vtk_every_time = 5.0e-4\nadaptive = {{ tolerance = {tolerance:e}, dt_max = 2.5e-4 }}"
    );
    cantilever(scheme, 2.5e-4, 4e-3, [0.0, 0.0], &extra) + load
}

/// The displacements at the landing times `k · 0.5 ms` of a run.
fn at_landings(states: &mut Vec<Vec<f64>>) -> impl FnMut(&State) + '_ {
    move |s: &State| {
        let k = s.t / 5e-4;
        if (k - k.round()).abs() < 1e-6 {
            states.push(s.u.clone());
        }
    }
}

#[test]
fn the_global_error_falls_with_the_tolerance_at_the_schemes_rate() {
    // The local error goes as h^(p+1) and the controller keeps it at the
    // tolerance, so h ∝ tol^(1/(p+1)) and the global error, O(h^p), falls as
    // tol^(p/(p+1)): 1/2 for backward Euler, 2/3 for the second-order schemes.
    // The reference: Richardson's extrapolation of fixed steps of a half and a
    // quarter of the bottom rung, at the landing times every run hits.
    for (scheme, p) in [
        ("backward_euler", 1),
        ("trapezoidal", 2),
        ("generalized_alpha", 2),
    ] {
        let m = forced_cantilever(scheme, 1e-3);
        let bottom = 2.5e-4 / 1024.0;
        let (mut half, mut quarter) = (Vec::new(), Vec::new());
        fixed(&m, bottom / 2.0, at_landings(&mut half));
        fixed(&m, bottom / 4.0, at_landings(&mut quarter));
        let w = f64::from(1 << p);
        let reference: Vec<Vec<f64>> = half
            .iter()
            .zip(&quarter)
            .map(|(a, b)| {
                a.iter()
                    .zip(b)
                    .map(|(a, b)| (w * b - a) / (w - 1.0))
                    .collect()
            })
            .collect();
        let tolerances = [1e-2, 1e-3, 1e-4, 1e-5];
        let mut errors = Vec::new();
        let mut counts = Vec::new();
        for tol in tolerances {
            let mut states = Vec::new();
            let (_, report, _) =
                adaptive(&forced_cantilever(scheme, tol), at_landings(&mut states));
            assert_eq!(states.len(), reference.len(), "{scheme}: landings");
            assert!(
                report.dt_min_used >= bottom,
                "{scheme}: a step below the ladder"
            );
            let err = states
                .iter()
                .zip(&reference)
                .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
                .fold(0.0, f64::max);
            errors.push(err);
            counts.push(report.steps_accepted);
        }
        // The rate per decade of tolerance: the least-squares slope of log error
        // against log tolerance (the steps are rungs, so a single decade's rate
        // jumps with the rung the tolerance falls on).
        let x: Vec<f64> = tolerances.iter().map(|t| -t.log10()).collect();
        let y: Vec<f64> = errors.iter().map(|e| -e.log10()).collect();
        let (mx, my) = (x.iter().sum::<f64>() / 4.0, y.iter().sum::<f64>() / 4.0);
        let rate = x
            .iter()
            .zip(&y)
            .map(|(a, b)| (a - mx) * (b - my))
            .sum::<f64>()
            / x.iter().map(|a| (a - mx) * (a - mx)).sum::<f64>();
        let expected = f64::from(p) / f64::from(p + 1);
        eprintln!(
            "{scheme}: steps {counts:?}, errors {errors:?}, rate {rate:.3} per decade (expected {expected:.3})"
        );
        assert!(
            (rate - expected).abs() < 0.1,
            "{scheme}: rate {rate}, expected {expected}"
        );
    }
}

/// Benchmark 1 (examples/benchmarks/two_blocks.toml) at the 0.2 m mesh to `t_end`,
/// with error-controlled steps from 16 µs down to 0.125 µs, and `sets`.
fn benchmark_1(t_end: f64, sets: &[&str]) -> Model {
    let mut ov = rothe::config::Overrides::none();
    for s in [
        "meshing.element_size=0.2",
        "analysis.vtk_every=0",
        "analysis.dt=1.6e-5",
        "analysis.adaptive.dt_max=1.6e-5",
        "analysis.adaptive.dt_min=1e-7",
        "analysis.adaptive.tolerance=1e-4",
    ]
    .iter()
    .chain(sets)
    {
        ov = ov.set(s).unwrap();
    }
    ov = ov.set(&format!("analysis.t_end={t_end:e}")).unwrap();
    rothe::config::load_with_overrides(
        Path::new("examples/benchmarks/two_blocks.toml"),
        &rothe::config::LoadOptions::default(),
        &ov,
    )
    .unwrap()
}

/// Runs `m` again with fixed steps of the sizes `steps` (its `analysis.adaptive`
/// removed, so no factor is kept): a run that took each step that stood directly,
/// its time counted in bottom rungs as the error-controlled run counts it.
fn replay(m: &Model, steps: &[f64]) -> State {
    let a = m.analysis.time.adaptive.expect("an adaptive scenario");
    let tick = rothe::time::step_ladder::Ladder::new(a.dt_max, a.dt_min, a.tolerance, 1).dt_min;
    let mut m = m.clone();
    m.analysis.time.adaptive = None;
    let mut i = BackwardEuler::new(&m, Backend::Faer).unwrap();
    let mut r = i.initial_state();
    let mut n = 0u64;
    for h in steps {
        if *h != i.h() {
            i.set_step(*h).unwrap();
        }
        i.step_accepted(&mut r).unwrap();
        n += (h / tick).round() as u64;
        r.t = n as f64 * tick;
    }
    r
}

/// `|a − b| / |b|` in the Euclidean norm.
fn relative(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    (d / b.iter().map(|y| y * y).sum::<f64>()).sqrt()
}

#[test]
fn a_rejected_step_leaves_no_trace() {
    // The forced cantilever with Kelvin-Voigt points (history at the Gauss points),
    // its first step far too large, and a second load switched on at 1.3 ms:
    // steps are taken back. Replaying the sizes that stood as fixed steps from the
    // start, without kept factors, gives the same state, Gauss-point history and
    // ledger, bit for bit.
    let jolt = "[[loads]]\nkind = \"traction\"\nset = \"beam.right\"\nvalue = [0.0, 2.0e6]\n\
                function = { kind = \"step\", at = 1.3e-3 }\n";
    for scheme in ["backward_euler", "trapezoidal", "generalized_alpha"] {
        let text = (forced_cantilever_text(scheme, 1e-5) + jolt)
            .replace(
                "model = \"elastic\"",
                "model = \"kelvin_voigt\"\nalpha = 1.0e-5",
            )
            .replace(
                "vtk_every = 0",
                "vtk_every = 0\nviscoelastic_state = \"points\"",
            );
        let m = model(&text);
        let (s, report, steps) = adaptive(&m, |_| {});
        assert!(report.steps_rejected > 0, "{scheme}: nothing taken back");
        let r = replay(&m, &steps);
        let same = |what: &str, a: String, b: String| assert!(a == b, "{scheme}: {what} differ");
        same("t", format!("{:?}", s.t), format!("{:?}", r.t));
        same("u", format!("{:?}", s.u), format!("{:?}", r.u));
        same("v", format!("{:?}", s.v), format!("{:?}", r.v));
        same("a", format!("{:?}", s.a), format!("{:?}", r.a));
        same(
            "ledger",
            format!("{:?}", s.ledger),
            format!("{:?}", r.ledger),
        );
        same(
            "points",
            format!("{:?}", s.points),
            format!("{:?}", r.points),
        );
        assert!(!s.points.is_empty() && s.ledger.dissipated().viscous > 0.0);
        eprintln!(
            "{scheme}: {} steps stood, {} taken back; the replay is the same to the bit",
            steps.len(),
            report.steps_rejected
        );
    }
}

#[test]
fn a_rejected_step_through_contact_leaves_no_trace_beyond_round_off() {
    // Benchmark 1 with Kelvin-Voigt concrete through the impact. The contact's
    // condensed operator is kept per step size with its factor, grown in the order
    // the contact dofs came, so the replay (which keeps none) sums it in another
    // order: the states agree to the round-off the contact QP carries over a run
    // (as between the two backends), the multipliers and the ledger with them.
    for (scheme, tolerance) in [("backward_euler", "1e-6"), ("trapezoidal", "1e-4")] {
        let sets = [
            &format!("analysis.scheme=\"{scheme}\"") as &str,
            &format!("analysis.adaptive.tolerance={tolerance}"),
            "materials.concrete.model=\"kelvin_voigt\"",
            "materials.concrete.beta=1.0e6",
            "analysis.viscoelastic_state=\"points\"",
        ];
        let m = benchmark_1(3.2e-3, &sets);
        let mut force: f64 = 0.0;
        let (s, report, steps) = adaptive(&m, |s| {
            force = force.max(s.contact.pairs[0].force);
        });
        assert!(report.steps_rejected > 0 && force > 0.0, "{scheme}");
        let r = replay(&m, &steps);
        let d = |x: &rothe::time::State| {
            let l = x.ledger.dissipated();
            vec![
                l.viscous,
                l.contact,
                l.numerical,
                x.ledger.kinetic(),
                x.ledger.elastic(),
            ]
        };
        let worst = [
            relative(&s.u, &r.u),
            relative(&s.v, &r.v),
            relative(&d(&s), &d(&r)),
        ];
        eprintln!(
            "{scheme}: {} taken back; u, v, ledger differ by {worst:?}",
            report.steps_rejected
        );
        assert!(worst.iter().all(|w| *w < 1e-7), "{scheme}: {worst:?}");
    }
}

#[test]
fn the_ledger_closes_under_changing_steps_with_every_material_model() {
    // Benchmark 1's concrete as each model, through the impact: the balance
    // closes at every step as at fixed steps (each step books with its own h; the
    // linear models to the contact QP's tolerance, 4e-10 at fixed steps too),
    // every dissipation line stays non-negative, and the steps did change.
    for (name, lines, bound) in [
        ("elastic", "", 1e-9),
        ("kelvin_voigt", "beta=1.0e6", 1e-9),
        ("sls", "alpha=0.5;beta=1.0e-4", 1e-9),
        ("maxwell", "beta=1.0e-3", 1e-9),
        (
            "mazars",
            "eps_t0=1.0e-4;A_t=1.0;B_t=1.0e4;A_c=1.2;B_c=1.5e3",
            1e-6,
        ),
        (
            "rankine_hill",
            "tension={ law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1.65e9 };\
             compression={ law = \"bilinear\", strength = 30.0e6, post_yield_modulus = 1.65e9 }",
            1e-6,
        ),
    ] {
        let mut sets = vec![format!("materials.concrete.model=\"{name}\"")];
        sets.extend(
            lines
                .split(';')
                .filter(|l| !l.is_empty())
                .map(|l| format!("materials.concrete.{l}")),
        );
        let sets: Vec<&str> = sets.iter().map(|s| s.as_str()).collect();
        let m = benchmark_1(3.0e-3, &sets);
        let mut worst: f64 = 0.0;
        let (s, report, steps) = adaptive(&m, |s| {
            let l = &s.ledger;
            worst = worst.max(l.residual().abs() / l.scale());
            let d = l.dissipated();
            for (line, v) in [
                ("viscous", d.viscous),
                ("damage", d.damage),
                ("plastic", d.plastic),
                ("contact", d.contact),
            ] {
                assert!(
                    v >= -1e-9 * l.scale(),
                    "{name}: D_{line} = {v} at t = {}",
                    s.t
                );
            }
        });
        let sizes = {
            let mut v = steps.clone();
            v.sort_by(f64::total_cmp);
            v.dedup();
            v.len()
        };
        eprintln!(
            "{name}: {} steps of {sizes} sizes ({} taken back), worst relative residual {worst:.1e}",
            steps.len(),
            report.steps_rejected
        );
        assert!(sizes >= 3, "{name}: the steps did not change");
        assert!(worst <= bound, "{name}: residual {worst:e} above {bound:e}");
        assert!((s.t - 3.0e-3).abs() < 1e-12);
    }
}

#[test]
fn the_first_contact_is_found_to_the_ladders_bottom_rung() {
    // The fixed-step run at the bottom rung (0.125 µs) first touches in the step
    // ending at t_c; the error-controlled run lands there, its first step in
    // contact ending within one bottom rung of t_c, though it fell at 16 µs, and
    // without taking a step back.
    let m = benchmark_1(2.7e-3, &[]);
    let bottom = 1.6e-5 / 128.0;
    let mut t_c = None;
    fixed(&m, bottom, |s| {
        if t_c.is_none() && !s.contact.active.is_empty() {
            t_c = Some(s.t);
        }
    });
    let t_c = t_c.expect("the blocks meet before 2.7 ms");
    let (_, report, steps) = adaptive(&m, |_| {});
    let found = report.first_impact_t.expect("an impact");
    eprintln!(
        "first contact: fixed {t_c:.7e} s, error-controlled {found:.7e} s ({} steps, the largest {:.2e} s)",
        steps.len(),
        report.dt_max_used
    );
    assert!(
        (found - t_c).abs() <= bottom * (1.0 + 1e-9),
        "{found} against {t_c}"
    );
    assert_eq!(report.dt_max_used, 1.6e-5);
    assert_eq!(report.impacts, 1);
    // The event landed it: no step was taken back on the way (the estimate alone
    // would find the contact too, by taking back the steps that crossed it).
    assert_eq!(report.steps_rejected, 0, "{report:?}");
}

/// Asserts that `text` is refused with a message holding every one of `words`.
fn refused(text: &str, words: &[&str]) {
    let e = rothe::config::from_str(text, Path::new("."))
        .expect_err("accepted")
        .to_string();
    for w in words {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
}

#[test]
fn bad_adaptive_input_is_refused_by_name() {
    let with = |scheme: &str, extra: &str| {
        cantilever(scheme, 1e-4, 4e-3, [0.0, -1.0], extra).replace("mass = \"consistent\"\n", "")
    };
    refused(
        &with("backward_euler", "adaptive = { tolerance = 0.0 }"),
        &["analysis.adaptive.tolerance", "(0, 1)"],
    );
    refused(
        &with("backward_euler", "adaptive = { tolerance = -1e-4 }"),
        &["analysis.adaptive.tolerance"],
    );
    refused(
        &with(
            "backward_euler",
            "adaptive = { dt_min = 1e-3, dt_max = 1e-4 }",
        ),
        &["analysis.adaptive.dt_min", "exceeds dt_max"],
    );
    refused(
        &with("backward_euler", "adaptive = { dt_max = 1e-5 }"),
        &["analysis.dt", "exceeds analysis.adaptive.dt_max"],
    );
    refused(
        &with("backward_euler", "adaptive = { dt_max = 1.0 }"),
        &["analysis.adaptive.dt_max", "exceeds t_end"],
    );
    refused(
        &with("central_difference", "adaptive = { tolerance = 1e-4 }"),
        &["analysis.adaptive", "central differences", "critical step"],
    );
    refused(
        &with(
            "backward_euler",
            "kind = \"static\"\nadaptive = { tolerance = 1e-4 }",
        ),
        &["analysis.adaptive", "static"],
    );
    refused(
        &with("backward_euler", "adaptive = { norm = \"l2\" }"),
        &["norm"],
    );
    refused(
        &with("backward_euler", "vtk_every_time = 0.0"),
        &["analysis.vtk_every_time"],
    );
    // A bottom rung too long for the wave an impact sends: warned of, by name.
    let m = benchmark_1(
        3e-3,
        &[
            "meshing.element_size=0.1",
            "analysis.adaptive.dt_min=1.6e-5",
        ],
    );
    assert!(
        m.warnings
            .iter()
            .any(|w| w.contains("analysis.adaptive.dt_min") && w.contains("L_e/c")),
        "{:?}",
        m.warnings
    );
    assert!(benchmark_1(3e-3, &[]).warnings.is_empty());
}

#[test]
fn the_studies_refuse_what_they_cannot_study() {
    let dir = tempfile::tempdir().unwrap();
    let adaptive = crate::common::scenario(
        dir.path(),
        "adaptive.toml",
        &cantilever(
            "backward_euler",
            1e-4,
            4e-3,
            [0.0, -1.0],
            "adaptive = { tolerance = 1e-4 }",
        ),
    );
    let plain = crate::common::scenario(
        dir.path(),
        "plain.toml",
        &cantilever("backward_euler", 1e-4, 4e-3, [0.0, -1.0], ""),
    );
    let none = rothe::config::Overrides::none();
    let e = rothe::study::time_study::plan(&adaptive, &none, &[1e-4, 5e-5], 0)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("analysis.adaptive") && e.contains("fixed steps"),
        "{e}"
    );
    let e = rothe::study::tolerance_study::plan(&plain, &none, &[1e-3], 2, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("analysis.adaptive") && e.contains("fixed steps"),
        "{e}"
    );
    let plan =
        rothe::study::tolerance_study::plan(&adaptive, &none, &[1e-3, 1e-4], 2, None).unwrap();
    // Two tolerances, three fixed steps, the reference; the fixed runs have no
    // adaptive table left.
    assert_eq!(plan.runs.len(), 6);
    for r in plan.runs.iter().filter(|r| !r.id.starts_with("tol")) {
        let m = rothe::config::load_with_overrides(
            &r.scenario,
            &rothe::config::LoadOptions::default(),
            &r.overrides,
        )
        .unwrap();
        assert!(m.analysis.time.adaptive.is_none(), "{}", r.id);
    }
}

#[test]
fn a_run_reports_its_steps_and_lands_its_frames() {
    // From the command line: VTK frames at every 0.5 ms exactly, the summary's
    // account of the steps, and `rothe check`'s plan.
    let dir = tempfile::tempdir().unwrap();
    let file = crate::common::scenario(
        dir.path(),
        "forced.toml",
        &forced_cantilever_text("generalized_alpha", 1e-4).replace("vtk_every = 0\n", ""),
    );
    let out = dir.path().join("out");
    let (ok, _, err) = crate::common::rothe(&[
        "run",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let pvd = std::fs::read_to_string(out.join("result.pvd")).unwrap();
    let times: Vec<f64> = pvd
        .split("timestep=\"")
        .skip(1)
        .map(|s| s[..s.find('"').unwrap()].parse().unwrap())
        .collect();
    assert_eq!(times.len(), 9, "{times:?}");
    for (k, t) in times.iter().enumerate() {
        assert!((t - 5e-4 * k as f64).abs() < 1e-15, "{times:?}");
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let steps = s["steps"].as_u64().unwrap();
    assert_eq!(s["steps_accepted"].as_u64(), Some(steps));
    assert!(s["steps_rejected"].as_u64().is_some());
    let (lo, hi) = (
        s["dt_min_used"].as_f64().unwrap(),
        s["dt_max_used"].as_f64().unwrap(),
    );
    assert!(
        lo >= 2.5e-4 / 1024.0 && lo < hi && hi <= 2.5e-4,
        "{lo} {hi}"
    );
    let (ok, plan, err) = crate::common::rothe(&["check", file.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        plan.contains("error-controlled") && plan.contains("between 16 (all at dt_max) and 16384"),
        "{plan}"
    );
}

#[test]
fn fixed_steps_end_on_t_end_without_a_sliver_of_a_step() {
    // 12000 steps of 5e-7 s sum to 1.2e-15 s short of 6 ms: that drift is no step
    // to take (one of 1e-15 s made the contact predictor's projection stall).
    let m = model(&cantilever("backward_euler", 5e-7, 6e-3, [0.0, -1.0], ""));
    let mut i = BackwardEuler::new(&m, Backend::Faer).unwrap();
    let mut s = i.initial_state();
    let mut smallest = f64::INFINITY;
    rothe::time::march::march(
        &mut i,
        &mut s,
        rothe::time::march::StepControl::of(&m),
        |i, _, _| {
            smallest = smallest.min(i.h());
            Ok(())
        },
    )
    .unwrap();
    assert_eq!(s.step, 12000);
    assert_eq!(smallest, 5e-7);
}

#[test]
fn a_t_end_off_the_ladder_is_reached_without_a_step_below_its_bottom_rung() {
    // t_end 1e-10 s past a multiple of the bottom rung (2.5e-4/1024 s): the step that
    // lands on the last rung takes the sliver along, so no step is shorter than the
    // bottom rung (a step of its own would be 1e-10 s, far below the floor), and the
    // run ends on t_end.
    let t_end = 4e-3 + 1e-10;
    let extra = "adaptive = { tolerance = 1e-3, dt_max = 2.5e-4 }";
    let m = model(&cantilever(
        "trapezoidal",
        2.5e-4,
        t_end,
        [0.0, -1.0],
        extra,
    ));
    let (s, report, steps) = adaptive(&m, |_| {});
    let smallest = steps.iter().copied().fold(f64::INFINITY, f64::min);
    eprintln!(
        "{} steps, smallest {smallest:e}, last {:e}, t = {:e}",
        steps.len(),
        steps.last().unwrap(),
        s.t
    );
    assert!(
        smallest >= report.bottom_rung * (1.0 - 1e-12),
        "{smallest:e}"
    );
    assert_eq!(report.dt_min_used, smallest);
    assert_eq!(s.t, t_end);
}
