//! `synovia gather`: the `summary.json` of the case folders of a parameter study (`[sweep]`,
//! docs/scenario.md) merged into one CSV table, one row per case.
//!
//! The arguments are case folders (holding `summary.json` or `manifest.json`) or parents of
//! them (their immediate subfolders are searched). A row has the case index, its folder, the
//! swept values (one column per key, in the order of `[sweep.values]`), and the run's figures:
//! dofs, steps, final KKT residual, wall time, and per contact pair the last step's normal
//! force, friction force, contact area and peak pressure, and the peak pressure over all
//! steps. Numbers are written in Rust's shortest round-trip form (the summary's values
//! exactly).
//!
//! Refused with a [`GatherError`] naming the folder: a case folder without `summary.json`
//! (a run that failed or is still running), an interrupted run or a manifest whose status is
//! not `complete`, cases of different sweeps (another case count or other keys), a case found
//! twice, and — unless `allow_missing` — cases missing from `0 … cases−1`.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::outdir::{MANIFEST, SUMMARY};
use crate::run::SweepSummary;

/// Why gathering failed.
#[derive(Debug, thiserror::Error)]
pub enum GatherError {
    /// A folder or file cannot be read.
    #[error("cannot read `{path}`: {message}")]
    Io {
        /// The path.
        path: PathBuf,
        /// The reason.
        message: String,
    },
    /// No case folders under the arguments.
    #[error("no case folders (with summary.json or manifest.json) in {0}")]
    NothingFound(String),
    /// A summary that is not valid JSON or lacks a field.
    #[error("`{path}`: not a synovia summary ({message})")]
    BadSummary {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A case whose run did not complete.
    #[error("`{path}`: the run did not complete ({status}); run the case again")]
    Incomplete {
        /// The folder.
        path: PathBuf,
        /// What was found (manifest status, interrupted, no summary).
        status: String,
    },
    /// Folders of different studies, or a mix of sweep cases and plain runs.
    #[error("`{path}` is not a case of the same sweep as `{first}`: {message}")]
    Mismatch {
        /// The folder.
        path: PathBuf,
        /// The first folder read.
        first: PathBuf,
        /// What differs.
        message: String,
    },
    /// A case found in two folders.
    #[error("case {case} is in both `{a}` and `{b}`")]
    Duplicate {
        /// The case.
        case: usize,
        /// One folder.
        a: PathBuf,
        /// The other.
        b: PathBuf,
    },
    /// Cases of the sweep without a folder.
    #[error("{} of {cases} cases missing: {}{} (run their tasks, or gather with --allow-missing)",
        missing.len(), list(missing), if missing.len() > 20 { ", …" } else { "" })]
    Missing {
        /// Their indices.
        missing: Vec<usize>,
        /// Number of cases of the sweep.
        cases: usize,
    },
}

fn list(v: &[usize]) -> String {
    v.iter().take(20).map(ToString::to_string).collect::<Vec<_>>().join(", ")
}

fn io(path: &Path, e: &std::io::Error) -> GatherError {
    GatherError::Io { path: path.to_path_buf(), message: e.to_string() }
}

/// Whether `dir` is a case folder (a run wrote into it).
fn is_case_folder(dir: &Path) -> bool {
    dir.join(SUMMARY).is_file() || dir.join(MANIFEST).is_file()
}

/// The case folders under `paths` (each a case folder or a parent of case folders), in order.
///
/// # Errors
/// [`GatherError::Io`] for unreadable paths, [`GatherError::NothingFound`] when a path holds
/// no case folder.
pub fn case_folders(paths: &[PathBuf]) -> Result<Vec<PathBuf>, GatherError> {
    let mut out = Vec::new();
    for p in paths {
        if !p.is_dir() {
            return Err(GatherError::Io { path: p.clone(), message: "not a directory".into() });
        }
        if is_case_folder(p) {
            out.push(p.clone());
            continue;
        }
        let mut subs: Vec<PathBuf> = std::fs::read_dir(p)
            .map_err(|e| io(p, &e))?
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|d| d.is_dir() && is_case_folder(d))
            .collect();
        if subs.is_empty() {
            return Err(GatherError::NothingFound(format!("`{}`", p.display())));
        }
        subs.sort();
        out.extend(subs);
    }
    Ok(out)
}

/// One read case.
struct Row {
    dir: PathBuf,
    sweep: Option<SweepSummary>,
    summary: Value,
}

fn read_case(dir: &Path) -> Result<Row, GatherError> {
    let manifest = dir.join(MANIFEST);
    if manifest.is_file() {
        let text = std::fs::read_to_string(&manifest).map_err(|e| io(&manifest, &e))?;
        let m: Value = serde_json::from_str(&text)
            .map_err(|e| GatherError::BadSummary { path: manifest.clone(), message: e.to_string() })?;
        let status = m.get("status").and_then(Value::as_str).unwrap_or("unknown");
        if status != "complete" {
            return Err(GatherError::Incomplete {
                path: dir.to_path_buf(),
                status: format!("manifest.json status `{status}`"),
            });
        }
    }
    let file = dir.join(SUMMARY);
    if !file.is_file() {
        return Err(GatherError::Incomplete { path: dir.to_path_buf(), status: "no summary.json".into() });
    }
    let text = std::fs::read_to_string(&file).map_err(|e| io(&file, &e))?;
    let summary: Value = serde_json::from_str(&text)
        .map_err(|e| GatherError::BadSummary { path: file.clone(), message: e.to_string() })?;
    if !summary.is_object() || summary.get("steps").and_then(Value::as_array).is_none() {
        return Err(GatherError::BadSummary { path: file, message: "no `steps` list".into() });
    }
    if summary.get("interrupted").and_then(Value::as_bool) == Some(true) {
        return Err(GatherError::Incomplete { path: dir.to_path_buf(), status: "interrupted".into() });
    }
    let sweep =
        match summary.get("sweep") {
            None | Some(Value::Null) => None,
            Some(s) => Some(serde_json::from_value::<SweepSummary>(s.clone()).map_err(|e| {
                GatherError::BadSummary { path: file.clone(), message: format!("sweep: {e}") }
            })?),
        };
    Ok(Row { dir: dir.to_path_buf(), sweep, summary })
}

/// A CSV field: numbers and plain strings as they are, anything else as compact JSON; quoted
/// when it holds a comma, quote or line break.
fn field(v: &Value) -> String {
    let s = match v {
        Value::Null => String::new(),
        Value::String(s) => s.clone(),
        Value::Number(n) => match n.as_f64() {
            Some(x) if n.is_f64() => format!("{x:?}"),
            _ => n.to_string(),
        },
        other => other.to_string(),
    };
    quote(&s)
}

fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The CSV table of the case folders under `paths` (module docs).
///
/// # Errors
/// See [`GatherError`].
pub fn gather(paths: &[PathBuf], allow_missing: bool) -> Result<String, GatherError> {
    let folders = case_folders(paths)?;
    let rows: Vec<Row> = folders.iter().map(|d| read_case(d)).collect::<Result<_, _>>()?;
    let Some(first) = rows.first() else {
        return Err(GatherError::NothingFound(
            paths.iter().map(|p| format!("`{}`", p.display())).collect::<Vec<_>>().join(", "),
        ));
    };
    let keys: Vec<String> = first
        .sweep
        .as_ref()
        .map(|s| s.parameters.iter().map(|p| p.key.clone()).collect())
        .unwrap_or_default();
    let mut seen: BTreeMap<usize, PathBuf> = BTreeMap::new();
    for r in &rows {
        let mismatch = |message: String| GatherError::Mismatch {
            path: r.dir.clone(),
            first: first.dir.clone(),
            message,
        };
        match (&first.sweep, &r.sweep) {
            (Some(a), Some(b)) => {
                if a.cases != b.cases {
                    return Err(mismatch(format!("{} cases instead of {}", b.cases, a.cases)));
                }
                let k: Vec<&String> = b.parameters.iter().map(|p| &p.key).collect();
                if k.len() != keys.len() || k.iter().zip(&keys).any(|(x, y)| *x != y) {
                    return Err(mismatch(format!("swept keys {k:?} instead of {keys:?}")));
                }
                if let Some(prev) = seen.insert(b.case, r.dir.clone()) {
                    return Err(GatherError::Duplicate { case: b.case, a: prev, b: r.dir.clone() });
                }
            }
            (None, None) => {}
            (Some(_), None) => return Err(mismatch("a plain run, not a sweep case".into())),
            (None, Some(_)) => return Err(mismatch("a sweep case among plain runs".into())),
        }
    }
    if let Some(s) = &first.sweep {
        let missing: Vec<usize> = (0..s.cases).filter(|c| !seen.contains_key(c)).collect();
        if !missing.is_empty() && !allow_missing {
            return Err(GatherError::Missing { missing, cases: s.cases });
        }
    }
    // pairs in first-seen order
    let mut pairs: Vec<String> = Vec::new();
    for r in &rows {
        for p in r.summary.get("pairs").and_then(Value::as_array).into_iter().flatten() {
            if let Some(p) = p.as_str().filter(|p| !pairs.iter().any(|q| q == p)) {
                pairs.push(p.to_string());
            }
        }
    }
    let mut order: Vec<&Row> = rows.iter().collect();
    order.sort_by_key(|r| r.sweep.as_ref().map(|s| s.case));

    let mut header: Vec<String> = vec!["case".into(), "folder".into()];
    header.extend(keys.iter().cloned());
    header.extend(
        ["name", "dofs", "steps", "final_kkt", "total_s", "last_time", "contact_force"].map(String::from),
    );
    for p in &pairs {
        for f in ["normal_force", "tangential_force", "contact_area", "peak_pressure", "max_peak_pressure"] {
            header.push(format!("{p}.{f}"));
        }
    }
    let mut csv = header.iter().map(|h| quote(h)).collect::<Vec<_>>().join(",");
    csv.push('\n');
    for (i, r) in order.iter().enumerate() {
        let s = &r.summary;
        let steps = s.get("steps").and_then(Value::as_array).map_or(&[][..], Vec::as_slice);
        let last = steps.last();
        let mut cells: Vec<String> = Vec::with_capacity(header.len());
        cells.push(r.sweep.as_ref().map_or(i, |w| w.case).to_string());
        cells.push(quote(&r.dir.display().to_string()));
        if let Some(w) = &r.sweep {
            cells.extend(w.parameters.iter().map(|p| field(&p.value)));
        }
        for k in ["name", "dofs"] {
            cells.push(field(s.get(k).unwrap_or(&Value::Null)));
        }
        cells.push(steps.len().to_string());
        for k in ["final_kkt", "total_s"] {
            cells.push(field(s.get(k).unwrap_or(&Value::Null)));
        }
        for k in ["time", "contact_force"] {
            cells.push(field(last.and_then(|l| l.get(k)).unwrap_or(&Value::Null)));
        }
        let pair_of = |step: &Value, name: &str| -> Option<Value> {
            step.get("pairs")?
                .as_array()?
                .iter()
                .find(|p| p.get("name").and_then(Value::as_str) == Some(name))
                .cloned()
        };
        for p in &pairs {
            let lp = last.and_then(|l| pair_of(l, p));
            for f in ["normal_force", "tangential_force", "contact_area", "peak_pressure"] {
                cells.push(field(lp.as_ref().and_then(|v| v.get(f)).unwrap_or(&Value::Null)));
            }
            let peak = steps
                .iter()
                .filter_map(|st| pair_of(st, p)?.get("peak_pressure")?.as_f64())
                .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))));
            cells.push(peak.map_or_else(String::new, |x| format!("{x:?}")));
        }
        let _ = writeln!(csv, "{}", cells.join(","));
    }
    Ok(csv)
}
