//! Sweeps from Python (`colcos.sweep`): a checked plan, the local runner, the runs of a list of ids
//! (what a Ray task calls) and the resumable results table the rows go into. The GIL is released while
//! runs execute.
use crate::arena_io::shaped;
use crate::errors::Kind;
use colcos_sweep::{Plan, ResultsTable, SweepError, SweepOptions, Trace};
use numpy::PyArray1;
use pyo3::exceptions::{PyOSError, PyRuntimeError};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A pool of `threads` workers (None: one per core) for a sweep's runs.
fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool, SweepError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| SweepError::Run {
            id: 0,
            message: e.to_string(),
        })
}

/// A run's id, its cells and its poses (`run_traced`).
type TracedRow<'py> = (u64, Vec<String>, Bound<'py, pyo3::types::PyDict>);

fn to_py(e: SweepError) -> PyErr {
    let msg = e.to_string();
    match e {
        SweepError::Io { .. } | SweepError::Csv { .. } => PyOSError::new_err(msg),
        SweepError::Run { .. } => PyRuntimeError::new_err(msg),
        _ => Kind::Scenario.err(msg),
    }
}

/// A checked sweep: `Sweep(path=...)`, `Sweep(text=..., base_dir=...)` (TOML) or
/// `Sweep(json=..., base_dir=...)` (the sweep file's content as JSON).
#[pyclass(frozen, module = "colcos._core")]
pub struct Sweep {
    plan: Arc<Plan>,
    scenario_dir: PathBuf,
}

#[pymethods]
impl Sweep {
    #[new]
    #[pyo3(signature = (path=None, text=None, json=None, base_dir=None))]
    fn new(
        py: Python<'_>,
        path: Option<PathBuf>,
        text: Option<String>,
        json: Option<String>,
        base_dir: Option<PathBuf>,
    ) -> PyResult<Self> {
        let dir = base_dir.unwrap_or_else(|| PathBuf::from("."));
        let plan = py
            .detach(|| match (path, text, json) {
                (Some(p), None, None) => Plan::from_file(&p),
                (None, Some(t), None) => Plan::from_toml_str(&t, "<text>", &dir),
                (None, None, Some(j)) => {
                    let toml_text = json_to_toml(&j)?;
                    Plan::from_toml_str(&toml_text, "<dict>", &dir)
                }
                _ => Err(SweepError::Invalid {
                    key: "spec".into(),
                    value: "(several or none)".into(),
                    reason: "give exactly one of path, text and json".into(),
                }),
            })
            .map_err(to_py)?;
        let scenario_dir = plan.scenario_dir().to_path_buf();
        Ok(Sweep {
            plan: Arc::new(plan),
            scenario_dir,
        })
    }

    /// The sweep's name.
    #[getter]
    fn name(&self) -> String {
        self.plan.name.clone()
    }

    /// The results table's columns.
    #[getter]
    fn columns(&self) -> Vec<String> {
        self.plan.columns.clone()
    }

    /// The metric columns.
    #[getter]
    fn metrics(&self) -> Vec<String> {
        self.plan.metrics.columns.clone()
    }

    /// Runs in all.
    #[getter]
    fn total(&self) -> u64 {
        self.plan.total()
    }

    /// The sweep as self-contained TOML (the base scenario inlined) and the directory its relative
    /// paths (image maps) resolve against: what a remote worker rebuilds the plan from.
    fn portable(&self) -> (String, String) {
        (
            self.plan.portable_toml(),
            self.scenario_dir.display().to_string(),
        )
    }

    /// Checks every run's scenario (the first bad combination raises, named).
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        let plan = self.plan.clone();
        py.detach(move || plan.check_all().map(|_| ()))
            .map_err(to_py)
    }

    /// Runs the sweep here into `out` (resumable); returns (total, ran, skipped, table path).
    #[pyo3(signature = (out, threads=None, resume=false))]
    fn run_local(
        &self,
        py: Python<'_>,
        out: PathBuf,
        threads: Option<usize>,
        resume: bool,
    ) -> PyResult<(u64, u64, u64, String)> {
        let plan = self.plan.clone();
        let r = py
            .detach(move || {
                colcos_sweep::run_sweep(
                    &plan,
                    &out,
                    SweepOptions {
                        threads,
                        resume,
                        ..Default::default()
                    },
                )
            })
            .map_err(to_py)?;
        Ok((r.total, r.ran, r.skipped, r.table.display().to_string()))
    }

    /// Runs the given ids (in parallel over `threads`, default all cores) and returns their rows, one
    /// list of cells per run in `columns` order.
    #[pyo3(signature = (ids, threads=None))]
    fn run_ids(
        &self,
        py: Python<'_>,
        ids: Vec<u64>,
        threads: Option<usize>,
    ) -> PyResult<Vec<(u64, Vec<String>)>> {
        let plan = self.plan.clone();
        py.detach(move || {
            let rows = pool(threads)?.install(|| colcos_sweep::run_ids(&plan, &ids))?;
            Ok(rows.iter().map(|r| (r.id, r.fields(&plan))).collect())
        })
        .map_err(to_py)
    }

    /// The same sweep with metric columns computed by the caller (after the built-in metrics).
    fn with_metrics(&self, names: Vec<String>) -> PyResult<Sweep> {
        let plan = (*self.plan)
            .clone()
            .with_extra_metrics(&names)
            .map_err(to_py)?;
        Ok(Sweep {
            plan: Arc::new(plan),
            scenario_dir: self.scenario_dir.clone(),
        })
    }

    /// Like `run_ids`, with each run's poses at the sample times: a list of
    /// `(id, cells, {"times": (T,), "positions": (T, N, 2), "headings": (T, N), "roles": [N]})`;
    /// the cells of `with_metrics` columns are empty, for the caller to fill.
    #[pyo3(signature = (ids, threads=None))]
    fn run_traced<'py>(
        &self,
        py: Python<'py>,
        ids: Vec<u64>,
        threads: Option<usize>,
    ) -> PyResult<Vec<TracedRow<'py>>> {
        let plan = self.plan.clone();
        let runs: Vec<(u64, Vec<String>, Trace)> = py
            .detach(move || {
                use rayon::prelude::*;
                pool(threads)?.install(|| {
                    ids.par_iter()
                        .map(|&id| {
                            let (row, trace) =
                                colcos_sweep::run_traced(&plan, id, &plan.scenario(id)?)?;
                            Ok((id, row.fields(&plan), trace))
                        })
                        .collect::<Result<Vec<_>, SweepError>>()
                })
            })
            .map_err(to_py)?;
        runs.into_iter()
            .map(|(id, cells, t)| {
                let (steps, n) = (t.times.len(), t.roles.len());
                let d = pyo3::types::PyDict::new(py);
                d.set_item("times", PyArray1::from_vec(py, t.times))?;
                d.set_item("positions", shaped(py, t.positions, [steps, n, 2])?)?;
                d.set_item("headings", shaped(py, t.headings, [steps, n])?)?;
                d.set_item("roles", t.roles)?;
                Ok((id, cells, d))
            })
            .collect()
    }

    /// Opens (or starts) this sweep's results table in `out`.
    #[pyo3(signature = (out, resume=false))]
    fn open_table(&self, out: PathBuf, resume: bool) -> PyResult<SweepTable> {
        let table = ResultsTable::open(Path::new(&out), &self.plan, resume).map_err(to_py)?;
        Ok(SweepTable {
            table: Some(table),
            total: self.plan.total(),
        })
    }
}

/// A sweep's results table, open for appending rows computed elsewhere.
#[pyclass(module = "colcos._core")]
pub struct SweepTable {
    table: Option<ResultsTable>,
    total: u64,
}

impl SweepTable {
    fn get(&mut self) -> PyResult<&mut ResultsTable> {
        self.table
            .as_mut()
            .ok_or_else(|| Kind::State.err("the sweep table is closed"))
    }
}

#[pymethods]
impl SweepTable {
    /// Run ids that do not have a complete row yet.
    fn pending(&mut self) -> PyResult<Vec<u64>> {
        let total = self.total;
        let t = self.get()?;
        Ok((0..total).filter(|&id| !t.contains(id)).collect())
    }

    /// Appends rows `(id, cells)`; a run already in the table is skipped. Returns the rows written.
    fn append(&mut self, rows: Vec<(u64, Vec<String>)>) -> PyResult<usize> {
        let t = self.get()?;
        let mut n = 0;
        for (id, cells) in rows {
            if t.append(id, &cells).map_err(to_py)? {
                n += 1;
            }
        }
        Ok(n)
    }

    /// Whether every run has its row.
    fn complete(&mut self) -> PyResult<bool> {
        let total = self.total;
        let t = self.get()?;
        Ok(t.done().len() as u64 == total)
    }

    /// Closes the table; a complete one is rewritten sorted by run id. Returns its path.
    fn finish(&mut self) -> PyResult<String> {
        let t = self
            .table
            .take()
            .ok_or_else(|| Kind::State.err("the sweep table is closed"))?;
        let path = t.path().display().to_string();
        if t.done().len() as u64 == self.total {
            t.finish_sorted().map_err(to_py)?;
        }
        Ok(path)
    }
}

/// The sweep file's content given as JSON (a Python dict), as TOML text.
fn json_to_toml(json: &str) -> Result<String, SweepError> {
    let bad = |m: String| SweepError::Parse {
        file: "<dict>".into(),
        message: m,
    };
    let value: serde_json::Value = serde_json::from_str(json).map_err(|e| bad(e.to_string()))?;
    let table: toml::Table = serde_json::from_value(value)
        .map_err(|e| bad(format!("{e} (TOML has no null: leave the key out)")))?;
    toml::to_string(&table).map_err(|e| bad(e.to_string()))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Sweep>()?;
    m.add_class::<SweepTable>()?;
    Ok(())
}
