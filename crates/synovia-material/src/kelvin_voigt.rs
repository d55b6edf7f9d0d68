//! The Kelvin–Voigt viscoelastic law `τ = C⁽⁰⁾ e(u) + C⁽¹⁾ e(u')` of docs/model.md §2.

use std::sync::Arc;

use crate::voigt::{check_finite, check_positive_semidefinite, check_size, voigt_pairs};
use crate::{check_admissible, voigt_len, LinearElastic, Material, MaterialError, VoigtMatrix, VoigtVector};

/// A Kelvin–Voigt viscoelastic body material (docs/model.md §2):
///
/// ```text
/// τ = C⁽⁰⁾ e(u) + C⁽¹⁾ e(u'),
/// ```
///
/// with the elasticity `C⁽⁰⁾` ([`KelvinVoigt::elastic`], positive definite), the optional
/// viscosity `C⁽¹⁾` ([`KelvinVoigt::viscous`], positive semi-definite; `None` means
/// `C⁽¹⁾ = 0`), the mass density `ρ > 0` ([`KelvinVoigt::density`]) and a damping coefficient
/// `α ≥ 0` ([`KelvinVoigt::damping`], interpreted by the dynamic solver, e.g. a
/// mass-proportional damping force `α ρ u'`; `α = 0` is undamped).
///
/// As a [`Material`] it behaves as its elastic part `C⁽⁰⁾`, so it can be used for static
/// problems unchanged.
#[derive(Debug, Clone)]
pub struct KelvinVoigt<const D: usize> {
    elastic: Arc<dyn Material<D>>,
    viscous: Option<Arc<dyn Material<D>>>,
    density: f64,
    damping: f64,
}

impl<const D: usize> KelvinVoigt<D> {
    /// Builds `τ = C⁽⁰⁾ e(u) + C⁽¹⁾ e(u')` with density `ρ` and damping `α`.
    ///
    /// Checks `D ∈ {2, 3}`, `ρ` finite and `> 0`, `α` finite and `≥ 0`; for a linear `C⁽⁰⁾`
    /// (its [`Material::linear_stiffness`] is `Some`) size `voigt_len(D)` and
    /// [`check_admissible`]; for a linear `C⁽¹⁾` size, symmetry and
    /// `λ_min(C⁽¹⁾) ≥ −1e-12 ‖C⁽¹⁾‖_F`. Nonlinear user materials are trusted.
    ///
    /// # Errors
    /// [`MaterialError::UnsupportedDimension`], [`MaterialError::NonFinite`],
    /// [`MaterialError::NonPositiveDensity`], [`MaterialError::NegativeDamping`],
    /// [`MaterialError::WrongVoigtSize`], [`MaterialError::NotSymmetric`],
    /// [`MaterialError::NotPositiveDefinite`] (for `C⁽⁰⁾`),
    /// [`MaterialError::NotPositiveSemiDefinite`] (for `C⁽¹⁾`).
    pub fn new(
        elastic: Arc<dyn Material<D>>,
        viscous: Option<Arc<dyn Material<D>>>,
        density: f64,
        damping: f64,
    ) -> Result<Self, MaterialError> {
        voigt_pairs(D)?;
        let rho = check_finite(density, "density rho")?;
        if rho <= 0.0 {
            return Err(MaterialError::NonPositiveDensity { rho });
        }
        let alpha = check_finite(damping, "damping alpha")?;
        if alpha < 0.0 {
            return Err(MaterialError::NegativeDamping { alpha });
        }
        if let Some(c0) = elastic.linear_stiffness() {
            check_size(&c0, voigt_len(D))?;
            check_admissible(&c0)?;
        }
        if let Some(c1) = viscous.as_ref().and_then(|v| v.linear_stiffness()) {
            check_size(&c1, voigt_len(D))?;
            check_positive_semidefinite(&c1)?;
        }
        Ok(Self { elastic, viscous, density: rho, damping: alpha })
    }

    /// Convenience constructor from linear parts, `C⁽⁰⁾ = c0`, `C⁽¹⁾ = c1` (pass
    /// [`LinearElastic::zero`] for no viscosity, stored as `None`).
    ///
    /// # Errors
    /// As [`KelvinVoigt::new`].
    pub fn from_linear(
        c0: LinearElastic<D>,
        c1: LinearElastic<D>,
        density: f64,
        damping: f64,
    ) -> Result<Self, MaterialError> {
        let viscous: Option<Arc<dyn Material<D>>> = if c1.is_zero() { None } else { Some(Arc::new(c1)) };
        Self::new(Arc::new(c0), viscous, density, damping)
    }

    /// The elasticity `C⁽⁰⁾`.
    pub fn elastic(&self) -> &Arc<dyn Material<D>> {
        &self.elastic
    }

    /// The viscosity `C⁽¹⁾` (`None` means `C⁽¹⁾ = 0`).
    pub fn viscous(&self) -> Option<&Arc<dyn Material<D>>> {
        self.viscous.as_ref()
    }

    /// The mass density `ρ > 0`.
    pub fn density(&self) -> f64 {
        self.density
    }

    /// The damping coefficient `α ≥ 0`.
    pub fn damping(&self) -> f64 {
        self.damping
    }

    /// The viscous stress `C⁽¹⁾ e(u')` for the strain rate `ε̇ = e(u')` (Voigt, engineering
    /// shear); zero when there is no viscosity.
    pub fn viscous_stress(&self, strain_rate: &VoigtVector) -> VoigtVector {
        match &self.viscous {
            Some(v) => v.stress(strain_rate),
            None => VoigtVector::zeros(voigt_len(D)),
        }
    }

    /// The total stress `τ = C⁽⁰⁾ e(u) + C⁽¹⁾ e(u')`.
    pub fn total_stress(&self, strain: &VoigtVector, strain_rate: &VoigtVector) -> VoigtVector {
        let elastic = self.elastic.stress(strain);
        let viscous = self.viscous_stress(strain_rate);
        if elastic.len() == viscous.len() {
            elastic + viscous
        } else {
            VoigtVector::from_element(voigt_len(D), f64::NAN)
        }
    }

    /// The constant viscosity matrix `C⁽¹⁾` when it is linear (zero matrix when absent);
    /// `None` for a nonlinear viscosity.
    pub fn viscous_stiffness(&self) -> Option<VoigtMatrix> {
        match &self.viscous {
            Some(v) => v.linear_stiffness(),
            None => Some(VoigtMatrix::zeros(voigt_len(D), voigt_len(D))),
        }
    }
}

impl<const D: usize> Material<D> for KelvinVoigt<D> {
    /// The elastic stress `C⁽⁰⁾ e(u)`.
    fn stress(&self, strain: &VoigtVector) -> VoigtVector {
        self.elastic.stress(strain)
    }

    /// The elastic tangent `∂(C⁽⁰⁾ e)/∂e`.
    fn tangent(&self, strain: &VoigtVector) -> VoigtMatrix {
        self.elastic.tangent(strain)
    }

    /// The elastic energy density `Φ(e)` of `C⁽⁰⁾`.
    fn energy_density(&self, strain: &VoigtVector) -> f64 {
        self.elastic.energy_density(strain)
    }

    /// The elastic stiffness `C⁽⁰⁾` if linear.
    fn linear_stiffness(&self) -> Option<VoigtMatrix> {
        self.elastic.linear_stiffness()
    }

    /// The out-of-plane stress of the elastic part.
    fn out_of_plane_stress(&self, strain: &VoigtVector) -> f64 {
        self.elastic.out_of_plane_stress(strain)
    }

    fn name(&self) -> String {
        let viscous = match &self.viscous {
            Some(v) => v.name(),
            None => "none".to_string(),
        };
        format!(
            "Kelvin-Voigt (elastic: {}; viscous: {}; rho = {}; alpha = {})",
            self.elastic.name(),
            viscous,
            self.density,
            self.damping
        )
    }
}
