//! ParaView time series: `.pvd` collections and a writer of whole series.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use quick_xml::events::Event;
use quick_xml::Reader;
use synovia_mesh::Mesh;

use crate::error::IoError;
use crate::field::Field;
use crate::util::{attributes, element_name, escape_attr, utf8_path, write_file_atomic};
use crate::vtu::{Encoding, VtuWriter};

/// One `<DataSet>` of a `.pvd` collection.
#[derive(Debug, Clone, PartialEq)]
pub struct PvdEntry {
    /// Time of the data set (`timestep` attribute).
    pub time: f64,
    /// Part index (`part` attribute; 0 unless several files make up one time step).
    pub part: usize,
    /// The data file. In a [`PvdWriter`] it is the path as written (relative to the `.pvd`
    /// file's directory when possible); from [`read_pvd`] it is resolved against that
    /// directory, ready for [`crate::read_vtu`].
    pub file: PathBuf,
}

/// Writer of a ParaView collection (`.pvd`): a list of `(time, part, file)` data sets that
/// ParaView opens as one time-dependent data set.
#[derive(Debug, Clone)]
pub struct PvdWriter {
    path: PathBuf,
    entries: Vec<PvdEntry>,
}

impl PvdWriter {
    /// An empty collection that [`PvdWriter::write`] will write to `path`.
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self { path: path.into(), entries: Vec::new() }
    }

    /// Where the collection is written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The data sets added so far (files as written into the collection).
    pub fn entries(&self) -> &[PvdEntry] {
        &self.entries
    }

    /// Adds `vtu_file` as part 0 at `time`. See [`PvdWriter::add_part`].
    ///
    /// # Errors
    /// As [`PvdWriter::add_part`].
    pub fn add(&mut self, time: f64, vtu_file: impl AsRef<Path>) -> Result<&mut Self, IoError> {
        self.add_part(time, 0, vtu_file)
    }

    /// Adds `vtu_file` as part `part` at `time`.
    ///
    /// ParaView resolves relative file names against the `.pvd` file's directory. A file
    /// given inside that directory (e.g. `out/run_0001.vtu` for `out/run.pvd`) is stored
    /// relative to it (`run_0001.vtu`); any other path is stored as given.
    ///
    /// # Errors
    /// [`IoError::NonFinite`] (name `"timestep"`, index = entry index) for a NaN or infinite
    /// time, [`IoError::NonUtf8Path`] for a file name that is not UTF-8.
    pub fn add_part(
        &mut self,
        time: f64,
        part: usize,
        vtu_file: impl AsRef<Path>,
    ) -> Result<&mut Self, IoError> {
        if !time.is_finite() {
            return Err(IoError::NonFinite { name: "timestep".into(), index: self.entries.len() });
        }
        let file = vtu_file.as_ref();
        utf8_path(file)?;
        let file = match self.path.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => file.strip_prefix(dir).unwrap_or(file),
            _ => file,
        };
        self.entries.push(PvdEntry { time, part, file: file.to_path_buf() });
        Ok(self)
    }

    /// Writes the collection to [`PvdWriter::path`] atomically (via a `.tmp` file and a
    /// rename), so an interrupted run leaves the previous complete collection.
    ///
    /// # Errors
    /// [`IoError::Io`] when the file cannot be written.
    pub fn write(&self) -> Result<(), IoError> {
        write_file_atomic(&self.path, |w| self.write_to(w))
    }

    /// Writes the XML document to any byte sink.
    ///
    /// # Errors
    /// Whatever the sink returns.
    pub fn write_to<W: Write>(&self, mut w: W) -> io::Result<()> {
        writeln!(w, r#"<?xml version="1.0"?>"#)?;
        writeln!(w, r#"<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">"#)?;
        writeln!(w, "  <Collection>")?;
        for e in &self.entries {
            // Paths were checked to be UTF-8 in `add_part`.
            let file = e.file.to_string_lossy();
            writeln!(
                w,
                r#"    <DataSet timestep="{:?}" group="" part="{}" file="{}"/>"#,
                e.time,
                e.part,
                escape_attr(&file)
            )?;
        }
        writeln!(w, "  </Collection>")?;
        writeln!(w, "</VTKFile>")?;
        w.flush()
    }
}

/// Reads a `.pvd` collection: its data sets in file order, each file resolved against the
/// `.pvd` file's directory. Missing `timestep` and `part` attributes default to 0.
///
/// # Errors
/// [`IoError::Io`] when the file cannot be read, [`IoError::Parse`] when it is not a
/// well-formed collection (bad XML, truncation, missing `file`, unparsable numbers).
pub fn read_pvd(path: impl AsRef<Path>) -> Result<Vec<PvdEntry>, IoError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| IoError::io(path, e))?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| IoError::parse(path, format!("the file is not UTF-8: {e}")))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut entries = parse_pvd(text).map_err(|m| IoError::parse(path, m))?;
    for e in &mut entries {
        if e.file.is_relative() {
            e.file = dir.join(&e.file);
        }
    }
    Ok(entries)
}

fn parse_pvd(xml: &str) -> Result<Vec<PvdEntry>, String> {
    let mut reader = Reader::from_str(xml);
    let mut stack: Vec<String> = Vec::new();
    let mut entries = Vec::new();
    loop {
        let position = reader.buffer_position();
        let event = reader
            .read_event()
            .map_err(|e| format!("malformed XML at byte {}: {e}", reader.error_position()))?;
        let (start, empty) = match event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                stack.pop();
                if stack.is_empty() {
                    return Ok(entries);
                }
                continue;
            }
            Event::Eof => {
                return Err(match stack.last() {
                    Some(open) => {
                        format!("unexpected end of file inside <{open}> (truncated file?)")
                    }
                    None => "no <VTKFile> element".to_string(),
                })
            }
            _ => continue,
        };
        let name = element_name(&start);
        let attrs = attributes(&start).map_err(|m| format!("{m} at byte {position}"))?;
        match (stack.last().map(String::as_str), name.as_str()) {
            (None, "VTKFile") => {
                let ty = attrs.get("type").map(String::as_str);
                if ty != Some("Collection") {
                    return Err(format!("VTKFile type is {ty:?}, expected \"Collection\""));
                }
            }
            (None, other) => return Err(format!("root element is <{other}>, expected <VTKFile>")),
            (Some("Collection"), "DataSet") => {
                let time = match attrs.get("timestep") {
                    None => 0.0,
                    Some(t) => t
                        .trim()
                        .parse::<f64>()
                        .map_err(|_| format!("bad timestep=\"{t}\" at byte {position}"))?,
                };
                let part = match attrs.get("part") {
                    None => 0,
                    Some(p) => p
                        .trim()
                        .parse::<usize>()
                        .map_err(|_| format!("bad part=\"{p}\" at byte {position}"))?,
                };
                let file = attrs
                    .get("file")
                    .filter(|f| !f.is_empty())
                    .ok_or_else(|| format!("<DataSet> at byte {position} has no file"))?;
                entries.push(PvdEntry { time, part, file: PathBuf::from(file) });
            }
            _ => {}
        }
        if empty {
            if stack.is_empty() {
                return Ok(entries);
            }
        } else {
            stack.push(name);
        }
    }
}

/// Writes a time series as `DIR/NAME_0000.vtu`, `DIR/NAME_0001.vtu`, … plus the collection
/// `DIR/NAME.pvd`, rewritten (atomically) after every step so that a run that stops early
/// still leaves a complete, readable series of the steps done.
///
/// Open `DIR/NAME.pvd` in ParaView to step through time. Existing files of the same names are
/// overwritten; steps of an earlier, longer run stay on disk but are no longer listed.
#[derive(Debug, Clone)]
pub struct TimeSeriesWriter {
    dir: PathBuf,
    name: String,
    encoding: Encoding,
    pvd: PvdWriter,
}

impl TimeSeriesWriter {
    /// A series named `name` in directory `dir` (created if missing); `encoding` is used by
    /// [`TimeSeriesWriter::write_mesh`].
    ///
    /// # Errors
    /// [`IoError::InvalidName`] when `name` is empty, `.`/`..`, or contains a path separator
    /// or control character; [`IoError::Io`] when the directory cannot be created.
    pub fn new(dir: impl Into<PathBuf>, name: &str, encoding: Encoding) -> Result<Self, IoError> {
        let invalid =
            |reason: &str| IoError::InvalidName { name: name.to_string(), reason: reason.to_string() };
        if name.is_empty() || name == "." || name == ".." {
            return Err(invalid("not a usable file-name stem"));
        }
        if name.contains(['/', '\\']) || name.chars().any(char::is_control) {
            return Err(invalid("contains a path separator or control character"));
        }
        let dir = dir.into();
        std::fs::create_dir_all(&dir).map_err(|e| IoError::io(&dir, e))?;
        utf8_path(&dir)?;
        let pvd = PvdWriter::new(dir.join(format!("{name}.pvd")));
        Ok(Self { dir, name: name.to_string(), encoding, pvd })
    }

    /// Path of the `.pvd` collection.
    pub fn pvd_path(&self) -> &Path {
        self.pvd.path()
    }

    /// Number of steps written.
    pub fn n_steps(&self) -> usize {
        self.pvd.entries().len()
    }

    /// Writes `vtu` (with its own encoding) as the next step at `time`, then rewrites the
    /// collection. Returns the path of the `.vtu` file written.
    ///
    /// # Errors
    /// [`IoError::NonFinite`] for a non-finite time, [`IoError::TimeNotIncreasing`] when `time`
    /// is not larger than the previous step's, [`IoError::Io`] on write failures (the series
    /// is then unchanged).
    pub fn write_step(&mut self, time: f64, vtu: &VtuWriter) -> Result<PathBuf, IoError> {
        if !time.is_finite() {
            return Err(IoError::NonFinite { name: "timestep".into(), index: self.n_steps() });
        }
        if let Some(previous) = self.pvd.entries().last().map(|e| e.time) {
            if time <= previous {
                return Err(IoError::TimeNotIncreasing { previous, time });
            }
        }
        let file = self.dir.join(format!("{}_{:04}.vtu", self.name, self.n_steps()));
        vtu.write(&file)?;
        let mut pvd = self.pvd.clone();
        pvd.add(time, &file)?;
        pvd.write()?;
        self.pvd = pvd;
        Ok(file)
    }

    /// Writes one body's `mesh` and `fields` (with the series' encoding) as the next step.
    ///
    /// # Errors
    /// As [`VtuWriter::add_piece`] and [`TimeSeriesWriter::write_step`].
    pub fn write_mesh<const D: usize>(
        &mut self,
        time: f64,
        mesh: &Mesh<D>,
        fields: Vec<Field>,
    ) -> Result<PathBuf, IoError> {
        let mut vtu = VtuWriter::new(self.encoding);
        vtu.add_piece(mesh, fields)?;
        self.write_step(time, &vtu)
    }
}
