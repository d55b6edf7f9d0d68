//! The error type of the linear-algebra layer.

/// Errors of sparse matrices, factorisations and operator solves.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LinalgError {
    /// The matrix is not positive definite (a non-positive pivot in the Cholesky factorisation).
    #[error("the system matrix is not positive definite: non-positive pivot at (permuted) index {index}")]
    NotPositiveDefinite {
        /// Index of the pivot in the factor's (permuted) order.
        index: usize,
    },
    /// A sparse-matrix or factorisation failure (pattern, ordering, memory).
    #[error("sparse linear algebra failed: {0}")]
    Sparse(String),
    /// A vector or matrix of the wrong size.
    #[error("{what}: length {got}, expected {expected}")]
    Length {
        /// What had the wrong size.
        what: &'static str,
        /// The size it should have had.
        expected: usize,
        /// The size it had.
        got: usize,
    },
    /// The numeric factorisation would need more memory than is available (checked after the
    /// symbolic analysis, before anything large is allocated; [`crate::cholesky::MemoryEstimate`]).
    #[error(
        "the factorisation needs ≈ {needed_gib:.2} GiB ({factor_entries} factor entries for {dofs} unknowns), {available_gib:.2} GiB {origin}; reduce the mesh size ({dofs} DOFs now), coarsen the mesh far from the contact, use the METIS ordering in 3D (`solver.ordering = \"metis\"`), or run on a machine with more memory"
    )]
    OutOfMemory {
        /// Estimated bytes needed by the numeric factorisation, GiB.
        needed_gib: f64,
        /// Bytes available, GiB.
        available_gib: f64,
        /// Where the available figure comes from (`available (MemAvailable of /proc/meminfo)`,
        /// `allowed by SYNOVIA_MEMORY_LIMIT_MB`, `allowed by the memory limit`).
        origin: String,
        /// Unknowns of the system.
        dofs: usize,
        /// Stored entries of the factor `L`.
        factor_entries: usize,
    },
    /// An invalid argument (ordering, dof list, capacity).
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
}
