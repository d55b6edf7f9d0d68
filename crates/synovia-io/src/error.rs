//! The error type of every synovia-io operation.

use std::path::PathBuf;

use synovia_mesh::{MeshError, SurfaceError};
use thiserror::Error;

/// Everything that can go wrong when writing or reading VTK XML files.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IoError {
    /// The operating system refused a file operation.
    #[error("I/O error on `{}`: {source}", path.display())]
    Io {
        /// The file or directory concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A field has the wrong number of values for its mesh and component count.
    #[error(
        "field `{name}` has {got} values, but {expected} are needed \
         (components × number of points or cells)"
    )]
    FieldLength {
        /// Field name.
        name: String,
        /// Number of values required.
        expected: usize,
        /// Number of values given.
        got: usize,
    },
    /// A value is NaN or infinite (ParaView cannot handle such data sensibly).
    #[error("`{name}` has a non-finite value (NaN or ±∞) at flat index {index}")]
    NonFinite {
        /// Field name (or `"time"` for a time step).
        name: String,
        /// Flat index into the field's values (or the time-step index).
        index: usize,
    },
    /// A field is ill-formed: empty name, zero components, duplicate or reserved name.
    #[error("invalid field `{name}`: {reason}")]
    InvalidField {
        /// Field name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A piece does not carry the same fields as the first piece of the file (VTK requires
    /// every piece of one file to have the same arrays).
    #[error("piece {piece} does not match the fields of piece 0: {reason}")]
    InconsistentPieces {
        /// Index of the offending piece.
        piece: usize,
        /// What differs.
        reason: String,
    },
    /// A data array exceeds the 4 GiB that a `UInt32` binary header can describe.
    #[error("array `{name}` has {bytes} bytes, more than a UInt32 binary header can describe; use Encoding::Ascii")]
    ArrayTooLarge {
        /// Array name.
        name: String,
        /// Size in bytes.
        bytes: usize,
    },
    /// A path cannot be written into an XML file because it is not valid UTF-8.
    #[error("path `{}` is not valid UTF-8", path.display())]
    NonUtf8Path {
        /// The path.
        path: PathBuf,
    },
    /// A time series got a time that is not larger than the previous one.
    #[error("time {time} does not follow the previous time step {previous}")]
    TimeNotIncreasing {
        /// Previous time.
        previous: f64,
        /// Offending time.
        time: f64,
    },
    /// A time-series name is unusable as a file-name stem.
    #[error("invalid series name `{name}`: {reason}")]
    InvalidName {
        /// The name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A file read back is not a well-formed file of the kind this crate writes.
    #[error("cannot parse `{}`: {message}", path.display())]
    Parse {
        /// The file (or `<string>` for in-memory input).
        path: PathBuf,
        /// What is wrong, with the byte position where known.
        message: String,
    },
    /// A piece read back holds a cell of another type than the mesh requested needs.
    #[error("cell {cell} has VTK type {found}, expected {expected}")]
    CellType {
        /// Cell index.
        cell: usize,
        /// The VTK type required (5 triangle, 10 tetrahedron).
        expected: u8,
        /// The VTK type found.
        found: u8,
    },
    /// A piece read back does not form a valid [`synovia_mesh::Mesh`].
    #[error("piece does not form a valid mesh: {0}")]
    Mesh(#[from] MeshError),
    /// A Gmsh `.msh` file uses a format version this crate cannot read.
    #[error(
        "`{}`: unsupported Gmsh MSH format version {version}; synovia reads MSH 4.1 and 2.2 \
         (ASCII or binary): re-export with `gmsh -format msh41` (or `msh22`)",
        path.display()
    )]
    MshVersion {
        /// The file (or `<bytes>` for in-memory input).
        path: PathBuf,
        /// The version as written in the file's `$MeshFormat` section.
        version: String,
    },
    /// A Gmsh physical group that synovia maps (a body or a boundary part) contains an element
    /// type other than the P1 simplex of its dimension.
    #[error(
        "unsupported element type {element_type} ({description}) in physical group `{group}`; \
         synovia uses P1 simplices"
    )]
    UnsupportedElement {
        /// The Gmsh element type number (e.g. 9 for the 6-node triangle).
        element_type: i32,
        /// Human-readable description of the type (e.g. `6-node triangle`).
        description: String,
        /// Name of the physical group.
        group: String,
    },
    /// A Gmsh mesh cannot be turned into synovia bodies: no physical group of the requested
    /// dimension, a boundary group on no body's boundary, a 2D mesh outside the plane `z = 0`,
    /// duplicate body names.
    #[error("Gmsh mesh cannot be mapped to synovia bodies: {0}")]
    GmshMapping(String),
    /// The cells (or boundary facets) of a Gmsh physical group do not form a valid
    /// [`synovia_mesh::Mesh`] (e.g. a degenerate cell).
    #[error("Gmsh body `{body}` does not form a valid mesh: {source}")]
    GmshBody {
        /// Name of the body (its physical group).
        body: String,
        /// The mesh error.
        source: MeshError,
    },
    /// The triangles of an STL file do not form a valid
    /// [`synovia_mesh::TriangleSurface`] (degenerate triangle, non-finite vertex, …).
    #[error("STL file `{}`: {source}", path.display())]
    Surface {
        /// The file.
        path: PathBuf,
        /// The surface error.
        source: SurfaceError,
    },
}

impl IoError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        IoError::Io { path: path.into(), source }
    }
    pub(crate) fn parse(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        IoError::Parse { path: path.into(), message: message.into() }
    }
}
