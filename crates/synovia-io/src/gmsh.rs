//! Reading [Gmsh](https://gmsh.info) `.msh` meshes and turning their physical groups into
//! synovia bodies and boundary parts.
//!
//! ```no_run
//! use synovia_io::gmsh::read_msh;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let msh = read_msh("knee.msh")?;
//! for (name, mesh) in msh.bodies::<3>()? {
//!     println!("{name}: {} nodes, {} tetrahedra", mesh.n_nodes(), mesh.n_cells());
//!     for part in mesh.boundary_parts() {
//!         println!("  {} ({:?}): {} facets", part.name(), part.kind(), part.n_facets());
//!     }
//! }
//! # Ok(())
//! # }
//! ```
//!
//! Reading is done in two steps: [`read_msh`] (or [`parse_msh`] for bytes in memory) parses the
//! file into a [`GmshMesh`], a faithful, format-independent image of the file (nodes, element
//! blocks with their physical tags, physical names); [`GmshMesh::bodies`] then maps it to
//! synovia [`Mesh`]es. [`read_msh_bodies`] does both.
//!
//! # Supported files
//!
//! * **MSH 4.1**, ASCII and binary; **MSH 2.2**, ASCII and binary (2.0 and 2.1 share the 2.2
//!   layout and are read the same way). Binary files may be little- or big-endian (the integer
//!   `1` that follows the `$MeshFormat` line tells which); in MSH 4.1 binary files the data size
//!   of `$MeshFormat` (the size of `size_t`) may be 4 or 8. MSH 1, 3 and 4.0 are rejected with
//!   [`IoError::MshVersion`].
//! * Sections read: `$MeshFormat` (must come first), `$PhysicalNames`, `$Entities` (4.1: maps
//!   each elementary entity to its physical tags), `$Nodes` (4.1: entity blocks, with or without
//!   parametric coordinates, which are skipped; 2.2: flat list) and `$Elements` (4.1: one block
//!   per entity and element type; 2.2: one line per element whose first tag is the physical
//!   tag, the second the elementary entity). `$Nodes` must come before `$Elements`.
//! * Every other section (`$Periodic`, `$NodeData`, `$ElementData`, `$Comments`, …) is skipped
//!   up to its `$End…` line. `$PartitionedEntities` is an error: partitioned meshes are not
//!   supported (save the mesh unpartitioned).
//! * Element types with a variable number of nodes (polygons, polyhedra, Gmsh's internal
//!   sub-elements) are tolerated in ASCII files (their connectivity is not kept) and rejected in
//!   binary files, where they cannot be skipped.
//!
//! # Mapping to synovia bodies
//!
//! [`GmshMesh::bodies::<D>`](GmshMesh::bodies) returns one `(name, Mesh<D>)` per body:
//!
//! * **Bodies.** Every physical group of dimension `D` is one body (in increasing physical tag
//!   order), named by its physical name, or `physical_<tag>` when it has none. It must hold
//!   only P1 simplices — 3-node triangles (type 2) for `D = 2`, 4-node tetrahedra (type 4) for
//!   `D = 3`; any other type (quadrangles, second-order elements, …) is
//!   [`IoError::UnsupportedElement`]. Each body's mesh contains only its own nodes, numbered in
//!   increasing Gmsh node tag order, and its own cells, in increasing element tag order (an
//!   element listed twice in a group is kept once); inverted cells are flipped by
//!   [`Mesh::new_with_repair`]. Bodies sharing nodes in the file (a conforming interface) get
//!   separate copies of them. In 2D every node of a body must have `z = 0` (within `1e-12`
//!   relative to the body's largest `|x|`, `|y|`); the `z` coordinate is then dropped.
//! * **Boundary parts.** Every physical group of dimension `D − 1` (2-node lines, type 1, in 2D;
//!   3-node triangles, type 2, in 3D — other types are [`IoError::UnsupportedElement`]) becomes a
//!   boundary part of the same name on *every* body that has some of its facets as boundary
//!   facets, holding those facets (re-oriented outward). Facets of the group that are not on a
//!   body's boundary are skipped for that body, so one group may describe, e.g., the contact
//!   interface of two touching bodies, or a symmetry plane crossing several bodies. A group that
//!   matches no body's boundary at all is an [`IoError::GmshMapping`] error naming it.
//! * **Part kinds** come from a function of the part name:
//!   [`GmshMesh::bodies_with_kinds`] takes any `&dyn Fn(&str) -> BoundaryKind`, and
//!   [`GmshMesh::bodies`] uses [`default_boundary_kind`], this naming convention (the name's
//!   case is ignored; the first matching prefix wins):
//!
//!   | name starts with                                      | kind                           |
//!   |-------------------------------------------------------|--------------------------------|
//!   | `traction_free`, `traction-free`, `tractionfree`, `free` | [`BoundaryKind::TractionFree`] |
//!   | `clamped`                                             | [`BoundaryKind::Clamped`]      |
//!   | `prescribed`                                          | [`BoundaryKind::Prescribed`]   |
//!   | `traction`                                            | [`BoundaryKind::Traction`]     |
//!   | `symmetry`                                            | [`BoundaryKind::Symmetry`]     |
//!   | `contact`                                             | [`BoundaryKind::Contact`]      |
//!   | anything else                                         | [`BoundaryKind::TractionFree`] |
//!
//! * Physical groups of other dimensions (points, lines in 3D, surfaces when `D = 2`, …) and
//!   elements in no physical group are ignored.
//!
//! For example, the `.geo` lines
//!
//! ```text
//! Physical Volume("femur") = {1};
//! Physical Volume("tibia") = {2};
//! Physical Surface("clamped_shaft") = {7};
//! Physical Surface("contact_cartilage") = {12, 13};
//! ```
//!
//! give two bodies, `femur` and `tibia`; `clamped_shaft` becomes a [`BoundaryKind::Clamped`] part
//! of whichever body it bounds, and `contact_cartilage` a [`BoundaryKind::Contact`] part on each
//! body that has some of its triangles on its boundary.
//!
//! # Errors
//!
//! Nothing here panics on any input. Malformed files give [`IoError::Parse`] whose message starts
//! with the line number (ASCII files) or the byte offset (binary files) of the problem:
//! truncation, bad numbers, missing or unclosed sections, unknown node tags, counts that do not
//! match the data, unknown element types. Unsupported versions give [`IoError::MshVersion`];
//! mapping problems [`IoError::UnsupportedElement`], [`IoError::GmshMapping`] or
//! [`IoError::GmshBody`] (a body that does not form a valid mesh, e.g. with a degenerate cell).
//! Counts read from a file are never trusted for allocation, so a huge count in a small file is
//! an error, not an out-of-memory abort.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use synovia_mesh::{BoundaryKind, Mesh, MeshError, Point};

use crate::error::IoError;

/// Version of the MSH format of a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MshVersion {
    /// MSH 2.2 (files declaring 2.0 or 2.1 are read the same way).
    Msh22,
    /// MSH 4.1.
    Msh41,
}

/// A `$PhysicalNames` entry: the name of physical group `tag` of dimension `dim`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhysicalName {
    /// Dimension of the group (0 points, 1 curves, 2 surfaces, 3 volumes).
    pub dim: usize,
    /// Physical tag (unique per dimension).
    pub tag: i32,
    /// The name, without the quotes.
    pub name: String,
}

/// A physical group present in a file (see [`GmshMesh::physical_groups`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhysicalGroup {
    /// Dimension of the group.
    pub dim: usize,
    /// Physical tag.
    pub tag: i32,
    /// The group's physical name, or `physical_<tag>` if it has none.
    pub name: String,
    /// Whether the name comes from `$PhysicalNames`.
    pub named: bool,
    /// Number of elements in the group (counted once per element block that belongs to it).
    pub n_elements: usize,
}

/// Elements of one type on one elementary entity, with the physical tags of that entity.
///
/// MSH 4.1 blocks are the file's blocks; MSH 2.2 elements are grouped into blocks of
/// consecutive elements with the same type, entity and physical tag.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementBlock {
    /// Dimension of the entity (and the elements).
    pub dim: usize,
    /// Elementary entity tag (0 if a 2.2 element has no second tag).
    pub entity_tag: i32,
    /// Gmsh element type number (2 = 3-node triangle, 4 = 4-node tetrahedron, …).
    pub element_type: i32,
    /// Physical tags of the elements (empty when they belong to no physical group).
    pub physical_tags: Vec<i32>,
    /// Element tags, one per element.
    pub element_tags: Vec<u64>,
    /// Nodes per element; `0` for types with a variable node count, whose connectivity is not
    /// kept.
    pub nodes_per_element: usize,
    /// Flat connectivity: `nodes_per_element` indices into [`GmshMesh::nodes`] per element.
    pub connectivity: Vec<usize>,
}

impl ElementBlock {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.element_tags.len()
    }
    /// `true` if the block holds no element.
    pub fn is_empty(&self) -> bool {
        self.element_tags.is_empty()
    }
    /// Node indices (into [`GmshMesh::nodes`]) of element `e` of the block (empty for types
    /// with a variable node count).
    pub fn element(&self, e: usize) -> &[usize] {
        let n = self.nodes_per_element;
        self.connectivity.get(e * n..(e + 1) * n).unwrap_or(&[])
    }
}

/// The contents of a Gmsh `.msh` file, independent of its version and encoding.
#[derive(Debug, Clone, PartialEq)]
pub struct GmshMesh {
    /// Format version of the file.
    pub version: MshVersion,
    /// Whether the file was binary.
    pub binary: bool,
    /// The `$PhysicalNames` entries, in file order.
    pub physical_names: Vec<PhysicalName>,
    /// Gmsh tag of each node (parallel to [`GmshMesh::nodes`]).
    pub node_tags: Vec<u64>,
    /// Node coordinates in file order (always 3).
    pub nodes: Vec<[f64; 3]>,
    /// The element blocks, in file order.
    pub element_blocks: Vec<ElementBlock>,
}

/// Reads a Gmsh `.msh` file (MSH 4.1 or 2.2, ASCII or binary), also gzip-compressed
/// (`.msh.gz`, recognised by its content).
///
/// # Errors
/// [`IoError::Io`] if the file cannot be read, [`IoError::MshVersion`] for other versions,
/// [`IoError::Parse`] (with the line number or byte offset) for malformed files.
pub fn read_msh(path: impl AsRef<Path>) -> Result<GmshMesh, IoError> {
    let path = path.as_ref();
    let bytes = crate::util::read_regular_file(path)?;
    parse_with_path(&bytes, path)
}

/// Parses a `.msh` file held in memory, as [`read_msh`] (errors name the path `<bytes>`).
///
/// # Errors
/// As [`read_msh`].
pub fn parse_msh(bytes: &[u8]) -> Result<GmshMesh, IoError> {
    parse_with_path(bytes, Path::new("<bytes>"))
}

/// Reads a `.msh` file and maps it to bodies with [`GmshMesh::bodies`].
///
/// # Errors
/// As [`read_msh`] and [`GmshMesh::bodies`].
pub fn read_msh_bodies<const D: usize>(path: impl AsRef<Path>) -> Result<Vec<(String, Mesh<D>)>, IoError> {
    read_msh(path)?.bodies::<D>()
}

/// The default boundary-kind convention of [`GmshMesh::bodies`], from the part name (case
/// ignored): names starting with `traction_free`, `traction-free`, `tractionfree` or `free` are
/// [`BoundaryKind::TractionFree`]; then `clamped` → [`BoundaryKind::Clamped`], `prescribed` →
/// [`BoundaryKind::Prescribed`], `traction` → [`BoundaryKind::Traction`], `symmetry` →
/// [`BoundaryKind::Symmetry`], `contact` → [`BoundaryKind::Contact`]; anything else is
/// [`BoundaryKind::TractionFree`].
pub fn default_boundary_kind(name: &str) -> BoundaryKind {
    let n = name.to_ascii_lowercase();
    let rules: [(&str, BoundaryKind); 9] = [
        ("traction_free", BoundaryKind::TractionFree),
        ("traction-free", BoundaryKind::TractionFree),
        ("tractionfree", BoundaryKind::TractionFree),
        ("free", BoundaryKind::TractionFree),
        ("clamped", BoundaryKind::Clamped),
        ("prescribed", BoundaryKind::Prescribed),
        ("traction", BoundaryKind::Traction),
        ("symmetry", BoundaryKind::Symmetry),
        ("contact", BoundaryKind::Contact),
    ];
    rules.iter().find(|(p, _)| n.starts_with(p)).map_or(BoundaryKind::TractionFree, |&(_, k)| k)
}

/// Description of a Gmsh element type, e.g. `6-node triangle` for type 9, `polygon` for
/// type 34, `unknown element type` for numbers Gmsh does not define.
pub fn element_type_name(element_type: i32) -> String {
    match element_info(element_type) {
        Some(ElementInfo { shape, nodes: Some(n), .. }) => format!("{n}-node {shape}"),
        Some(ElementInfo { shape, nodes: None, .. }) => shape.to_string(),
        None => "unknown element type".to_string(),
    }
}

#[derive(Debug, Clone, Copy)]
struct ElementInfo {
    dim: usize,
    shape: &'static str,
    /// `None` for types with a variable number of nodes.
    nodes: Option<usize>,
}

/// The Gmsh element types (GmshDefines.h, `MSH_*`): dimension, shape, node count.
fn element_info(t: i32) -> Option<ElementInfo> {
    const PNT: (usize, &str) = (0, "point");
    const LIN: (usize, &str) = (1, "line");
    const TRI: (usize, &str) = (2, "triangle");
    const QUA: (usize, &str) = (2, "quadrangle");
    const TET: (usize, &str) = (3, "tetrahedron");
    const HEX: (usize, &str) = (3, "hexahedron");
    const PRI: (usize, &str) = (3, "prism");
    const PYR: (usize, &str) = (3, "pyramid");
    let fixed =
        |(dim, shape): (usize, &'static str), n: usize| Some(ElementInfo { dim, shape, nodes: Some(n) });
    let variable = |dim: usize, shape: &'static str| Some(ElementInfo { dim, shape, nodes: None });
    match t {
        1 => fixed(LIN, 2),
        2 => fixed(TRI, 3),
        3 => fixed(QUA, 4),
        4 => fixed(TET, 4),
        5 => fixed(HEX, 8),
        6 => fixed(PRI, 6),
        7 => fixed(PYR, 5),
        8 => fixed(LIN, 3),
        9 => fixed(TRI, 6),
        10 => fixed(QUA, 9),
        11 => fixed(TET, 10),
        12 => fixed(HEX, 27),
        13 => fixed(PRI, 18),
        14 => fixed(PYR, 14),
        15 => fixed(PNT, 1),
        16 => fixed(QUA, 8),
        17 => fixed(HEX, 20),
        18 => fixed(PRI, 15),
        19 => fixed(PYR, 13),
        20 => fixed(TRI, 9),
        21 => fixed(TRI, 10),
        22 => fixed(TRI, 12),
        23 | 24 => fixed(TRI, 15),
        25 => fixed(TRI, 21),
        26..=28 => fixed(LIN, (t - 22) as usize),
        29 => fixed(TET, 20),
        30 => fixed(TET, 35),
        31 => fixed(TET, 56),
        32 => fixed(TET, 22),
        33 => fixed(TET, 28),
        34 => variable(2, "polygon"),
        35 => variable(3, "polyhedron"),
        36 => fixed(QUA, 16),
        37 => fixed(QUA, 25),
        38 => fixed(QUA, 36),
        39 => fixed(QUA, 12),
        40 => fixed(QUA, 16),
        41 => fixed(QUA, 20),
        42 => fixed(TRI, 28),
        43 => fixed(TRI, 36),
        44 => fixed(TRI, 45),
        45 => fixed(TRI, 55),
        46 => fixed(TRI, 66),
        47..=51 => {
            let k = (t - 40) as usize; // 7..=11 nodes per side
            fixed(QUA, k * k)
        }
        52..=56 => fixed(TRI, 18 + 3 * (t - 52) as usize),
        57..=61 => fixed(QUA, 24 + 4 * (t - 57) as usize),
        62..=66 => fixed(LIN, (t - 55) as usize),
        71..=75 => {
            let p = (t - 65) as usize; // order 6..=10
            fixed(TET, (p + 1) * (p + 2) * (p + 3) / 6)
        }
        79..=83 => fixed(TET, 34 + 6 * (t - 79) as usize),
        84 => fixed(LIN, 1),
        85 => fixed(TRI, 1),
        86 => fixed(QUA, 1),
        87 => fixed(TET, 1),
        88 => fixed(HEX, 1),
        89 => fixed(PRI, 1),
        90 => fixed(PRI, 40),
        91 => fixed(PRI, 75),
        92..=98 => {
            let k = (t - 88) as usize; // 4..=10 nodes per edge
            fixed(HEX, k * k * k)
        }
        99..=105 => fixed(HEX, 32 + 12 * (t - 99) as usize),
        106..=110 => {
            let p = (t - 100) as usize; // order 6..=10
            fixed(PRI, (p + 1) * (p + 1) * (p + 2) / 2)
        }
        111..=117 => fixed(PRI, 24 + 9 * (t - 111) as usize),
        118..=124 => {
            let p = (t - 115) as usize; // order 3..=9
            fixed(PYR, (p + 1) * (p + 2) * (2 * p + 3) / 6)
        }
        125..=131 => fixed(PYR, 21 + 8 * (t - 125) as usize),
        132 => fixed(PYR, 1),
        133 => variable(0, "point sub-element"),
        134 => variable(1, "line sub-element"),
        135 => variable(2, "triangle sub-element"),
        136 => variable(3, "tetrahedron sub-element"),
        137 => fixed(TET, 16),
        138 => fixed(TRI, 4),
        139 => fixed(TET, 5),
        140 => fixed((3, "trihedron"), 4),
        _ => None,
    }
}

// ---------------------------------------------------------------------------------------------
// Low-level reader
// ---------------------------------------------------------------------------------------------

/// An internal parse failure: a message at a byte position, or an unsupported version.
#[derive(Debug)]
enum PErr {
    At { pos: usize, msg: String },
    Version(String),
}

type PResult<T> = Result<T, PErr>;

fn at(pos: usize, msg: impl Into<String>) -> PErr {
    PErr::At { pos, msg: msg.into() }
}

/// At most 40 characters of `bytes`, for messages.
fn show(bytes: &[u8]) -> String {
    let s = String::from_utf8_lossy(bytes);
    let mut out: String = s.chars().take(40).collect();
    if s.chars().count() > 40 {
        out.push('…');
    }
    out
}

fn trim(bytes: &[u8]) -> &[u8] {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    let end = bytes.iter().rposition(|b| !b.is_ascii_whitespace()).map_or(start, |e| e + 1);
    bytes.get(start..end).unwrap_or(&[])
}

/// The first whitespace-separated token of `bytes` and the (trimmed) rest.
fn split_token(bytes: &[u8]) -> (&[u8], &[u8]) {
    let b = trim(bytes);
    let end = b.iter().position(u8::is_ascii_whitespace).unwrap_or(b.len());
    (&b[..end], trim(&b[end..]))
}

fn parse_token<T: std::str::FromStr>(t: &[u8]) -> Option<T> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// 1-based line number of byte `pos`.
fn line_of(data: &[u8], pos: usize) -> usize {
    let end = pos.min(data.len());
    data[..end].iter().filter(|&&b| b == b'\n').count() + 1
}

/// A cursor over the file: ASCII lines split into whitespace-separated tokens, or binary values.
///
/// Values are read inside *records*: in ASCII, a record is one non-blank line and must be used
/// up exactly; in binary, records have no delimiters.
struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
    binary: bool,
    big_endian: bool,
    /// Size of `size_t` in MSH 4.1 binary files (4 or 8).
    size_t: usize,
    toks: Vec<&'a [u8]>,
    tok_i: usize,
    rec_pos: usize,
    ascii_rec: bool,
}

impl<'a> Reader<'a> {
    fn new(data: &'a [u8]) -> Self {
        Self {
            data,
            pos: 0,
            binary: false,
            big_endian: false,
            size_t: 8,
            toks: Vec::new(),
            tok_i: 0,
            rec_pos: 0,
            ascii_rec: false,
        }
    }

    fn at_eof(&self) -> bool {
        self.pos >= self.data.len()
    }

    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    /// A capacity to reserve for `count` items of at least `min_bytes` bytes each: never more
    /// than the rest of the file can hold, so a corrupt count cannot exhaust memory.
    fn capacity(&self, count: u64, min_bytes: usize) -> usize {
        let fit = self.remaining() / min_bytes.max(1);
        usize::try_from(count).map_or(fit, |c| c.min(fit))
    }

    fn skip_ws(&mut self) {
        while self.data.get(self.pos).is_some_and(u8::is_ascii_whitespace) {
            self.pos += 1;
        }
    }

    /// The next line (without its terminator) and its start, or `None` at the end of the file.
    fn raw_line(&mut self) -> Option<(usize, &'a [u8])> {
        let data: &'a [u8] = self.data;
        let rest = data.get(self.pos..).filter(|r| !r.is_empty())?;
        let start = self.pos;
        let (line, advance) = match rest.iter().position(|&b| b == b'\n') {
            Some(i) => (&rest[..i], i + 1),
            None => (rest, rest.len()),
        };
        self.pos += advance;
        Some((start, line))
    }

    /// The next non-blank line, trimmed, and its start.
    fn content_line(&mut self, what: &str) -> PResult<(usize, &'a [u8])> {
        loop {
            match self.raw_line() {
                None => return Err(at(self.pos, format!("unexpected end of file while reading {what}"))),
                Some((start, line)) => {
                    let t = trim(line);
                    if !t.is_empty() {
                        return Ok((start, t));
                    }
                }
            }
        }
    }

    /// Starts a record: the next line in ASCII files, nothing in binary files.
    fn record(&mut self, what: &str) -> PResult<()> {
        if self.binary {
            self.ascii_rec = false;
            self.rec_pos = self.pos;
            self.tok_i = self.toks.len();
            Ok(())
        } else {
            self.ascii_record(what)
        }
    }

    /// Starts an ASCII record even in a binary file (the counts of MSH 2.2 binary sections).
    fn ascii_record(&mut self, what: &str) -> PResult<()> {
        let (start, line) = self.content_line(what)?;
        if line.first() == Some(&b'$') {
            return Err(at(
                start,
                format!(
                    "expected {what}, found `{}`: the section ends too early (is a count wrong?)",
                    show(line)
                ),
            ));
        }
        self.toks.clear();
        self.toks.extend(line.split(u8::is_ascii_whitespace).filter(|t| !t.is_empty()));
        self.tok_i = 0;
        self.rec_pos = start;
        self.ascii_rec = true;
        Ok(())
    }

    /// Ends a record: an ASCII line must have no value left.
    fn end_record(&mut self) -> PResult<()> {
        if self.ascii_rec {
            if let Some(t) = self.toks.get(self.tok_i) {
                return Err(at(
                    self.rec_pos,
                    format!("unexpected extra value `{}` at the end of the line", show(t)),
                ));
            }
        }
        self.ascii_rec = false;
        self.tok_i = self.toks.len();
        Ok(())
    }

    fn in_ascii(&self) -> bool {
        !self.binary || self.ascii_rec
    }

    /// Position to report for the next value: the line in ASCII, the byte in binary.
    fn value_pos(&self) -> usize {
        if self.in_ascii() {
            self.rec_pos
        } else {
            self.pos
        }
    }

    /// Values left on the current ASCII line.
    fn tokens_left(&self) -> usize {
        self.toks.len().saturating_sub(self.tok_i)
    }

    fn skip_rest(&mut self) {
        self.tok_i = self.toks.len();
    }

    fn tok(&mut self, what: &str) -> PResult<&'a [u8]> {
        match self.toks.get(self.tok_i) {
            Some(&t) => {
                self.tok_i += 1;
                Ok(t)
            }
            None => Err(at(self.rec_pos, format!("the line ends before {what}"))),
        }
    }

    fn take(&mut self, n: usize, what: &str) -> PResult<&'a [u8]> {
        let data: &'a [u8] = self.data;
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= data.len())
            .ok_or_else(|| at(self.pos, format!("unexpected end of file while reading {what}")))?;
        let s = &data[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn bytes<const N: usize>(&mut self, what: &str) -> PResult<[u8; N]> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, what)?);
        if self.big_endian {
            a.reverse();
        }
        Ok(a) // now little-endian
    }

    fn bin_i32(&mut self, what: &str) -> PResult<i32> {
        Ok(i32::from_le_bytes(self.bytes::<4>(what)?))
    }

    fn bin_f64(&mut self, what: &str) -> PResult<f64> {
        Ok(f64::from_le_bytes(self.bytes::<8>(what)?))
    }

    /// A signed `int`.
    fn int(&mut self, what: &str) -> PResult<i32> {
        if self.in_ascii() {
            let t = self.tok(what)?;
            parse_token(t)
                .ok_or_else(|| at(self.rec_pos, format!("bad {what} `{}`: expected an integer", show(t))))
        } else {
            self.bin_i32(what)
        }
    }

    /// An unsigned count or tag (`size_t` in MSH 4.1 binary files).
    fn size(&mut self, what: &str) -> PResult<u64> {
        if self.in_ascii() {
            let t = self.tok(what)?;
            parse_token(t).ok_or_else(|| {
                at(self.rec_pos, format!("bad {what} `{}`: expected a non-negative integer", show(t)))
            })
        } else if self.size_t == 4 {
            Ok(u64::from(u32::from_le_bytes(self.bytes::<4>(what)?)))
        } else {
            Ok(u64::from_le_bytes(self.bytes::<8>(what)?))
        }
    }

    fn double(&mut self, what: &str) -> PResult<f64> {
        if self.in_ascii() {
            let t = self.tok(what)?;
            parse_token(t)
                .ok_or_else(|| at(self.rec_pos, format!("bad {what} `{}`: expected a number", show(t))))
        } else {
            self.bin_f64(what)
        }
    }

    /// The closing `$End<section>` line (after optional whitespace, e.g. the newline that
    /// follows binary data).
    fn expect_end(&mut self, section: &str) -> PResult<()> {
        self.skip_ws();
        let start = self.pos;
        let want = format!("$End{section}");
        match self.raw_line() {
            Some((_, line)) if trim(line) == want.as_bytes() => Ok(()),
            Some((_, line)) => Err(at(
                start,
                format!("expected `{want}`, found `{}` (is a count in the section wrong?)", show(trim(line))),
            )),
            None => Err(at(start, format!("unexpected end of file: missing `{want}`"))),
        }
    }

    /// Skips an unknown section up to its `$End<name>` line.
    fn skip_section(&mut self, name: &[u8], header: usize) -> PResult<()> {
        let mut marker = b"$End".to_vec();
        marker.extend_from_slice(name);
        let mut from = self.pos;
        while let Some(i) =
            self.data.get(from..).and_then(|r| r.windows(marker.len()).position(|w| w == marker))
        {
            let idx = from + i;
            let after = idx + marker.len();
            let line_start =
                idx == self.pos || matches!(self.data.get(idx.wrapping_sub(1)), Some(b'\n' | b'\r'));
            let line_end = self.data.get(after).is_none_or(u8::is_ascii_whitespace);
            if line_start && line_end {
                self.pos = idx;
                self.raw_line();
                return Ok(());
            }
            from = idx + 1;
        }
        Err(at(header, format!("section `${}` is not closed by `$End{}`", show(name), show(name))))
    }
}

// ---------------------------------------------------------------------------------------------
// Section parser
// ---------------------------------------------------------------------------------------------

struct Parser<'a> {
    r: Reader<'a>,
    version: Option<MshVersion>,
    physical_names: Option<Vec<PhysicalName>>,
    /// `(dim, entity tag)` → physical tags (MSH 4.1 `$Entities`).
    entities: Option<HashMap<(usize, i32), Vec<i32>>>,
    node_tags: Vec<u64>,
    nodes: Vec<[f64; 3]>,
    node_index: HashMap<u64, usize>,
    nodes_seen: bool,
    blocks: Option<Vec<ElementBlock>>,
    /// Position of each block's header (MSH 4.1), to report unknown entities.
    block_pos: Vec<usize>,
}

/// The largest decompressed size of a gzip-compressed `.msh` file (a guard against inputs
/// that expand without bound).
const MAX_DECOMPRESSED_BYTES: u64 = 1 << 30;

/// `bytes`, or their gzip decompression if they start with the gzip magic `1f 8b` (a
/// `.msh.gz` file; MSH itself starts with `$MeshFormat`).
fn decompressed<'a>(bytes: &'a [u8], path: &Path) -> Result<std::borrow::Cow<'a, [u8]>, IoError> {
    use std::io::Read;
    if !bytes.starts_with(&[0x1f, 0x8b]) {
        return Ok(std::borrow::Cow::Borrowed(bytes));
    }
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(bytes)
        .take(MAX_DECOMPRESSED_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| IoError::parse(path, format!("gzip-compressed mesh: {e}")))?;
    if out.len() as u64 > MAX_DECOMPRESSED_BYTES {
        return Err(IoError::parse(
            path,
            format!("gzip-compressed mesh expands beyond {MAX_DECOMPRESSED_BYTES} bytes"),
        ));
    }
    Ok(std::borrow::Cow::Owned(out))
}

fn parse_with_path(bytes: &[u8], path: &Path) -> Result<GmshMesh, IoError> {
    let bytes = decompressed(bytes, path)?;
    let bytes: &[u8] = &bytes;
    let mut p = Parser {
        r: Reader::new(bytes),
        version: None,
        physical_names: None,
        entities: None,
        node_tags: Vec::new(),
        nodes: Vec::new(),
        node_index: HashMap::new(),
        nodes_seen: false,
        blocks: None,
        block_pos: Vec::new(),
    };
    match p.run() {
        Ok(mesh) => Ok(mesh),
        Err(PErr::Version(version)) => Err(IoError::MshVersion { path: path.to_path_buf(), version }),
        Err(PErr::At { pos, msg }) => {
            let location = if p.r.binary {
                format!("byte offset {pos}")
            } else {
                format!("line {}", line_of(bytes, pos))
            };
            Err(IoError::parse(path, format!("{location}: {msg}")))
        }
    }
}

impl Parser<'_> {
    fn run(&mut self) -> PResult<GmshMesh> {
        loop {
            self.r.skip_ws();
            if self.r.at_eof() {
                break;
            }
            let (start, line) = self.r.content_line("a section header")?;
            if line.first() != Some(&b'$') {
                return Err(at(
                    start,
                    format!("expected a section header such as `$Nodes`, found `{}`", show(line)),
                ));
            }
            let name = trim(&line[1..]);
            let v41 = self.version == Some(MshVersion::Msh41);
            if self.version.is_none() && name != b"MeshFormat" {
                if matches!(name, b"NOD" | b"NOE" | b"ELM") {
                    return Err(PErr::Version("1.0".to_string()));
                }
                return Err(at(
                    start,
                    format!(
                        "expected `$MeshFormat` at the start of the file, found `{}`; is this a Gmsh .msh file?",
                        show(line)
                    ),
                ));
            }
            let once = |seen: bool| {
                if seen {
                    Err(at(start, format!("duplicate `{}` section", show(line))))
                } else {
                    Ok(())
                }
            };
            match name {
                b"MeshFormat" => {
                    once(self.version.is_some())?;
                    self.mesh_format()?;
                }
                b"PhysicalNames" => {
                    once(self.physical_names.is_some())?;
                    self.physical_names()?;
                }
                b"Entities" if v41 => {
                    once(self.entities.is_some())?;
                    self.entities41()?;
                }
                b"PartitionedEntities" if v41 => {
                    return Err(at(
                        start,
                        "partitioned meshes (`$PartitionedEntities`) are not supported; save the mesh unpartitioned",
                    ))
                }
                b"Nodes" => {
                    once(self.nodes_seen)?;
                    if v41 {
                        self.nodes41()?;
                    } else {
                        self.nodes22()?;
                    }
                    self.nodes_seen = true;
                }
                b"Elements" => {
                    once(self.blocks.is_some())?;
                    if !self.nodes_seen {
                        return Err(at(start, "`$Elements` comes before `$Nodes`"));
                    }
                    let blocks = if v41 { self.elements41()? } else { self.elements22()? };
                    self.blocks = Some(blocks);
                }
                _ if name.starts_with(b"End") => {
                    return Err(at(start, format!("`{}` without a matching opening section", show(line))))
                }
                _ => self.r.skip_section(name, start)?,
            }
        }
        let end = self.r.data.len();
        let version = self.version.ok_or_else(|| at(0, "the file is empty (no `$MeshFormat` section)"))?;
        if !self.nodes_seen {
            return Err(at(end, "missing `$Nodes` section"));
        }
        let mut blocks = self.blocks.take().ok_or_else(|| at(end, "missing `$Elements` section"))?;
        if version == MshVersion::Msh41 {
            if let Some(entities) = &self.entities {
                for (block, &pos) in blocks.iter_mut().zip(&self.block_pos) {
                    match entities.get(&(block.dim, block.entity_tag)) {
                        Some(tags) => block.physical_tags.clone_from(tags),
                        None => {
                            return Err(at(
                                pos,
                                format!(
                                    "element block on entity (dimension {}, tag {}), which `$Entities` does not define",
                                    block.dim, block.entity_tag
                                ),
                            ))
                        }
                    }
                }
            }
        }
        Ok(GmshMesh {
            version,
            binary: self.r.binary,
            physical_names: self.physical_names.take().unwrap_or_default(),
            node_tags: std::mem::take(&mut self.node_tags),
            nodes: std::mem::take(&mut self.nodes),
            element_blocks: blocks,
        })
    }

    fn mesh_format(&mut self) -> PResult<()> {
        let r = &mut self.r;
        r.ascii_record("the `version file-type data-size` line")?;
        let pos = r.rec_pos;
        let version = r.tok("the version")?;
        let version = match version {
            b"4.1" => MshVersion::Msh41,
            b"2.2" | b"2.1" | b"2.0" | b"2" => MshVersion::Msh22,
            other => return Err(PErr::Version(show(other))),
        };
        let file_type = r.int("file type")?;
        let data_size = r.int("data size")?;
        r.end_record()?;
        match file_type {
            0 => {}
            1 => {
                let ok = match version {
                    MshVersion::Msh41 => data_size == 4 || data_size == 8,
                    MshVersion::Msh22 => data_size == 8,
                };
                if !ok {
                    return Err(at(pos, format!("unsupported data size {data_size} for a binary file")));
                }
                let one_pos = r.pos;
                let one = r.take(4, "the binary endianness check (the integer 1)")?;
                r.big_endian = match one {
                    [1, 0, 0, 0] => false,
                    [0, 0, 0, 1] => true,
                    _ => {
                        return Err(at(
                            one_pos,
                            format!(
                                "binary endianness check: expected the integer 1, found bytes {one:02x?}"
                            ),
                        ))
                    }
                };
                r.binary = true;
                r.size_t = if data_size == 4 { 4 } else { 8 };
            }
            _ => return Err(at(pos, format!("bad file type {file_type}: expected 0 (ASCII) or 1 (binary)"))),
        }
        r.expect_end("MeshFormat")?;
        self.version = Some(version);
        Ok(())
    }

    fn physical_names(&mut self) -> PResult<()> {
        let r = &mut self.r;
        r.ascii_record("the number of physical names")?;
        let n = r.size("number of physical names")?;
        r.end_record()?;
        let mut names = Vec::with_capacity(r.capacity(n, 8));
        for _ in 0..n {
            let (start, line) = r.content_line("a physical name")?;
            let bad = |m: &str| at(start, format!("bad physical name line `{}`: {m}", show(line)));
            let (dim, rest) = split_token(line);
            let dim = parse_token::<usize>(dim).filter(|&d| d <= 3);
            let dim = dim.ok_or_else(|| bad("expected `dimension tag \"name\"` with dimension 0 to 3"))?;
            let (tag, rest) = split_token(rest);
            let tag = parse_token::<i32>(tag).ok_or_else(|| bad("bad physical tag"))?;
            let name = match rest {
                [b'"', inner @ .., b'"'] => inner,
                _ if !rest.is_empty() && !rest.contains(&b'"') => rest,
                _ => return Err(bad("the name must be in double quotes")),
            };
            let name = std::str::from_utf8(name).map_err(|_| bad("the name is not valid UTF-8"))?;
            if names.iter().any(|p: &PhysicalName| p.dim == dim && p.tag == tag) {
                return Err(at(start, format!("physical group (dimension {dim}, tag {tag}) is named twice")));
            }
            names.push(PhysicalName { dim, tag, name: name.to_string() });
        }
        r.expect_end("PhysicalNames")?;
        self.physical_names = Some(names);
        Ok(())
    }

    fn entities41(&mut self) -> PResult<()> {
        let r = &mut self.r;
        r.record("the `$Entities` counts")?;
        let mut counts = [0u64; 4];
        for (d, c) in counts.iter_mut().enumerate() {
            *c = r.size(
                ["number of points", "number of curves", "number of surfaces", "number of volumes"][d],
            )?;
        }
        r.end_record()?;
        let mut map = HashMap::new();
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                r.record("an entity")?;
                let pos = r.rec_pos;
                let tag = r.int("entity tag")?;
                for _ in 0..(if dim == 0 { 3 } else { 6 }) {
                    r.double("entity coordinate")?;
                }
                let n_phys = r.size("number of physical tags")?;
                let mut phys = Vec::new();
                for _ in 0..n_phys {
                    phys.push(r.int("physical tag")?);
                }
                if dim > 0 {
                    let n_bounding = r.size("number of bounding entities")?;
                    for _ in 0..n_bounding {
                        r.int("bounding entity tag")?;
                    }
                }
                r.end_record()?;
                if map.insert((dim, tag), phys).is_some() {
                    return Err(at(pos, format!("entity (dimension {dim}, tag {tag}) is defined twice")));
                }
            }
        }
        r.expect_end("Entities")?;
        self.entities = Some(map);
        Ok(())
    }

    fn add_node(&mut self, pos: usize, tag: u64) -> PResult<()> {
        let index = self.node_tags.len();
        if self.node_index.insert(tag, index).is_some() {
            return Err(at(pos, format!("node tag {tag} is defined twice")));
        }
        self.node_tags.push(tag);
        Ok(())
    }

    fn push_coords(&mut self, pos: usize, x: [f64; 3]) -> PResult<()> {
        if x.iter().any(|v| !v.is_finite()) {
            return Err(at(pos, format!("node coordinates {x:?} are not finite")));
        }
        self.nodes.push(x);
        Ok(())
    }

    fn nodes41(&mut self) -> PResult<()> {
        self.r.record("the `$Nodes` header `numEntityBlocks numNodes minNodeTag maxNodeTag`")?;
        let header = self.r.rec_pos;
        let n_blocks = self.r.size("number of node blocks")?;
        let n_nodes = self.r.size("number of nodes")?;
        self.r.size("minimum node tag")?;
        self.r.size("maximum node tag")?;
        self.r.end_record()?;
        let cap = self.r.capacity(n_nodes, 8);
        self.nodes.reserve(cap);
        self.node_tags.reserve(cap);
        let mut total: u64 = 0;
        for _ in 0..n_blocks {
            self.r.record("a node block header `entityDim entityTag parametric numNodesInBlock`")?;
            let pos = self.r.rec_pos;
            let dim = self.r.int("entity dimension")?;
            self.r.int("entity tag")?;
            let parametric = self.r.int("parametric flag")?;
            let n = self.r.size("number of nodes in the block")?;
            self.r.end_record()?;
            if !(0..=3).contains(&dim) {
                return Err(at(pos, format!("bad entity dimension {dim}: expected 0 to 3")));
            }
            let extra = match parametric {
                0 => 0,
                1 => dim as usize,
                _ => return Err(at(pos, format!("bad parametric flag {parametric}: expected 0 or 1"))),
            };
            for _ in 0..n {
                self.r.record("a node tag")?;
                let pos = self.r.value_pos();
                let tag = self.r.size("node tag")?;
                self.r.end_record()?;
                self.add_node(pos, tag)?;
            }
            for _ in 0..n {
                self.r.record("node coordinates `x y z`")?;
                let pos = self.r.value_pos();
                let x = [self.r.double("x")?, self.r.double("y")?, self.r.double("z")?];
                for _ in 0..extra {
                    self.r.double("parametric coordinate")?;
                }
                self.r.end_record()?;
                self.push_coords(pos, x)?;
            }
            total = total.saturating_add(n);
        }
        if total != n_nodes {
            return Err(at(
                header,
                format!("the `$Nodes` header announces {n_nodes} nodes, but its blocks hold {total}"),
            ));
        }
        self.r.expect_end("Nodes")
    }

    fn nodes22(&mut self) -> PResult<()> {
        self.r.ascii_record("the number of nodes")?;
        let n = self.r.size("number of nodes")?;
        self.r.end_record()?;
        let cap = self.r.capacity(n, 8);
        self.nodes.reserve(cap);
        self.node_tags.reserve(cap);
        for _ in 0..n {
            self.r.record("a node line `id x y z`")?;
            let pos = self.r.value_pos();
            let tag = if self.r.in_ascii() {
                self.r.size("node id")?
            } else {
                let id = self.r.int("node id")?;
                u64::try_from(id).map_err(|_| at(pos, format!("negative node id {id}")))?
            };
            let x = [self.r.double("x")?, self.r.double("y")?, self.r.double("z")?];
            self.r.end_record()?;
            self.add_node(pos, tag)?;
            self.push_coords(pos, x)?;
        }
        self.r.expect_end("Nodes")
    }

    fn node(&mut self, element: u64, binary_int: bool) -> PResult<usize> {
        let pos = self.r.value_pos();
        let tag = if binary_int {
            let id = self.r.int("node id")?;
            u64::try_from(id).map_err(|_| at(pos, format!("element {element}: negative node id {id}")))?
        } else {
            self.r.size("node tag")?
        };
        self.node_index.get(&tag).copied().ok_or_else(|| {
            at(pos, format!("element {element} refers to node {tag}, which `$Nodes` does not define"))
        })
    }

    fn elements41(&mut self) -> PResult<Vec<ElementBlock>> {
        self.r.record("the `$Elements` header `numEntityBlocks numElements minElementTag maxElementTag`")?;
        let header = self.r.rec_pos;
        let n_blocks = self.r.size("number of element blocks")?;
        let n_elements = self.r.size("number of elements")?;
        self.r.size("minimum element tag")?;
        self.r.size("maximum element tag")?;
        self.r.end_record()?;
        let mut blocks = Vec::with_capacity(self.r.capacity(n_blocks, 16));
        let mut total: u64 = 0;
        for _ in 0..n_blocks {
            self.r.record("an element block header `entityDim entityTag elementType numElementsInBlock`")?;
            let pos = self.r.rec_pos;
            let dim = self.r.int("entity dimension")?;
            let entity_tag = self.r.int("entity tag")?;
            let element_type = self.r.int("element type")?;
            let n = self.r.size("number of elements in the block")?;
            self.r.end_record()?;
            let dim = usize::try_from(dim)
                .ok()
                .filter(|&d| d <= 3)
                .ok_or_else(|| at(pos, format!("bad entity dimension {dim}: expected 0 to 3")))?;
            let info = element_info(element_type)
                .ok_or_else(|| at(pos, format!("unknown element type {element_type}")))?;
            if info.dim != dim {
                return Err(at(
                    pos,
                    format!(
                        "element type {element_type} ({}) has dimension {}, but the block's entity has dimension {dim}",
                        element_type_name(element_type),
                        info.dim
                    ),
                ));
            }
            if info.nodes.is_none() && self.r.binary {
                return Err(at(
                    pos,
                    format!(
                        "element type {element_type} ({}) has no fixed number of nodes and cannot be read from a binary file",
                        element_type_name(element_type)
                    ),
                ));
            }
            let per = info.nodes.unwrap_or(0);
            let mut block = ElementBlock {
                dim,
                entity_tag,
                element_type,
                physical_tags: Vec::new(),
                element_tags: Vec::with_capacity(self.r.capacity(n, 4 * (per + 1))),
                nodes_per_element: per,
                connectivity: Vec::new(),
            };
            block.connectivity.reserve(self.r.capacity(n.saturating_mul(per as u64), 4));
            for _ in 0..n {
                self.r.record("an element line `elementTag nodeTag …`")?;
                let tag = self.r.size("element tag")?;
                match info.nodes {
                    Some(k) => {
                        if self.r.in_ascii() && self.r.tokens_left() != k {
                            return Err(at(
                                self.r.rec_pos,
                                format!(
                                    "element {tag} has {} nodes, but type {element_type} ({}) needs {k}",
                                    self.r.tokens_left(),
                                    element_type_name(element_type)
                                ),
                            ));
                        }
                        for _ in 0..k {
                            let i = self.node(tag, false)?;
                            block.connectivity.push(i);
                        }
                    }
                    None => self.r.skip_rest(),
                }
                self.r.end_record()?;
                block.element_tags.push(tag);
            }
            total = total.saturating_add(n);
            blocks.push(block);
            self.block_pos.push(pos);
        }
        if total != n_elements {
            return Err(at(
                header,
                format!(
                    "the `$Elements` header announces {n_elements} elements, but its blocks hold {total}"
                ),
            ));
        }
        self.r.expect_end("Elements")?;
        Ok(blocks)
    }

    fn elements22(&mut self) -> PResult<Vec<ElementBlock>> {
        self.r.ascii_record("the number of elements")?;
        let n = self.r.size("number of elements")?;
        self.r.end_record()?;
        let mut blocks: Vec<ElementBlock> = Vec::new();
        let mut nodes: Vec<usize> = Vec::new();
        if self.r.binary {
            let mut read: u64 = 0;
            while read < n {
                let pos = self.r.pos;
                self.r.record("an element header")?;
                let element_type = self.r.int("element type")?;
                let count = self.r.int("number of elements following")?;
                let n_tags = self.r.int("number of tags")?;
                let count =
                    u64::try_from(count).ok().filter(|&c| c > 0 && c <= n - read).ok_or_else(|| {
                        at(
                            pos,
                            format!("bad element header: {count} elements announced, {} remain", n - read),
                        )
                    })?;
                let n_tags =
                    usize::try_from(n_tags).map_err(|_| at(pos, format!("bad number of tags {n_tags}")))?;
                let info = element_info(element_type)
                    .ok_or_else(|| at(pos, format!("unknown element type {element_type}")))?;
                let k = info.nodes.ok_or_else(|| {
                    at(
                        pos,
                        format!(
                            "element type {element_type} ({}) has no fixed number of nodes and cannot be read from a binary file",
                            element_type_name(element_type)
                        ),
                    )
                })?;
                for _ in 0..count {
                    let id_pos = self.r.pos;
                    let id = self.r.int("element id")?;
                    let id =
                        u64::try_from(id).map_err(|_| at(id_pos, format!("negative element id {id}")))?;
                    let mut physical = 0;
                    let mut entity = 0;
                    for t in 0..n_tags {
                        let v = self.r.int("element tag")?;
                        match t {
                            0 => physical = v,
                            1 => entity = v,
                            _ => {}
                        }
                    }
                    nodes.clear();
                    for _ in 0..k {
                        nodes.push(self.node(id, true)?);
                    }
                    push22(&mut blocks, info, element_type, physical, entity, id, &nodes);
                }
                read += count;
            }
        } else {
            for _ in 0..n {
                self.r.record("an element line `id type numTags tag … node …`")?;
                let pos = self.r.rec_pos;
                let id = self.r.size("element id")?;
                let element_type = self.r.int("element type")?;
                let n_tags = self.r.size("number of tags")?;
                let info = element_info(element_type)
                    .ok_or_else(|| at(pos, format!("unknown element type {element_type}")))?;
                let mut physical = 0;
                let mut entity = 0;
                for t in 0..n_tags {
                    let v = self.r.int("element tag")?;
                    match t {
                        0 => physical = v,
                        1 => entity = v,
                        _ => {}
                    }
                }
                nodes.clear();
                match info.nodes {
                    Some(k) => {
                        if self.r.tokens_left() != k {
                            return Err(at(
                                pos,
                                format!(
                                    "element {id} has {} nodes, but type {element_type} ({}) needs {k}",
                                    self.r.tokens_left(),
                                    element_type_name(element_type)
                                ),
                            ));
                        }
                        for _ in 0..k {
                            nodes.push(self.node(id, false)?);
                        }
                    }
                    None => self.r.skip_rest(),
                }
                self.r.end_record()?;
                push22(&mut blocks, info, element_type, physical, entity, id, &nodes);
            }
        }
        self.r.expect_end("Elements")?;
        Ok(blocks)
    }
}

/// Appends a MSH 2.2 element to the last block if it matches, else to a new block.
fn push22(
    blocks: &mut Vec<ElementBlock>,
    info: ElementInfo,
    element_type: i32,
    physical: i32,
    entity: i32,
    id: u64,
    nodes: &[usize],
) {
    let physical_tags = if physical == 0 { Vec::new() } else { vec![physical] };
    let matches = blocks.last().is_some_and(|b| {
        b.element_type == element_type && b.entity_tag == entity && b.physical_tags == physical_tags
    });
    if !matches {
        blocks.push(ElementBlock {
            dim: info.dim,
            entity_tag: entity,
            element_type,
            physical_tags,
            element_tags: Vec::new(),
            nodes_per_element: info.nodes.unwrap_or(0),
            connectivity: Vec::new(),
        });
    }
    if let Some(b) = blocks.last_mut() {
        b.element_tags.push(id);
        b.connectivity.extend_from_slice(nodes);
    }
}

// ---------------------------------------------------------------------------------------------
// Mapping to synovia bodies
// ---------------------------------------------------------------------------------------------

/// A body under construction.
struct Body<const D: usize> {
    name: String,
    mesh: Mesh<D>,
    /// Index in [`GmshMesh::nodes`] → local node index.
    local: HashMap<usize, usize>,
    /// Sorted local node lists of the boundary facets.
    boundary: HashSet<[usize; D]>,
}

impl GmshMesh {
    /// Name of physical group `(dim, tag)`: its physical name, or `physical_<tag>`.
    pub fn physical_name(&self, dim: usize, tag: i32) -> String {
        self.physical_names
            .iter()
            .find(|p| p.dim == dim && p.tag == tag)
            .map_or_else(|| format!("physical_{tag}"), |p| p.name.clone())
    }

    /// Every physical group that has a name or elements, sorted by dimension and tag.
    pub fn physical_groups(&self) -> Vec<PhysicalGroup> {
        let mut count: HashMap<(usize, i32), usize> = HashMap::new();
        for p in &self.physical_names {
            count.entry((p.dim, p.tag)).or_insert(0);
        }
        for b in &self.element_blocks {
            let mut tags = b.physical_tags.clone();
            tags.sort_unstable();
            tags.dedup();
            for t in tags {
                *count.entry((b.dim, t)).or_insert(0) += b.len();
            }
        }
        let mut groups: Vec<PhysicalGroup> = count
            .into_iter()
            .map(|((dim, tag), n_elements)| PhysicalGroup {
                dim,
                tag,
                name: self.physical_name(dim, tag),
                named: self.physical_names.iter().any(|p| p.dim == dim && p.tag == tag),
                n_elements,
            })
            .collect();
        groups.sort_by_key(|g| (g.dim, g.tag));
        groups
    }

    /// The bodies of a `D`-dimensional mesh, with boundary-part kinds from
    /// [`default_boundary_kind`]; see the [module documentation](crate::gmsh) for the mapping.
    ///
    /// # Errors
    /// [`IoError::UnsupportedElement`], [`IoError::GmshMapping`], [`IoError::GmshBody`], and
    /// [`IoError::Mesh`] for `D` other than 2 or 3.
    pub fn bodies<const D: usize>(&self) -> Result<Vec<(String, Mesh<D>)>, IoError> {
        self.bodies_with_kinds::<D>(&default_boundary_kind)
    }

    /// As [`GmshMesh::bodies`], with the kind of each boundary part given by `kind_of(name)`.
    ///
    /// # Errors
    /// As [`GmshMesh::bodies`].
    pub fn bodies_with_kinds<const D: usize>(
        &self,
        kind_of: &dyn Fn(&str) -> BoundaryKind,
    ) -> Result<Vec<(String, Mesh<D>)>, IoError> {
        if D != 2 && D != 3 {
            return Err(MeshError::UnsupportedDimension(D).into());
        }
        let (cell_type, facet_type) = if D == 2 { (2, 1) } else { (4, 2) };
        let groups = self.physical_groups();
        let body_groups: Vec<&PhysicalGroup> = groups.iter().filter(|g| g.dim == D).collect();
        if body_groups.is_empty() {
            let kind = if D == 2 { "Surface" } else { "Volume" };
            return Err(IoError::GmshMapping(format!(
                "the mesh has no physical group of dimension {D} to make a body of \
                 (define e.g. `Physical {kind}(\"femur\") = {{1}};` in the .geo file)"
            )));
        }
        let mut bodies: Vec<Body<D>> = Vec::with_capacity(body_groups.len());
        for g in body_groups {
            if bodies.iter().any(|b| b.name == g.name) {
                return Err(IoError::GmshMapping(format!(
                    "two physical groups of dimension {D} are named `{}`",
                    g.name
                )));
            }
            bodies.push(self.body::<D>(g, cell_type)?);
        }
        for g in groups.iter().filter(|g| g.dim + 1 == D) {
            let facets = self.group_elements(g, facet_type, D)?; // D nodes per facet
            if facets.is_empty() {
                return Err(IoError::GmshMapping(format!(
                    "boundary physical group `{}` has no elements",
                    g.name
                )));
            }
            let mut matched = false;
            for body in &mut bodies {
                let local: Vec<Vec<usize>> = facets
                    .iter()
                    .filter_map(|(_, f)| {
                        let lf: Vec<usize> =
                            f.iter().map(|n| body.local.get(n).copied()).collect::<Option<_>>()?;
                        let mut key = [0usize; D];
                        for (k, &n) in key.iter_mut().zip(&lf) {
                            *k = n;
                        }
                        key.sort_unstable();
                        body.boundary.contains(&key).then_some(lf)
                    })
                    .collect();
                if local.is_empty() {
                    continue;
                }
                matched = true;
                body.mesh
                    .add_boundary_part_from_facets(&g.name, kind_of(&g.name), &local)
                    .map_err(|source| IoError::GmshBody { body: body.name.clone(), source })?;
            }
            if !matched {
                return Err(IoError::GmshMapping(format!(
                    "boundary physical group `{}` (dimension {}) lies on the boundary of no body",
                    g.name, g.dim
                )));
            }
        }
        Ok(bodies.into_iter().map(|b| (b.name, b.mesh)).collect())
    }

    /// The elements of group `g` (element tag, node indices), deduplicated by element tag and
    /// sorted by it; every element must be of type `wanted`, with `nodes` nodes.
    fn group_elements(
        &self,
        g: &PhysicalGroup,
        wanted: i32,
        nodes: usize,
    ) -> Result<Vec<(u64, Vec<usize>)>, IoError> {
        let mut out: Vec<(u64, Vec<usize>)> = Vec::new();
        let mut seen: HashSet<u64> = HashSet::new();
        for b in self.element_blocks.iter().filter(|b| b.dim == g.dim && b.physical_tags.contains(&g.tag)) {
            if b.element_type != wanted || b.nodes_per_element != nodes {
                return Err(IoError::UnsupportedElement {
                    element_type: b.element_type,
                    description: element_type_name(b.element_type),
                    group: g.name.clone(),
                });
            }
            for (e, &tag) in b.element_tags.iter().enumerate() {
                if seen.insert(tag) {
                    out.push((tag, b.element(e).to_vec()));
                }
            }
        }
        out.sort_by_key(|e| e.0);
        Ok(out)
    }

    fn body<const D: usize>(&self, g: &PhysicalGroup, cell_type: i32) -> Result<Body<D>, IoError> {
        let cells = self.group_elements(g, cell_type, D + 1)?;
        if cells.is_empty() {
            return Err(IoError::GmshMapping(format!(
                "physical group `{}` (dimension {D}) has no elements",
                g.name
            )));
        }
        let mut used: Vec<usize> = cells.iter().flat_map(|(_, c)| c.iter().copied()).collect();
        used.sort_unstable_by_key(|&i| (self.node_tags.get(i).copied().unwrap_or(u64::MAX), i));
        used.dedup();
        let local: HashMap<usize, usize> = used.iter().enumerate().map(|(l, &i)| (i, l)).collect();
        let coords: Vec<[f64; 3]> =
            used.iter().map(|&i| self.nodes.get(i).copied().unwrap_or([0.0; 3])).collect();
        if D == 2 {
            let scale = coords.iter().fold(0.0_f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
            if let Some((k, p)) = coords.iter().enumerate().find(|(_, p)| p[2].abs() > 1e-12 * scale) {
                let tag = used.get(k).and_then(|&i| self.node_tags.get(i)).copied().unwrap_or(0);
                return Err(IoError::GmshMapping(format!(
                    "body `{}`: node {tag} has z = {:e}, but a 2D mesh must lie in the plane z = 0",
                    g.name, p[2]
                )));
            }
        }
        let nodes: Vec<Point<D>> = coords.iter().map(|p| Point::<D>::from_fn(|k, _| p[k])).collect();
        let flat: Vec<usize> = cells
            .iter()
            .flat_map(|(_, c)| c.iter().map(|n| local.get(n).copied().unwrap_or(usize::MAX)))
            .collect();
        let (mesh, _flipped) = Mesh::new_with_repair(nodes, flat)
            .map_err(|source| IoError::GmshBody { body: g.name.clone(), source })?;
        let boundary = boundary_keys(&mesh);
        Ok(Body { name: g.name.clone(), mesh, local, boundary })
    }
}

/// Sorted node lists of the boundary facets of a mesh (faces of exactly one cell); the same set
/// as [`Mesh::boundary_facets`], without the orientation work.
fn boundary_keys<const D: usize>(mesh: &Mesh<D>) -> HashSet<[usize; D]> {
    let mut count: HashMap<[usize; D], u32> = HashMap::with_capacity(mesh.n_cells() * (D + 1));
    for cell in mesh.cells() {
        for opposite in 0..cell.len() {
            let mut key = [0usize; D];
            let others = cell.iter().enumerate().filter(|&(i, _)| i != opposite).map(|(_, &n)| n);
            for (k, n) in key.iter_mut().zip(others) {
                *k = n;
            }
            key.sort_unstable();
            *count.entry(key).or_insert(0) += 1;
        }
    }
    count.into_iter().filter(|&(_, c)| c == 1).map(|(k, _)| k).collect()
}
