//! # synovia-material
//!
//! Constitutive laws for synovia's bodies (bone, cartilage, menisci, ...): linear elastic
//! materials of any symmetry class in 2D and 3D, and the Kelvin–Voigt viscoelastic law of
//! docs/model.md §2.
//!
//! ## Constitutive laws (docs/model.md §2)
//!
//! For an elastic body the stress `τ` depends on the small-strain tensor
//! `e(u) = ½(∇u + ∇uᵀ)` through
//!
//! ```text
//! τ = C⁽⁰⁾ e(u),          τ = ∂Φ/∂e,   Φ(e) = ½ e : C⁽⁰⁾ e   (linear case)
//! ```
//!
//! and for a Kelvin–Voigt viscoelastic body, with `u' = ∂u/∂t`,
//!
//! ```text
//! τ = C⁽⁰⁾ e(u) + C⁽¹⁾ e(u')
//! ```
//!
//! where `C⁽⁰⁾` (elasticity) is symmetric positive definite and `C⁽¹⁾` (viscosity) symmetric
//! positive semi-definite. The [`Material`] trait describes `C⁽⁰⁾` (possibly nonlinear, through
//! its potential `Φ`); [`KelvinVoigt`] pairs it with `C⁽¹⁾`, a density `ρ` and a damping
//! coefficient `α`.
//!
//! ## Voigt convention
//!
//! Symmetric tensors are stored as vectors of length [`voigt_len`]`(D) = D(D+1)/2`:
//!
//! | D | order |
//! |---|-------|
//! | 2 | `(xx, yy, xy)` |
//! | 3 | `(xx, yy, zz, yz, xz, xy)` |
//!
//! **Strains use engineering shear** (`γ_xy = 2 e_xy`, ...), **stresses are plain**
//! (`σ_xy`). With this choice the Voigt stiffness `C` is symmetric, `σ = C ε`, the strain
//! energy density is `Φ = ½ εᵀ C ε` and the stress power is `σ · ε̇` (plain dot product).
//! A rotation `x_global = R x_local` acts on stresses by the Bond matrix `M(R)`
//! ([`bond_stress_matrix`]), on engineering strains by `N(R) = M(R)⁻ᵀ`
//! ([`bond_strain_matrix`]), and on stiffnesses by `C_global = M C_local Mᵀ`.
//!
//! In 2D the in-plane operator comes from a 3D one either by **plane strain**
//! (`ε_zz = γ_yz = γ_xz = 0`: keep the `(xx, yy, xy)` rows and columns of `C`; the out-of-plane
//! stress `σ_zz` is generally nonzero, see [`Material::out_of_plane_stress`]) or by **plane
//! stress** (`σ_zz = σ_yz = σ_xz = 0`: invert the `(xx, yy, xy)` block of the compliance
//! `S = C⁻¹`).
//!
//! ## Materials
//!
//! All linear materials are a [`LinearElastic`] holding a validated stiffness plus metadata:
//!
//! * isotropic: [`isotropic`], [`plane_strain`], [`plane_stress`], [`from_lame`],
//!   [`plane_strain_from_lame`], Lamé helpers [`lame_parameters`], [`IsotropicParameters`];
//! * transversely isotropic about any axis: [`transversely_isotropic`],
//!   [`transversely_isotropic_plane_strain`], [`transversely_isotropic_plane_stress`] with
//!   parameters [`TransverseIsotropy`];
//! * general anisotropic: [`anisotropic`], and any linear material rotated:
//!   [`LinearElastic::rotated`];
//! * admissibility check of a Voigt matrix: [`check_admissible`].
//!
//! Hyperelastic laws (docs/model.md §2.3) are [`Hyperelastic`] materials of an energy
//! `W(I₁, I₂, J)` ([`InvariantEnergy`]): [`neo_hookean`], [`mooney_rivlin`], or a user's own
//! energy. With `synovia_fem::nonlinear` they run in small-strain or total Lagrangian
//! finite-strain kinematics.
//!
//! Users may implement [`Material`] for their own (nonlinear) laws; the trait is object safe and
//! [`KelvinVoigt`] stores `Arc<dyn Material<D>>`.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod error;
mod hyperelastic;
mod isotropic;
mod kelvin_voigt;
mod linear;
mod transverse;
mod voigt;

pub use error::MaterialError;
pub use hyperelastic::{
    mooney_rivlin, neo_hookean, Hyperelastic, InvariantEnergy, Invariants, MooneyRivlin, NeoHookean,
};
pub use isotropic::{
    from_lame, isotropic, lame_parameters, plane_strain, plane_strain_from_lame, plane_stress,
    IsotropicParameters,
};
pub use kelvin_voigt::KelvinVoigt;
pub use linear::{anisotropic, LinearElastic, Reduction, Symmetry};
pub use transverse::{
    transversely_isotropic, transversely_isotropic_plane_strain, transversely_isotropic_plane_stress,
    TransverseIsotropy,
};
pub use voigt::{
    bond_strain_matrix, bond_stress_matrix, check_admissible, mandel_form, min_eigenvalue, voigt_len,
    voigt_pairs,
};

/// A symmetric tensor in Voigt notation, a vector of length [`voigt_len`]`(D)`.
///
/// Strains `ε = (ε_xx, ε_yy, ε_zz, γ_yz, γ_xz, γ_xy)` with engineering shear `γ_ij = 2 e_ij`,
/// stresses `σ = (σ_xx, σ_yy, σ_zz, σ_yz, σ_xz, σ_xy)` (2D: `(xx, yy, xy)`).
pub type VoigtVector = nalgebra::DVector<f64>;

/// A fourth-order tensor with minor and major symmetries in Voigt notation: a
/// `voigt_len(D) × voigt_len(D)` matrix `C` with `σ = C ε` (engineering shear strains).
pub type VoigtMatrix = nalgebra::DMatrix<f64>;

/// A (possibly nonlinear) hyperelastic constitutive law `τ = C⁽⁰⁾(e) = ∂Φ/∂e` in dimension `D`.
///
/// All vectors are in Voigt notation (see the crate docs): strains with engineering shear,
/// stresses plain, of length [`voigt_len`]`(D)`. The trait is object safe, so bodies may hold
/// `Arc<dyn Material<D>>`.
///
/// Implementations must satisfy, for every strain `ε`:
/// `stress(ε) = ∂Φ/∂ε` with `Φ = energy_density`, and `tangent(ε) = ∂ stress/∂ε` (symmetric).
/// The built-in linear materials return a vector of NaN when given a strain of the wrong
/// length rather than panicking.
pub trait Material<const D: usize>: Send + Sync + std::fmt::Debug {
    /// Stress (Voigt) for a strain (Voigt, engineering shear): `τ = C⁽⁰⁾(e)`
    /// (`σ = C ε` for linear materials).
    fn stress(&self, strain: &VoigtVector) -> VoigtVector;

    /// Consistent tangent `∂τ/∂e` at `strain`: a symmetric `voigt_len(D)` square matrix
    /// (the constant `C` for linear materials).
    fn tangent(&self, strain: &VoigtVector) -> VoigtMatrix;

    /// Strain energy density `Φ(e)`, the potential of docs/model.md §2 with `τ = ∂Φ/∂e`
    /// (`Φ = ½ εᵀ C ε` for linear materials).
    fn energy_density(&self, strain: &VoigtVector) -> f64;

    /// For linear materials the constant stiffness `C` of `σ = C ε` (so assembly evaluates it
    /// once per body); `None` (the default) for nonlinear materials.
    fn linear_stiffness(&self) -> Option<VoigtMatrix> {
        None
    }

    /// In 2D, the out-of-plane normal stress `σ_zz` produced by the in-plane strain
    /// `(ε_xx, ε_yy, γ_xy)`: `σ_zz = λ (ε_xx + ε_yy)` for isotropic plane strain, `0` for plane
    /// stress. The default is `0`.
    fn out_of_plane_stress(&self, _strain: &VoigtVector) -> f64 {
        0.0
    }

    /// The stress, the energy density and, if `with_tangent`, the tangent at one strain: what
    /// an element's response needs, `(τ(e), Φ(e), ∂τ/∂e)`, in one call. The default calls
    /// [`Self::stress`], [`Self::energy_density`] and [`Self::tangent`]; a law whose three
    /// share their work (the invariants and `C⁻¹` of a hyperelastic law) overrides it with
    /// the same values.
    fn response(&self, strain: &VoigtVector, with_tangent: bool) -> (VoigtVector, f64, Option<VoigtMatrix>) {
        (self.stress(strain), self.energy_density(strain), with_tangent.then(|| self.tangent(strain)))
    }

    /// A short human-readable name.
    fn name(&self) -> String;
}
