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
    /// An invalid argument (ordering, dof list, capacity).
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
}
