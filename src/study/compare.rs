//! `rothe compare`: one scenario through the implicit path (backward Euler or, with
//! `--implicit-scheme trapezoidal`, the trapezoidal rule; the contact QP) and the
//! explicit path (central differences with lumped mass, the
//! kinematic contact method, its stable step), the two ledgers side by side and the
//! difference put down to its mechanism. Theory: `theory/explicit.md`,
//! `theory/contact.md`.

use std::path::Path;

use super::plan::{Plan, PlannedRun, StudyKind};
use super::run_data::RunData;
use super::table::{num, Table};
use crate::config::Overrides;
use crate::error::{Error, Result};
use crate::plot::{draw, Figure, Series, Style};

/// The two runs of a comparison of `scenario` (with `base` applied to both), the
/// implicit one by `implicit_scheme` (`backward_euler`, `trapezoidal` or
/// `generalized_alpha`).
pub fn plan(scenario: &Path, base: &Overrides, implicit_scheme: &str) -> Result<Plan> {
    if !matches!(
        implicit_scheme,
        "backward_euler" | "trapezoidal" | "generalized_alpha"
    ) {
        return Err(Error::config(
            "--implicit-scheme",
            format!(
                "`{implicit_scheme}` is no implicit scheme (backward_euler, trapezoidal or \
                 generalized_alpha)"
            ),
        ));
    }
    let scheme = Overrides::none().set(&format!("analysis.scheme=\"{implicit_scheme}\""))?;
    Ok(Plan {
        kind: StudyKind::Compare,
        runs: pair(scenario, &base.then(&scheme), "", "")?,
    })
}

/// What `rothe compare` replaces of the scenario, as a warning: the implicit run
/// takes `implicit_scheme` (the `--implicit-scheme` option) whatever scheme the
/// scenario (with `base`) gives, and the explicit run central differences.
pub fn replaced_scheme(
    scenario: &Path,
    base: &Overrides,
    implicit_scheme: &str,
) -> Result<Option<String>> {
    let table = crate::config::merged_table(scenario, base)?;
    let given = table
        .get("analysis")
        .and_then(|a| a.get("scheme"))
        .and_then(|s| s.as_str())
        .map(str::to_string);
    Ok(given
        .filter(|g| g != implicit_scheme && g != "central_difference")
        .map(|g| {
            format!(
                "analysis.scheme = \"{g}\" is replaced: compare runs the implicit side by \
             --implicit-scheme ({implicit_scheme}) and the explicit side by central \
             differences; pass --implicit-scheme {g} to keep it"
            )
        }))
}

/// The implicit and explicit runs of `scenario` with ids `<prefix>implicit`,
/// `<prefix>explicit` and labels `<label>implicit`, `<label>explicit`.
pub fn pair(
    scenario: &Path,
    base: &Overrides,
    prefix: &str,
    label: &str,
) -> Result<Vec<PlannedRun>> {
    let scenario = super::plan::absolute(scenario)?;
    // The implicit run keeps an implicit scheme the overrides chose, else backward
    // Euler.
    let table = crate::config::merged_table(&scenario, base)?;
    let chosen = table
        .get("analysis")
        .and_then(|a| a.get("scheme"))
        .and_then(|s| s.as_str())
        .filter(|s| matches!(*s, "trapezoidal" | "generalized_alpha"));
    let implicit = match chosen {
        Some(_) => base.clone(),
        None => base.then(&Overrides::none().set("analysis.scheme=\"backward_euler\"")?),
    };
    // The explicit run takes its own stable step and lumped mass, and has no
    // generalized-α radius or contact predictor: `dt`, `mass`, `rho_inf` and
    // `contact_predictor` are removed where the scenario (with its variants) has
    // them, and the overrides' values for them are not passed on.
    const IMPLICIT_ONLY: [&str; 4] = [
        "analysis.dt",
        "analysis.mass",
        "analysis.rho_inf",
        "analysis.contact_predictor",
    ];
    let variants_only = Overrides {
        variants: base.variants.clone(),
        ..Overrides::none()
    };
    let file = crate::config::merged_table(&scenario, &variants_only)?;
    let mut own = base.clone();
    own.sets
        .retain(|(p, _)| !IMPLICIT_ONLY.contains(&p.as_str()));
    own.unsets.retain(|p| !IMPLICIT_ONLY.contains(&p.as_str()));
    for key in IMPLICIT_ONLY {
        if crate::config::overrides::has_path(&file, key) {
            own = own.unset(key);
        }
    }
    let explicit = own.set("analysis.scheme=\"central_difference\"")?;
    Ok(vec![
        PlannedRun {
            id: format!("{prefix}implicit"),
            scenario: scenario.clone(),
            overrides: implicit,
            param: 0.0,
            label: format!("{label}implicit"),
            record_fields: false,
        },
        PlannedRun {
            id: format!("{prefix}explicit"),
            scenario,
            overrides: explicit,
            param: 1.0,
            label: format!("{label}explicit"),
            record_fields: false,
        },
    ])
}

/// What explains the difference of each ledger line between the two paths.
const WHY: [(&str, &str); 8] = [
    (
        "numerical",
        "backward Euler loses ½|Δv|²_M per step (and the material's algorithmic share): \
         first order in h, concentrated in the high frequencies an impact excites; the \
         trapezoidal rule loses nothing of its own in linear elasticity (the materials' \
         algorithmic share only, of either sign). Central differences conserve a modified \
         energy: their line is the small oscillating difference to it",
    ),
    (
        "contact",
        "implicit: the work of the QP's contact forces on the gaps they close; the velocity \
         jump of an impact is split between this line and the scheme's loss (backward \
         Euler) or booked here whole (trapezoidal). Explicit: the kinetic energy the \
         perfectly inelastic impulses remove",
    ),
    (
        "friction",
        "implicit: the work of the Coulomb forces on the slip, step by step. Explicit: \
         none of its own, the impacts' friction loss is inside D_contact (an impulse's \
         loss does not split by direction)",
    ),
    (
        "predictor",
        "implicit with analysis.contact_predictor = \"stabilised\": the kinetic energy the \
         M-projection of the free flight onto the admissible set removes before a step \
         (the contact nodes' normal velocity at arrival). Explicit: none, the impulses take \
         the same loss inside D_contact",
    ),
    (
        "viscous",
        "the same dashpots on both paths; the explicit viscous force lags half a step, and \
         the wave fields differ (backward Euler damps the high frequencies that carry strain \
         rate)",
    ),
    (
        "damage",
        "the same damage law on both paths; differences follow the peak strains, which the \
         explicit path does not smooth",
    ),
    (
        "plastic",
        "the same return mapping on both paths; differences follow the peak stresses",
    ),
    (
        "mass",
        "mass and Rayleigh damping, the same matrices on both paths",
    ),
];

/// The ledger of two runs as rows `line, a, b, b − a, (b − a)/E_kin⁰ [%], why`.
pub fn ledger_table(a: &RunData, b: &RunData) -> Table {
    let mut t = Table::new(&[
        "line",
        &a.run.label,
        &b.run.label,
        "difference",
        "difference / E_kin0 [%]",
        "why",
    ]);
    let k0 = a.kinetic_0().max(b.kinetic_0());
    let row = |t: &mut Table, name: &str, x: f64, y: f64, why: &str| {
        // Only the energy lines are put against the initial kinetic energy.
        let pct = if k0 > 0.0 && name.ends_with("[J]") {
            Some(100.0 * (y - x) / k0)
        } else {
            None
        };
        t.push(vec![
            name.into(),
            num(Some(x)),
            num(Some(y)),
            num(Some(y - x)),
            num(pct),
            why.into(),
        ]);
    };
    let e = |r: &RunData, p: &str| r.number(p).unwrap_or(f64::NAN);
    row(
        &mut t,
        "E_kin0 [J]",
        a.kinetic_0(),
        b.kinetic_0(),
        "the same initial state",
    );
    row(
        &mut t,
        "W_ext [J]",
        e(a, "/energy/external_work"),
        e(b, "/energy/external_work"),
        "gravity's work follows the motion",
    );
    row(
        &mut t,
        "E_kin(T) [J]",
        e(a, "/energy/kinetic"),
        e(b, "/energy/kinetic"),
        "what the rebound keeps after the losses below",
    );
    row(
        &mut t,
        "E_el(T) [J]",
        e(a, "/energy/elastic"),
        e(b, "/energy/elastic"),
        "stored energy at the end (free vibration)",
    );
    for (line, why) in WHY {
        row(
            &mut t,
            &format!("D_{line} [J]"),
            a.dissipated(line),
            b.dissipated(line),
            why,
        );
    }
    row(
        &mut t,
        "D_total [J]",
        a.dissipated_total(),
        b.dissipated_total(),
        "the sum of the lines above",
    );
    row(
        &mut t,
        "balance residual [J]",
        e(a, "/energy/balance_residual"),
        e(b, "/energy/balance_residual"),
        "the ledger closes on both paths",
    );
    for p in a.probes() {
        row(
            &mut t,
            &format!("{p} min u_y [mm]"),
            1e3 * a.probe_min(&p),
            1e3 * b.probe_min(&p),
            "peak deflection",
        );
    }
    row(
        &mut t,
        "steps",
        e(a, "/steps"),
        e(b, "/steps"),
        "the explicit step is bounded by stability",
    );
    row(&mut t, "wall time [s]", a.seconds(), b.seconds(), "");
    t
}

/// Charts of two runs side by side: energies and each probe.
pub fn overlay(dir: &Path, a: &RunData, b: &RunData, stem: &str) -> Result<()> {
    let plots = dir.join("plots");
    let mut fig = Figure::new(
        "Energies, implicit against explicit",
        "t [ms]",
        "energy [J]",
    );
    for r in [a, b] {
        for (col, name) in [("E_kin", "E_kin"), ("E_el", "E_el")] {
            fig = fig.with(Series::new(
                format!("{name}, {}", r.run.label),
                r.series(col, 1.0),
                Style::Line,
            ));
        }
        fig = fig.with(Series::new(
            format!("D_total, {}", r.run.label),
            r.dissipation_series(1.0),
            Style::Line,
        ));
    }
    draw(&fig, &plots.join(format!("{stem}energies")))?;
    for p in a.probes() {
        let mut fig = Figure::new(
            format!("Probe {p}, implicit against explicit"),
            "t [ms]",
            "u_y [mm]",
        );
        for r in [a, b] {
            fig = fig.with(Series::new(
                r.run.label.clone(),
                r.series(&format!("{p}_uy"), 1e3),
                Style::Line,
            ));
        }
        draw(&fig, &plots.join(format!("{stem}probe_{p}")))?;
    }
    Ok(())
}

/// Tables, plots and summary of a collected comparison.
pub fn collect(dir: &Path, runs: &[RunData]) -> Result<String> {
    let [a, b] = runs else {
        return Err(Error::Stepping("a comparison has two runs".into()));
    };
    if !a.completed() || !b.completed() {
        return Err(Error::Stepping(format!(
            "both runs must complete: implicit {}, explicit {}",
            a.status_word(),
            b.status_word()
        )));
    }
    let table = ledger_table(a, b);
    table.write_csv(&dir.join("compare.csv"))?;
    overlay(dir, a, b, "")?;
    let mut md = format!(
        "# Implicit against explicit: {}\n\nThe same scenario through backward Euler with \
         the contact QP (h = {:e} s) and central differences with the kinematic contact \
         method (h = {:e} s, the stable step). Final ledger lines; the difference of each \
         is put down to its mechanism. Table: `compare.csv`; plots: `plots/`.\n\n",
        a.run.scenario.display(),
        a.number("/dt").unwrap_or(f64::NAN),
        b.number("/dt").unwrap_or(f64::NAN),
    );
    md.push_str(&table.markdown());
    md.push_str("\n![energies](plots/energies.png)\n");
    for p in a.probes() {
        md.push_str(&format!("\n![probe {p}](plots/probe_{p}.png)\n"));
    }
    Ok(md)
}
