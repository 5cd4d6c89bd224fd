//! The material-point driver behind `rothe material`: one Gauss point taken along a
//! strain or stress path with mixed control, the same update the FE loop calls.
//!
//! A path fixes, per Voigt component, either the strain or the stress; the free
//! components are found by Newton with the material's consistent tangent. The output
//! `material.csv` has time, strain, stress, stored energy, history variables and the
//! cumulative dissipation by mechanism, plus the work `∫ σ:dε` (backward Euler sum
//! `Σ σ_{n+1}:Δε`) which equals `Δψ + D` exactly (see `theory/viscoelasticity.md`).

use std::io::Write;
use std::path::Path;

use serde::Deserialize;

use crate::config::MaterialSpec;
use crate::error::{Error, Result};
use crate::fe::{
    Idealisation, PlaneStrain, PlaneStress, Solid, StrainSpace, STRAIN_NAMES, STRESS_NAMES,
};
use crate::material::linalg::{solve_in_place, MAX_DIM};
use crate::material::{Material, PointResponse, StrainStep};
use crate::model::TimeFunction;

/// A `rothe material` file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriverFile {
    /// The material, as in a scenario's `[materials.NAME]`.
    pub material: MaterialSpec,
    /// The path.
    pub path: PathSpec,
}

/// Which loading path.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum PathKind {
    /// `x` loaded; `σ_yy = σ_xy = 0`.
    UniaxialStress,
    /// `x` loaded; `ε_yy = γ_xy = 0`.
    UniaxialStrain,
    /// `γ_xy` (or `σ_xy`) loaded; `ε_xx = ε_yy = 0`.
    PureShear,
    /// `x` and `y` loaded in the ratio `ratio`; `σ_xy = 0`.
    Biaxial,
    /// The full strain `[ε_xx, ε_yy, γ_xy]` tabulated at `times`.
    Table,
}

/// What the amplitude prescribes.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum Control {
    /// Strain.
    #[default]
    Strain,
    /// Stress.
    Stress,
}

fn one() -> f64 {
    1.0
}

fn constant() -> TimeFunction {
    TimeFunction::Constant
}

/// `[path]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathSpec {
    /// The path kind.
    pub kind: PathKind,
    /// Plane stress (default), plane strain, or a solid's point (six components).
    #[serde(default)]
    pub plane: Idealisation,
    /// Strain or stress control of the loaded components.
    #[serde(default)]
    pub control: Control,
    /// Amplitude of the loaded component (strain, or stress in Pa).
    #[serde(default)]
    pub amplitude: f64,
    /// Time function of the amplitude (default constant: a step at t = 0).
    #[serde(default = "constant")]
    pub function: TimeFunction,
    /// Biaxial ratio `y / x` (default 1).
    #[serde(default = "one")]
    pub ratio: f64,
    /// End time (s).
    pub t_end: f64,
    /// Step (s).
    pub dt: f64,
    /// Table path: times.
    #[serde(default)]
    pub times: Vec<f64>,
    /// Table path: strains at `times` (linear in between), `[ε_xx, ε_yy, γ_xy]` in
    /// the plane, `[ε_xx, ε_yy, γ_xy, ε_zz, γ_yz, γ_zx]` for a solid's point.
    #[serde(default)]
    pub strains: Vec<Vec<f64>>,
    /// Size of the element the point stands for (m), the crack-band length of
    /// softening laws. Default 0.1 m, a typical concrete element.
    #[serde(default = "default_length")]
    pub length: f64,
}

fn default_length() -> f64 {
    0.1
}

/// One output row (`V` strain components: 3 in the plane, 6 for a solid's point).
#[derive(Clone, Debug, PartialEq)]
pub struct PointRecord<const V: usize = 3> {
    /// Time.
    pub t: f64,
    /// Strain.
    pub eps: [f64; V],
    /// Material response of the step.
    pub response: PointResponse<V>,
    /// History after the step.
    pub state: Vec<f64>,
    /// Cumulative viscous, damage, plastic, numerical dissipation.
    pub dissipated: [f64; 4],
    /// Cumulative work `Σ σ_{n+1}:Δε`.
    pub work: f64,
}

/// Targets per component at time `t`: `(strain_given, value)`. A solid's point
/// (`V = 6`, components `[xx, yy, xy, zz, yz, zx]`) leaves its out-of-plane
/// components stress free where the plane path leaves `σ_yy` or `σ_xy` free, and
/// holds their strain at zero where the plane path holds strain.
fn targets<const V: usize>(p: &PathSpec, t: f64) -> [(bool, f64); V] {
    let a = p.amplitude * p.function.at(t);
    let s = p.control == Control::Strain;
    let loaded = |i: usize, given: bool, v: f64| move |k: usize| (k == i).then_some((given, v));
    let free = (false, 0.0);
    let held = (true, 0.0);
    let pick = |first: &[(usize, (bool, f64))], rest: (bool, f64)| -> [(bool, f64); V] {
        std::array::from_fn(|k| {
            first
                .iter()
                .find_map(|&(i, x)| loaded(i, x.0, x.1)(k))
                .unwrap_or(rest)
        })
    };
    match p.kind {
        PathKind::UniaxialStress => pick(&[(0, (s, a))], free),
        PathKind::UniaxialStrain => pick(&[(0, (s, a))], held),
        PathKind::PureShear => pick(&[(2, (s, a))], held),
        PathKind::Biaxial => pick(&[(0, (s, a)), (1, (s, p.ratio * a))], free),
        PathKind::Table => std::array::from_fn(|i| {
            let pts: Vec<[f64; 2]> = p
                .times
                .iter()
                .zip(&p.strains)
                .map(|(t, e)| [*t, e[i]])
                .collect();
            (true, TimeFunction::Table { points: pts }.at(t))
        }),
    }
}

/// Validates the path: every number finite, steps that fit a counter, a table path
/// with as many strains as strictly increasing times.
fn check(p: &PathSpec) -> Result<()> {
    crate::config::positive("path.dt", p.dt)?;
    crate::config::positive("path.t_end", p.t_end)?;
    crate::config::positive("path.length", p.length)?;
    let steps = (p.t_end / p.dt).round();
    if steps.is_nan() || steps > MAX_POINT_STEPS {
        return Err(Error::config(
            "path.dt",
            format!("t_end / dt = {steps:e} steps; at most {MAX_POINT_STEPS:e} are taken"),
        ));
    }
    crate::config::finite("path.amplitude", &[p.amplitude])?;
    crate::config::finite("path.ratio", &[p.ratio])?;
    crate::config::check_function("path.function", &p.function)?;
    if p.kind != PathKind::Table {
        // The other kinds drive one component by `amplitude` and `function`: a table
        // given beside them would be ignored.
        for (k, given) in [
            ("times", !p.times.is_empty()),
            ("strains", !p.strains.is_empty()),
        ] {
            if given {
                return Err(Error::config(
                    format!("path.{k}"),
                    "is read by a table path only (`kind = \"table\"`); this path is \
                     driven by `amplitude` and `function`: remove the key, or make the \
                     path a table",
                ));
            }
        }
    }
    if p.kind == PathKind::Table {
        // The table prescribes every component itself: the keys of the other kinds
        // would be ignored.
        let ignored = [
            ("control", p.control != Control::default()),
            ("amplitude", p.amplitude != 0.0),
            ("function", p.function != TimeFunction::Constant),
            ("ratio", p.ratio != 1.0),
        ];
        if let Some((k, _)) = ignored.iter().find(|(_, given)| *given) {
            return Err(Error::config(
                format!("path.{k}"),
                "a table path prescribes every strain component from `times` and \
                 `strains`; remove the key (it would be ignored)",
            ));
        }
        if p.times.is_empty() || p.times.len() != p.strains.len() {
            return Err(Error::config(
                "path.strains",
                format!(
                    "a table path needs `times` and as many `strains` (got {} times, {} strains)",
                    p.times.len(),
                    p.strains.len()
                ),
            ));
        }
        crate::config::finite("path.times", &p.times)?;
        let v = p.plane.voigt();
        for (i, e) in p.strains.iter().enumerate() {
            if e.len() != v {
                return Err(Error::config(
                    format!("path.strains[{i}]"),
                    format!(
                        "has {} components, expected {v} ({})",
                        e.len(),
                        if v == 6 {
                            "a solid's point: [ε_xx, ε_yy, γ_xy, ε_zz, γ_yz, γ_zx]"
                        } else {
                            "a plane point: [ε_xx, ε_yy, γ_xy]"
                        }
                    ),
                ));
            }
            crate::config::finite(&format!("path.strains[{i}]"), e)?;
        }
        if let Some(i) = p.times.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::config(
                "path.times",
                format!(
                    "must increase strictly, but times[{}] = {} follows times[{i}] = {}",
                    i + 1,
                    p.times[i + 1],
                    p.times[i]
                ),
            ));
        }
    }
    Ok(())
}

/// Steps a material-point path may take (one row each in `material.csv`).
const MAX_POINT_STEPS: f64 = 1e8;

/// Runs a plane path and returns one record per step (the first at `t = 0`).
pub fn run_path(mat: &Material, p: &PathSpec) -> Result<Vec<PointRecord>> {
    match p.plane {
        Idealisation::PlaneStress => collect_path::<3, PlaneStress>(mat, p),
        Idealisation::PlaneStrain => collect_path::<3, PlaneStrain>(mat, p),
        Idealisation::Solid => Err(wrong_size(p, 3)),
    }
}

/// Runs a solid point's path (`plane = "solid"`) and returns one record per step.
pub fn run_solid_path(mat: &Material, p: &PathSpec) -> Result<Vec<PointRecord<6>>> {
    match p.plane {
        Idealisation::Solid => collect_path::<6, Solid>(mat, p),
        _ => Err(wrong_size(p, 6)),
    }
}

/// The error of a path driven with `v` strain components that its `plane` does not
/// have (after the checks of the path itself, which come first).
fn wrong_size(p: &PathSpec, v: usize) -> Error {
    if let Err(e) = check(p) {
        return e;
    }
    Error::config(
        "path.plane",
        format!(
            "a point of {} strain components driven as one of {v}",
            p.plane.voigt()
        ),
    )
}

fn collect_path<const V: usize, K: StrainSpace<V>>(
    mat: &Material,
    p: &PathSpec,
) -> Result<Vec<PointRecord<V>>> {
    let mut out = Vec::new();
    drive::<V, K, _>(mat, p, |r| {
        out.push(r.clone());
        Ok(())
    })?;
    Ok(out)
}

/// Runs a plane path and hands each record to `sink` as it is computed (the first
/// at `t = 0`), so a long path needs no memory of its own.
pub fn run_path_with<F>(mat: &Material, p: &PathSpec, sink: F) -> Result<usize>
where
    F: FnMut(&PointRecord) -> Result<()>,
{
    match p.plane {
        Idealisation::PlaneStress => drive::<3, PlaneStress, F>(mat, p, sink),
        Idealisation::PlaneStrain => drive::<3, PlaneStrain, F>(mat, p, sink),
        Idealisation::Solid => Err(wrong_size(p, 3)),
    }
}

/// The path of a point of the idealisation `K` (`V` strain components; the
/// callers pick `K` from the path's `plane`).
fn drive<const V: usize, K: StrainSpace<V>, F>(
    mat: &Material,
    p: &PathSpec,
    mut sink: F,
) -> Result<usize>
where
    F: FnMut(&PointRecord<V>) -> Result<()>,
{
    check(p)?;
    let ns = mat.n_state(V);
    let mut state_n = vec![0.0; ns];
    mat.init_state(&mut state_n);
    let mut state = state_n.clone();
    let mut eps_n = [0.0; V];
    sink(&PointRecord {
        t: 0.0,
        eps: eps_n,
        response: PointResponse::default(),
        state: state_n.clone(),
        dissipated: [0.0; 4],
        work: 0.0,
    })?;
    let n = (p.t_end / p.dt).round().max(1.0) as usize;
    let (mut diss, mut work) = ([0.0; 4], 0.0);
    let mut record = PointRecord {
        t: 0.0,
        eps: eps_n,
        response: PointResponse::default(),
        state: state.clone(),
        dissipated: diss,
        work,
    };
    for k in 1..=n {
        let t = k as f64 * p.dt;
        let tg = targets::<V>(p, t);
        let mut eps = eps_n;
        for (i, (given, v)) in tg.iter().enumerate() {
            if *given {
                eps[i] = *v;
            }
        }
        let mut resp;
        let mut it = 0;
        loop {
            resp = mat.update::<V, K>(
                &StrainStep {
                    eps_n,
                    eps,
                    dt: p.dt,
                    length: p.length,
                    tangent: true,
                },
                &state_n,
                &mut state,
            );
            if resp.status != crate::material::PointStatus::Ok {
                return Err(Error::Stepping(format!(
                    "material point: the return mapping found no admissible state at t = {t:e} \
                     (strain {eps:?})"
                )));
            }
            let free: Vec<usize> = (0..V).filter(|&i| !tg[i].0).collect();
            let r: Vec<f64> = free.iter().map(|&i| resp.sigma[i] - tg[i].1).collect();
            let scale = resp
                .sigma
                .iter()
                .map(|s| s.abs())
                .fold(mat.e * 1e-12, f64::max)
                .max(tg.iter().map(|x| x.1.abs()).fold(0.0, f64::max));
            if free.is_empty() || r.iter().all(|x| x.abs() <= 1e-12 * scale) {
                break;
            }
            if it == 50 || r.iter().any(|x| !x.is_finite()) {
                return Err(Error::Stepping(format!(
                    "material point: no convergence of the mixed-control path at t = {t:e}"
                )));
            }
            // Newton on the stress-controlled components.
            let m = free.len();
            let mut a = [[0.0; MAX_DIM]; MAX_DIM];
            let mut d = [0.0; MAX_DIM];
            for (ii, &i) in free.iter().enumerate() {
                for (jj, &j) in free.iter().enumerate() {
                    a[ii][jj] = resp.tangent[i][j];
                }
                d[ii] = r[ii];
            }
            if !solve_in_place(a, &mut d, m) {
                return Err(Error::Stepping(format!(
                    "material point: singular tangent at t = {t:e}"
                )));
            }
            for (ii, &i) in free.iter().enumerate() {
                eps[i] -= d[ii];
            }
            it += 1;
        }
        let d = &resp.dissipation;
        diss[0] += d.viscous;
        diss[1] += d.damage;
        diss[2] += d.plastic;
        diss[3] += d.numerical;
        work += (0..V)
            .map(|i| resp.sigma[i] * (eps[i] - eps_n[i]))
            .sum::<f64>();
        record.t = t;
        record.eps = eps;
        record.response = resp;
        record.state.clone_from(&state);
        record.dissipated = diss;
        record.work = work;
        if let Some(bad) = record
            .response
            .sigma
            .iter()
            .chain(&eps)
            .chain(&diss)
            .find(|x| !x.is_finite())
        {
            return Err(Error::NonFinite {
                quantity: "material point stress, strain or dissipation".into(),
                value: *bad,
                location: None,
                t,
            });
        }
        sink(&record)?;
        eps_n = eps;
        state_n.clone_from(&state);
    }
    Ok(n)
}

/// Reads a driver file, runs it and writes `out/material.csv` row by row as the path
/// is computed (a failure part way keeps the rows written). Returns the steps taken.
///
/// `announce` sees the material before the path runs (the command line prints its
/// parameters, identified ones included).
pub fn run_file(file: &Path, out: &Path, announce: impl FnOnce(&Material)) -> Result<usize> {
    let text = std::fs::read_to_string(file).map_err(|e| Error::io(file, e))?;
    let in_file = |e: Error| match e {
        Error::Config { field, message } => {
            Error::config(format!("{}: {field}", file.display()), message)
        }
        other => other,
    };
    let spec: DriverFile = crate::config::parse_located(&text).map_err(in_file)?;
    let mat = crate::config::material("point", "material", &spec.material)
        .map_err(|e| Error::config(file.display().to_string(), e.to_string()))?;
    check(&spec.path).map_err(|e| Error::config(file.display().to_string(), e.to_string()))?;
    announce(&mat);
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    crate::dispatch_kinematics!(spec.path.plane, <D, V, K> => write_csv::<V, K>(&mat, &spec.path, out))
}

/// Runs the path of a point with `V` strain components and writes `material.csv`.
fn write_csv<const V: usize, K: StrainSpace<V>>(
    mat: &Material,
    p: &PathSpec,
    out: &Path,
) -> Result<usize> {
    let path = out.join("material.csv");
    let mut w =
        std::io::BufWriter::new(std::fs::File::create(&path).map_err(|e| Error::io(&path, e))?);
    let (strains, stresses) = (&STRAIN_NAMES[..V], &STRESS_NAMES[..V]);
    let mut header = vec!["t"];
    header.extend(strains);
    header.extend(stresses);
    header.push("psi");
    header.extend(mat.state_names(V));
    header.extend(["D_viscous", "D_damage", "D_plastic", "D_num", "work"]);
    let io = |e| Error::io(&path, e);
    writeln!(w, "{}", header.join(",")).map_err(io)?;
    let mut line = String::new();
    let steps = drive::<V, K, _>(mat, p, |r| {
        line.clear();
        let values = std::iter::once(r.t)
            .chain(r.eps)
            .chain(r.response.sigma)
            .chain([r.response.psi])
            .chain(r.state.iter().copied())
            .chain(r.dissipated)
            .chain([r.work]);
        for (k, v) in values.enumerate() {
            if k > 0 {
                line.push(',');
            }
            line.push_str(&format!("{v:.12e}"));
        }
        writeln!(w, "{line}").map_err(io)?;
        if r.t == 0.0 {
            w.flush().map_err(io)?;
        }
        Ok(())
    });
    w.flush().map_err(io)?;
    steps
}
