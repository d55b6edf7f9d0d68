//! Errors of model set-up, assembly and the elastic solve.

use thiserror::Error;

use synovia_material::MaterialError;
use synovia_mesh::MeshError;

/// Everything that can go wrong between a model description and its elastic solution.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FemError {
    /// A mesh error (invalid geometry, unknown boundary part, …).
    #[error("mesh of body `{body}`: {source}")]
    Mesh {
        /// Body name.
        body: String,
        /// The underlying error.
        #[source]
        source: MeshError,
    },
    /// A material error (non-physical parameters, …).
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// A body index or name does not exist.
    #[error("no body `{0}` in the model")]
    UnknownBody(String),
    /// Two bodies have the same name.
    #[error("two bodies are called `{0}`")]
    DuplicateBody(String),
    /// The model has no bodies.
    #[error("the model has no bodies")]
    NoBodies,
    /// A boundary part of kind Prescribed or Traction has no data attached.
    #[error("body `{body}`, boundary part `{part}` is of kind {kind} but no data was given for it (missing boundary data)")]
    MissingBoundaryData {
        /// Body name.
        body: String,
        /// Part name.
        part: String,
        /// Kind of the part.
        kind: String,
    },
    /// Data was given for a part whose kind does not take it.
    #[error("body `{body}`, boundary part `{part}` is of kind {kind}; it cannot take {given} (re-tag the part with Mesh::set_part_kind)")]
    BoundaryKindMismatch {
        /// Body name.
        body: String,
        /// Part name.
        part: String,
        /// Kind of the part.
        kind: String,
        /// What was given.
        given: &'static str,
    },
    /// A function of the problem data (load, prescribed displacement) returned NaN or ∞.
    #[error("{what} is not finite at x = {}, t = {t}", fmt_point(x))]
    NonFiniteData {
        /// Which data.
        what: String,
        /// Where.
        x: Vec<f64>,
        /// When.
        t: f64,
    },
    /// Two constraints on the same node contradict each other (e.g. clamped and prescribed to a
    /// non-zero value).
    #[error("body `{body}`, node {node}: constraints contradict each other (residual {residual:e})")]
    ConflictingConstraints {
        /// Body name.
        body: String,
        /// Node index in the body's mesh.
        node: usize,
        /// Size of the contradiction.
        residual: f64,
    },
    /// Nodes of a tied (bonded) interface have no partner at the same position.
    #[error("{0}")]
    UnmatchedInterface(Box<UnmatchedInterface>),
    /// Some bodies are not held against rigid motion (docs/model.md §4): the elastic problem is
    /// semi-coercive and its stiffness matrix singular.
    #[error("bodies {} are semi-coercive: {free_modes} rigid-body mode(s) are not restrained by Dirichlet or symmetry data; add boundary conditions or solve it as a contact problem", fmt_names(bodies))]
    SemiCoercive {
        /// Names of the bodies of the unrestrained component.
        bodies: Vec<String>,
        /// Number of unrestrained rigid modes.
        free_modes: usize,
    },
    /// The material is nonlinear; the linear elastic solve needs a constant stiffness.
    #[error("body `{body}`: material `{material}` is nonlinear; the linear elastic solve needs Material::linear_stiffness")]
    NonlinearMaterial {
        /// Body name.
        body: String,
        /// Material name.
        material: String,
    },
    /// A cell could not be evaluated by a nonlinear solve: `det F ≤ 0` (an inverted element) or
    /// a non-finite stress from its material.
    #[error("body `{body}`, cell {cell}: the element is inverted or its material gave no finite stress (det F = {det_f:e}); reduce the load step")]
    InvertedElement {
        /// Body name.
        body: String,
        /// Cell index.
        cell: usize,
        /// `det F` of the cell (1 for small strain).
        det_f: f64,
    },
    /// The material stiffness has the wrong size for the dimension.
    #[error("body `{body}`: material stiffness is {got}×{got}, expected {expected}×{expected}")]
    MaterialSize {
        /// Body name.
        body: String,
        /// Expected Voigt size.
        expected: usize,
        /// Actual size.
        got: usize,
    },
    /// A failure of the linear algebra (factorisation, solve; e.g. a matrix that is not
    /// positive definite).
    #[error(transparent)]
    Linalg(#[from] synovia_linalg::LinalgError),
    /// A sparse-matrix or factorisation failure that is not a numerical one (memory, sizes).
    #[error("sparse linear algebra failed: {0}")]
    Sparse(String),
    /// A vector given to the library has the wrong length.
    #[error("{what}: length {got}, expected {expected}")]
    Length {
        /// Which vector.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A parameter is out of its domain.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
}

/// Details of [`FemError::UnmatchedInterface`].
#[derive(Debug, Clone, PartialEq, Error)]
#[error(
    "tie {tie} (bonded interface `{body_a}:{part_a}` – `{body_b}:{part_b}`): the nodes of the two parts do not coincide: {} node(s) of `{body_a}:{part_a}` and {} of `{body_b}:{part_b}` have no partner at the same position{}; the largest distance to the nearest node of the other part is {max_distance:.4e}; tied parts need matching nodes (mesh them conformingly, or use a contact pair)",
    unmatched_a.len(),
    unmatched_b.len(),
    example.as_ref().map(|(b, n, x)| format!(" (e.g. node {n} of `{b}` at {})", crate::error::fmt_point(x))).unwrap_or_default()
)]
pub struct UnmatchedInterface {
    /// Index of the tie in the model (0-based, in the order the ties were added).
    pub tie: usize,
    /// The largest distance of an unmatched node to the nearest node of the other part.
    pub max_distance: f64,
    /// The unmatched node farthest from the other part: body name, mesh index, coordinates.
    pub example: Option<(String, usize, Vec<f64>)>,
    /// First body.
    pub body_a: String,
    /// First part.
    pub part_a: String,
    /// Second body.
    pub body_b: String,
    /// Second part.
    pub part_b: String,
    /// Unmatched nodes of the first body (mesh indices).
    pub unmatched_a: Vec<usize>,
    /// Unmatched nodes of the second body (mesh indices).
    pub unmatched_b: Vec<usize>,
}

/// A point as `(x, y[, z])` with 6 significant digits, for messages.
pub fn fmt_point(x: &[f64]) -> String {
    let parts: Vec<String> = x.iter().map(|v| format!("{v:.6}")).collect();
    format!("({})", parts.join(", "))
}

/// Names as `` `a`, `b` ``, for messages.
pub fn fmt_names(names: &[String]) -> String {
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}
