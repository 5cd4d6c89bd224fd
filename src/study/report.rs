//! `rothe report`: the paper's two benchmarks, every model and mesh, implicit and
//! explicit, and a Markdown report of peak deflections and normalised dissipation
//! beside the paper's figures, with the plots a paper would print. Why the numbers
//! differ from the paper's: `theory/benchmarks.md`.

use std::path::{Path, PathBuf};

use super::compare::{ledger_table, pair};
use super::mesh_study::{dissipation_cells, dissipation_header};
use super::plan::{Plan, PlannedRun, StudyKind};
use super::run_data::RunData;
use super::table::{num, Table};
use crate::config::Overrides;
use crate::error::{Error, Result};
use crate::plot::{draw, Figure, Series, Style};

/// The concrete models of benchmark 1 (the variants of `two_blocks.toml`): the
/// paper's four (Mazars nonlocal), the local Mazars law and the bilinearised one.
pub const BENCHMARK1_MODELS: [&str; 6] = [
    "elastic",
    "kelvin_voigt",
    "mazars",
    "mazars_local",
    "mazars_plateau",
    "rankine_hill",
];
/// The meshes of benchmark 1 (NOTES.md's four and 0.025 m).
pub const BENCHMARK1_MESHES: [f64; 5] = [0.2, 0.15, 0.1, 0.05, 0.025];
/// The damage models run on `ReportOptions::damage_meshes` too.
pub const DAMAGE_MODELS: [&str; 2] = ["mazars", "mazars_local"];
/// The concrete models of benchmark 1 run as solids too
/// (`two_blocks_solid.toml`, at the comparison mesh), against plane stress.
pub const SOLID_MODELS: [&str; 3] = ["elastic", "mazars", "rankine_hill"];
/// The concrete models of benchmark 2, run as solids too
/// (`rc_beam_punch_solid.toml`).
pub const BENCHMARK2_MODELS: [&str; 4] = ["mazars", "mazars_local", "rankine_hill", "kelvin_voigt"];

/// What the report runs.
#[derive(Clone, Debug)]
pub struct ReportOptions {
    /// Directory holding `two_blocks.toml`, `two_blocks_solid.toml`,
    /// `rc_beam_punch.toml` and `rc_beam_punch_solid.toml`.
    pub benchmarks: PathBuf,
    /// Benchmark 1's meshes.
    pub meshes: Vec<f64>,
    /// Benchmark 1's extra meshes of the damage models ([`DAMAGE_MODELS`]).
    pub damage_meshes: Vec<f64>,
    /// Benchmark 1's mesh of the implicit-against-explicit comparison.
    pub compare_mesh: f64,
    /// Benchmark 2's element size (`None`: the scenario's own).
    pub beam_size: Option<f64>,
    /// Overrides applied to every run (e.g. a shorter `analysis.t_end` for a quick look).
    pub base: Overrides,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            benchmarks: PathBuf::from("examples/benchmarks"),
            meshes: BENCHMARK1_MESHES.to_vec(),
            damage_meshes: Vec::new(),
            compare_mesh: 0.1,
            beam_size: None,
            base: Overrides::none(),
        }
    }
}

fn variant(model: &str) -> Overrides {
    Overrides::none()
        .variant(&format!("concrete={model}"))
        .expect("g=o")
}

fn size(s: f64) -> Overrides {
    Overrides::none()
        .set(&format!("meshing.element_size={s}"))
        .expect("k=v")
}

/// The plan of the report: benchmark 1 for every model and mesh, benchmark 2 for its
/// models, and the explicit path of both (benchmark 1 at `compare_mesh`).
pub fn plan(o: &ReportOptions) -> Result<Plan> {
    let b1 = o.benchmarks.join("two_blocks.toml");
    let b2 = o.benchmarks.join("rc_beam_punch.toml");
    let b1_solid = o.benchmarks.join("two_blocks_solid.toml");
    let b2_solid = o.benchmarks.join("rc_beam_punch_solid.toml");
    for f in [&b1, &b2, &b1_solid, &b2_solid] {
        if !f.is_file() {
            return Err(Error::config(
                "--benchmarks",
                format!("{} does not exist", f.display()),
            ));
        }
    }
    for (flag, sizes) in [
        ("--meshes", &o.meshes),
        ("--damage-meshes", &o.damage_meshes),
    ] {
        super::plan::check_sizes(flag, sizes, flag == "--meshes")?;
    }
    super::plan::check_sizes("--compare-mesh", &[o.compare_mesh], true)?;
    if let Some(s) = o.beam_size {
        super::plan::check_sizes("--beam-size", &[s], true)?;
    }
    let abs1 = super::plan::absolute(&b1)?;
    let abs2 = super::plan::absolute(&b2)?;
    let mut runs = Vec::new();
    for m in BENCHMARK1_MODELS {
        let extra: &[f64] = if DAMAGE_MODELS.contains(&m) {
            &o.damage_meshes
        } else {
            &[]
        };
        for &s in o.meshes.iter().chain(extra) {
            runs.push(PlannedRun {
                id: format!("b1_{m}_{s}"),
                scenario: abs1.clone(),
                overrides: o.base.then(&variant(m)).then(&size(s)),
                param: s,
                label: format!("{m}, {s} m"),
                record_fields: false,
            });
        }
        let base = o.base.then(&variant(m)).then(&size(o.compare_mesh));
        let explicit = pair(&abs1, &base, &format!("b1_{m}_{}_", o.compare_mesh), "")?;
        runs.push(PlannedRun {
            label: format!("{m}, {} m, explicit", o.compare_mesh),
            ..explicit[1].clone()
        });
        // The same by the trapezoidal rule (theory/trapezoidal.md).
        runs.push(PlannedRun {
            id: format!("b1_{m}_{}_{TRAPEZOIDAL}", o.compare_mesh),
            scenario: abs1.clone(),
            overrides: base.then(&Overrides::none().set("analysis.scheme=\"trapezoidal\"")?),
            param: o.compare_mesh,
            label: format!("{m}, {} m, trapezoidal", o.compare_mesh),
            record_fields: false,
        });
    }
    // Benchmark 1 as solids at the comparison mesh (theory/contact3d.md).
    let abs_solid = super::plan::absolute(&b1_solid)?;
    for m in SOLID_MODELS {
        runs.push(PlannedRun {
            id: format!("b1solid_{m}_{}", o.compare_mesh),
            scenario: abs_solid.clone(),
            overrides: o.base.then(&variant(m)).then(&size(o.compare_mesh)),
            param: o.compare_mesh,
            label: format!("{m}, {} m, solid", o.compare_mesh),
            record_fields: false,
        });
    }
    for m in BENCHMARK2_MODELS {
        let mut base = o.base.then(&variant(m));
        if let Some(s) = o.beam_size {
            base = base.then(&size(s));
        }
        let both = pair(&abs2, &base, &format!("b2_{m}_"), "")?;
        runs.push(PlannedRun {
            label: m.to_string(),
            ..both[0].clone()
        });
        runs.push(PlannedRun {
            label: format!("{m}, explicit"),
            ..both[1].clone()
        });
    }
    // Benchmark 2 as solids, the same models (theory/benchmarks.md).
    let abs2_solid = super::plan::absolute(&b2_solid)?;
    for m in BENCHMARK2_MODELS {
        let mut base = o.base.then(&variant(m));
        if let Some(s) = o.beam_size {
            base = base.then(&size(s));
        }
        runs.push(PlannedRun {
            id: format!("b2solid_{m}"),
            scenario: abs2_solid.clone(),
            overrides: base,
            param: o.beam_size.unwrap_or(f64::NAN),
            label: format!("{m}, solid"),
            record_fields: false,
        });
    }
    if !o.meshes.contains(&o.compare_mesh) {
        return Err(Error::config(
            "--compare-mesh",
            format!("{} is not one of the meshes {:?}", o.compare_mesh, o.meshes),
        ));
    }
    Ok(Plan {
        kind: StudyKind::Report,
        runs,
    })
}

/// The suffix of the benchmark 1 runs by the trapezoidal rule.
const TRAPEZOIDAL: &str = "trapezoidal";

/// Benchmark 1 by backward Euler and by the trapezoidal rule at one mesh, model by
/// model: the scheme's own loss, the contact's, the material dissipation and how
/// much of it the scheme changes, and the peak deflection.
fn schemes_side_by_side(runs: &[RunData]) -> String {
    let mut t = Table::new(&[
        "model",
        "mesh [m]",
        "D_num / E_kin⁰ BE",
        "trapezoidal",
        "D_contact / E_kin⁰ BE",
        "trapezoidal",
        "material / E_kin⁰ BE",
        "trapezoidal",
        "material change [%]",
        "peak [mm] BE",
        "trapezoidal",
    ]);
    for m in BENCHMARK1_MODELS {
        let Some(tr) = runs.iter().find(|r| {
            r.run.id.starts_with(&format!("b1_{m}_"))
                && r.run.id.ends_with(&format!("_{TRAPEZOIDAL}"))
                && r.completed()
        }) else {
            continue;
        };
        let Some(be) = find(runs, &format!("b1_{m}_{}", tr.run.param)) else {
            continue;
        };
        let k = be.kinetic_0();
        let (mb, mt) = (be.dissipated_material(), tr.dissipated_material());
        t.push(vec![
            m.to_string(),
            format!("{}", tr.run.param),
            num(Some(be.dissipated("numerical") / k)),
            num(Some(tr.dissipated("numerical") / k)),
            num(Some(be.dissipated("contact") / k)),
            num(Some(tr.dissipated("contact") / k)),
            num(Some(mb / k)),
            num(Some(mt / k)),
            num((mb > 0.0).then(|| 100.0 * (mt - mb) / mb)),
            num(Some(-1e3 * be.probe_min("probe"))),
            num(Some(-1e3 * tr.probe_min("probe"))),
        ]);
    }
    if t.rows.is_empty() {
        return String::new();
    }
    format!(
        "\n## Backward Euler against the trapezoidal rule\n\nBenchmark 1 at the \
         comparison mesh, the same file by both implicit schemes: backward Euler's own \
         loss, which the trapezoidal rule does not have in linear elasticity, and how much \
         each model's dissipation changes with it (theory/trapezoidal.md).\n\n{}",
        t.markdown()
    )
}

/// The paper's figures the report sets beside its own (NOTES.md).
const PAPER: &str = "Paper (commercial explicit code, shells, line-to-line contact): \
benchmark 1 peak probe deflection about 1.45 mm (Mazars) and 1.6 mm (Rankine-Hill), \
Rankine-Hill dissipating about 53 % more than Mazars; benchmark 2 Mazars' peak \
deflection about 4.8 × Rankine-Hill's, normalised dissipation about 65 % for both, and \
the viscoelastic and elastoplastic beams swinging to negative deflection after the \
first impact.";

fn find<'a>(runs: &'a [RunData], id: &str) -> Option<&'a RunData> {
    runs.iter().find(|r| r.run.id == id && r.completed())
}

/// Whether a body lifted off a support after an impact: the support's force
/// (history column) was positive at some step after the impact force first was,
/// and zero at a later one.
pub fn lifts_off(support: &[f64], impact: &[f64]) -> bool {
    let Some(first) = impact.iter().position(|&x| x > 0.0) else {
        return false;
    };
    let Some(pressed) = support[first..].iter().position(|&x| x > 0.0) else {
        return false;
    };
    support[first + pressed..].contains(&0.0)
}

fn run_lifts_off(r: &RunData, support: &str) -> bool {
    lifts_off(
        &r.column(&format!("{support}_force")),
        &r.column("impact_force"),
    )
}

/// Benchmark 1 as solids against plane stress: peak probe deflection, dissipation
/// by mechanism, the contact force's peak and duration, and the force histories.
fn solid_against_plane(runs: &[RunData], plots: &Path) -> Result<String> {
    let pairs: Vec<(&str, &RunData, &RunData)> = SOLID_MODELS
        .iter()
        .filter_map(|m| {
            let solid = runs
                .iter()
                .find(|r| r.run.id.starts_with(&format!("b1solid_{m}_")) && r.completed())?;
            let plane = find(runs, &format!("b1_{m}_{}", solid.run.param))?;
            Some((*m, plane, solid))
        })
        .collect();
    if pairs.is_empty() {
        return Ok(String::new());
    }
    let mut md = String::from(
        "\n## Benchmark 1 as solids against plane stress\n\nThe blocks as boxes with the \
         plane model's thicknesses as depths (`two_blocks_solid.toml`), the same data, \
         mesh size and step; energies over E_kin⁰, the contact force's peak (its first \
         step) and the time it acts (theory/contact3d.md).\n\n",
    );
    let mut t = Table::new(&[
        "model",
        "run",
        "peak probe [mm]",
        "D_material / E_kin0",
        "D_num / E_kin0",
        "D_contact / E_kin0",
        "peak force [MN]",
        "contact [ms]",
    ]);
    for (m, plane, solid) in &pairs {
        for (what, r) in [("plane stress", plane), ("solid", solid)] {
            let k0 = r.kinetic_0();
            let force = r.column("impact_force");
            let time = r.column("t");
            let pressed: Vec<f64> = time
                .iter()
                .zip(&force)
                .filter(|(_, f)| **f > 0.0)
                .map(|(t, _)| *t)
                .collect();
            let duration = match (pressed.first(), pressed.last()) {
                (Some(a), Some(b)) => Some(1e3 * (b - a)),
                _ => None,
            };
            t.push(vec![
                m.to_string(),
                what.into(),
                num(Some(1e3 * r.probe_min("probe"))),
                num(Some(r.dissipated_material() / k0)),
                num(Some(r.dissipated("numerical") / k0)),
                num(Some(r.dissipated("contact") / k0)),
                num(Some(1e-6 * force.iter().fold(0.0f64, |a, f| a.max(*f)))),
                num(duration),
            ]);
        }
    }
    md.push_str(&t.markdown());
    let mut fig = Figure::new(
        "Benchmark 1: contact force, plane stress and solid",
        "t [ms]",
        "F [MN]",
    );
    // From the second step in contact on: the first step's force (the bottom
    // layer's momentum stopped in one step, in the table) would flatten the rest.
    let after_touch = |r: &RunData| {
        let points = r.series("impact_force", 1e-6);
        let first = points.iter().position(|p| p.1 > 0.0).unwrap_or(0);
        points[(first + 1).min(points.len())..].to_vec()
    };
    for (m, plane, solid) in &pairs {
        fig = fig
            .with(Series::new(
                format!("{m}, plane"),
                after_touch(plane),
                Style::Line,
            ))
            .with(Series::new(
                format!("{m}, solid"),
                after_touch(solid),
                Style::Line,
            ));
    }
    draw(&fig, &plots.join("b1_solid_force"))?;
    md.push_str(
        "\n![benchmark 1 contact force, plane and solid](plots/b1_solid_force.png)\n\n\
         The force from the second step in contact on (the first step's is the table's \
         peak).\n",
    );
    Ok(md)
}

/// Benchmark 2 as solids against plane stress: mid-span deflection, lift-off,
/// dissipation by mechanism, and the deflection histories.
fn beam_solid_against_plane(runs: &[RunData], plots: &Path) -> Result<String> {
    let pairs: Vec<(&str, &RunData, &RunData)> = BENCHMARK2_MODELS
        .iter()
        .filter_map(|m| {
            let solid = find(runs, &format!("b2solid_{m}"))?;
            let plane = find(runs, &format!("b2_{m}_implicit"))?;
            Some((*m, plane, solid))
        })
        .collect();
    if pairs.is_empty() {
        return Ok(String::new());
    }
    let mut md = String::from(
        "\n## Benchmark 2 as solids against plane stress\n\nThe beam, the punch and the \
         supports as boxes with the plane model's thicknesses as depths, the rebars as \
         bars through the beam (`rc_beam_punch_solid.toml`; the supports are steel boxes \
         where the plane has rigid lines); its own mesh unless `--beam-size` sets both \
         (theory/benchmarks.md).\n\n",
    );
    let mut t = Table::new(&{
        let mut h = vec![
            "model".to_string(),
            "run".into(),
            "peak deflection [mm]".into(),
            "max upward [mm]".into(),
            "lifts off".into(),
        ];
        h.extend(dissipation_header());
        h
    });
    for (m, plane, solid) in &pairs {
        for (what, r) in [("plane stress", plane), ("solid", solid)] {
            let mut row = vec![
                m.to_string(),
                what.to_string(),
                num(Some(-1e3 * r.probe_min("midspan"))),
                num(r.number("/probes/midspan/max_uy").map(|v| 1e3 * v)),
                (run_lifts_off(r, "left_support") || run_lifts_off(r, "right_support")).to_string(),
            ];
            row.extend(dissipation_cells(r));
            t.push(row);
        }
    }
    md.push_str(&t.markdown());
    let mut fig = Figure::new(
        "Benchmark 2: mid-span deflection, plane stress and solid",
        "t [ms]",
        "u_y [mm]",
    );
    for (m, plane, solid) in &pairs {
        fig = fig
            .with(Series::new(
                format!("{m}, plane"),
                plane.series("midspan_uy", 1e3),
                Style::Line,
            ))
            .with(Series::new(
                format!("{m}, solid"),
                solid.series("midspan_uy", 1e3),
                Style::Line,
            ));
    }
    draw(&fig, &plots.join("b2_solid_probe"))?;
    md.push_str("\n![benchmark 2 deflection, plane and solid](plots/b2_solid_probe.png)\n");
    Ok(md)
}

/// Writes the report's tables and plots into `dir`; returns the Markdown.
pub fn collect(dir: &Path, runs: &[RunData]) -> Result<String> {
    let plots = dir.join("plots");
    let meshes: Vec<f64> = {
        let mut m: Vec<f64> = runs
            .iter()
            .filter(|r| {
                r.run.id.starts_with("b1_")
                    && !r.run.id.ends_with("explicit")
                    && !r.run.id.ends_with(TRAPEZOIDAL)
            })
            .map(|r| r.run.param)
            .collect();
        m.sort_by(|a, b| b.total_cmp(a));
        m.dedup();
        m
    };
    let b1 = |m: &str, s: f64| find(runs, &format!("b1_{m}_{s}"));
    let mut md = String::from(
        "# rothe: the paper's benchmarks\n\nEvery run below is an implicit (backward \
         Euler, contact QP) run of `examples/benchmarks/` unless marked explicit or \
         trapezoidal; \
         energies are normalised by the initial kinetic energy `E_kin⁰`. Why the numbers \
         differ from the paper's: `theory/benchmarks.md`.\n\n",
    );
    md.push_str(PAPER);
    md.push_str("\n\n## Benchmark 1: two blocks\n\n### Peak probe deflection [mm]\n\n");
    let mut header = vec!["model".to_string()];
    header.extend(meshes.iter().map(|s| format!("{s} m")));
    let mut peaks = Table::new(&header);
    let mut diss = Table::new(&header);
    let mut mat = Table::new(&header);
    for m in BENCHMARK1_MODELS {
        let mut p = vec![m.to_string()];
        let mut d = vec![m.to_string()];
        let mut q = vec![m.to_string()];
        for &s in &meshes {
            let r = b1(m, s);
            p.push(num(r.map(|r| -1e3 * r.probe_min("probe"))));
            d.push(num(r.map(|r| r.dissipated_total() / r.kinetic_0())));
            q.push(num(r.map(|r| r.dissipated_material() / r.kinetic_0())));
        }
        peaks.push(p);
        diss.push(d);
        mat.push(q);
    }
    md.push_str(&peaks.markdown());
    md.push_str("\n### Material dissipation / E_kin⁰ (viscous + damage + plastic)\n\n");
    md.push_str(&mat.markdown());
    md.push_str("\n### Total dissipation / E_kin⁰ (every ledger line: material, contact, the scheme's own loss)\n\n");
    md.push_str(&diss.markdown());
    md.push_str("\n### Rankine-Hill against Mazars\n\n");
    let mut ratio = Table::new(&[
        "mesh",
        "material dissipation RH / Mazars (identified)",
        "RH / Mazars (bilinearised)",
        "paper",
        "peak deflection RH / Mazars (identified)",
        "RH / Mazars (bilinearised)",
        "paper",
    ]);
    for &s in &meshes {
        let rh = b1("rankine_hill", s);
        let both = |mz: &str, f: &dyn Fn(&RunData) -> f64| match (rh, b1(mz, s)) {
            (Some(a), Some(b)) => num(Some(f(a) / f(b))),
            _ => num(None),
        };
        let diss = |r: &RunData| r.dissipated_material();
        let peak = |r: &RunData| r.probe_min("probe");
        if rh.is_some() {
            ratio.push(vec![
                format!("{s} m"),
                both("mazars", &diss),
                both("mazars_plateau", &diss),
                "1.53".into(),
                both("mazars", &peak),
                both("mazars_plateau", &peak),
                "1.10".into(),
            ]);
        }
    }
    md.push_str(&ratio.markdown());
    md.push_str(&damage_convergence(runs, &meshes));
    // Figures 6-9: probe per mesh, one chart per model.
    md.push('\n');
    for m in BENCHMARK1_MODELS {
        let mut fig = Figure::new(
            format!("Benchmark 1, {m}: probe under the steel's corner"),
            "t [ms]",
            "u_y [mm]",
        );
        for &s in &meshes {
            if let Some(r) = b1(m, s) {
                fig = fig.with(Series::new(
                    format!("{s} m"),
                    r.series("probe_uy", 1e3),
                    Style::Line,
                ));
            }
        }
        draw(&fig, &plots.join(format!("b1_probe_{m}")))?;
        md.push_str(&format!(
            "![benchmark 1 probe, {m}](plots/b1_probe_{m}.png)\n"
        ));
    }
    // Figures 10-12 and 13: energies per model and normalised dissipation, finest mesh.
    let fine = meshes.last().copied().unwrap_or(0.1);
    for m in BENCHMARK1_MODELS {
        if let Some(r) = b1(m, fine) {
            energies(
                r,
                &format!("Benchmark 1, {m}, {fine} m: energies"),
                &plots.join(format!("b1_energies_{m}")),
            )?;
            md.push_str(&format!(
                "![benchmark 1 energies, {m}](plots/b1_energies_{m}.png)\n"
            ));
        }
    }
    let mut fig = Figure::new(
        format!("Benchmark 1, {fine} m: dissipation"),
        "t [ms]",
        "D / E_kin⁰ [-]",
    );
    for m in BENCHMARK1_MODELS {
        if let Some(r) = b1(m, fine) {
            fig = fig.with(Series::new(
                m,
                r.dissipation_series(r.kinetic_0()),
                Style::Line,
            ));
        }
    }
    draw(&fig, &plots.join("b1_dissipation"))?;
    md.push_str("![benchmark 1 dissipation](plots/b1_dissipation.png)\n");

    md.push_str("\n## Benchmark 2: reinforced beam and punch\n\n");
    let mut t2 = Table::new(&{
        let mut h = vec![
            "model".to_string(),
            "peak deflection [mm]".into(),
            "max upward [mm]".into(),
            "lifts off".into(),
        ];
        h.extend(dissipation_header());
        h
    });
    for m in BENCHMARK2_MODELS {
        if let Some(r) = find(runs, &format!("b2_{m}_implicit")) {
            let mut row = vec![
                m.to_string(),
                num(Some(-1e3 * r.probe_min("midspan"))),
                num(r.number("/probes/midspan/max_uy").map(|v| 1e3 * v)),
                (run_lifts_off(r, "left_support") || run_lifts_off(r, "right_support")).to_string(),
            ];
            row.extend(dissipation_cells(r));
            t2.push(row);
        }
    }
    md.push_str(&t2.markdown());
    if let (Some(mz), Some(rh)) = (
        find(runs, "b2_mazars_implicit"),
        find(runs, "b2_rankine_hill_implicit"),
    ) {
        md.push_str(&format!(
            "\nMazars' peak deflection / Rankine-Hill's: {} (paper 4.8); normalised total \
             dissipation {} and {} (paper about 0.65 for both).\n\n",
            num(Some(mz.probe_min("midspan") / rh.probe_min("midspan"))),
            num(Some(mz.dissipated_total() / mz.kinetic_0())),
            num(Some(rh.dissipated_total() / rh.kinetic_0())),
        ));
    }
    let mut fig = Figure::new("Benchmark 2: mid-span deflection", "t [ms]", "u_y [mm]");
    let mut fig_d = Figure::new("Benchmark 2: dissipation", "t [ms]", "D / E_kin⁰ [-]");
    for m in BENCHMARK2_MODELS {
        if let Some(r) = find(runs, &format!("b2_{m}_implicit")) {
            fig = fig.with(Series::new(m, r.series("midspan_uy", 1e3), Style::Line));
            fig_d = fig_d.with(Series::new(
                m,
                r.dissipation_series(r.kinetic_0()),
                Style::Line,
            ));
            energies(
                r,
                &format!("Benchmark 2, {m}: energies"),
                &plots.join(format!("b2_energies_{m}")),
            )?;
        }
    }
    draw(&fig, &plots.join("b2_probe"))?;
    draw(&fig_d, &plots.join("b2_dissipation"))?;
    md.push_str("![benchmark 2 probe](plots/b2_probe.png)\n![benchmark 2 dissipation](plots/b2_dissipation.png)\n");
    for m in BENCHMARK2_MODELS {
        md.push_str(&format!(
            "![benchmark 2 energies, {m}](plots/b2_energies_{m}.png)\n"
        ));
    }

    md.push_str(&solid_against_plane(runs, &plots)?);
    md.push_str(&beam_solid_against_plane(runs, &plots)?);

    md.push_str(&schemes_side_by_side(runs));

    md.push_str("\n## Implicit against explicit\n\n");
    for m in BENCHMARK1_MODELS {
        let ex = runs.iter().find(|r| {
            r.run.id.starts_with(&format!("b1_{m}_"))
                && r.run.id.ends_with("_explicit")
                && r.completed()
        });
        let Some(ex) = ex else { continue };
        let s: f64 = ex
            .run
            .id
            .trim_start_matches(&format!("b1_{m}_"))
            .trim_end_matches("_explicit")
            .parse()
            .unwrap_or(f64::NAN);
        if let Some(im) = b1(m, s) {
            md.push_str(&format!("### Benchmark 1, {m}, {s} m\n\n"));
            md.push_str(&ledger_table(im, ex).markdown());
            md.push('\n');
        }
    }
    for m in BENCHMARK2_MODELS {
        if let (Some(im), Some(ex)) = (
            find(runs, &format!("b2_{m}_implicit")),
            find(runs, &format!("b2_{m}_explicit")),
        ) {
            md.push_str(&format!("### Benchmark 2, {m}\n\n"));
            md.push_str(&ledger_table(im, ex).markdown());
            md.push('\n');
        }
    }

    md.push_str("\n## Energy checks and run times\n\n");
    let mut t = Table::new(&["run", "status", "checks", "dofs", "steps", "wall time [s]"]);
    let mut total = 0.0;
    for r in runs {
        let secs = r.seconds();
        if secs.is_finite() {
            total += secs;
        }
        t.push(vec![
            r.run.label.clone(),
            r.status_word().into(),
            if r.checks_hold() {
                "hold".into()
            } else {
                "FAIL".into()
            },
            num(r.number("/dofs")),
            num(r.number("/steps")),
            num(Some(secs)),
        ]);
    }
    md.push_str(&t.markdown());
    md.push_str(&format!("\nSum of the runs' wall times: {total:.1} s.\n"));
    t.write_csv(&dir.join("runs.csv"))?;
    Ok(md)
}

/// The damage models' material dissipation over the meshes, fine to coarse, with
/// the successive differences and their ratios (a ratio above 1 is a difference
/// that shrinks).
fn damage_convergence(runs: &[RunData], meshes: &[f64]) -> String {
    let mut t = Table::new(&[
        "model",
        "mesh",
        "material dissipation / E_kin⁰",
        "difference to the previous mesh",
        "ratio of successive differences",
    ]);
    for m in ["mazars", "mazars_local", "mazars_plateau", "rankine_hill"] {
        let values: Vec<(f64, f64)> = meshes
            .iter()
            .filter_map(|&s| {
                find(runs, &format!("b1_{m}_{s}"))
                    .map(|r| (s, r.dissipated_material() / r.kinetic_0()))
            })
            .collect();
        let mut previous: Option<(f64, f64)> = None;
        let mut last_diff: Option<f64> = None;
        for &(s, d) in &values {
            let diff = previous.map(|p| d - p.1);
            let ratio = match (last_diff, diff) {
                (Some(a), Some(b)) if b != 0.0 => Some(a.abs() / b.abs()),
                _ => None,
            };
            t.push(vec![
                m.to_string(),
                format!("{s} m"),
                num(Some(d)),
                num(diff),
                num(ratio),
            ]);
            previous = Some((s, d));
            last_diff = diff.or(last_diff);
        }
    }
    format!(
        "\n### Mesh convergence of the material dissipation\n\n{}",
        t.markdown()
    )
}

/// The energies of one run against time: E_kin, E_el, W_ext, each nonzero
/// dissipation line and the total.
fn energies(r: &RunData, title: &str, stem: &Path) -> Result<()> {
    let mut fig = Figure::new(title, "t [ms]", "energy [J]");
    for (c, l) in [("E_kin", "E_kin"), ("E_el", "E_el"), ("W_ext", "W_ext")] {
        fig = fig.with(Series::new(l, r.series(c, 1.0), Style::Line));
    }
    for c in super::run_data::DISSIPATION_COLUMNS {
        let s = r.series(c, 1.0);
        if s.iter().any(|p| p.1 != 0.0) {
            fig = fig.with(Series::new(c, s, Style::Line));
        }
    }
    fig = fig.with(Series::new(
        "D total",
        r.dissipation_series(1.0),
        Style::Dashed,
    ));
    draw(&fig, stem).map(|_| ())
}
