//! The output folder of a run: what an earlier run left there, atomic writes, and the manifest
//! (`manifest.json`) of what this run wrote.
//!
//! Before a run writes, [`OutDir::prepare`] sorts the folder's entries:
//! - **stale** (removed): the files listed in an earlier `manifest.json`, and the outputs of
//!   the scenario's name that no manifest explains (`NAME.pvd`, `NAME_NNNN.vtu`, `NAME.csv`,
//!   `summary.json`, and their `.tmp` leftovers), then the old manifest itself;
//! - **foreign** (everything else, directories included): never deleted; the run is refused
//!   unless `force` is given, and then writes beside them.
//!
//! The manifest is rewritten (atomically) after every file the run adds, with `status`
//! `"running"`, so that it always explains the folder, even after a crash; its final version,
//! written last, has `status` `"complete"`, `"interrupted"` or `"failed"`.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::run::RunError;

/// The manifest's file name.
pub const MANIFEST: &str = "manifest.json";
/// The summary's file name.
pub const SUMMARY: &str = "summary.json";

/// One file of the manifest.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ManifestEntry {
    /// File name, relative to the output folder.
    pub file: String,
    /// Its size in bytes when the manifest was written.
    pub bytes: u64,
}

/// `manifest.json`: every file the run wrote into the output folder.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Manifest {
    /// The program and version that wrote the folder.
    pub tool: String,
    /// The scenario file.
    pub scenario: String,
    /// The scenario's name (base name of the outputs).
    pub name: String,
    /// `running`, `complete`, `interrupted` or `failed`.
    pub status: String,
    /// The files, in the order they were first written (the manifest itself is not listed).
    pub files: Vec<ManifestEntry>,
}

/// A plain file name (no directory part), as manifests may list.
fn plain_name(s: &str) -> bool {
    !s.is_empty() && s != "." && s != ".." && !s.contains(['/', '\\']) && !s.chars().any(char::is_control)
}

/// Whether `file` is an output a run of the scenario `name` writes (or its `.tmp` leftover).
pub fn is_own_output(file: &str, name: &str) -> bool {
    let f = file.strip_suffix(".tmp").unwrap_or(file);
    if f == SUMMARY || f == MANIFEST || f == format!("{name}.pvd") || f == format!("{name}.csv") {
        return true;
    }
    f.strip_prefix(name)
        .and_then(|r| r.strip_prefix('_'))
        .and_then(|r| r.strip_suffix(".vtu"))
        .is_some_and(|digits| !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()))
}

/// The files an earlier manifest in `dir` lists (empty without a readable one).
fn previous_manifest(dir: &Path) -> HashSet<String> {
    let Ok(text) = std::fs::read_to_string(dir.join(MANIFEST)) else {
        return HashSet::new();
    };
    let Ok(m) = serde_json::from_str::<Manifest>(&text) else {
        return HashSet::new();
    };
    m.files.into_iter().map(|e| e.file).filter(|f| plain_name(f)).collect()
}

/// Writes `bytes` to `dir/file` through `dir/file.tmp` and a rename.
pub fn write_atomic(dir: &Path, file: &str, bytes: &[u8]) -> anyhow::Result<()> {
    let path = dir.join(file);
    let tmp = dir.join(format!("{file}.tmp"));
    std::fs::write(&tmp, bytes).map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", tmp.display()))?;
    std::fs::rename(&tmp, &path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        anyhow::anyhow!("cannot rename `{}` to `{}`: {e}", tmp.display(), path.display())
    })
}

/// The output folder of one run.
#[derive(Debug)]
pub struct OutDir {
    dir: PathBuf,
    scenario: String,
    name: String,
    written: Vec<String>,
}

impl OutDir {
    /// Creates `dir` if needed and clears what an earlier run left (see the module docs).
    ///
    /// # Errors
    /// [`RunError::Refused`] when `dir` holds files no earlier run explains and `force` is
    /// false; [`RunError::Failed`] when the folder cannot be created, read or cleaned.
    pub fn prepare(dir: &Path, scenario: &str, name: &str, force: bool) -> Result<Self, RunError> {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("cannot create the output directory `{}`: {e}", dir.display()))?;
        let listed = previous_manifest(dir);
        let read_err =
            |e: std::io::Error| anyhow::anyhow!("cannot read the output directory `{}`: {e}", dir.display());
        let mut stale = Vec::new();
        let mut foreign = Vec::new();
        let mut has_manifest = false;
        for entry in std::fs::read_dir(dir).map_err(read_err)? {
            let entry = entry.map_err(read_err)?;
            let is_file = entry.file_type().map_err(read_err)?.is_file();
            let file = entry.file_name().to_string_lossy().into_owned();
            let base = file.strip_suffix(".tmp").unwrap_or(&file);
            if is_file && file == MANIFEST {
                has_manifest = true;
            } else if is_file && (listed.contains(base) || is_own_output(&file, name)) {
                stale.push(file);
            } else {
                foreign.push(if is_file { file } else { format!("{file}/") });
            }
        }
        if !foreign.is_empty() && !force {
            foreign.sort();
            let shown: Vec<&str> = foreign.iter().take(5).map(String::as_str).collect();
            let more =
                if foreign.len() > 5 { format!(" and {} more", foreign.len() - 5) } else { String::new() };
            return Err(RunError::Refused(format!(
                "the output directory `{}` holds {} entr{} that no earlier synovia run wrote ({}{more}); \
                 choose another directory with --out, or pass --force to write beside them (they are kept)",
                dir.display(),
                foreign.len(),
                if foreign.len() == 1 { "y" } else { "ies" },
                shown.join(", ")
            )));
        }
        // the data files first, the manifest that explains them last
        if has_manifest {
            stale.push(MANIFEST.to_string());
        }
        for file in stale {
            let path = dir.join(&file);
            match std::fs::remove_file(&path) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => {
                    return Err(RunError::Failed(anyhow::anyhow!(
                        "cannot remove `{}` left by an earlier run: {e}",
                        path.display()
                    )))
                }
            }
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            scenario: scenario.to_string(),
            name: name.to_string(),
            written: Vec::new(),
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Notes that the run wrote `file` (once).
    pub fn record(&mut self, file: &str) {
        if !self.written.iter().any(|f| f == file) {
            self.written.push(file.to_string());
        }
    }

    /// Writes `bytes` to `file` atomically and records it.
    ///
    /// # Errors
    /// When the file cannot be written or renamed.
    pub fn write(&mut self, file: &str, bytes: &[u8]) -> anyhow::Result<()> {
        write_atomic(&self.dir, file, bytes)?;
        self.record(file);
        Ok(())
    }

    /// Writes `manifest.json` (atomically) with `status` and the files written so far.
    ///
    /// # Errors
    /// When a recorded file cannot be read or the manifest cannot be written.
    pub fn write_manifest(&self, status: &str) -> anyhow::Result<Manifest> {
        let mut files = Vec::with_capacity(self.written.len());
        for file in &self.written {
            let path = self.dir.join(file);
            let bytes = std::fs::metadata(&path)
                .map_err(|e| anyhow::anyhow!("cannot read `{}`: {e}", path.display()))?
                .len();
            files.push(ManifestEntry { file: file.clone(), bytes });
        }
        let manifest = Manifest {
            tool: format!("synovia {}", env!("CARGO_PKG_VERSION")),
            scenario: self.scenario.clone(),
            name: self.name.clone(),
            status: status.to_string(),
            files,
        };
        let json = serde_json::to_string_pretty(&manifest)?;
        write_atomic(&self.dir, MANIFEST, (json + "\n").as_bytes())?;
        Ok(manifest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn own_outputs_by_name() {
        for f in ["knee.pvd", "knee.csv", "knee_0000.vtu", "knee_12345.vtu", "summary.json", "manifest.json"]
        {
            assert!(is_own_output(f, "knee"), "{f}");
            assert!(is_own_output(&format!("{f}.tmp"), "knee"), "{f}.tmp");
        }
        for f in [
            "knee_.vtu",
            "knee_00a1.vtu",
            "knee2.pvd",
            "other_0000.vtu",
            "knee.txt",
            "notes.md",
            "knee.csv.bak",
        ] {
            assert!(!is_own_output(f, "knee"), "{f}");
        }
        assert!(plain_name("a.vtu") && !plain_name("../a.vtu") && !plain_name("..") && !plain_name(""));
    }
}
