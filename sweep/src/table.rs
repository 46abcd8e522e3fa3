//! The results table `results.csv`: a header, then one row per finished run, each written whole with
//! one `write` and no buffering, so a process killed at any moment leaves complete rows and at most one
//! torn last line. Opening it again drops the torn line, keeps the complete rows (the first of any run
//! id), and appends; once every run is in, the table is rewritten sorted by run id, so an interrupted
//! and resumed sweep ends with the same table as an uninterrupted one (the `wall_s` column aside).
//! `plan.toml` beside it records the sweep's fingerprint: a directory is resumed only by the same sweep.
use crate::error::{Result, SweepError};
use crate::plan::Plan;
use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

pub const TABLE_FILE: &str = "results.csv";
pub const PLAN_FILE: &str = "plan.toml";

/// Complete rows by run id.
type Rows = BTreeMap<u64, Vec<String>>;

/// An open results table.
pub struct ResultsTable {
    path: PathBuf,
    file: File,
    columns: Vec<String>,
    total: u64,
    /// Complete rows by run id (their cells).
    rows: Rows,
}

impl ResultsTable {
    /// Opens (or starts) the table of `plan` in `dir`; `require_existing`: refuse to start a new one.
    pub fn open(dir: &Path, plan: &Plan, require_existing: bool) -> Result<ResultsTable> {
        let path = dir.join(TABLE_FILE);
        let plan_path = dir.join(PLAN_FILE);
        let exists = path.exists();
        if require_existing && !exists {
            return Err(SweepError::NothingToResume {
                path: path.display().to_string(),
            });
        }
        std::fs::create_dir_all(dir)
            .map_err(|e| SweepError::io(format!("creating {}", dir.display()), e))?;
        let other = || SweepError::OtherSweep {
            dir: dir.display().to_string(),
        };
        if exists {
            match std::fs::read_to_string(&plan_path) {
                Ok(text) => {
                    let recorded = text.parse::<toml::Table>().ok().and_then(|t| {
                        t.get("fingerprint")
                            .and_then(|f| f.as_str().map(String::from))
                    });
                    if recorded.as_deref() != Some(plan.fingerprint.as_str()) {
                        return Err(other());
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => {
                    return Err(SweepError::io(
                        format!("reading {}", plan_path.display()),
                        e,
                    ));
                }
            }
        }
        let mut file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|e| SweepError::io(format!("opening {}", path.display()), e))?;
        // One writer per table: a second sweep into the same directory would run the same rows twice.
        // The lock goes with the process, however it ends.
        file.try_lock().map_err(|_| SweepError::Busy {
            path: path.display().to_string(),
        })?;
        write_plan(&plan_path, plan)?;
        let (rows, keep) = if exists {
            read_rows(&path, plan)?
        } else {
            (BTreeMap::new(), None)
        };
        match keep {
            // Drop a torn last line (and anything after the last complete row).
            Some(len) => file
                .set_len(len)
                .map_err(|e| SweepError::io(format!("truncating {}", path.display()), e))?,
            None => {
                file.set_len(0)
                    .map_err(|e| SweepError::io(format!("truncating {}", path.display()), e))?;
                file.write_all(&record(&plan.columns))
                    .map_err(|e| SweepError::io(format!("writing {}", path.display()), e))?;
            }
        }
        Ok(ResultsTable {
            path,
            file,
            columns: plan.columns.clone(),
            total: plan.total(),
            rows,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Run ids with a complete row.
    pub fn done(&self) -> std::collections::btree_map::Keys<'_, u64, Vec<String>> {
        self.rows.keys()
    }

    /// Whether run `id` has a complete row.
    pub fn contains(&self, id: u64) -> bool {
        self.rows.contains_key(&id)
    }

    /// Appends the row of run `id` (the cells of `plan.columns`); `false`: it was already there and
    /// nothing was written.
    pub fn append(&mut self, id: u64, cells: &[String]) -> Result<bool> {
        if self.rows.contains_key(&id) {
            return Ok(false);
        }
        if cells.len() != self.columns.len() || id >= self.total {
            return Err(SweepError::Run {
                id,
                message: format!(
                    "a row of {} cells for a table of {} columns and {} runs",
                    cells.len(),
                    self.columns.len(),
                    self.total
                ),
            });
        }
        self.file
            .write_all(&record(cells))
            .map_err(|e| SweepError::io(format!("appending to {}", self.path.display()), e))?;
        self.rows.insert(id, cells.to_vec());
        Ok(true)
    }

    /// Rewrites the table sorted by run id (to a temporary file renamed over it: never half written).
    pub fn finish_sorted(self) -> Result<()> {
        let tmp = self.path.with_extension("csv.tmp");
        let mut bytes = record(&self.columns);
        for cells in self.rows.values() {
            bytes.extend(record(cells));
        }
        std::fs::write(&tmp, &bytes)
            .map_err(|e| SweepError::io(format!("writing {}", tmp.display()), e))?;
        std::fs::rename(&tmp, &self.path)
            .map_err(|e| SweepError::io(format!("replacing {}", self.path.display()), e))?;
        let rows: Vec<&[String]> = self.rows.values().map(Vec::as_slice).collect();
        let parquet = self.path.with_file_name(crate::parquet_table::PARQUET_FILE);
        crate::parquet_table::write_parquet(&parquet, &self.columns, &rows)
    }
}

/// One CSV line (quoted where needed), newline included.
fn record(cells: &[String]) -> Vec<u8> {
    let mut w = csv::WriterBuilder::new().from_writer(Vec::new());
    // Writing to memory does not fail.
    let _ = w.write_record(cells);
    w.into_inner().unwrap_or_default()
}

/// The complete rows of an existing table, and the length to keep (through the last complete line);
/// `None`: no complete header, start the file again.
fn read_rows(path: &Path, plan: &Plan) -> Result<(Rows, Option<u64>)> {
    let bytes = std::fs::read(path)
        .map_err(|e| SweepError::io(format!("reading {}", path.display()), e))?;
    let Some(last_nl) = bytes.iter().rposition(|&b| b == b'\n') else {
        return Ok((BTreeMap::new(), None));
    };
    let complete = &bytes[..=last_nl];
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(complete);
    let header = reader
        .headers()
        .map_err(|e| SweepError::csv(format!("reading {}", path.display()), e))?;
    if header.iter().ne(plan.columns.iter().map(String::as_str)) {
        return Err(SweepError::OtherSweep {
            dir: path
                .parent()
                .unwrap_or(Path::new("."))
                .display()
                .to_string(),
        });
    }
    let mut rows = BTreeMap::new();
    for rec in reader.records() {
        let Ok(rec) = rec else { continue };
        if rec.len() != plan.columns.len() {
            continue;
        }
        let Some(id) = rec.get(0).and_then(|s| s.parse::<u64>().ok()) else {
            continue;
        };
        if id < plan.total() {
            rows.entry(id)
                .or_insert_with(|| rec.iter().map(String::from).collect());
        }
    }
    Ok((rows, Some(complete.len() as u64)))
}

/// `plan.toml`: what the table's columns are, for readers of the directory (plots, Python).
fn write_plan(path: &Path, plan: &Plan) -> Result<()> {
    let mut t = toml::Table::new();
    t.insert("name".into(), plan.name.clone().into());
    t.insert("fingerprint".into(), plan.fingerprint.clone().into());
    t.insert("runs".into(), (plan.total() as i64).into());
    t.insert("columns".into(), plan.columns.clone().into());
    t.insert("metrics".into(), plan.metrics.columns.clone().into());
    t.insert(
        "seeds".into(),
        plan.seeds
            .iter()
            .map(|&s| s as i64)
            .collect::<Vec<_>>()
            .into(),
    );
    let axes: Vec<toml::Value> = plan
        .axes
        .iter()
        .map(|a| {
            let mut x = toml::Table::new();
            x.insert("name".into(), a.name.clone().into());
            x.insert(
                "keys".into(),
                a.keys
                    .iter()
                    .map(|k| k.to_string())
                    .collect::<Vec<_>>()
                    .into(),
            );
            x.insert("log".into(), a.log.into());
            toml::Value::Table(x)
        })
        .collect();
    t.insert("axes".into(), axes.into());
    let text = toml::to_string(&t).unwrap_or_default();
    let tmp = path.with_extension("toml.tmp");
    std::fs::write(&tmp, text)
        .map_err(|e| SweepError::io(format!("writing {}", tmp.display()), e))?;
    std::fs::rename(&tmp, path)
        .map_err(|e| SweepError::io(format!("writing {}", path.display()), e))
}
