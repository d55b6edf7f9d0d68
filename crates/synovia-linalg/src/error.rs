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
        "the factorisation needs ≈ {} ({factor_entries} factor entries for {dofs} unknowns), {} {origin}; reduce the mesh size ({dofs} DOFs now), coarsen the mesh far from the contact, use the METIS ordering in 3D (`solver.ordering = \"metis\"`), or run on a machine with more memory",
        fmt_bytes(*needed),
        fmt_bytes(*available)
    )]
    OutOfMemory {
        /// Estimated bytes needed by the numeric factorisation.
        needed: u64,
        /// Bytes available.
        available: u64,
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

/// Bytes as `1.23 GiB`, `4.5 MiB` or `12 KiB`, for messages.
pub fn fmt_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    const K: f64 = 1024.0;
    if b >= K * K * K {
        format!("{:.2} GiB", b / (K * K * K))
    } else if b >= K * K {
        format!("{:.1} MiB", b / (K * K))
    } else {
        format!("{:.0} KiB", (b / K).ceil())
    }
}
