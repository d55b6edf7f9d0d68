//! [`LinearElastic`]: the one type behind every linear material, `σ = C ε`.

use nalgebra::{SMatrix, Vector3};

use crate::voigt::{apply, check_finite_matrix, check_size, spd_inverse, symmetrized, voigt_pairs};
use crate::{
    bond_stress_matrix, check_admissible, mandel_form, voigt_len, IsotropicParameters, Material,
    MaterialError, TransverseIsotropy, VoigtMatrix, VoigtVector,
};

/// Tolerance on `max |RᵀR − I|` accepted by [`LinearElastic::rotated`].
const ROTATION_TOL: f64 = 1e-10;

/// The material symmetry a [`LinearElastic`] was built with (metadata; the stiffness matrix
/// is authoritative).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Symmetry {
    /// `C = 0` ([`LinearElastic::zero`], e.g. "no viscosity" in [`crate::KelvinVoigt`]).
    Zero,
    /// Isotropic: `σ = λ tr(e) I + 2μ e`.
    Isotropic(IsotropicParameters),
    /// Transversely isotropic about the unit `axis` (global frame; `z = 0` in 2D).
    TransverselyIsotropic {
        /// Engineering constants.
        parameters: TransverseIsotropy,
        /// Unit symmetry axis in the global frame.
        axis: Vector3<f64>,
    },
    /// A general (anisotropic) stiffness given as a matrix.
    Anisotropic,
}

/// How a [`LinearElastic`] relates to a 3D law.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Reduction {
    /// A full 3D law (`D = 3`).
    ThreeDimensional,
    /// 2D plane strain (`ε_zz = γ_yz = γ_xz = 0`): the `(xx, yy, xy)` block of the 3D `C`.
    PlaneStrain,
    /// 2D plane stress (`σ_zz = σ_yz = σ_xz = 0`): the inverse of the `(xx, yy, xy)` block of
    /// the 3D compliance `S = C⁻¹`.
    PlaneStress,
    /// A 2D law given directly as a 3×3 matrix (out-of-plane stress taken as 0).
    Planar,
}

/// A linear elastic material `σ = C ε` (Voigt, engineering shear), energy `Φ = ½ εᵀ C ε`.
///
/// `C` is a validated `voigt_len(D)` square symmetric matrix, positive definite for every
/// constructor except [`LinearElastic::zero`]. Build one with [`crate::isotropic`],
/// [`crate::plane_strain`], [`crate::plane_stress`], [`crate::from_lame`],
/// [`crate::transversely_isotropic`], [`crate::anisotropic`], ...; reduce 3D laws to 2D with
/// [`LinearElastic::plane_strain`] / [`LinearElastic::plane_stress`]; rotate any of them with
/// [`LinearElastic::rotated`].
#[derive(Debug, Clone, PartialEq)]
pub struct LinearElastic<const D: usize> {
    stiffness: VoigtMatrix,
    /// 2D plane strain only: the row `r` with `σ_zz = r · (ε_xx, ε_yy, γ_xy)`.
    out_of_plane: Option<VoigtVector>,
    symmetry: Symmetry,
    reduction: Reduction,
}

/// Builds a general anisotropic linear material from its Voigt stiffness `C` (`σ = C ε`,
/// engineering shear strains). The matrix is symmetrised, `C ↦ ½(C + Cᵀ)`, after validation.
/// In 2D the result is [`Reduction::Planar`] with zero out-of-plane stress; for plane strain
/// from a 3D matrix use `anisotropic::<3>(c)?.plane_strain()`.
///
/// # Errors
/// [`MaterialError::UnsupportedDimension`] unless `D ∈ {2, 3}`,
/// [`MaterialError::WrongVoigtSize`] unless `C` is `voigt_len(D)` square, then the errors of
/// [`check_admissible`] (non-finite, not symmetric to relative `1e-10`, not positive definite).
pub fn anisotropic<const D: usize>(c: VoigtMatrix) -> Result<LinearElastic<D>, MaterialError> {
    voigt_pairs(D)?;
    LinearElastic::from_parts(c, None, Symmetry::Anisotropic, LinearElastic::<D>::full())
}

impl<const D: usize> LinearElastic<D> {
    /// The reduction of a law built directly in dimension `D`.
    fn full() -> Reduction {
        if D == 3 {
            Reduction::ThreeDimensional
        } else {
            Reduction::Planar
        }
    }

    /// Validates (size `voigt_len(D)`, [`check_admissible`]) and symmetrises `c`.
    pub(crate) fn from_parts(
        c: VoigtMatrix,
        out_of_plane: Option<VoigtVector>,
        symmetry: Symmetry,
        reduction: Reduction,
    ) -> Result<Self, MaterialError> {
        check_size(&c, voigt_len(D))?;
        check_admissible(&c)?;
        Ok(Self { stiffness: symmetrized(&c), out_of_plane, symmetry, reduction })
    }

    /// The zero material `C = 0` (`σ = 0`, `Φ = 0`), e.g. "no viscosity" `C⁽¹⁾ = 0`.
    /// It is positive semi-definite but not definite, so it is only admissible as `C⁽¹⁾`.
    pub fn zero() -> Self {
        let n = voigt_len(D);
        Self {
            stiffness: VoigtMatrix::zeros(n, n),
            out_of_plane: None,
            symmetry: Symmetry::Zero,
            reduction: Self::full(),
        }
    }

    /// `true` for the zero material (`C = 0`).
    pub fn is_zero(&self) -> bool {
        self.stiffness.iter().all(|&v| v == 0.0)
    }

    /// The Voigt stiffness `C` of `σ = C ε`.
    pub fn stiffness(&self) -> &VoigtMatrix {
        &self.stiffness
    }

    /// The Voigt compliance `S = C⁻¹` (`ε = S σ`, engineering shear); `None` for the zero
    /// material.
    pub fn compliance(&self) -> Option<VoigtMatrix> {
        spd_inverse(&self.stiffness).ok()
    }

    /// The Kelvin moduli: eigenvalues (ascending) of the Mandel form of `C`
    /// ([`mandel_form`]), which are invariant under rotations.
    pub fn kelvin_moduli(&self) -> VoigtVector {
        let mut eig = match mandel_form(&self.stiffness) {
            Ok(m) if m.nrows() > 0 => nalgebra::SymmetricEigen::new(m).eigenvalues,
            _ => VoigtVector::zeros(0),
        };
        eig.as_mut_slice().sort_by(f64::total_cmp);
        eig
    }

    /// The symmetry class the material was built with.
    pub fn symmetry(&self) -> &Symmetry {
        &self.symmetry
    }

    /// How the material relates to a 3D law (3D, plane strain, plane stress, planar).
    pub fn reduction(&self) -> Reduction {
        self.reduction
    }

    /// The isotropic parameters (`E`, `ν`, `λ`, `μ` of the underlying 3D law) if isotropic.
    pub fn isotropic_parameters(&self) -> Option<&IsotropicParameters> {
        match &self.symmetry {
            Symmetry::Isotropic(p) => Some(p),
            _ => None,
        }
    }

    /// The 3D Lamé parameters `(λ, μ)` if isotropic, `λ = Eν/((1+ν)(1−2ν))`, `μ = E/(2(1+ν))`.
    pub fn lame(&self) -> Option<(f64, f64)> {
        self.isotropic_parameters().map(|p| (p.lambda(), p.mu()))
    }

    /// In 2D plane strain, the row `r` with `σ_zz = r · (ε_xx, ε_yy, γ_xy)` (the `zz` row of the
    /// 3D stiffness restricted to in-plane columns; `r = (λ, λ, 0)` if isotropic). `None`
    /// otherwise (`σ_zz = 0`).
    pub fn out_of_plane_row(&self) -> Option<&VoigtVector> {
        self.out_of_plane.as_ref()
    }

    /// The same material rotated by `R` (`x_global = R x_local`): `C' = M C Mᵀ` with the Bond
    /// matrix `M = M(R)` ([`bond_stress_matrix`]), so that for any strain `ε` and
    /// `ε' = N(R) ε` the energies agree: `½ ε'ᵀ C' ε' = ½ εᵀ C ε`. In 2D (rotation about `z`)
    /// the out-of-plane row becomes `r' = M r`. The symmetry metadata follows (a transversely
    /// isotropic axis `a` becomes `R a`).
    ///
    /// # Errors
    /// [`MaterialError::UnsupportedDimension`] unless `D ∈ {2, 3}`,
    /// [`MaterialError::NonFinite`] for NaN/∞ entries of `R`, and
    /// [`MaterialError::NotARotation`] unless `max |RᵀR − I| ≤ 1e-10` and `det R > 0`.
    pub fn rotated(&self, r: &SMatrix<f64, D, D>) -> Result<Self, MaterialError> {
        voigt_pairs(D)?;
        check_rotation(r)?;
        let m = bond_stress_matrix(r)?;
        let stiffness = symmetrized(&(&m * &self.stiffness * m.transpose()));
        let out_of_plane = self.out_of_plane.as_ref().map(|row| &m * row);
        let symmetry = match &self.symmetry {
            Symmetry::TransverselyIsotropic { parameters, axis } => {
                let mut new_axis = *axis;
                for i in 0..D {
                    new_axis[i] = (0..D).map(|k| r[(i, k)] * axis[k]).sum();
                }
                Symmetry::TransverselyIsotropic { parameters: *parameters, axis: new_axis }
            }
            other => other.clone(),
        };
        Ok(Self { stiffness, out_of_plane, symmetry, reduction: self.reduction })
    }

    /// The same stiffness with different symmetry metadata.
    pub(crate) fn with_symmetry(self, symmetry: Symmetry) -> Self {
        Self { symmetry, ..self }
    }
}

impl LinearElastic<3> {
    /// The plane strain reduction (`ε_zz = γ_yz = γ_xz = 0`): `C₂ = C[(xx,yy,xy), (xx,yy,xy)]`
    /// (Voigt indices 0, 1, 5) and `σ_zz = C[zz, (xx,yy,xy)] · ε` (row 2, columns 0, 1, 5).
    /// A principal submatrix of a positive definite matrix is positive definite, so this
    /// cannot fail.
    pub fn plane_strain(&self) -> LinearElastic<2> {
        const IDX: [usize; 3] = [0, 1, 5];
        let c = &self.stiffness;
        let c2 = VoigtMatrix::from_fn(3, 3, |i, j| c[(IDX[i], IDX[j])]);
        let row = VoigtVector::from_fn(3, |j, _| c[(2, IDX[j])]);
        LinearElastic {
            stiffness: c2,
            out_of_plane: Some(row),
            symmetry: self.symmetry.clone(),
            reduction: Reduction::PlaneStrain,
        }
    }

    /// The plane stress reduction (`σ_zz = σ_yz = σ_xz = 0`): `C₂ = (S[(xx,yy,xy),
    /// (xx,yy,xy)])⁻¹` with the 3D compliance `S = C⁻¹` (indices 0, 1, 5). The zero material
    /// reduces to the zero material.
    ///
    /// # Errors
    /// [`MaterialError::NotPositiveDefinite`] if the inversions fail numerically.
    pub fn plane_stress(&self) -> Result<LinearElastic<2>, MaterialError> {
        const IDX: [usize; 3] = [0, 1, 5];
        if matches!(self.symmetry, Symmetry::Zero) {
            let mut z = LinearElastic::<2>::zero();
            z.reduction = Reduction::PlaneStress;
            return Ok(z);
        }
        let s = spd_inverse(&self.stiffness)?;
        let s2 = VoigtMatrix::from_fn(3, 3, |i, j| s[(IDX[i], IDX[j])]);
        let c2 = spd_inverse(&s2)?;
        LinearElastic::from_parts(c2, None, self.symmetry.clone(), Reduction::PlaneStress)
    }
}

impl<const D: usize> Material<D> for LinearElastic<D> {
    /// `σ = C ε` (a vector of NaN if `ε` does not have length `voigt_len(D)`).
    fn stress(&self, strain: &VoigtVector) -> VoigtVector {
        apply(&self.stiffness, strain)
    }

    /// `∂σ/∂ε = C` (independent of the strain).
    fn tangent(&self, _strain: &VoigtVector) -> VoigtMatrix {
        self.stiffness.clone()
    }

    /// `Φ = ½ εᵀ C ε` (NaN if `ε` has the wrong length).
    fn energy_density(&self, strain: &VoigtVector) -> f64 {
        if strain.len() == self.stiffness.ncols() {
            0.5 * strain.dot(&(&self.stiffness * strain))
        } else {
            f64::NAN
        }
    }

    /// `Some(C)`.
    fn linear_stiffness(&self) -> Option<VoigtMatrix> {
        Some(self.stiffness.clone())
    }

    /// Plane strain: `σ_zz = r · ε` ([`LinearElastic::out_of_plane_row`]); otherwise `0`.
    fn out_of_plane_stress(&self, strain: &VoigtVector) -> f64 {
        match (&self.out_of_plane, D) {
            (Some(row), 2) if row.len() == strain.len() => row.dot(strain),
            (Some(_), 2) => f64::NAN,
            _ => 0.0,
        }
    }

    fn name(&self) -> String {
        let sym = match &self.symmetry {
            Symmetry::Zero => "zero".to_string(),
            Symmetry::Isotropic(p) => {
                format!("isotropic (E = {}, nu = {})", p.youngs_modulus(), p.poisson_ratio())
            }
            Symmetry::TransverselyIsotropic { axis, .. } => {
                format!("transversely isotropic (axis = [{}, {}, {}])", axis[0], axis[1], axis[2])
            }
            Symmetry::Anisotropic => "anisotropic".to_string(),
        };
        let red = match self.reduction {
            Reduction::ThreeDimensional => "3D",
            Reduction::PlaneStrain => "plane strain",
            Reduction::PlaneStress => "plane stress",
            Reduction::Planar => "2D",
        };
        format!("{sym}, {red}")
    }
}

/// Checks `R` finite, `max |RᵀR − I| ≤ 1e-10`, `det R > 0` (`D ∈ {2, 3}`).
fn check_rotation<const D: usize>(r: &SMatrix<f64, D, D>) -> Result<(), MaterialError> {
    let as_dyn = VoigtMatrix::from_fn(D, D, |i, j| r[(i, j)]);
    check_finite_matrix(&as_dyn, "rotation matrix entry")?;
    let gram = as_dyn.transpose() * &as_dyn;
    let defect = (gram - VoigtMatrix::identity(D, D)).amax();
    let det = match D {
        2 => r[(0, 0)] * r[(1, 1)] - r[(0, 1)] * r[(1, 0)],
        3 => {
            r[(0, 0)] * (r[(1, 1)] * r[(2, 2)] - r[(1, 2)] * r[(2, 1)])
                - r[(0, 1)] * (r[(1, 0)] * r[(2, 2)] - r[(1, 2)] * r[(2, 0)])
                + r[(0, 2)] * (r[(1, 0)] * r[(2, 1)] - r[(1, 1)] * r[(2, 0)])
        }
        _ => return Err(MaterialError::UnsupportedDimension(D)),
    };
    if defect > ROTATION_TOL || det <= 0.0 {
        return Err(MaterialError::NotARotation { orthogonality_defect: defect, det });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use nalgebra::{Matrix2, Matrix3};

    #[test]
    fn rotated_rejects_non_rotations() {
        let m = crate::isotropic(1.0, 0.25).unwrap();
        let reflection = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        assert!(matches!(
            m.rotated(&reflection),
            Err(MaterialError::NotARotation { det, .. }) if det < 0.0
        ));
        let scaled = Matrix3::identity() * 2.0;
        assert!(matches!(m.rotated(&scaled), Err(MaterialError::NotARotation { .. })));
        let nan = Matrix2::new(f64::NAN, 0.0, 0.0, 1.0);
        let m2 = crate::plane_strain(1.0, 0.25).unwrap();
        assert!(matches!(m2.rotated(&nan), Err(MaterialError::NonFinite { .. })));
    }

    #[test]
    fn isotropic_is_rotation_invariant() {
        let m = crate::isotropic(3.0, 0.3).unwrap();
        let r: Matrix3<f64> = *nalgebra::Rotation3::from_euler_angles(0.3, 1.0, -0.2).matrix();
        let mr = m.rotated(&r).unwrap();
        assert!((mr.stiffness() - m.stiffness()).amax() < 1e-13);
        let p = crate::plane_strain(3.0, 0.3).unwrap();
        let (c, s) = (0.8_f64.cos(), 0.8_f64.sin());
        let pr = p.rotated(&Matrix2::new(c, -s, s, c)).unwrap();
        assert!((pr.stiffness() - p.stiffness()).amax() < 1e-13);
        let row_diff = pr.out_of_plane_row().unwrap() - p.out_of_plane_row().unwrap();
        assert!(row_diff.amax() < 1e-13);
    }

    #[test]
    fn zero_material() {
        let z = LinearElastic::<3>::zero();
        assert!(z.is_zero());
        assert!(z.compliance().is_none());
        assert_eq!(z.energy_density(&VoigtVector::from_element(6, 1.0)), 0.0);
        let zs = z.plane_stress().unwrap();
        assert!(zs.is_zero());
        assert_eq!(zs.reduction(), Reduction::PlaneStress);
        assert!(z.plane_strain().is_zero());
    }

    #[test]
    fn wrong_length_strain_is_nan_not_panic() {
        let m = crate::plane_strain(1.0, 0.3).unwrap();
        let bad = VoigtVector::zeros(6);
        assert!(m.stress(&bad).iter().all(|v| v.is_nan()));
        assert!(m.energy_density(&bad).is_nan());
        assert!(m.out_of_plane_stress(&bad).is_nan());
    }
}
