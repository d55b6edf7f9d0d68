//! Transversely isotropic linear elasticity about an arbitrary unit axis.

use nalgebra::{Matrix3, Vector2, Vector3};

use crate::linear::{Reduction, Symmetry};
use crate::voigt::{check_finite, min_eigenvalue};
use crate::{LinearElastic, MaterialError, VoigtMatrix};

/// Engineering constants of a transversely isotropic material (isotropic in the plane normal to
/// the axis `a`; "p" = in the isotropy plane, "a" = along the axis).
///
/// * `e_p`: Young's modulus `E_p` for uniaxial stress in the plane;
/// * `nu_p`: Poisson ratio `ν_p` in the plane (in-plane contraction under in-plane stress);
/// * `e_a`: Young's modulus `E_a` for uniaxial stress along the axis;
/// * `nu_ap`: Poisson ratio `ν_ap = −ε_p / ε_a` for uniaxial stress **along the axis**
///   (the in-plane strain due to axial stress: `ε_p = −ν_ap σ_a / E_a`). The converse ratio
///   (axial contraction under in-plane stress) follows from the symmetry relation
///   `ν_pa / E_p = ν_ap / E_a` ([`TransverseIsotropy::nu_pa`]);
/// * `g_a`: shear modulus `G_a` in planes containing the axis.
///
/// In the local frame with the axis as `z` the Voigt compliance (`ε = S σ`, engineering shear)
/// is
///
/// ```text
/// S11 = S22 = 1/E_p      S12 = −ν_p/E_p      S13 = S23 = −ν_ap/E_a     S33 = 1/E_a
/// S44 = S55 = 1/G_a      S66 = 2(1+ν_p)/E_p = 1/G_p
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransverseIsotropy {
    /// In-plane Young's modulus `E_p > 0`.
    pub e_p: f64,
    /// In-plane Poisson ratio `ν_p`.
    pub nu_p: f64,
    /// Axial Young's modulus `E_a > 0`.
    pub e_a: f64,
    /// Poisson ratio `ν_ap`: in-plane strain due to axial stress, `ε_p = −ν_ap σ_a / E_a`.
    pub nu_ap: f64,
    /// Shear modulus `G_a > 0` in planes containing the axis.
    pub g_a: f64,
}

impl TransverseIsotropy {
    /// The converse Poisson ratio `ν_pa = ν_ap E_p / E_a` (axial strain due to in-plane stress,
    /// `ε_a = −ν_pa σ_p / E_p`), from the symmetry relation `ν_pa / E_p = ν_ap / E_a`.
    pub fn nu_pa(&self) -> f64 {
        self.nu_ap * self.e_p / self.e_a
    }

    /// The in-plane shear modulus `G_p = E_p / (2(1+ν_p))`.
    pub fn g_p(&self) -> f64 {
        self.e_p / (2.0 * (1.0 + self.nu_p))
    }

    /// Checks finiteness and `E_p, E_a, G_a > 0` (the Poisson ratios are constrained by
    /// positive definiteness, checked when building the stiffness).
    ///
    /// # Errors
    /// [`MaterialError::NonFinite`], [`MaterialError::NonPositiveYoungsModulus`],
    /// [`MaterialError::NonPositiveShearModulus`].
    pub fn validate(&self) -> Result<(), MaterialError> {
        check_finite(self.e_p, "in-plane Young's modulus E_p")?;
        check_finite(self.nu_p, "in-plane Poisson ratio nu_p")?;
        check_finite(self.e_a, "axial Young's modulus E_a")?;
        check_finite(self.nu_ap, "Poisson ratio nu_ap")?;
        check_finite(self.g_a, "axial shear modulus G_a")?;
        for e in [self.e_p, self.e_a] {
            if e <= 0.0 {
                return Err(MaterialError::NonPositiveYoungsModulus { e });
            }
        }
        if self.g_a <= 0.0 {
            return Err(MaterialError::NonPositiveShearModulus { mu: self.g_a });
        }
        Ok(())
    }

    /// The 6×6 Voigt compliance in the local frame (axis = local `z`), see the type docs.
    ///
    /// # Errors
    /// As [`TransverseIsotropy::validate`].
    pub fn local_compliance(&self) -> Result<VoigtMatrix, MaterialError> {
        self.validate()?;
        let (s11, s12) = (1.0 / self.e_p, -self.nu_p / self.e_p);
        let (s13, s33) = (-self.nu_ap / self.e_a, 1.0 / self.e_a);
        let (s44, s66) = (1.0 / self.g_a, 2.0 * (1.0 + self.nu_p) / self.e_p);
        let mut s = VoigtMatrix::zeros(6, 6);
        s[(0, 0)] = s11;
        s[(1, 1)] = s11;
        s[(2, 2)] = s33;
        s[(0, 1)] = s12;
        s[(1, 0)] = s12;
        for i in 0..2 {
            s[(i, 2)] = s13;
            s[(2, i)] = s13;
        }
        s[(3, 3)] = s44;
        s[(4, 4)] = s44;
        s[(5, 5)] = s66;
        Ok(s)
    }

    /// The 3D stiffness with the axis along local `z`, `C_local = S_local⁻¹`.
    ///
    /// # Errors
    /// As [`TransverseIsotropy::validate`], and [`MaterialError::NotPositiveDefinite`] when
    /// the constants are not admissible (e.g. `|ν_p| ≥ 1` or
    /// `2 ν_ap ν_pa ≥ 1 − ν_p`).
    pub fn local_material(&self) -> Result<LinearElastic<3>, MaterialError> {
        let s = self.local_compliance()?;
        let c = match s.clone().try_inverse() {
            Some(c) => c,
            None => return Err(MaterialError::NotPositiveDefinite { min_eigenvalue: min_eigenvalue(&s)? }),
        };
        LinearElastic::from_parts(
            c,
            None,
            Symmetry::TransverselyIsotropic { parameters: *self, axis: Vector3::z() },
            Reduction::ThreeDimensional,
        )
    }
}

/// A right-handed orthonormal frame `R = [e₁ e₂ a]` (columns) with third column the unit `a`,
/// i.e. the rotation taking the local axis `z` to `a`.
fn frame_with_axis(a: &Vector3<f64>) -> Matrix3<f64> {
    // Helper: the coordinate axis least aligned with `a`.
    let k = (0..3).min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs())).unwrap_or(0);
    let mut h = Vector3::zeros();
    h[k] = 1.0;
    let e1 = (h - a * a.dot(&h)).normalize();
    let e2 = a.cross(&e1);
    Matrix3::from_columns(&[e1, e2, *a])
}

fn unit_axis(axis: Vector3<f64>) -> Result<Vector3<f64>, MaterialError> {
    if !axis.iter().all(|v| v.is_finite()) {
        return Err(MaterialError::NonFinite { what: "material axis" });
    }
    let norm = axis.norm();
    if norm <= f64::MIN_POSITIVE.sqrt() {
        return Err(MaterialError::DegenerateAxis { norm });
    }
    Ok(axis / norm)
}

/// 3D transversely isotropic material about `axis` (normalised here; any direction):
/// `C = M(R) C_local M(R)ᵀ` where `C_local = S_local⁻¹` ([`TransverseIsotropy`]) has the axis
/// along local `z`, `R = [e₁ e₂ a]` takes local to global, and `M(R)` is the Bond stress matrix
/// ([`crate::bond_stress_matrix`]). The result does not depend on the choice of `e₁ ⊥ a`.
///
/// # Errors
/// [`MaterialError::NonFinite`] / [`MaterialError::DegenerateAxis`] for a NaN or zero axis,
/// the errors of [`TransverseIsotropy::local_material`] (including
/// [`MaterialError::NotPositiveDefinite`] with the smallest eigenvalue).
pub fn transversely_isotropic(
    parameters: TransverseIsotropy,
    axis: Vector3<f64>,
) -> Result<LinearElastic<3>, MaterialError> {
    let a = unit_axis(axis)?;
    let local = parameters.local_material()?;
    let global = local.rotated(&frame_with_axis(&a))?;
    // Record the exact normalised axis (rather than R·e_z, which carries rounding).
    Ok(global.with_symmetry(Symmetry::TransverselyIsotropic { parameters, axis: a }))
}

/// 2D plane strain transversely isotropic material with the in-plane axis `(a_x, a_y)`: the
/// `(xx, yy, xy)` block of the 3D [`transversely_isotropic`] stiffness with axis
/// `(a_x, a_y, 0)` ([`LinearElastic::plane_strain`]), `σ_zz` from its `zz` row.
///
/// # Errors
/// As [`transversely_isotropic`].
pub fn transversely_isotropic_plane_strain(
    parameters: TransverseIsotropy,
    axis: Vector2<f64>,
) -> Result<LinearElastic<2>, MaterialError> {
    Ok(transversely_isotropic(parameters, Vector3::new(axis.x, axis.y, 0.0))?.plane_strain())
}

/// 2D plane stress transversely isotropic material with the in-plane axis `(a_x, a_y)`: the
/// inverse of the `(xx, yy, xy)` block of the 3D compliance with axis `(a_x, a_y, 0)`
/// ([`LinearElastic::plane_stress`]).
///
/// # Errors
/// As [`transversely_isotropic`].
pub fn transversely_isotropic_plane_stress(
    parameters: TransverseIsotropy,
    axis: Vector2<f64>,
) -> Result<LinearElastic<2>, MaterialError> {
    transversely_isotropic(parameters, Vector3::new(axis.x, axis.y, 0.0))?.plane_stress()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn frame_is_proper_rotation_with_axis() {
        for a in [
            Vector3::z(),
            Vector3::x(),
            Vector3::new(1.0, 2.0, -3.0).normalize(),
            Vector3::new(0.0, -1.0, 0.0),
        ] {
            let r = frame_with_axis(&a);
            assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-15);
            assert!((r.determinant() - 1.0).abs() < 1e-15);
            assert!((r.column(2) - a).amax() < 1e-15);
        }
        assert_eq!(frame_with_axis(&Vector3::z()), Matrix3::identity());
    }

    #[test]
    fn axis_validation() {
        let p = TransverseIsotropy { e_p: 1.0, nu_p: 0.3, e_a: 2.0, nu_ap: 0.2, g_a: 0.5 };
        assert!(matches!(
            transversely_isotropic(p, Vector3::zeros()),
            Err(MaterialError::DegenerateAxis { norm }) if norm == 0.0
        ));
        assert!(matches!(
            transversely_isotropic(p, Vector3::new(f64::NAN, 0.0, 1.0)),
            Err(MaterialError::NonFinite { .. })
        ));
        let m = transversely_isotropic(p, Vector3::new(0.0, 3.0, 4.0)).unwrap();
        match m.symmetry() {
            Symmetry::TransverselyIsotropic { axis, .. } => {
                assert!((axis - Vector3::new(0.0, 0.6, 0.8)).amax() < 1e-15)
            }
            other => panic!("unexpected symmetry {other:?}"),
        }
    }
}
