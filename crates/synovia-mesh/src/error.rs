//! Errors of mesh construction, validation and queries.

use thiserror::Error;

/// Everything that can be wrong with a mesh or a request on it.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum MeshError {
    /// Only 2D (triangles) and 3D (tetrahedra) are supported.
    #[error("unsupported spatial dimension {0}: synovia supports D = 2 (triangles) and D = 3 (tetrahedra)")]
    UnsupportedDimension(usize),
    /// A node coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate (NaN or ±∞)")]
    NonFiniteNode {
        /// Index of the offending node.
        node: usize,
    },
    /// The flat cell array does not hold a whole number of cells.
    #[error("cell array has length {len}, not a multiple of {per_cell} nodes per cell")]
    RaggedCells {
        /// Length of the array.
        len: usize,
        /// Nodes per cell (`D + 1`).
        per_cell: usize,
    },
    /// A cell refers to a node that does not exist.
    #[error("cell {cell} refers to node {node}, but the mesh has {n_nodes} nodes")]
    NodeOutOfRange {
        /// Cell index.
        cell: usize,
        /// The bad node index.
        node: usize,
        /// Number of nodes.
        n_nodes: usize,
    },
    /// A cell lists the same node twice.
    #[error("cell {cell} repeats node {node}")]
    RepeatedNode {
        /// Cell index.
        cell: usize,
        /// The repeated node.
        node: usize,
    },
    /// A cell has (numerically) zero measure.
    #[error("cell {cell} is degenerate: |det| = {det:e} relative to its size (zero-measure element)")]
    DegenerateCell {
        /// Cell index.
        cell: usize,
        /// Relative determinant `det / h^D`.
        det: f64,
    },
    /// A cell is inverted (negative orientation). `Mesh::new_with_repair` flips such cells.
    #[error("cell {cell} is inverted (negative orientation, relative det = {det:e}); use Mesh::new_with_repair to flip it")]
    InvertedCell {
        /// Cell index.
        cell: usize,
        /// Relative determinant `det / h^D` (negative).
        det: f64,
    },
    /// A node belongs to no cell (its displacement would be undetermined).
    #[error("node {node} belongs to no cell (its displacement would be undetermined); remove it from the node list")]
    UnusedNode {
        /// Node index.
        node: usize,
    },
    /// Two cells overlap: they share a facet on the same side of it, or a facet is shared by
    /// more than two cells (a duplicated or folded cell).
    #[error("cells {cell} and {other} overlap across the facet with nodes {facet:?} ({}; a facet may be shared by at most two cells, one on each side)", if *more_than_two { "the facet already has two cells" } else { "a duplicated or folded cell" })]
    OverlappingCells {
        /// The later cell.
        cell: usize,
        /// The first cell with that facet.
        other: usize,
        /// The shared facet's nodes (sorted).
        facet: Vec<usize>,
        /// `true` if the facet was already shared by two cells.
        more_than_two: bool,
    },
    /// The mesh has no cells.
    #[error("mesh has no cells")]
    Empty,
    /// No boundary part has the given name.
    #[error("no boundary part named `{0}`")]
    UnknownPart(String),
    /// A boundary part with this name exists already.
    #[error("a boundary part named `{0}` exists already")]
    DuplicatePart(String),
    /// A boundary selection matched no facet.
    #[error("boundary part `{0}` selects no boundary facet")]
    EmptyPart(String),
    /// A facet given for a boundary part is not a boundary facet of the mesh.
    #[error("boundary part `{part}`: facet {facet:?} is not a boundary facet of the mesh")]
    NotABoundaryFacet {
        /// Part name.
        part: String,
        /// The node list of the facet.
        facet: Vec<usize>,
    },
    /// A generator was called with invalid parameters.
    #[error("invalid generator parameter: {0}")]
    InvalidParameter(String),
    /// Refinement produced a boundary facet that lies in no boundary facet of the input mesh
    /// (an internal inconsistency, reported instead of a panic).
    #[error(
        "refinement produced boundary facet {facet:?}, which lies in no boundary facet of the input mesh"
    )]
    RefinementInconsistent {
        /// Node list of the new facet.
        facet: Vec<usize>,
    },
}
