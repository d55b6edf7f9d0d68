//! Tables of measured histories: kinematics from fluoroscopy or motion capture, loads from a
//! simulator, as OpenSim storage files (`.sto`, `.mot`) or CSV, turned into
//! [`PiecewiseLinear`] histories by column name with a unit factor.
//!
//! * **OpenSim storage** (`.sto`, `.mot`): header lines up to `endheader`, then a line of
//!   column names and rows of numbers separated by tabs (or spaces); the first column is the
//!   time.
//! * **CSV** (`.csv`, any other extension): a header line of column names, then rows of numbers
//!   separated by commas (or semicolons, or tabs — detected from the header); quoted fields are
//!   read by the [`csv`] crate. The first column is the time.
//!
//! A [`Table`] names every problem it finds — the file, line and column of a value that is not
//! a number, a missing column (with the columns that exist), times that do not increase — as a
//! [`TableError`]. Units are the caller's: [`Table::history`] multiplies a column by a factor
//! (e.g. `0.001` for millimetres to metres, `π/180` for degrees to radians).

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::history::PiecewiseLinear;
use synovia_mesh::math::Real;

/// Errors of [`Table`]s.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum TableError {
    /// The file cannot be read.
    #[error("cannot read the table `{}`: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The file is not a table of the expected form.
    #[error("table `{}`, line {line}: {message}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A column that was asked for is not in the table.
    #[error("table `{}` has no column `{column}`; its columns are: {}", path.display(), available.join(", "))]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column asked for.
        column: String,
        /// The columns of the table.
        available: Vec<String>,
    },
    /// Several columns that were asked for are not in the table ([`Table::require`]).
    #[error("table `{}` has no columns {}; its columns are: {}", path.display(), missing.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", "), available.join(", "))]
    MissingColumns {
        /// The file.
        path: PathBuf,
        /// The columns asked for that are missing.
        missing: Vec<String>,
        /// The columns of the table.
        available: Vec<String>,
    },
    /// A unit factor that is not finite or is zero.
    #[error("invalid unit factor {factor} for column `{column}` (must be finite and non-zero)")]
    InvalidFactor {
        /// The column.
        column: String,
        /// The factor.
        factor: Real,
    },
}

/// A table of histories: a time column and named value columns (see the
/// [module documentation](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    path: PathBuf,
    names: Vec<String>,
    time: Vec<Real>,
    columns: Vec<Vec<Real>>,
}

impl Table {
    /// Reads the table at `path`: OpenSim storage for `.sto` and `.mot`, CSV otherwise.
    ///
    /// # Errors
    /// [`TableError::Io`], [`TableError::Format`].
    pub fn read(path: impl AsRef<Path>) -> Result<Self, TableError> {
        let path = path.as_ref();
        let text =
            std::fs::read_to_string(path).map_err(|source| TableError::Io { path: path.into(), source })?;
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        if ext == "sto" || ext == "mot" {
            Self::parse_storage(&text, path)
        } else {
            Self::parse_csv(&text, path)
        }
    }

    /// Parses an OpenSim storage text (`path` names it in errors).
    ///
    /// # Errors
    /// [`TableError::Format`]: no `endheader`, no columns, a value that is not a number, a
    /// row of the wrong length, times that do not increase.
    pub fn parse_storage(text: &str, path: impl AsRef<Path>) -> Result<Self, TableError> {
        let path = path.as_ref();
        let lines: Vec<&str> = text.lines().collect();
        let end = lines.iter().position(|l| l.trim() == "endheader").ok_or_else(|| TableError::Format {
            path: path.into(),
            line: lines.len().max(1),
            message: "no `endheader` line: not an OpenSim storage file".into(),
        })?;
        let body: String = lines[end + 1..]
            .iter()
            .map(|l| l.split_whitespace().collect::<Vec<_>>().join(",") + "\n")
            .collect();
        Self::from_records(&body, b',', path, end + 1)
    }

    /// Parses a CSV text (`path` names it in errors); the delimiter (comma, semicolon or tab)
    /// is the first of them found in the header line.
    ///
    /// # Errors
    /// As [`Table::parse_storage`].
    pub fn parse_csv(text: &str, path: impl AsRef<Path>) -> Result<Self, TableError> {
        let header = text.lines().next().unwrap_or("");
        let delimiter =
            [b',', b';', b'\t'].into_iter().find(|d| header.as_bytes().contains(d)).unwrap_or(b',');
        Self::from_records(text, delimiter, path.as_ref(), 0)
    }

    /// The table from delimited `text` whose first line (line `offset + 1` of the file) holds
    /// the column names.
    fn from_records(text: &str, delimiter: u8, path: &Path, offset: usize) -> Result<Self, TableError> {
        let format = |line: usize, message: String| TableError::Format { path: path.into(), line, message };
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(delimiter)
            .has_headers(true)
            .flexible(true)
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let names: Vec<String> = reader
            .headers()
            .map_err(|e| format(offset + 1, format!("cannot read the column names: {e}")))?
            .iter()
            .map(str::to_string)
            .collect();
        if names.len() < 2 || names.iter().any(String::is_empty) {
            return Err(format(
                offset + 1,
                format!("expected a time column and at least one named column, got {names:?}"),
            ));
        }
        let mut time = Vec::new();
        let mut columns = vec![Vec::new(); names.len() - 1];
        for record in reader.records() {
            let record = record.map_err(|e| {
                let line = e.position().map_or(offset + 1, |p| offset + p.line() as usize);
                format(line, format!("cannot read the row: {e}"))
            })?;
            let line = offset + record.position().map_or(0, |p| p.line() as usize);
            if record.iter().all(str::is_empty) {
                continue;
            }
            if record.len() != names.len() {
                return Err(format(
                    line,
                    format!("{} values, but the header names {} columns", record.len(), names.len()),
                ));
            }
            let mut values = record.iter().enumerate().map(|(k, field)| {
                field.parse::<Real>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                    format(line, format!("column `{}`: `{field}` is not a finite number", names[k]))
                })
            });
            let t = values.next().unwrap_or_else(|| Err(format(line, "empty row".into())))?;
            if let Some(&last) = time.last() {
                if t <= last {
                    return Err(format(
                        line,
                        format!("the time {t} does not increase (previous row: {last})"),
                    ));
                }
            }
            time.push(t);
            for (column, v) in columns.iter_mut().zip(values) {
                column.push(v?);
            }
        }
        if time.is_empty() {
            return Err(format(offset + 1, "the table has no rows".into()));
        }
        Ok(Self { path: path.into(), names, time, columns })
    }

    /// The column names (the first is the time column).
    pub fn names(&self) -> &[String] {
        &self.names
    }
    /// The times (first column).
    pub fn time(&self) -> &[Real] {
        &self.time
    }
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.time.len()
    }
    /// The values of column `name` (not the time column).
    ///
    /// # Errors
    /// [`TableError::MissingColumn`] naming the columns that exist.
    pub fn column(&self, name: &str) -> Result<&[Real], TableError> {
        self.names.iter().skip(1).position(|n| n == name).map(|k| self.columns[k].as_slice()).ok_or_else(
            || TableError::MissingColumn {
                path: self.path.clone(),
                column: name.into(),
                available: self.names.clone(),
            },
        )
    }
    /// Checks that the table has every column of `names` (e.g. the six coordinates of a
    /// kinematics file) before any is used, naming all that are missing at once.
    ///
    /// # Errors
    /// [`TableError::MissingColumn`] for one missing column, [`TableError::MissingColumns`]
    /// for several; both list the columns that exist.
    pub fn require(&self, names: &[&str]) -> Result<(), TableError> {
        let missing: Vec<String> = names
            .iter()
            .filter(|n| !self.names.iter().skip(1).any(|m| m == *n))
            .map(|n| n.to_string())
            .collect();
        match missing.len() {
            0 => Ok(()),
            1 => Err(TableError::MissingColumn {
                path: self.path.clone(),
                column: missing[0].clone(),
                available: self.names.clone(),
            }),
            _ => Err(TableError::MissingColumns {
                path: self.path.clone(),
                missing,
                available: self.names.clone(),
            }),
        }
    }
    /// Column `name` times `factor` (the unit conversion) as a history of the table's time
    /// times `time_factor` (e.g. `0.01` for a gait cycle in percent to cycles).
    ///
    /// # Errors
    /// [`TableError::MissingColumn`], [`TableError::InvalidFactor`].
    pub fn history(
        &self,
        name: &str,
        factor: Real,
        time_factor: Real,
    ) -> Result<PiecewiseLinear, TableError> {
        for (what, f) in [(name, factor), ("time", time_factor)] {
            if !f.is_finite() || f == 0.0 {
                return Err(TableError::InvalidFactor { column: what.into(), factor: f });
            }
        }
        let values = self.column(name)?;
        let mut points: Vec<(Real, Real)> =
            self.time.iter().zip(values).map(|(&t, &v)| (t * time_factor, v * factor)).collect();
        if time_factor < 0.0 {
            points.reverse();
        }
        PiecewiseLinear::new(&points).map_err(|e| TableError::Format {
            path: self.path.clone(),
            line: 0,
            message: format!("column `{name}`: {e}"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::LoadHistory;

    const STO: &str = "DataType=double\nversion=3\nendheader\ntime\tknee_ant_r\tknee_flex_r\n0\t-0.0074\t-0.0943\n1\t-0.0071\t-0.0929\n2\t-0.0068\t-0.0974\n";

    #[test]
    fn storage_and_csv_give_the_same_table() {
        let sto = Table::parse_storage(STO, "a.sto").expect("sto");
        let csv = Table::parse_csv(
            "time,knee_ant_r,knee_flex_r\n0,-0.0074,-0.0943\n1,-0.0071,-0.0929\n2,-0.0068,-0.0974\n",
            "a.csv",
        )
        .expect("csv");
        assert_eq!(sto.names(), csv.names());
        assert_eq!(sto.time(), csv.time());
        assert_eq!(sto.column("knee_flex_r").expect("col"), csv.column("knee_flex_r").expect("col"));
        let semicolons = Table::parse_csv("t;x\n0;1\n1;2\n", "b.csv").expect("semicolons");
        assert_eq!(semicolons.column("x").expect("x"), &[1.0, 2.0]);
        // mm → m, percent of the cycle → cycles
        let h = sto.history("knee_ant_r", 1e3, 0.01).expect("history");
        assert!((h.value(0.015) - (-6.95)).abs() < 1e-12, "{}", h.value(0.015));
    }

    #[test]
    fn problems_are_named() {
        let e = Table::parse_storage(STO, "a.sto").expect("sto").column("knee_sup_r").expect_err("missing");
        let msg = e.to_string();
        assert!(msg.contains("no column `knee_sup_r`") && msg.contains("knee_ant_r, knee_flex_r"), "{msg}");
        let e = Table::parse_storage("time\tx\n0\t1\n", "a.sto").expect_err("no endheader");
        assert!(e.to_string().contains("endheader"), "{e}");
        let e = Table::parse_csv("t,x\n0,1\n1,abc\n", "b.csv").expect_err("not a number");
        assert!(e.to_string().contains("line 3") && e.to_string().contains("`abc`"), "{e}");
        let e = Table::parse_csv("t,x\n0,1\n0,2\n", "b.csv").expect_err("time");
        assert!(e.to_string().contains("does not increase"), "{e}");
        let e = Table::parse_csv("t,x\n0,1,5\n", "b.csv").expect_err("row length");
        assert!(e.to_string().contains("3 values"), "{e}");
        let e = Table::parse_csv("t,x\n", "b.csv").expect_err("empty");
        assert!(e.to_string().contains("no rows"), "{e}");
        let e = Table::parse_csv("t,x\n0,NaN\n", "b.csv").expect_err("nan");
        assert!(e.to_string().contains("finite"), "{e}");
        let t = Table::parse_csv("t,x\n0,1\n", "b.csv").expect("one row");
        assert!(matches!(t.history("x", 0.0, 1.0), Err(TableError::InvalidFactor { .. })));
        assert!(matches!(Table::read("/nonexistent/k.sto"), Err(TableError::Io { .. })));
    }
}
