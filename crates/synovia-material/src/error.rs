//! The error type of synovia-material.

use thiserror::Error;

/// Why a material could not be built: every variant names the offending value(s).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MaterialError {
    /// A Young's modulus `E ≤ 0` (all Young's moduli must satisfy `E > 0`).
    #[error("Young's modulus must be positive, got E = {e}")]
    NonPositiveYoungsModulus {
        /// The offending Young's modulus.
        e: f64,
    },

    /// A Poisson ratio outside the isotropic admissible range `−1 < ν < ½`.
    #[error("Poisson ratio must lie in (−1, ½), got ν = {nu}")]
    PoissonRatioOutOfRange {
        /// The offending Poisson ratio.
        nu: f64,
    },

    /// A shear modulus (`μ` or `G_a`) `≤ 0`.
    #[error("shear modulus must be positive, got {mu}")]
    NonPositiveShearModulus {
        /// The offending shear modulus.
        mu: f64,
    },

    /// Lamé parameters violating the admissibility condition (`3λ + 2μ > 0` in 3D,
    /// `λ + μ > 0` in plane strain).
    #[error("inadmissible Lame parameters lambda = {lambda}, mu = {mu}: {condition} must hold")]
    InadmissibleLame {
        /// First Lamé parameter `λ`.
        lambda: f64,
        /// Shear modulus `μ`.
        mu: f64,
        /// The violated condition, e.g. `"3λ + 2μ > 0"`.
        condition: &'static str,
    },

    /// A parameter or matrix entry is NaN or infinite.
    #[error("{what} must be finite (got NaN or infinity)")]
    NonFinite {
        /// Which parameter.
        what: &'static str,
    },

    /// A Voigt vector or matrix of the wrong size for the dimension.
    #[error("wrong Voigt size: expected {expected}, got {got}")]
    WrongVoigtSize {
        /// `voigt_len(D)`.
        expected: usize,
        /// The size given.
        got: usize,
    },

    /// A matrix that should be square is not.
    #[error("matrix must be square, got {rows}x{cols}")]
    NotSquare {
        /// Number of rows.
        rows: usize,
        /// Number of columns.
        cols: usize,
    },

    /// A stiffness matrix that is not symmetric (to relative tolerance `1e-10`).
    #[error("matrix is not symmetric: a[{i}][{j}] = {a_ij} but a[{j}][{i}] = {a_ji}")]
    NotSymmetric {
        /// Row of the first offending entry.
        i: usize,
        /// Column of the first offending entry.
        j: usize,
        /// `a[i][j]`.
        a_ij: f64,
        /// `a[j][i]`.
        a_ji: f64,
    },

    /// A stiffness matrix that is not positive definite.
    #[error("matrix is not positive definite: smallest eigenvalue {min_eigenvalue}")]
    NotPositiveDefinite {
        /// Smallest eigenvalue of the (symmetrised) matrix.
        min_eigenvalue: f64,
    },

    /// A viscosity matrix `C⁽¹⁾` that is not positive semi-definite.
    #[error("matrix is not positive semi-definite: smallest eigenvalue {min_eigenvalue}")]
    NotPositiveSemiDefinite {
        /// Smallest eigenvalue of the (symmetrised) matrix.
        min_eigenvalue: f64,
    },

    /// A mass density `ρ ≤ 0`.
    #[error("density must be positive, got rho = {rho}")]
    NonPositiveDensity {
        /// The offending density.
        rho: f64,
    },

    /// A damping coefficient `α < 0`.
    #[error("damping coefficient must be non-negative, got alpha = {alpha}")]
    NegativeDamping {
        /// The offending damping coefficient.
        alpha: f64,
    },

    /// A material axis of (near) zero length that cannot be normalised.
    #[error("material axis must be nonzero, got a vector of norm {norm}")]
    DegenerateAxis {
        /// Euclidean norm of the given axis.
        norm: f64,
    },

    /// A matrix that is not a proper rotation (`RᵀR = I`, `det R = 1`).
    #[error("not a proper rotation: max |RᵀR − I| = {orthogonality_defect}, det R = {det}")]
    NotARotation {
        /// `max |(RᵀR − I)_ij|`.
        orthogonality_defect: f64,
        /// `det R`.
        det: f64,
    },

    /// A spatial dimension other than 2 or 3.
    #[error("unsupported dimension {0} (only 2 and 3 are supported)")]
    UnsupportedDimension(usize),
}
