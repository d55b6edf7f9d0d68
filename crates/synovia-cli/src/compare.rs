//! Comparing the output folders of two runs of one scenario (e.g. the solver `tfeti` against a
//! direct solver, or `tfeti` on 1, 2 and 4 MPI ranks): the nodal fields of every `.vtu` file
//! and the per-pair forces of `summary.json`, as largest relative differences.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

/// Why two folders could not be compared.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// A file could not be read or parsed.
    #[error("`{path}`: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The folders do not hold the same kind of results (steps, files, bodies, fields).
    #[error("{0}")]
    Mismatch(String),
}

/// The nodal fields of the `.vtu` files that are compared.
pub const FIELDS: &[&str] = &["displacement", "contact_pressure", "friction_traction"];

/// The per-pair figures of `summary.json` that are compared.
pub const PAIR_FIGURES: &[&str] = &["force", "normal_force", "tangential_force"];

/// The largest relative differences between two output folders, by quantity: for each field of
/// [`FIELDS`] over every `.vtu` file, and for each figure of [`PAIR_FIGURES`] over every step
/// and pair, `max |a − b| / max |a|` (max norms over all values of that quantity in the first
/// folder; the absolute difference where they are all 0).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Comparison {
    /// Quantity (`vtu:displacement`, `pair:normal_force`, …) → largest relative difference.
    pub differences: BTreeMap<String, f64>,
    /// Steps compared.
    pub steps: usize,
    /// `.vtu` files compared.
    pub files: usize,
}

impl Comparison {
    /// The largest relative difference over all quantities.
    pub fn max(&self) -> f64 {
        self.differences.values().fold(0.0, |m, &d| m.max(d))
    }
    /// The largest relative difference of one quantity (`None` if it was not compared).
    pub fn of(&self, quantity: &str) -> Option<f64> {
        self.differences.get(quantity).copied()
    }
}

/// `(max |a − b|, max |a|)` accumulated over the values of one quantity.
#[derive(Debug, Clone, Copy, Default)]
struct Accumulator {
    diff: f64,
    scale: f64,
}

impl Accumulator {
    fn add(&mut self, a: &[f64], b: &[f64]) {
        for (x, y) in a.iter().zip(b) {
            let d = (x - y).abs();
            // NaN compares as the largest difference
            self.diff = if d.is_nan() { f64::INFINITY } else { self.diff.max(d) };
            self.scale = self.scale.max(x.abs());
        }
    }
    fn relative(&self) -> f64 {
        if self.scale > 0.0 {
            self.diff / self.scale
        } else {
            self.diff
        }
    }
}

fn read_json(path: &Path) -> Result<Value, CompareError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CompareError::File { path: path.into(), message: e.to_string() })?;
    serde_json::from_str(&text).map_err(|e| CompareError::File { path: path.into(), message: e.to_string() })
}

/// The numbers of a JSON number or array of numbers (`null` entries as NaN).
fn numbers(v: &Value) -> Vec<f64> {
    match v {
        Value::Number(n) => vec![n.as_f64().unwrap_or(f64::NAN)],
        Value::Array(a) => a.iter().flat_map(numbers).collect(),
        _ => Vec::new(),
    }
}

/// Compares the output folders `a` and `b` of two runs (module docs).
///
/// # Errors
/// [`CompareError::File`] for a missing or unreadable `summary.json` or `.vtu` file;
/// [`CompareError::Mismatch`] when the folders differ in steps, files, pairs, bodies or field
/// sizes.
pub fn compare(a: &Path, b: &Path) -> Result<Comparison, CompareError> {
    let (sa, sb) = (read_json(&a.join("summary.json"))?, read_json(&b.join("summary.json"))?);
    let empty = Vec::new();
    let steps_a = sa["steps"].as_array().unwrap_or(&empty);
    let steps_b = sb["steps"].as_array().unwrap_or(&empty);
    if steps_a.len() != steps_b.len() {
        return Err(CompareError::Mismatch(format!(
            "{} has {} steps, {} has {}",
            a.display(),
            steps_a.len(),
            b.display(),
            steps_b.len()
        )));
    }
    let mut acc: BTreeMap<String, Accumulator> = BTreeMap::new();
    let mut files = 0;
    for (i, (x, y)) in steps_a.iter().zip(steps_b).enumerate() {
        let (pa, pb) = (x["pairs"].as_array().unwrap_or(&empty), y["pairs"].as_array().unwrap_or(&empty));
        if pa.len() != pb.len() {
            return Err(CompareError::Mismatch(format!("step {i}: {} and {} pairs", pa.len(), pb.len())));
        }
        for (p, q) in pa.iter().zip(pb) {
            for figure in PAIR_FIGURES {
                let (u, v) = (numbers(&p[figure]), numbers(&q[figure]));
                if u.len() != v.len() {
                    return Err(CompareError::Mismatch(format!(
                        "step {i}: pair figure `{figure}` differs in size"
                    )));
                }
                acc.entry(format!("pair:{figure}")).or_default().add(&u, &v);
            }
        }
        match (x["vtu"].as_str(), y["vtu"].as_str()) {
            (None, None) => {}
            (Some(fa), Some(fb)) => {
                let read = |dir: &Path, f: &str| {
                    let path = dir.join(f);
                    synovia::io::read_vtu(&path)
                        .map_err(|e| CompareError::File { path: path.clone(), message: e.to_string() })
                };
                let (va, vb) = (read(a, fa)?, read(b, fb)?);
                if va.pieces.len() != vb.pieces.len() {
                    return Err(CompareError::Mismatch(format!("`{fa}`: the files hold different bodies")));
                }
                for (pa, pb) in va.pieces.iter().zip(&vb.pieces) {
                    for field in FIELDS {
                        match (pa.point_field(field), pb.point_field(field)) {
                            (None, None) => {}
                            (Some(u), Some(v)) if u.values.len() == v.values.len() => {
                                acc.entry(format!("vtu:{field}")).or_default().add(&u.values, &v.values);
                            }
                            _ => {
                                return Err(CompareError::Mismatch(format!(
                                    "`{fa}`: point field `{field}` differs between the folders"
                                )))
                            }
                        }
                    }
                }
                files += 1;
            }
            _ => return Err(CompareError::Mismatch(format!("step {i}: a .vtu file in one folder only"))),
        }
    }
    Ok(Comparison {
        differences: acc.into_iter().map(|(k, v)| (k, v.relative())).collect(),
        steps: steps_a.len(),
        files,
    })
}
