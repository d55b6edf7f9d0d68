//! Isotropic linear elasticity `σ = λ tr(e) I + 2μ e` in 3D, plane strain and plane stress.

use crate::linear::{Reduction, Symmetry};
use crate::voigt::check_finite;
use crate::{LinearElastic, MaterialError, VoigtMatrix, VoigtVector};

/// Validated isotropic constants of a 3D law: Young's modulus `E`, Poisson ratio `ν` and the
/// Lamé parameters `λ = Eν/((1+ν)(1−2ν))`, `μ = E/(2(1+ν))`, related conversely by
/// `E = μ(3λ+2μ)/(λ+μ)`, `ν = λ/(2(λ+μ))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsotropicParameters {
    youngs_modulus: f64,
    poisson_ratio: f64,
    lambda: f64,
    mu: f64,
}

impl IsotropicParameters {
    /// From Young's modulus `E > 0` and Poisson ratio `−1 < ν < ½`:
    /// `λ = Eν/((1+ν)(1−2ν))`, `μ = E/(2(1+ν))`.
    ///
    /// # Errors
    /// [`MaterialError::NonFinite`] (NaN/∞, checked first),
    /// [`MaterialError::NonPositiveYoungsModulus`], [`MaterialError::PoissonRatioOutOfRange`].
    pub fn new(youngs_modulus: f64, poisson_ratio: f64) -> Result<Self, MaterialError> {
        let e = check_finite(youngs_modulus, "Young's modulus E")?;
        let nu = check_finite(poisson_ratio, "Poisson ratio nu")?;
        if e <= 0.0 {
            return Err(MaterialError::NonPositiveYoungsModulus { e });
        }
        if nu <= -1.0 || nu >= 0.5 {
            return Err(MaterialError::PoissonRatioOutOfRange { nu });
        }
        Ok(Self {
            youngs_modulus: e,
            poisson_ratio: nu,
            lambda: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            mu: e / (2.0 * (1.0 + nu)),
        })
    }

    /// From the Lamé parameters with `μ > 0` and `3λ + 2μ > 0` (positive bulk modulus):
    /// `E = μ(3λ+2μ)/(λ+μ)`, `ν = λ/(2(λ+μ))`.
    ///
    /// # Errors
    /// [`MaterialError::NonFinite`], [`MaterialError::NonPositiveShearModulus`],
    /// [`MaterialError::InadmissibleLame`].
    pub fn from_lame(lambda: f64, mu: f64) -> Result<Self, MaterialError> {
        let (lambda, mu) = check_lame(lambda, mu)?;
        if 3.0 * lambda + 2.0 * mu <= 0.0 {
            return Err(MaterialError::InadmissibleLame { lambda, mu, condition: "3*lambda + 2*mu > 0" });
        }
        Ok(Self::from_lame_unchecked(lambda, mu))
    }

    /// `E`, `ν` from `λ`, `μ` without range checks (requires `λ + μ ≠ 0`).
    fn from_lame_unchecked(lambda: f64, mu: f64) -> Self {
        Self {
            youngs_modulus: mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu),
            poisson_ratio: lambda / (2.0 * (lambda + mu)),
            lambda,
            mu,
        }
    }

    /// Young's modulus `E`.
    pub fn youngs_modulus(&self) -> f64 {
        self.youngs_modulus
    }

    /// Poisson ratio `ν`.
    pub fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }

    /// First Lamé parameter `λ = Eν/((1+ν)(1−2ν))`.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// Shear modulus `μ = G = E/(2(1+ν))`.
    pub fn mu(&self) -> f64 {
        self.mu
    }

    /// Bulk modulus `K = λ + 2μ/3 = E/(3(1−2ν))`.
    pub fn bulk_modulus(&self) -> f64 {
        self.lambda + 2.0 * self.mu / 3.0
    }

    /// The 3D stiffness: `C_ij = λ + 2μ δ_ij` on the normal block (`i, j < 3`), `C_ii = μ` on
    /// the engineering-shear diagonal (`i ≥ 3`), zero elsewhere.
    pub fn stiffness_3d(&self) -> VoigtMatrix {
        let (l, m) = (self.lambda, self.mu);
        VoigtMatrix::from_fn(6, 6, |i, j| match (i < 3, j < 3) {
            (true, true) => l + if i == j { 2.0 * m } else { 0.0 },
            (false, false) if i == j => m,
            _ => 0.0,
        })
    }

    /// The plane strain stiffness `[[λ+2μ, λ, 0], [λ, λ+2μ, 0], [0, 0, μ]]`.
    pub fn plane_strain_stiffness(&self) -> VoigtMatrix {
        let (l, m) = (self.lambda, self.mu);
        VoigtMatrix::from_row_slice(3, 3, &[l + 2.0 * m, l, 0.0, l, l + 2.0 * m, 0.0, 0.0, 0.0, m])
    }

    /// The plane stress stiffness `E/(1−ν²) [[1, ν, 0], [ν, 1, 0], [0, 0, (1−ν)/2]]`.
    pub fn plane_stress_stiffness(&self) -> VoigtMatrix {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        let f = e / (1.0 - nu * nu);
        VoigtMatrix::from_row_slice(3, 3, &[f, f * nu, 0.0, f * nu, f, 0.0, 0.0, 0.0, f * (1.0 - nu) / 2.0])
    }
}

fn check_lame(lambda: f64, mu: f64) -> Result<(f64, f64), MaterialError> {
    let lambda = check_finite(lambda, "Lame parameter lambda")?;
    let mu = check_finite(mu, "shear modulus mu")?;
    if mu <= 0.0 {
        return Err(MaterialError::NonPositiveShearModulus { mu });
    }
    Ok((lambda, mu))
}

/// The Lamé parameters `(λ, μ) = (Eν/((1+ν)(1−2ν)), E/(2(1+ν)))` of `E > 0`, `−1 < ν < ½`.
///
/// # Errors
/// As [`IsotropicParameters::new`].
pub fn lame_parameters(youngs_modulus: f64, poisson_ratio: f64) -> Result<(f64, f64), MaterialError> {
    let p = IsotropicParameters::new(youngs_modulus, poisson_ratio)?;
    Ok((p.lambda(), p.mu()))
}

fn build_3d(p: IsotropicParameters) -> Result<LinearElastic<3>, MaterialError> {
    LinearElastic::from_parts(p.stiffness_3d(), None, Symmetry::Isotropic(p), Reduction::ThreeDimensional)
}

fn build_plane_strain(p: IsotropicParameters) -> Result<LinearElastic<2>, MaterialError> {
    let row = VoigtVector::from_column_slice(&[p.lambda(), p.lambda(), 0.0]);
    LinearElastic::from_parts(
        p.plane_strain_stiffness(),
        Some(row),
        Symmetry::Isotropic(p),
        Reduction::PlaneStrain,
    )
}

/// 3D isotropic material `σ = λ tr(e) I + 2μ e` from `E > 0`, `−1 < ν < ½`
/// (stiffness [`IsotropicParameters::stiffness_3d`]).
///
/// # Errors
/// As [`IsotropicParameters::new`].
pub fn isotropic(youngs_modulus: f64, poisson_ratio: f64) -> Result<LinearElastic<3>, MaterialError> {
    build_3d(IsotropicParameters::new(youngs_modulus, poisson_ratio)?)
}

/// 3D isotropic material from the Lamé parameters (`μ > 0`, `3λ + 2μ > 0`).
///
/// # Errors
/// As [`IsotropicParameters::from_lame`].
pub fn from_lame(lambda: f64, mu: f64) -> Result<LinearElastic<3>, MaterialError> {
    build_3d(IsotropicParameters::from_lame(lambda, mu)?)
}

/// 2D plane strain isotropic material: `C = [[λ+2μ, λ, 0], [λ, λ+2μ, 0], [0, 0, μ]]`,
/// out-of-plane stress `σ_zz = λ (ε_xx + ε_yy)`.
///
/// # Errors
/// As [`IsotropicParameters::new`].
pub fn plane_strain(youngs_modulus: f64, poisson_ratio: f64) -> Result<LinearElastic<2>, MaterialError> {
    build_plane_strain(IsotropicParameters::new(youngs_modulus, poisson_ratio)?)
}

/// 2D plane strain isotropic material from the Lamé parameters, requiring `μ > 0` and
/// `λ + μ > 0` (positive definiteness of the 2D operator). If `3λ + 2μ ≤ 0` the reported
/// 3D `E`, `ν` lie outside their 3D ranges, but the plane strain law is still admissible.
///
/// # Errors
/// [`MaterialError::NonFinite`], [`MaterialError::NonPositiveShearModulus`],
/// [`MaterialError::InadmissibleLame`].
pub fn plane_strain_from_lame(lambda: f64, mu: f64) -> Result<LinearElastic<2>, MaterialError> {
    let (lambda, mu) = check_lame(lambda, mu)?;
    if lambda + mu <= 0.0 {
        return Err(MaterialError::InadmissibleLame { lambda, mu, condition: "lambda + mu > 0" });
    }
    build_plane_strain(IsotropicParameters::from_lame_unchecked(lambda, mu))
}

/// 2D plane stress isotropic material: `C = E/(1−ν²) [[1, ν, 0], [ν, 1, 0], [0, 0, (1−ν)/2]]`
/// (equivalently Lamé `λ* = 2λμ/(λ+2μ)`, `μ`), out-of-plane stress `0`.
///
/// # Errors
/// As [`IsotropicParameters::new`].
pub fn plane_stress(youngs_modulus: f64, poisson_ratio: f64) -> Result<LinearElastic<2>, MaterialError> {
    let p = IsotropicParameters::new(youngs_modulus, poisson_ratio)?;
    LinearElastic::from_parts(
        p.plane_stress_stiffness(),
        None,
        Symmetry::Isotropic(p),
        Reduction::PlaneStress,
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn lame_round_trip() {
        let p = IsotropicParameters::new(210e9, 0.3).unwrap();
        let q = IsotropicParameters::from_lame(p.lambda(), p.mu()).unwrap();
        assert!((q.youngs_modulus() / 210e9 - 1.0).abs() < 1e-14);
        assert!((q.poisson_ratio() - 0.3).abs() < 1e-14);
        assert!((p.bulk_modulus() - 210e9 / (3.0 * (1.0 - 0.6))).abs() < 1e-3);
        let (l, m) = lame_parameters(1.0, 0.25).unwrap();
        assert!((l - 0.4).abs() < 1e-15 && (m - 0.4).abs() < 1e-15);
    }

    #[test]
    fn lame_validation() {
        assert!(matches!(
            from_lame(1.0, 0.0),
            Err(MaterialError::NonPositiveShearModulus { mu }) if mu == 0.0
        ));
        assert!(matches!(from_lame(-1.0, 1.0), Err(MaterialError::InadmissibleLame { .. })));
        // 3λ+2μ = −0.5 < 0 but λ+μ = 0.25 > 0: fine in plane strain only.
        assert!(plane_strain_from_lame(-0.75, 1.0).is_ok());
        assert!(matches!(plane_strain_from_lame(-1.0, 1.0), Err(MaterialError::InadmissibleLame { .. })));
        assert!(matches!(from_lame(f64::INFINITY, 1.0), Err(MaterialError::NonFinite { .. })));
    }
}
