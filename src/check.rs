//! `rothe check`: what a scenario will take before it runs. The report gives the
//! bodies, nodes, elements and dofs, the steps and the output they write (history
//! rows, VTK files and their size), the explicit critical step, the nonzeros of the
//! effective matrix and of its factor (from the symbolic analysis, so nothing large is
//! allocated), and the memory the run needs against what the machine has. Huge step
//! counts and outputs are warnings; a model that would not fit is an error unless the
//! limit is lifted.

use std::fmt;

use crate::assembly::Pattern;
use crate::error::Result;
use crate::linsolve::Backend;
use crate::memory::{human, Estimate};
use crate::model::Model;
use crate::system::{DofMap, EffectiveSystem};

/// Output volumes from which `check` warns.
pub const HUGE_OUTPUT: u64 = 20_000_000_000;

/// What `rothe check` reports.
#[derive(Clone, Debug)]
pub struct Report {
    /// Body lines: name, elements, thickness (none for a solid), velocity (two
    /// components in the plane, three in a solid).
    pub bodies: Vec<(String, usize, Option<f64>, Vec<f64>)>,
    /// Nodes.
    pub nodes: usize,
    /// Elements.
    pub elements: usize,
    /// Dofs and free dofs.
    pub dofs: (usize, usize),
    /// Steps, step size, end time.
    pub steps: (usize, f64, f64),
    /// An error-controlled run's plan (`None` for fixed steps).
    pub adaptive: Option<crate::time::adaptive::AdaptivePlan>,
    /// History rows and their bytes.
    pub history: (usize, u64),
    /// VTK files and their total bytes.
    pub vtk: (usize, u64),
    /// The explicit critical step, its block and element, and `h / Δt_crit`.
    pub cfl: Option<(f64, usize, usize, f64)>,
    /// The stable step of central differences (element eigenvalue bound), its block
    /// and element.
    pub stable: Option<(f64, usize, usize)>,
    /// Central differences: the stable step of the whole mesh (`λ_max` of
    /// `M_lumped⁻¹K` by Lanczos, shortened for the damping taken at the half-step
    /// velocity).
    pub exact_step: Option<crate::modal::ExactStep>,
    /// The time scheme (for a dynamic analysis).
    pub scheme: Option<crate::model::TimeScheme>,
    /// Generalized-α's spectral radius at infinity.
    pub rho_inf: f64,
    /// The second-order schemes' contact predictor.
    pub contact_predictor: crate::model::ContactPredictor,
    /// How an implicit step of damage or plasticity iterates: the method and the
    /// kept factor's rate (`None` when every material has a constant tangent or the
    /// scheme is explicit).
    pub iteration: Option<(crate::model::IterationMethod, Option<f64>)>,
    /// nnz of the effective matrix (lower) and of the factor.
    pub nnz: (usize, usize),
    /// Whether the ordering is nested dissection.
    pub nested_dissection: bool,
    /// The backend that analysed the factor.
    pub backend: Backend,
    /// A distributed backend's analysis: the factor's size and each rank's memory.
    pub distributed: Option<crate::linsolve::distributed::DistributedAnalysis>,
    /// The memory estimate with the factor's exact size.
    pub memory: Estimate,
    /// Memory available on this machine.
    pub available: Option<u64>,
    /// Warnings (huge step counts, huge outputs).
    pub warnings: Vec<String>,
    /// One entry per material: its lines (model and elastic constants, where an
    /// identification came from, the parameters).
    pub materials: Vec<Vec<String>>,
    /// The nonlocal table, when a material is nonlocal: points, neighbour counts
    /// (fewest, most, mean) and bytes.
    pub nonlocal: Option<(usize, usize, usize, f64, u64)>,
    /// One line per contact pair: name, master, formulation, friction.
    pub contacts: Vec<String>,
    /// Rayleigh's pair set from modal targets, and the damping ratio it gives the
    /// first modes (computed), when the scenario gave `analysis.damping`.
    pub damping: Vec<String>,
}

/// The lines `check` and `material` print for a material: model, elastic constants,
/// where identified parameters came from, the parameters.
pub fn material_lines(m: &crate::material::Material) -> Vec<String> {
    let kind = m.model_name();
    let mut lines = vec![format!(
        "{}: {kind}, E = {} Pa, nu = {}, rho = {}",
        m.name,
        crate::material::sig(m.e),
        m.nu,
        m.rho
    )];
    if let Some(from) = &m.identified_from {
        lines.push(format!("identified from {from}"));
    }
    let params = m.parameters();
    if !params.is_empty() {
        lines.push(
            params
                .iter()
                .map(|(k, v)| format!("{k} = {v}"))
                .collect::<Vec<_>>()
                .join(", "),
        );
    }
    lines
}

/// The output a run of `model` writes and the warnings of a runaway run.
pub struct Volume {
    /// `(rows, bytes)` of `history.csv`.
    pub history: (usize, u64),
    /// `(files, bytes)` of the VTK series.
    pub vtk: (usize, u64),
    /// A step count or an output size far past what is meant, one sentence each.
    pub warnings: Vec<String>,
}

/// Estimates the output of a run of `model`: `check` prints it and `run` warns with
/// the same sentences before it starts.
pub fn volume(model: &Model) -> Volume {
    let mesh = &model.mesh;
    let a = &model.analysis;
    // An error-controlled run: the fewest steps it can take (all at dt_max).
    let steps = match a.time.adaptive {
        Some(ad) => (a.time.t_end / ad.dt_max).ceil() as usize,
        None => a.n_steps(),
    };
    let probes = model.probes.len();
    // A row: 12 ledger columns, 2 solver columns, 2 per probe, about 20 bytes each.
    let row_bytes = (16 + 2 * probes) as u64 * 20;
    let history = (steps + 1, (steps as u64 + 1) * row_bytes);
    let vtk_files = match a.output.vtk_every_time {
        // At most one file per step: frames closer than the steps are written at the
        // steps (an error-controlled run lands its steps on them, down to dt_min).
        Some(every) => {
            let frames = (a.time.t_end / every + 1e-9).floor() + 1.0;
            let most_steps = match a.time.adaptive {
                Some(ad) => (a.time.t_end / ad.dt_min).ceil(),
                None => steps as f64,
            };
            frames.min(most_steps + 1.0) as usize
        }
        None => steps.checked_div(a.output.vtk_every).map_or(0, |k| k + 1),
    };
    // Points (3 doubles), connectivity, two vector fields, cell fields, as ASCII.
    let vtk_file_bytes =
        (mesh.n_nodes() as u64) * (3 + 3 + 3) * 24 + (mesh.n_elements() as u64) * (5 + 6) * 24;
    let vtk = (vtk_files, vtk_files as u64 * vtk_file_bytes);
    let mut warnings = Vec::new();
    if steps >= crate::config::HUGE_STEPS {
        warnings.push(format!(
            "{steps} steps: is dt ({:e} s) meant? t_end / dt sets the step count",
            a.time.dt
        ));
    }
    if history.1 + vtk.1 >= HUGE_OUTPUT {
        warnings.push(format!(
            "the output will take about {} (history {}, {} VTK files {}): raise vtk_every or \
             shorten the run",
            human(history.1 + vtk.1),
            human(history.1),
            vtk.0,
            human(vtk.1)
        ));
    }
    Volume {
        history,
        vtk,
        warnings,
    }
}

/// Analyses `model` (pattern and symbolic factorisation, no numeric work) and
/// reports; refuses a model whose memory estimate exceeds `memory_limit`.
pub fn report(model: &Model, memory_limit: Option<u64>) -> Result<Report> {
    report_with(model, memory_limit, Backend::Faer)
}

/// [`report`] with the factor analysed by `backend`: with `mumps`, MUMPS's own
/// analysis over the MPI ranks, whose estimates of the factor and of each rank's
/// memory the report gives and the memory check uses (per node).
pub fn report_with(model: &Model, memory_limit: Option<u64>, backend: Backend) -> Result<Report> {
    let mesh = &model.mesh;
    let pattern = Pattern::new(mesh);
    let dofs = DofMap::new(mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
    let system = EffectiveSystem::new(
        &pattern,
        dofs,
        backend,
        model.analysis.iteration.ordering,
        &mesh.coords,
    )?;
    let nnz_l = system.factor_nnz().unwrap_or(0);
    let memory = crate::memory::of_model(model, Some(nnz_l));
    let distributed = system.distributed().cloned();
    match &distributed {
        Some(d) => crate::memory::check_distributed(model, d, memory_limit, "the run")?,
        None => memory.check(memory_limit, "the run")?,
    }
    let a = &model.analysis;
    let steps = a.n_steps();
    let Volume {
        history,
        vtk,
        mut warnings,
    } = volume(model);
    warnings.extend(model.warnings.iter().cloned());
    let cfl = crate::time::cfl::critical_step(model)
        .map(|c| (c.dt, c.block, c.element, a.time.dt / c.dt));
    Ok(Report {
        bodies: model
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let els: usize = mesh
                    .blocks
                    .iter()
                    .filter(|bl| bl.body == i)
                    .map(|bl| bl.elements.len())
                    .sum();
                (
                    b.name.clone(),
                    els,
                    (mesh.dim == 2).then_some(b.thickness),
                    b.velocity[..mesh.dim].to_vec(),
                )
            })
            .collect(),
        nodes: mesh.n_nodes(),
        elements: mesh.n_elements(),
        dofs: (mesh.n_dofs(), system.dofs().n_free()),
        steps: (steps, a.time.dt, a.time.t_end),
        adaptive: crate::time::adaptive::AdaptivePlan::of(model),
        history,
        vtk,
        cfl,
        stable: crate::time::cfl::stable_step(model).map(|c| (c.dt, c.block, c.element)),
        exact_step: if a.time.scheme == crate::model::TimeScheme::CentralDifference {
            Some(crate::modal::exact_stable_step(model)?)
        } else {
            None
        },
        scheme: (a.time.kind == crate::model::AnalysisKind::Dynamic).then_some(a.time.scheme),
        rho_inf: a.time.rho_inf,
        contact_predictor: a.time.contact_predictor,
        iteration: (a.time.scheme.is_implicit()
            && model.materials.iter().any(|m| !m.has_constant_tangent()))
        .then_some((a.iteration.method, a.iteration.refactor_rate)),
        nnz: (system.matrix().row_idx.len(), nnz_l),
        nested_dissection: system.nested_dissection(),
        backend,
        distributed,
        memory,
        available: memory_limit.or_else(crate::memory::available),
        warnings,
        materials: model.materials.iter().map(material_lines).collect(),
        contacts: model.contacts.iter().map(contact_line).collect(),
        damping: damping_lines(model)?,
        nonlocal: crate::assembly::nonlocal::NonlocalTable::build(mesh, &model.materials).map(
            |t| {
                let (lo, hi) = t.neighbour_range();
                let mean = t.n_entries() as f64 / t.n_points().max(1) as f64;
                (t.n_points(), lo, hi, mean, t.bytes())
            },
        ),
    })
}

/// How a contact pair is enforced, for `check`: its master, the formulation of its
/// gaps and its friction.
fn contact_line(p: &crate::model::ContactPair) -> String {
    use crate::model::{Formulation, Master};
    let faces = p
        .sides
        .iter()
        .any(|s| matches!(s.master, Master::Faces { .. } | Master::Plane { .. }));
    let master = match p.sides.first().map(|s| &s.master) {
        Some(Master::Rigid { .. }) => "a rigid line",
        Some(Master::Plane { .. }) => "a rigid plane",
        Some(Master::Faces { .. }) if p.sides.len() == 2 => "faces, both ways",
        Some(Master::Faces { .. }) => "faces",
        _ if p.sides.len() == 2 => "segments, both ways",
        _ => "segments",
    };
    let formulation = match p.formulation {
        Formulation::Mortar => "mortar (one weighted gap per slave node)",
        Formulation::NodeToSegment if faces => "node to face",
        Formulation::NodeToSegment => "node to segment",
    };
    let friction = if p.mu > 0.0 {
        format!("Coulomb mu = {}", p.mu)
    } else if p.friction > 0.0 {
        format!("interpolated beta = {} (explicit)", p.friction)
    } else {
        "frictionless".to_string()
    };
    format!("{}: against {master}, {formulation}, {friction}", p.name)
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        writeln!(f, "bodies      {}", self.bodies.len())?;
        for (name, els, t, v) in &self.bodies {
            match t {
                Some(t) => writeln!(
                    f,
                    "  {name:<12} {els} elements, thickness {t} m, velocity {v:?} m/s"
                )?,
                None => writeln!(f, "  {name:<12} {els} elements (solid), velocity {v:?} m/s")?,
            }
        }
        writeln!(f, "materials   {}", self.materials.len())?;
        for lines in &self.materials {
            for (i, l) in lines.iter().enumerate() {
                writeln!(f, "  {}{l}", if i == 0 { "" } else { "  " })?;
            }
        }
        if let Some((points, lo, hi, mean, bytes)) = self.nonlocal {
            writeln!(
                f,
                "nonlocal    {points} points, {lo} to {hi} neighbours each (mean {mean:.1}), table {}",
                human(bytes)
            )?;
        }
        if !self.contacts.is_empty() {
            writeln!(f, "contact     {}", self.contacts.len())?;
            for l in &self.contacts {
                writeln!(f, "  {l}")?;
            }
        }
        writeln!(f, "nodes       {}", self.nodes)?;
        writeln!(f, "elements    {}", self.elements)?;
        writeln!(f, "dofs        {} ({} free)", self.dofs.0, self.dofs.1)?;
        let (steps, dt, t_end) = self.steps;
        if let Some(scheme) = self.scheme {
            writeln!(
                f,
                "scheme      {}",
                match scheme {
                    crate::model::TimeScheme::BackwardEuler => String::from("backward Euler (implicit)"),
                    crate::model::TimeScheme::Trapezoidal =>
                        "trapezoidal rule (implicit, second order, contact at the step's end)".into(),
                    crate::model::TimeScheme::GeneralizedAlpha => format!(
                        "generalized-α (implicit, second order, rho_inf = {}, contact at the step's end)",
                        self.rho_inf
                    ),
                    crate::model::TimeScheme::CentralDifference =>
                        "central differences (explicit, lumped mass, kinematic contact)".into(),
                }
            )?;
            if self.contact_predictor == crate::model::ContactPredictor::Stabilised {
                writeln!(
                    f,
                    "predictor   contact-stabilised (the free flight projected onto the \
                     admissible set before each step; its loss in D_predictor)"
                )?;
            }
        }
        if let Some((method, rate)) = self.iteration {
            let method = match method {
                crate::model::IterationMethod::Newton => "newton (the material tangent)",
                crate::model::IterationMethod::Fixed => "fixed (the tangent of the step's start)",
            };
            let factor = match rate {
                Some(r) => {
                    let fold = format!("{:.3}", 1.0 / r);
                    let fold = fold.trim_end_matches('0').trim_end_matches('.');
                    format!("the factor kept while each iteration divides the residual by {fold} or more")
                }
                None => "refactorised at every changed tangent".into(),
            };
            writeln!(f, "iteration   {method}; {factor}")?;
        }
        for (i, l) in self.damping.iter().enumerate() {
            writeln!(f, "{}{l}", if i == 0 { "damping     " } else { "  " })?;
        }
        match &self.adaptive {
            Some(plan) => writeln!(f, "steps       {plan}; T = {t_end:e} s")?,
            None => writeln!(f, "steps       {steps} of h = {dt:e} s to T = {t_end:e} s")?,
        }
        writeln!(
            f,
            "output      history.csv {}{} rows ({}), {} VTK files ({})",
            if self.adaptive.is_some() {
                "at least "
            } else {
                ""
            },
            self.history.0,
            human(self.history.1),
            self.vtk.0,
            human(self.vtk.1)
        )?;
        if let Some((dt_c, block, element, ratio)) = self.cfl {
            writeln!(
                f,
                "CFL step    {dt_c:.4e} s (the paper's estimate L_e/c; block {block}, element {element}); h / CFL = {ratio:.3}"
            )?;
        }
        if let Some((dt_s, block, element)) = self.stable {
            writeln!(
                f,
                "stable step {dt_s:.4e} s (central differences, 2/ω_max of the elements; block {block}, element {element}); h / stable = {:.3}",
                self.steps.1 / dt_s
            )?;
        }
        if let Some(e) = self.exact_step {
            let damping = if e.damping_rate > 0.0 {
                format!(
                    ", shortened for the damping rate c = {:.4e} 1/s",
                    e.damping_rate
                )
            } else {
                ", undamped".to_string()
            };
            writeln!(
                f,
                "exact step  {:.4e} s (2/ω_max of the whole mesh, M_lumped⁻¹K by Lanczos, ω_max = {:.4e} rad/s{damping}); h / exact = {:.3}",
                e.dt,
                e.omega_max,
                self.steps.1 / e.dt
            )?;
        }
        writeln!(
            f,
            "nnz(K_eff)  {} (lower), nnz(L) {} ({}{}, {})",
            self.nnz.0,
            self.nnz.1,
            self.backend.name(),
            if self.distributed.is_some() {
                "'s estimate"
            } else {
                ""
            },
            if self.nested_dissection {
                "nested dissection"
            } else {
                "AMD"
            }
        )?;
        let m = &self.memory;
        write!(
            f,
            "memory      about {} (mesh {}, matrices {}, factor {}, state {})",
            human(m.total()),
            human(m.mesh),
            human(m.matrices),
            human(m.factor),
            human(m.state)
        )?;
        match self.available {
            Some(a) => writeln!(f, "; {} available", human(a))?,
            None => writeln!(f)?,
        }
        if let Some(d) = &self.distributed {
            distributed_lines(f, d)?;
        }
        for w in &self.warnings {
            writeln!(f, "warning     {w}")?;
        }
        Ok(())
    }
}

/// A count of entries for people: `5.55G`, `97.0M`, `22220`.
fn entries(n: u64) -> String {
    let x = n as f64;
    if x >= 1e9 {
        format!("{:.2}G", x / 1e9)
    } else if x >= 1e6 {
        format!("{:.1}M", x / 1e6)
    } else {
        n.to_string()
    }
}

/// MUMPS's analysis: the factor, each rank's estimate and each node's sum.
fn distributed_lines(
    f: &mut fmt::Formatter,
    d: &crate::linsolve::distributed::DistributedAnalysis,
) -> fmt::Result {
    writeln!(
        f,
        "mumps       MUMPS {} on {} rank{}: factor about {} entries, {:.2e} flop; \
         the factorisation needs about {} per rank at most, {} in all",
        d.version,
        d.ranks,
        if d.ranks == 1 { "" } else { "s" },
        entries(d.factor_entries),
        d.flops,
        human(d.max_rank()),
        human(d.total())
    )?;
    for r in &d.per_rank {
        writeln!(
            f,
            "rank {:<6} {} on {}{}",
            r.rank,
            human(r.estimate),
            r.node,
            if r.rank == 0 {
                " (with the run: assembly, materials, contact, output)"
            } else {
                ""
            }
        )?;
    }
    for n in d.nodes() {
        let ranks: Vec<String> = n.ranks.iter().map(|r| r.to_string()).collect();
        writeln!(
            f,
            "node        {}: ranks {}, {} for the factorisation{}",
            n.name,
            ranks.join(", "),
            human(n.estimate),
            match n.available {
                Some(a) => format!(" of {} available", human(a)),
                None => String::new(),
            }
        )?;
    }
    Ok(())
}

/// The lines of Rayleigh's pair from modal targets: the pair, its targets, and the
/// ratio at each of the first six modes (computed; rigid ones left out).
fn damping_lines(model: &Model) -> Result<Vec<String>> {
    let d = &model.analysis.damping;
    let Some((xi, w)) = d.targets else {
        return Ok(Vec::new());
    };
    let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
    let mut lines = vec![format!(
        "Rayleigh a_m = {:.6e} 1/s, a_k = {:.6e} s: ratio {xi} at {:.6e} and {:.6e} Hz",
        d.rayleigh[0],
        d.rayleigh[1],
        hz(w[0]),
        hz(w[1])
    )];
    let found = crate::modal::modes(
        model,
        &crate::modal::ModalOptions {
            count: 6.min(model.mesh.n_dofs()),
            backend: crate::linsolve::Backend::Faer,
            ..Default::default()
        },
    )?;
    for (i, m) in found.modes.iter().enumerate().filter(|(_, m)| !m.rigid) {
        lines.push(format!(
            "mode {:>2}  {:.6e} Hz  ratio {:.6}",
            i + 1,
            hz(m.omega()),
            d.ratio_at(m.omega())
        ));
    }
    Ok(lines)
}

/// Writes the matrices of the model's first step in Matrix Market format (through
/// nalgebra-sparse's I/O) into `dir`, for study in SciPy or MATLAB:
/// `K.mtx` and `M.mtx` (all dofs, dof `d n + c` for node `n`, component `c`, `d`
/// the mesh dimension),
/// `K_eff.mtx` (the effective matrix of the first step on the free dofs, both
/// triangles), `free_dofs.txt` (the dof of each free equation), and `G.mtx` (the
/// linearised gap rows of every contact candidate at the initial geometry, all dofs)
/// when the model has contact. Returns the files written.
pub fn write_matrices(model: &Model, dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>> {
    use nalgebra_sparse::io::save_to_matrix_market_file;
    use nalgebra_sparse::{CooMatrix, CscMatrix};
    std::fs::create_dir_all(dir).map_err(|e| crate::Error::io(dir, e))?;
    let (asm, k, mass, sys) = crate::time::first_matrices(model)?;
    let p = &asm.pattern;
    let n = p.n_dofs();
    let on_pattern = |values: &[f64]| {
        let mut coo = CooMatrix::new(n, n);
        let d = p.dim;
        for node in 0..p.n_nodes {
            let nbrs = &p.adj[p.adj_ptr[node]..p.adj_ptr[node + 1]];
            for j in 0..d {
                let c0 = p.col_start(node, j);
                for (kk, &m) in nbrs.iter().enumerate() {
                    for i in 0..d {
                        let v = values[c0 + d * kk + i];
                        if v != 0.0 {
                            coo.push(d * m as usize + i, d * node + j, v);
                        }
                    }
                }
            }
        }
        CscMatrix::from(&coo)
    };
    let mut written = Vec::new();
    let save =
        |name: &str, m: &CscMatrix<f64>, written: &mut Vec<std::path::PathBuf>| -> Result<()> {
            let path = dir.join(name);
            save_to_matrix_market_file(m, &path).map_err(|e| crate::Error::io(&path, e))?;
            written.push(path);
            Ok(())
        };
    save("K.mtx", &on_pattern(&k), &mut written)?;
    let m_values = match &mass {
        crate::assembly::Mass::Consistent(v) => on_pattern(v),
        crate::assembly::Mass::Lumped(d) => {
            let mut coo = CooMatrix::new(n, n);
            for (i, &v) in d.iter().enumerate() {
                coo.push(i, i, v);
            }
            CscMatrix::from(&coo)
        }
    };
    save("M.mtx", &m_values, &mut written)?;
    let a = sys.matrix();
    let mut coo = CooMatrix::new(a.n, a.n);
    for j in 0..a.n {
        for q in a.col_ptr[j]..a.col_ptr[j + 1] {
            let i = a.row_idx[q];
            coo.push(i, j, a.values[q]);
            if i != j {
                coo.push(j, i, a.values[q]);
            }
        }
    }
    save("K_eff.mtx", &CscMatrix::from(&coo), &mut written)?;
    let path = dir.join("free_dofs.txt");
    let text: String = sys.dofs().free.iter().map(|d| format!("{d}\n")).collect();
    std::fs::write(&path, text).map_err(|e| crate::Error::io(&path, e))?;
    written.push(path);
    if !model.contacts.is_empty() {
        let mut cands = Vec::new();
        crate::contact::candidates(model, &vec![0.0; n], &mut cands);
        let all: Vec<usize> = (0..n).collect();
        let g = crate::contact::gap_matrix(&cands, &all, n);
        let path = dir.join("G.mtx");
        save_to_matrix_market_file(&g, &path).map_err(|e| crate::Error::io(&path, e))?;
        written.push(path);
    }
    Ok(written)
}
