//! Voigt bookkeeping: sizes, index pairs, Bond rotation matrices and admissibility checks.

use nalgebra::SMatrix;

use crate::{MaterialError, VoigtMatrix, VoigtVector};

/// Relative tolerance of the symmetry check: `|a_ij − a_ji| ≤ 1e-10 · max_kl |a_kl|`.
pub(crate) const SYMMETRY_TOL: f64 = 1e-10;

/// Relative tolerance of the positive semi-definiteness check of `C⁽¹⁾`:
/// `λ_min ≥ −1e-12 · ‖C⁽¹⁾‖_F`.
pub(crate) const PSD_TOL: f64 = 1e-12;

/// Number of independent components of a symmetric `d × d` tensor: `d(d+1)/2`
/// (3 in 2D, 6 in 3D).
pub const fn voigt_len(d: usize) -> usize {
    d * (d + 1) / 2
}

/// The tensor index pairs `(i, j)` of the Voigt components, in Voigt order:
/// 2D `[(0,0), (1,1), (0,1)]` = `(xx, yy, xy)`,
/// 3D `[(0,0), (1,1), (2,2), (1,2), (0,2), (0,1)]` = `(xx, yy, zz, yz, xz, xy)`.
///
/// # Errors
/// [`MaterialError::UnsupportedDimension`] unless `d ∈ {2, 3}`.
pub fn voigt_pairs(d: usize) -> Result<&'static [(usize, usize)], MaterialError> {
    const P2: [(usize, usize); 3] = [(0, 0), (1, 1), (0, 1)];
    const P3: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)];
    match d {
        2 => Ok(&P2),
        3 => Ok(&P3),
        _ => Err(MaterialError::UnsupportedDimension(d)),
    }
}

/// The Bond matrix `M(R)` transforming Voigt **stresses** under the rotation
/// `x_global = R x_local`: `σ_global = M σ_local`, which is the Voigt form of
/// `σ'_ij = R_ik R_jl σ_kl`, i.e. for Voigt rows `I = (i, j)` and columns `K = (k, l)`
///
/// ```text
/// M_IK = R_ik R_jk                 (k = l)
/// M_IK = R_ik R_jl + R_il R_jk     (k ≠ l)
/// ```
///
/// Stiffnesses transform as `C_global = M C_local Mᵀ`. `R` is not checked here (any matrix
/// gives the Voigt form of `A σ Aᵀ`).
///
/// # Errors
/// [`MaterialError::UnsupportedDimension`] unless `D ∈ {2, 3}`.
pub fn bond_stress_matrix<const D: usize>(r: &SMatrix<f64, D, D>) -> Result<VoigtMatrix, MaterialError> {
    let pairs = voigt_pairs(D)?;
    let n = pairs.len();
    Ok(VoigtMatrix::from_fn(n, n, |row, col| {
        let (i, j) = pairs[row];
        let (k, l) = pairs[col];
        if k == l {
            r[(i, k)] * r[(j, k)]
        } else {
            r[(i, k)] * r[(j, l)] + r[(i, l)] * r[(j, k)]
        }
    }))
}

/// The Bond matrix `N(R)` transforming Voigt **engineering strains** under the rotation
/// `x_global = R x_local`: `ε_global = N ε_local`, the Voigt form of `e'_ij = R_ik R_jl e_kl`
/// with `γ = 2e` off the diagonal. For a rotation `N = M⁻ᵀ` ([`bond_stress_matrix`]), so the
/// energy `½ εᵀ C ε` is invariant when `C ↦ M C Mᵀ` and `ε ↦ N ε`:
///
/// ```text
/// N_IK = M_IK · s_I / s_K,   s = 1 on normal components, 2 on shear components
/// ```
///
/// # Errors
/// [`MaterialError::UnsupportedDimension`] unless `D ∈ {2, 3}`.
pub fn bond_strain_matrix<const D: usize>(r: &SMatrix<f64, D, D>) -> Result<VoigtMatrix, MaterialError> {
    let pairs = voigt_pairs(D)?;
    let m = bond_stress_matrix(r)?;
    let s = |idx: usize| {
        if pairs[idx].0 == pairs[idx].1 {
            1.0
        } else {
            2.0
        }
    };
    Ok(VoigtMatrix::from_fn(m.nrows(), m.ncols(), |row, col| m[(row, col)] * s(row) / s(col)))
}

/// The Mandel (Kelvin) form `C̃ = W C W` of a Voigt stiffness, `W = diag(1, …, 1, √2, …, √2)`
/// (`√2` on the shear components). `C̃` is the matrix of the stiffness tensor in an
/// orthonormal basis of symmetric tensors, so rotations act on it orthogonally
/// (`C̃ ↦ Q C̃ Qᵀ`, `Q = W M W⁻¹` orthogonal) and its eigenvalues, the Kelvin moduli, are
/// rotation invariant. (The eigenvalues of the Voigt matrix `C` itself are not.)
///
/// # Errors
/// [`MaterialError::NotSquare`] for a non-square matrix, and
/// [`MaterialError::UnsupportedDimension`] unless the size is 3 (2D) or 6 (3D).
pub fn mandel_form(c: &VoigtMatrix) -> Result<VoigtMatrix, MaterialError> {
    check_square(c)?;
    let pairs = match c.nrows() {
        3 => voigt_pairs(2)?,
        6 => voigt_pairs(3)?,
        n => return Err(MaterialError::UnsupportedDimension(n)),
    };
    let w = |idx: usize| {
        if pairs[idx].0 == pairs[idx].1 {
            1.0
        } else {
            std::f64::consts::SQRT_2
        }
    };
    Ok(VoigtMatrix::from_fn(c.nrows(), c.ncols(), |row, col| w(row) * c[(row, col)] * w(col)))
}

/// The smallest eigenvalue `λ_min` of the symmetric part `½(A + Aᵀ)` of a square matrix
/// (`+∞` for an empty matrix).
///
/// # Errors
/// [`MaterialError::NotSquare`], or [`MaterialError::NonFinite`] for NaN/∞ entries.
pub fn min_eigenvalue(a: &VoigtMatrix) -> Result<f64, MaterialError> {
    check_square(a)?;
    check_finite_matrix(a, "matrix entry")?;
    Ok(sym_eigenvalues(a).iter().copied().fold(f64::INFINITY, f64::min))
}

/// Checks that `C` is an admissible elasticity matrix: square, finite, symmetric
/// (`|C_ij − C_ji| ≤ 1e-10 · max|C_kl|`) and positive definite (`λ_min(C) > 0`, i.e. the energy
/// `½ εᵀ C ε > 0` for every strain `ε ≠ 0`; eigenvalues not above `n·ε_mach·max|λ|` count as
/// zero).
///
/// # Errors
/// [`MaterialError::NotSquare`], [`MaterialError::NonFinite`],
/// [`MaterialError::NotSymmetric`] (first offending `(i, j)`) or
/// [`MaterialError::NotPositiveDefinite`] (with `λ_min`).
pub fn check_admissible(c: &VoigtMatrix) -> Result<(), MaterialError> {
    check_square(c)?;
    check_finite_matrix(c, "stiffness matrix entry")?;
    check_symmetric(c)?;
    let eig = sym_eigenvalues(c);
    let min = eig.iter().copied().fold(f64::INFINITY, f64::min);
    let max_abs = eig.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let tol = c.nrows() as f64 * f64::EPSILON * max_abs;
    if min <= tol {
        return Err(MaterialError::NotPositiveDefinite { min_eigenvalue: min });
    }
    Ok(())
}

/// Square, finite, symmetric and positive semi-definite: `λ_min ≥ −1e-12 · ‖C‖_F`.
pub(crate) fn check_positive_semidefinite(c: &VoigtMatrix) -> Result<(), MaterialError> {
    check_square(c)?;
    check_finite_matrix(c, "viscosity matrix entry")?;
    check_symmetric(c)?;
    let min = sym_eigenvalues(c).iter().copied().fold(f64::INFINITY, f64::min);
    if min < -PSD_TOL * c.norm() {
        return Err(MaterialError::NotPositiveSemiDefinite { min_eigenvalue: min });
    }
    Ok(())
}

pub(crate) fn check_square(a: &VoigtMatrix) -> Result<(), MaterialError> {
    if a.nrows() != a.ncols() {
        return Err(MaterialError::NotSquare { rows: a.nrows(), cols: a.ncols() });
    }
    Ok(())
}

/// Checks that `a` is `n × n` with `n = expected`.
pub(crate) fn check_size(a: &VoigtMatrix, expected: usize) -> Result<(), MaterialError> {
    for got in [a.nrows(), a.ncols()] {
        if got != expected {
            return Err(MaterialError::WrongVoigtSize { expected, got });
        }
    }
    Ok(())
}

pub(crate) fn check_finite_matrix(a: &VoigtMatrix, what: &'static str) -> Result<(), MaterialError> {
    if a.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(MaterialError::NonFinite { what })
    }
}

pub(crate) fn check_finite(value: f64, what: &'static str) -> Result<f64, MaterialError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(MaterialError::NonFinite { what })
    }
}

fn check_symmetric(a: &VoigtMatrix) -> Result<(), MaterialError> {
    let scale = a.amax();
    let n = a.nrows();
    for i in 0..n {
        for j in (i + 1)..n {
            let (a_ij, a_ji) = (a[(i, j)], a[(j, i)]);
            if (a_ij - a_ji).abs() > SYMMETRY_TOL * scale {
                return Err(MaterialError::NotSymmetric { i, j, a_ij, a_ji });
            }
        }
    }
    Ok(())
}

/// `½(A + Aᵀ)`.
pub(crate) fn symmetrized(a: &VoigtMatrix) -> VoigtMatrix {
    (a + a.transpose()) * 0.5
}

fn sym_eigenvalues(a: &VoigtMatrix) -> VoigtVector {
    if a.nrows() == 0 {
        return VoigtVector::zeros(0);
    }
    nalgebra::SymmetricEigen::new(symmetrized(a)).eigenvalues
}

/// Inverse of a symmetric positive definite matrix (by Cholesky).
///
/// # Errors
/// [`MaterialError::NotPositiveDefinite`] when the factorisation fails.
pub(crate) fn spd_inverse(a: &VoigtMatrix) -> Result<VoigtMatrix, MaterialError> {
    match symmetrized(a).cholesky() {
        Some(ch) => Ok(symmetrized(&ch.inverse())),
        None => Err(MaterialError::NotPositiveDefinite {
            min_eigenvalue: sym_eigenvalues(a).iter().copied().fold(f64::INFINITY, f64::min),
        }),
    }
}

/// `C x`, or a vector of NaN (of the output size) when `x` has the wrong length.
pub(crate) fn apply(c: &VoigtMatrix, x: &VoigtVector) -> VoigtVector {
    if x.len() == c.ncols() {
        c * x
    } else {
        VoigtVector::from_element(c.nrows(), f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use nalgebra::{Matrix2, Matrix3, Rotation3, Vector3};

    #[test]
    fn voigt_lengths() {
        assert_eq!(voigt_len(1), 1);
        assert_eq!(voigt_len(2), 3);
        assert_eq!(voigt_len(3), 6);
        assert!(voigt_pairs(4).is_err());
    }

    #[test]
    fn bond_matrices_are_inverse_transposes() {
        let r: Matrix3<f64> =
            *Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(Vector3::new(1.0, -2.0, 0.5)), 0.7)
                .matrix();
        let m = bond_stress_matrix(&r).unwrap();
        let n = bond_strain_matrix(&r).unwrap();
        let prod = m.transpose() * n;
        assert!((prod - VoigtMatrix::identity(6, 6)).amax() < 1e-14);

        let (c, s) = (0.3_f64.cos(), 0.3_f64.sin());
        let r2 = Matrix2::new(c, -s, s, c);
        let m2 = bond_stress_matrix(&r2).unwrap();
        let n2 = bond_strain_matrix(&r2).unwrap();
        assert!((m2.transpose() * n2 - VoigtMatrix::identity(3, 3)).amax() < 1e-14);
    }

    #[test]
    fn bond_stress_matches_tensor_rotation() {
        let r: Matrix3<f64> = *Rotation3::from_euler_angles(0.2, -0.4, 1.1).matrix();
        let sigma = Matrix3::new(1.0, 0.4, -0.3, 0.4, -2.0, 0.7, -0.3, 0.7, 0.5);
        let rotated = r * sigma * r.transpose();
        let pairs = voigt_pairs(3).unwrap();
        let v = VoigtVector::from_iterator(6, pairs.iter().map(|&(i, j)| sigma[(i, j)]));
        let mv = bond_stress_matrix(&r).unwrap() * v;
        for (idx, &(i, j)) in pairs.iter().enumerate() {
            assert!((mv[idx] - rotated[(i, j)]).abs() < 1e-14);
        }
        // Strains: engineering shear.
        let ev = VoigtVector::from_iterator(
            6,
            pairs.iter().map(|&(i, j)| if i == j { sigma[(i, j)] } else { 2.0 * sigma[(i, j)] }),
        );
        let nv = bond_strain_matrix(&r).unwrap() * ev;
        for (idx, &(i, j)) in pairs.iter().enumerate() {
            let f = if i == j { 1.0 } else { 2.0 };
            assert!((nv[idx] - f * rotated[(i, j)]).abs() < 1e-14);
        }
    }

    #[test]
    fn apply_wrong_length_gives_nan() {
        let c = VoigtMatrix::identity(3, 3);
        let y = apply(&c, &VoigtVector::zeros(6));
        assert_eq!(y.len(), 3);
        assert!(y.iter().all(|v| v.is_nan()));
    }

    #[test]
    fn psd_accepts_zero_rejects_negative() {
        assert!(check_positive_semidefinite(&VoigtMatrix::zeros(3, 3)).is_ok());
        let mut c = VoigtMatrix::identity(3, 3);
        c[(2, 2)] = -1e-3;
        assert!(matches!(
            check_positive_semidefinite(&c),
            Err(MaterialError::NotPositiveSemiDefinite { .. })
        ));
        assert!(matches!(
            check_admissible(&VoigtMatrix::zeros(3, 3)),
            Err(MaterialError::NotPositiveDefinite { .. })
        ));
        assert!(matches!(
            check_admissible(&VoigtMatrix::zeros(3, 2)),
            Err(MaterialError::NotSquare { rows: 3, cols: 2 })
        ));
    }
}
