//! Workload W1, the project's speed yardstick: a plane-stress rectangle 2.0 m x 0.5 m,
//! thickness 0.2 m, structured Q4 with `nx = 4 ny`, `E = 30e9, ν = 0.2, ρ = 2400`,
//! consistent mass, left edge fixed, a step traction of 1e6 Pa downwards on the top
//! edge, backward Euler `h = 1e-5`, 100 steps from rest; probe `u_y` at (2.0, 0.25).
#![allow(dead_code)] // each bench, example and test uses a part

use rothe::error::Result;
use rothe::model::Model;

/// The W1 material block with the standard linear solid of eq. (10) in place of
/// elasticity (`α = 0.5`, `β = 1e-4 s`), for cost comparisons.
pub const W1_SLS: &str = "model = \"sls\"\nalpha = 0.5\nbeta = 1.0e-4";

/// The W1 material block with Mazars damage (NOTES.md parameters for concrete): the
/// 1 MPa step cracks the clamped end, so the iterations have work to do.
pub const W1_MAZARS: &str =
    "model = \"mazars\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3";

/// The W1 Mazars block with nonlocal averaging over `R = 0.03 m` (three cells of
/// W1 at `ny = 50`).
pub const W1_MAZARS_NONLOCAL: &str = "model = \"mazars\"\neps_t0 = 1.0e-4\nA_t = 1.0\nB_t = 1.0e4\nA_c = 1.2\nB_c = 1.5e3\nnonlocal = { radius = 0.03 }";

/// The W1 material block with Rankine-Hill plasticity (bilinear C30/37 diagram).
pub const W1_RANKINE_HILL: &str = "model = \"rankine_hill\"\ntension = { law = \"bilinear\", strength = 2.9e6, post_yield_modulus = 1.5e9 }\ncompression = { law = \"bilinear\", strength = 30.0e6, post_yield_modulus = 1.5e9 }";

/// A W1 variant by name: `elastic`, `sls`, `mazars` (secant refactorised every
/// iteration), `mazars-fixed` (one factorisation per step), `rankine-hill` (Newton).
pub fn w1_variant(ny: usize, name: &str) -> Result<Model> {
    let (lines, iteration) = match name {
        "elastic" => ("model = \"elastic\"", "newton"),
        "sls" => (W1_SLS, "newton"),
        "mazars" => (W1_MAZARS, "newton"),
        "mazars-fixed" => (W1_MAZARS, "fixed"),
        "mazars-nonlocal" => (W1_MAZARS_NONLOCAL, "newton"),
        "rankine-hill" => (W1_RANKINE_HILL, "newton"),
        other => {
            return Err(rothe::error::Error::config(
                "variant",
                format!(
                "unknown W1 variant `{other}` (elastic, sls, mazars, mazars-fixed, mazars-nonlocal, rankine-hill)"
            ),
            ))
        }
    };
    let text = w1_scenario_with(ny, lines).replace(
        "vtk_every = 0",
        &format!("vtk_every = 0\niteration = \"{iteration}\""),
    );
    rothe::config::from_str(&text, std::path::Path::new("."))
}

/// The W1 scenario text for `ny` cells across the height.
pub fn w1_scenario(ny: usize) -> String {
    w1_scenario_with(ny, "model = \"elastic\"")
}

/// The W1 scenario with another material model line block (`model = ...` plus its
/// parameters; `E, nu, rho` stay W1's).
pub fn w1_scenario_with(ny: usize, model_lines: &str) -> String {
    cantilever_scenario(
        [4 * ny, ny],
        1e-5,
        1e-3,
        &format!("{model_lines}\nE = 30e9\nnu = 0.2\nrho = 2400.0"),
        "mass = \"consistent\"\nvtk_every = 0",
    )
}

/// The cantilever wall behind W1 and many tests: 2.0 m x 0.5 m x 0.2 m, `divisions`
/// Q4 cells, left edge clamped, a step traction of 1 MPa down on the top edge, probe
/// `tip` at (2.0, 0.25). `material_lines` is the body of `[materials.concrete]`
/// (model, parameters, `E`, `nu`, `rho`); `analysis_extra` adds lines to `[analysis]`.
/// Step sizes print as `1.0e-5`.
pub fn cantilever_scenario(
    divisions: [usize; 2],
    dt: f64,
    t_end: f64,
    material_lines: &str,
    analysis_extra: &str,
) -> String {
    format!(
        r#"
[analysis]
t_end = {t_end:.1e}
dt = {dt:.1e}
{analysis_extra}
[materials.concrete]
{material_lines}
[[bodies]]
name = "beam"
material = "concrete"
thickness = 0.2
mesh = {{ kind = "rectangle", size = [2.0, 0.5], divisions = [{nx}, {ny}] }}
[[supports]]
set = "beam.left"
fix = ["x", "y"]
[[loads]]
kind = "traction"
set = "beam.top"
value = [0.0, -1.0e6]
function = {{ kind = "step", at = 0.0 }}
[[probes]]
name = "tip"
at = [2.0, 0.25]
"#,
        nx = divisions[0],
        ny = divisions[1]
    )
}

/// Workload W3, the solid counterpart of W1: a box 2.0 m x 0.5 m x 0.5 m of
/// `4n x n x n` hexahedra, W1's concrete, consistent mass, clamped at `x = 0`, a
/// step traction of 1 MPa down on the top face, backward Euler `h = 1e-5`, 100
/// steps from rest; probe `tip` at the top right front corner.
pub fn w3_scenario(n: usize) -> String {
    format!(
        r#"
[analysis]
t_end = 1.0e-3
dt = 1.0e-5
mass = "consistent"
vtk_every = 0
[materials.concrete]
model = "elastic"
E = 30e9
nu = 0.2
rho = 2400.0
[[bodies]]
name = "beam"
material = "concrete"
mesh = {{ kind = "box", size = [2.0, 0.5, 0.5], divisions = [{nx}, {n}, {n}] }}
[[supports]]
set = "beam.left"
fix = ["x", "y", "z"]
[[loads]]
kind = "traction"
set = "beam.top"
value = [0.0, -1.0e6, 0.0]
function = {{ kind = "step", at = 0.0 }}
[[probes]]
name = "tip"
set = "beam.top_right_front"
"#,
        nx = 4 * n
    )
}

/// The W3 model for `n` cells across the height.
pub fn w3(n: usize) -> Result<Model> {
    rothe::config::from_str(&w3_scenario(n), std::path::Path::new("."))
}

/// The W1 model for `ny` cells across the height.
pub fn w1(ny: usize) -> Result<Model> {
    rothe::config::from_str(&w1_scenario(ny), std::path::Path::new("."))
}

/// The W1 model with the material block `model_lines`.
pub fn w1_with(ny: usize, model_lines: &str) -> Result<Model> {
    rothe::config::from_str(
        &w1_scenario_with(ny, model_lines),
        std::path::Path::new("."),
    )
}

/// The reduced effective matrix `c_m M + c_k K` of a model (consistent mass unless
/// the model's analysis lumps it), as the integrators build it: the matrices the
/// solver tests and benches factorise.
pub fn effective_matrix(model: &Model, c_m: f64, c_k: f64) -> rothe::linsolve::LowerCsc {
    let asm = rothe::assembly::Assembler::new(&model.mesh);
    let k = asm.stiffness(&model.mesh, &model.materials, model.idealisation);
    let mass = asm.mass(&model.mesh, &model.materials, false);
    let dofs =
        rothe::system::DofMap::new(model.mesh.n_dofs(), model.constraints.iter().map(|c| c.dof));
    let mut reduced = rothe::system::ReducedMatrix::new(&asm.pattern, &dofs);
    reduced.fill(&dofs, c_m, &mass, &[(c_k, &k)]);
    reduced.csc
}

/// The memory bandwidth of a STREAM-triad-like kernel `a = b + s c` over three
/// arrays of `n` doubles (bytes/s, 24 bytes per element, best of `reps`), on one
/// thread or, with `all_cores`, split over the rayon pool's threads (STREAM's
/// convention, and what a solve on both cores can draw on), so that a solve's
/// achieved bandwidth can be set beside the machine's in the same run.
pub fn triad_bandwidth(n: usize, reps: usize, all_cores: bool) -> f64 {
    let b = vec![1.0f64; n];
    let c = vec![2.0f64; n];
    let mut a = vec![0.0f64; n];
    let chunk = probe_chunk(n, all_cores);
    let best = best_time(reps, || triad(&mut a, &b, &c, chunk));
    24.0 * n as f64 / best
}

/// `a = b + 3 c`, each thread of the rayon pool on `chunk` elements at a time.
pub fn triad(a: &mut [f64], b: &[f64], c: &[f64], chunk: usize) {
    use rayon::prelude::*;
    a.par_chunks_mut(chunk)
        .zip(b.par_chunks(chunk).zip(c.par_chunks(chunk)))
        .for_each(|(a, (b, c))| {
            for ((x, y), z) in a.iter_mut().zip(b).zip(c) {
                *x = y + 3.0 * z;
            }
        });
    std::hint::black_box(a);
}

/// The bandwidth of reading one array of `n` doubles front to back (bytes/s, best
/// of `reps`; each thread's part one sequential stream, summed in 16 independent
/// partial sums), on one thread or split over the rayon pool's threads: the access
/// a triangular solve makes of its factor, which on some machines streams slower
/// than the triad's mix of two reads and a write.
pub fn read_bandwidth(n: usize, reps: usize, all_cores: bool) -> f64 {
    let a: Vec<f64> = (0..n).map(|i| (i % 7) as f64).collect();
    let chunk = probe_chunk(n, all_cores);
    let best = best_time(reps, || {
        std::hint::black_box(read_sum(&a, chunk));
    });
    8.0 * n as f64 / best
}

/// The sum of `a` (its whole 16-value chunks), each thread of the rayon pool
/// reading `chunk` elements front to back.
pub fn read_sum(a: &[f64], chunk: usize) -> f64 {
    use rayon::prelude::*;
    a.par_chunks(chunk)
        .map(|part| {
            let mut acc = [0.0f64; 16];
            for c in part.chunks_exact(16) {
                for (s, v) in acc.iter_mut().zip(c) {
                    *s += v;
                }
            }
            acc.iter().sum::<f64>()
        })
        .sum()
}

/// The part of `n` values each thread of a bandwidth probe takes.
fn probe_chunk(n: usize, all_cores: bool) -> usize {
    if all_cores {
        n.div_ceil(rayon::current_num_threads()).max(1)
    } else {
        n.max(1)
    }
}

/// The shortest of `reps` (at least one) timings of `run`, in seconds.
fn best_time(reps: usize, mut run: impl FnMut()) -> f64 {
    (0..reps.max(1))
        .map(|_| {
            let t = std::time::Instant::now();
            run();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Prints the machine's bandwidth, measured now on one core and on all, the bound
/// it puts on a solve that streams a factor of `nnz_l` stored entries (`lower` of
/// them on and below the diagonal) twice, and how far the measured solve
/// (`solve_per` seconds) and step (`step_per`) are from it.
pub fn print_stream_bounds(nnz_l: usize, lower: usize, solve_per: f64, step_per: f64) {
    // The machine's bandwidth, measured now (outside the run's total) on one core
    // and on all (the solve runs on both cores; the bound uses the all-core figure),
    // and the solve's and the step's shares of it; beside it the bandwidth of
    // reading one stream per core, which is how a solve reads its factor.
    let triad_one = triad_bandwidth(1 << 24, 10, false);
    let triad = triad_bandwidth(1 << 24, 10, true);
    let read_one = read_bandwidth(1 << 25, 5, false);
    let read = read_bandwidth(1 << 25, 5, true);
    let bytes = 2.0 * nnz_l as f64 * 8.0;
    let bound = bytes / triad;
    let read_bound = bytes / read;
    let cores = rayon::current_num_threads();
    println!(
        "  triad bandwidth      {:.1} GB/s on one core, {:.1} GB/s on all {cores}",
        triad_one / 1e9,
        triad / 1e9,
    );
    println!(
        "  read bandwidth       {:.1} GB/s on one core, {:.1} GB/s on all {cores}",
        read_one / 1e9,
        read / 1e9,
    );
    println!(
        "  factor stream bound  {:.2} ms per solve (2 x nnz(L) x 8 B at {:.1} GB/s; {:.2} ms at the read bandwidth)",
        1e3 * bound,
        triad / 1e9,
        1e3 * read_bound
    );
    println!(
        "  solve achieved       {:.2} ms per solve, {:.1} GB/s ({:.2} x the bound, {:.2} x the read bound)",
        1e3 * solve_per,
        bytes / solve_per / 1e9,
        solve_per / bound,
        solve_per / read_bound
    );
    println!(
        "  step                 {:.2} x the bound, {:.2} x the read bound",
        step_per / bound,
        step_per / read_bound
    );
    // faer's supernodes store the upper triangles of their diagonal blocks too (the
    // sweeps stream them with the rest); the bound of the entries on and below the
    // diagonal alone is the stricter figure.
    if lower < nnz_l {
        let lower_bound = 2.0 * lower as f64 * 8.0 / triad;
        println!(
            "  lower entries        {:.2}M of the {:.2}M stored: bound {:.2} ms, solve {:.2} x, step {:.2} x",
            lower as f64 / 1e6,
            nnz_l as f64 / 1e6,
            1e3 * lower_bound,
            solve_per / lower_bound,
            step_per / lower_bound
        );
    }
}
