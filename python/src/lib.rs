//! The native part of the `rothe` Python package: scenarios, runs, studies and the
//! material driver over the core crate. The Python layer (`python/rothe`) gives the
//! documented interface; this module keeps to strings, numbers and NumPy arrays.
//!
//! Every call that runs the solver releases the GIL for its whole duration and
//! re-takes it only to call a progress callback and to look for a pending signal
//! (Ctrl-C), about every 50 ms. Panics never cross into Python: the core catches
//! them and reports an internal error.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use rothe::config::{LoadOptions, Overrides};
use rothe::linsolve::Backend;
use rothe::model::Model;
use rothe::run::{Control, Hooks, Kept, Observer, RunOptions, StepInfo};

create_exception!(
    _rothe,
    Error,
    PyValueError,
    "An error of rothe: bad input (the message names the field) or a run that failed."
);

/// The core's error as a Python exception, with the command line's message.
fn py_err(e: rothe::Error) -> PyErr {
    match e {
        rothe::Error::Interrupted { .. } => PyKeyboardInterrupt::new_err(e.to_string()),
        e => Error::new_err(e.to_string()),
    }
}

fn overrides(
    variants: Vec<(String, String)>,
    unsets: Vec<String>,
    sets: Vec<(String, String)>,
) -> Overrides {
    Overrides {
        variants,
        unsets,
        sets,
    }
}

fn backend(name: &str) -> PyResult<Backend> {
    name.parse::<Backend>()
        .map_err(|m| Error::new_err(format!("backend: {m}")))
}

/// A validated scenario: its merged table (variants and overrides applied), where
/// it came from, and the model built from it.
#[pyclass(module = "rothe._rothe", frozen)]
struct NativeScenario {
    /// The scenario file, when it came from one.
    path: Option<PathBuf>,
    /// The directory mesh files are read relative to.
    dir: PathBuf,
    /// The text it was read from and the overrides applied to it.
    text: String,
    ov: Overrides,
    /// The merged table.
    table: toml::Table,
    model: Arc<Model>,
}

/// Reads a scenario: `kind` is `path`, `toml` (text) or `json` (a dict's JSON).
#[pyfunction]
#[pyo3(signature = (source, kind, dir, variants, unsets, sets, ignore_memory=false))]
#[allow(clippy::too_many_arguments)]
fn scenario(
    py: Python<'_>,
    source: String,
    kind: &str,
    dir: Option<PathBuf>,
    variants: Vec<(String, String)>,
    unsets: Vec<String>,
    sets: Vec<(String, String)>,
    ignore_memory: bool,
) -> PyResult<NativeScenario> {
    let ov = overrides(variants, unsets, sets);
    let opts = if ignore_memory {
        LoadOptions::unlimited()
    } else {
        LoadOptions::default()
    };
    py.detach(move || {
        let (path, dir, text) = match kind {
            "path" => {
                let path = PathBuf::from(&source);
                let text =
                    std::fs::read_to_string(&path).map_err(|e| rothe::Error::io(&path, e))?;
                let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
                (Some(path), dir, text)
            }
            "toml" => (None, dir.unwrap_or_else(|| PathBuf::from(".")), source),
            "json" => {
                let value: serde_json::Value = serde_json::from_str(&source).map_err(|e| {
                    rothe::Error::config("scenario", format!("not a table of TOML values: {e}"))
                })?;
                let table: toml::Table = serde_json::from_value(value).map_err(|e| {
                    rothe::Error::config("scenario", format!("not a table of TOML values: {e}"))
                })?;
                let text = toml::to_string(&table).map_err(|e| {
                    rothe::Error::config("scenario", format!("cannot be written as TOML: {e}"))
                })?;
                (None, dir.unwrap_or_else(|| PathBuf::from(".")), text)
            }
            other => return Err(rothe::Error::Internal(format!("scenario kind `{other}`"))),
        };
        let model = match &path {
            Some(p) => rothe::config::load_with_overrides(p, &opts, &ov)?,
            None => rothe::config::from_str_with_overrides(&text, &dir, &opts, &ov)?,
        };
        let table = match &path {
            Some(p) => rothe::config::merged_table(p, &ov)?,
            None => rothe::config::merged_table_of(&text, &ov)?,
        };
        Ok(NativeScenario {
            path,
            dir,
            text,
            ov,
            table,
            model: Arc::new(model),
        })
    })
    .map_err(py_err)
}

/// What a progress callback is told, and how the run learns it must stop.
struct Watch {
    callback: Option<Py<PyAny>>,
    /// A pending exception (the callback's own, or KeyboardInterrupt).
    raised: Mutex<Option<PyErr>>,
    /// Set when the waiting thread saw a signal.
    interrupt: AtomicBool,
}

/// How often the waiting thread looks for a signal.
const SIGNAL_EVERY: Duration = Duration::from_millis(50);

impl Watch {
    fn observe(&self, info: &StepInfo) -> Control {
        if self.interrupt.load(Ordering::SeqCst) {
            // A signal the waiting thread saw (KeyboardInterrupt, or what a
            // handler raised).
            let interrupt = Python::attach(|py| {
                self.raised
                    .lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .as_ref()
                    .is_none_or(|e| e.is_instance_of::<PyKeyboardInterrupt>(py))
            });
            return if interrupt {
                Control::Interrupt
            } else {
                Control::Stop
            };
        }
        let Some(cb) = &self.callback else {
            return Control::Continue;
        };
        Python::attach(|py| {
            let d = PyDict::new(py);
            let fill = || -> PyResult<()> {
                d.set_item("step", info.step)?;
                d.set_item("steps", info.steps)?;
                d.set_item("t", info.t)?;
                d.set_item("iterations", info.iterations)?;
                d.set_item("E_kin", info.kinetic)?;
                d.set_item("E_el", info.elastic)?;
                d.set_item("W_ext", info.external_work)?;
                d.set_item("D_total", info.dissipated)?;
                Ok(())
            };
            let answer = fill()
                .and_then(|_| cb.call1(py, (d,)))
                .and_then(|r| r.is_truthy(py));
            match answer {
                Ok(false) => Control::Continue,
                Ok(true) => Control::Stop,
                Err(e) => {
                    let interrupt = e.is_instance_of::<PyKeyboardInterrupt>(py);
                    *self.raised.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
                    if interrupt {
                        Control::Interrupt
                    } else {
                        Control::Stop
                    }
                }
            }
        })
    }
}

#[pymethods]
impl NativeScenario {
    /// The merged scenario as JSON text (variants resolved, overrides applied).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.table).map_err(|e| Error::new_err(e.to_string()))
    }

    /// The merged scenario as TOML text.
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.table).map_err(|e| Error::new_err(e.to_string()))
    }

    /// The scenario file, the directory meshes are read from, the text and the
    /// overrides (for the studies, which plan from a file).
    #[allow(clippy::type_complexity)]
    fn source(
        &self,
    ) -> (
        Option<PathBuf>,
        PathBuf,
        String,
        Vec<(String, String)>,
        Vec<String>,
        Vec<(String, String)>,
    ) {
        (
            self.path.clone(),
            self.dir.clone(),
            self.text.clone(),
            self.ov.variants.clone(),
            self.ov.unsets.clone(),
            self.ov.sets.clone(),
        )
    }

    /// What `rothe check` prints, as text.
    fn check_text(&self, py: Python<'_>) -> PyResult<String> {
        let model = self.model.clone();
        py.detach(move || rothe::check::report(&model, LoadOptions::default().memory_limit))
            .map(|r| r.to_string())
            .map_err(py_err)
    }

    /// The facts of `rothe check` as JSON text.
    fn check_json(&self, py: Python<'_>) -> PyResult<String> {
        let model = self.model.clone();
        let r = py
            .detach(move || rothe::check::report(&model, LoadOptions::default().memory_limit))
            .map_err(py_err)?;
        let m = &r.memory;
        let v = serde_json::json!({
            "bodies": r.bodies.iter().map(|(name, elements, thickness, velocity)| serde_json::json!({
                "name": name, "elements": elements, "thickness": thickness, "velocity": velocity,
            })).collect::<Vec<_>>(),
            "nodes": r.nodes,
            "elements": r.elements,
            "dofs": r.dofs.0,
            "free_dofs": r.dofs.1,
            "steps": r.steps.0,
            "dt": r.steps.1,
            "t_end": r.steps.2,
            "history_rows": r.history.0,
            "history_bytes": r.history.1,
            "vtk_files": r.vtk.0,
            "vtk_bytes": r.vtk.1,
            "critical_step": r.cfl.map(|c| c.0),
            "dt_over_critical": r.cfl.map(|c| c.3),
            "stable_step": r.stable.map(|c| c.0),
            "scheme": r.scheme,
            "rho_inf": (r.scheme == Some(rothe::model::TimeScheme::GeneralizedAlpha)).then_some(r.rho_inf),
            "contact_predictor": r.contact_predictor,
            "factor_nnz": r.nnz.1,
            "matrix_nnz": r.nnz.0,
            "memory": {
                "mesh": m.mesh, "matrices": m.matrices, "factor": m.factor, "state": m.state,
                "total": m.total(),
            },
            "memory_available": r.available,
            "warnings": r.warnings,
            "materials": r.materials,
            "contacts": r.contacts,
            "text": r.to_string(),
        });
        Ok(v.to_string())
    }

    /// The lowest `count` modes (or the `count` nearest `around` Hz): `modes.json`'s
    /// value as JSON text, the `M`-normalised shapes `(modes, dofs)`, and the files
    /// written into `out` (none without it).
    #[pyo3(signature = (count, shift, around, out, backend_name, overwrite))]
    #[allow(clippy::type_complexity, clippy::too_many_arguments)]
    fn modes<'py>(
        &self,
        py: Python<'py>,
        count: usize,
        shift: Option<f64>,
        around: Option<f64>,
        out: Option<PathBuf>,
        backend_name: &str,
        overwrite: bool,
    ) -> PyResult<(String, Bound<'py, PyArray2<f64>>, Vec<PathBuf>)> {
        let model = self.model.clone();
        let backend = backend(backend_name)?;
        let (json, shapes, k, files) = py
            .detach(move || -> rothe::Result<_> {
                // One writer per directory, as for a run.
                let _lock = match &out {
                    Some(dir) => Some(rothe::output::prepare(dir, overwrite)?),
                    None => None,
                };
                let opts = rothe::modal::ModalOptions {
                    count,
                    shift,
                    around,
                    backend,
                };
                let modes = rothe::modal::modes(&model, &opts)?;
                let json = rothe::output::modes::summary(&model, &modes).to_string();
                let files = match &out {
                    Some(dir) => rothe::output::modes::write(&model, &modes, dir)?,
                    None => Vec::new(),
                };
                let shapes: Vec<f64> = modes
                    .modes
                    .iter()
                    .flat_map(|m| m.shape.iter().copied())
                    .collect();
                Ok((json, shapes, modes.modes.len(), files))
            })
            .map_err(py_err)?;
        let n = self.model.mesh.n_dofs();
        Ok((json, PyArray1::from_vec(py, shapes).reshape([k, n])?, files))
    }

    /// Runs the scenario. `out = None`: in memory, nothing written.
    #[pyo3(signature = (out, overwrite, record_fields, bar, callback, threads, backend_name))]
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        py: Python<'_>,
        out: Option<PathBuf>,
        overwrite: bool,
        record_fields: bool,
        bar: bool,
        callback: Option<Py<PyAny>>,
        threads: Option<usize>,
        backend_name: &str,
    ) -> PyResult<NativeRun> {
        let backend = backend(backend_name)?;
        let model = self.model.clone();
        let watch = Arc::new(Watch {
            callback,
            raised: Mutex::new(None),
            interrupt: AtomicBool::new(false),
        });
        let w = watch.clone();
        let observer = Observer(Arc::new(move |info: &StepInfo| w.observe(info)));
        let opts = RunOptions {
            out: out.clone().unwrap_or_default(),
            backend,
            progress: bar,
            memory_limit: LoadOptions::default().memory_limit,
            record_fields,
            overwrite,
            hooks: Hooks {
                no_files: out.is_none(),
                keep: true,
                observer: Some(observer),
            },
        };
        // The run marches on a thread of its own while this one, without the GIL,
        // waits for it and every `SIGNAL_EVERY` takes the GIL to look for a signal:
        // Python runs its signal handlers on the main thread only, so a Ctrl-C is
        // seen here and handed to the run's observer as a flag.
        type Outcome = rothe::Result<(rothe::output::summary::Summary, Kept)>;
        let (tx, rx) = std::sync::mpsc::channel::<Outcome>();
        let work = move || {
            let r = match threads {
                Some(n) => {
                    rayon_pool(n).and_then(|p| p.install(|| rothe::run::run_kept(&model, &opts)))
                }
                None => rothe::run::run_kept(&model, &opts),
            };
            let _ = tx.send(r);
        };
        let runner = std::thread::Builder::new()
            .name("rothe-run".into())
            .spawn(work)
            .map_err(|e| Error::new_err(format!("cannot start the run's thread: {e}")))?;
        let rx = Mutex::new(rx);
        let result = loop {
            let next = py.detach(|| {
                rx.lock()
                    .unwrap_or_else(|p| p.into_inner())
                    .recv_timeout(SIGNAL_EVERY)
            });
            match next {
                Ok(r) => break r,
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    if let Err(e) = py.check_signals() {
                        watch.interrupt.store(true, Ordering::SeqCst);
                        let mut raised = watch.raised.lock().unwrap_or_else(|p| p.into_inner());
                        raised.get_or_insert(e);
                    }
                }
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                    break Err(rothe::Error::Internal(
                        "the run's thread ended without a result".into(),
                    ))
                }
            }
        };
        let _ = runner.join();
        // An exception the callback raised (or the interrupt) is the caller's.
        if let Some(e) = watch
            .raised
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take()
        {
            return Err(e);
        }
        let (summary, mut kept) = result.map_err(py_err)?;
        let columns = Mutex::new(std::mem::take(&mut kept.columns));
        let summary_json =
            serde_json::to_string(&summary).map_err(|e| Error::new_err(e.to_string()))?;
        Ok(NativeRun {
            summary_json,
            columns,
            kept,
            model: self.model.clone(),
            out,
        })
    }
}

/// A thread pool of `n` threads for one run (`threads=`).
fn rayon_pool(n: usize) -> rothe::Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n.max(1))
        .build()
        .map_err(|e| rothe::Error::config("threads", e.to_string()))
}

/// A finished run: its summary, kept history and fields, and the model.
#[pyclass(module = "rothe._rothe", frozen)]
struct NativeRun {
    summary_json: String,
    /// The history's columns until they are taken.
    columns: Mutex<Vec<(String, Vec<f64>)>>,
    kept: Kept,
    model: Arc<Model>,
    out: Option<PathBuf>,
}

#[pymethods]
impl NativeRun {
    /// `summary.json` as JSON text.
    fn summary_json(&self) -> String {
        self.summary_json.clone()
    }

    /// The output directory, when the run wrote one.
    fn out(&self) -> Option<PathBuf> {
        self.out.clone()
    }

    /// The history's columns as `(name, array)` pairs, in `history.csv`'s order,
    /// handed over without a copy: a second call returns none.
    fn take_history<'py>(&self, py: Python<'py>) -> Vec<(String, Bound<'py, PyArray1<f64>>)> {
        let columns = std::mem::take(&mut *self.columns.lock().unwrap_or_else(|p| p.into_inner()));
        columns
            .into_iter()
            .map(|(n, v)| (n, PyArray1::from_vec(py, v)))
            .collect()
    }

    /// Node coordinates `(n, dim)`, cells by kind `(m, nodes)` with their block,
    /// and the named node sets.
    #[allow(clippy::type_complexity)]
    fn mesh<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Vec<(String, Bound<'py, PyArray2<u64>>, Bound<'py, PyArray1<u64>>)>,
        Vec<(String, Bound<'py, PyArray1<u64>>)>,
    )> {
        let mesh = &self.model.mesh;
        let dim = mesh.dim;
        let coords: Vec<f64> = mesh.coords.iter().flat_map(|c| c[..dim].to_vec()).collect();
        let coords = PyArray1::from_vec(py, coords).reshape([mesh.n_nodes(), dim])?;
        let mut kinds: Vec<(String, usize, Vec<u64>, Vec<u64>)> = Vec::new();
        for (b, block) in mesh.blocks.iter().enumerate() {
            let kind = block.elements.kind;
            let name = format!("{kind:?}").to_lowercase();
            let nn = kind.nodes();
            let entry = match kinds.iter_mut().position(|k| k.0 == name) {
                Some(i) => &mut kinds[i],
                None => {
                    kinds.push((name, nn, Vec::new(), Vec::new()));
                    kinds.last_mut().expect("pushed")
                }
            };
            entry
                .2
                .extend(block.elements.conn.iter().map(|&n| n as u64));
            entry
                .3
                .extend(std::iter::repeat_n(b as u64, block.elements.len()));
        }
        let cells = kinds
            .into_iter()
            .map(|(name, nn, conn, blocks)| {
                let m = blocks.len();
                Ok((
                    name,
                    PyArray1::from_vec(py, conn).reshape([m, nn])?,
                    PyArray1::from_vec(py, blocks),
                ))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let sets = mesh
            .node_sets
            .iter()
            .map(|(n, v)| {
                (
                    n.clone(),
                    PyArray1::from_vec(py, v.iter().map(|&x| x as u64).collect()),
                )
            })
            .collect();
        Ok((coords, cells, sets))
    }

    /// Every recorded displacement `(states, dofs)`, when the run recorded fields.
    fn fields<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let n = self.model.mesh.n_dofs();
        if self.kept.fields.is_empty() || n == 0 {
            return Ok(None);
        }
        let rows = self.kept.fields.len() / n;
        Ok(Some(
            PyArray1::from_slice(py, &self.kept.fields).reshape([rows, n])?,
        ))
    }

    /// The last state's displacements `(nodes, dim)`.
    fn displacement<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let dim = self.model.mesh.dim;
        let n = self.kept.u.len() / dim.max(1);
        PyArray1::from_slice(py, &self.kept.u).reshape([n, dim])
    }

    /// The names of the last state's cell fields.
    fn cell_names(&self) -> Vec<String> {
        self.kept.cells.iter().map(|c| c.0.clone()).collect()
    }

    /// One of the last state's cell fields `(cells, components)` (cells in block
    /// order), or `None`.
    fn cell_data<'py>(
        &self,
        py: Python<'py>,
        name: &str,
    ) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let Some((_, width, v)) = self.kept.cells.iter().find(|c| c.0 == name) else {
            return Ok(None);
        };
        Ok(Some(
            PyArray1::from_slice(py, v).reshape([v.len() / width, *width])?,
        ))
    }
}

/// The material driver (`rothe material FILE --out DIR`): writes `material.csv`.
#[pyfunction]
fn material(py: Python<'_>, file: PathBuf, out: PathBuf) -> PyResult<usize> {
    py.detach(move || rothe::point_driver::run_file(&file, &out, |_| {}))
        .map_err(py_err)
}

/// A study: `kind` is `time`, `mesh`, `tolerance` or `compare`; `values` the steps
/// (time), the element sizes (mesh), the tolerances (tolerance); `halvings` the
/// step's halvings (time) or the fixed runs' (tolerance); `option` the reference
/// halvings (time), the reference step (tolerance) or the implicit scheme (compare). Sweeps the runs into `out` and collects them; returns the
/// Markdown summary and the runs that did not complete.
#[pyfunction]
#[pyo3(signature = (kind, scenario, variants, unsets, sets, out, values, halvings, option, jobs, backend_name))]
#[allow(clippy::too_many_arguments)]
fn study(
    py: Python<'_>,
    kind: &str,
    scenario: PathBuf,
    variants: Vec<(String, String)>,
    unsets: Vec<String>,
    sets: Vec<(String, String)>,
    out: PathBuf,
    values: Vec<f64>,
    halvings: Option<usize>,
    option: Option<String>,
    jobs: Option<usize>,
    backend_name: &str,
) -> PyResult<(String, Vec<String>)> {
    let base = overrides(variants, unsets, sets);
    let backend = backend(backend_name)?;
    let kind = kind.to_string();
    py.detach(move || -> rothe::Result<(String, Vec<String>)> {
        use rothe::study::{compare, mesh_study, time_study, tolerance_study};
        let plan = match kind.as_str() {
            "time" => {
                let reference = option
                    .as_deref()
                    .map(|s| {
                        s.parse::<usize>().map_err(|_| {
                            rothe::Error::config("reference_halvings", format!("`{s}` is no count"))
                        })
                    })
                    .transpose()?
                    .unwrap_or(time_study::DEFAULT_REFERENCE_HALVINGS);
                let hs = match halvings {
                    Some(n) => time_study::halvings(&scenario, &base, n)?,
                    None => values,
                };
                time_study::plan(&scenario, &base, &hs, reference)?
            }
            "mesh" => mesh_study::plan(&scenario, &base, &values)?,
            "tolerance" => {
                let reference = option
                    .as_deref()
                    .map(|s| {
                        s.parse::<f64>().map_err(|_| {
                            rothe::Error::config("reference_dt", format!("`{s}` is no step"))
                        })
                    })
                    .transpose()?;
                tolerance_study::plan(
                    &scenario,
                    &base,
                    &values,
                    halvings.unwrap_or(tolerance_study::DEFAULT_FIXED_HALVINGS),
                    reference,
                )?
            }
            "compare" => compare::plan(
                &scenario,
                &base,
                option.as_deref().unwrap_or("backward_euler"),
            )?,
            other => return Err(rothe::Error::Internal(format!("study kind `{other}`"))),
        };
        plan.preflight()?;
        let mut opts = rothe::study::SweepOptions {
            progress: false,
            backend,
            ..Default::default()
        };
        if let Some(j) = jobs {
            opts.jobs = j.max(1);
        }
        rothe::study::sweep(&plan, &out, &opts)?;
        let c = rothe::study::collect(&out)?;
        Ok((c.markdown, c.incomplete))
    })
    .map_err(py_err)
}

/// The native module.
#[pymodule]
fn _rothe(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<Error>())?;
    // An environment variable out of range is refused by name at import.
    rothe::simd::Simd::asked().map_err(Error::new_err)?;
    m.add_class::<NativeScenario>()?;
    m.add_class::<NativeRun>()?;
    m.add_function(wrap_pyfunction!(scenario, m)?)?;
    m.add_function(wrap_pyfunction!(material, m)?)?;
    m.add_function(wrap_pyfunction!(study, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
