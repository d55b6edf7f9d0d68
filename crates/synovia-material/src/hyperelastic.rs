//! Isotropic hyperelastic laws defined by a strain energy `W(I₁, I₂, J)` of the invariants of the
//! right Cauchy–Green tensor `C = FᵀF` (docs/model.md §2.3): compressible neo-Hookean,
//! Mooney–Rivlin, and any energy a user writes through [`InvariantEnergy`].
//!
//! ## One law, two kinematics
//!
//! A [`Hyperelastic`] law is a [`Material`]: a function of a strain `e` (Voigt, engineering
//! shear) returning the conjugate stress `τ = ∂Φ/∂e` with the potential
//!
//! ```text
//! Φ(e) = W(C),   C = I + 2e,
//! ```
//!
//! so that `τ = S = 2 ∂W/∂C` is the second Piola–Kirchhoff stress and `∂τ/∂e = 4 ∂²W/∂C∂C`
//! the material tangent. With the total Lagrangian finite-strain kinematics
//! (`synovia_fem::nonlinear`, `e = E = ½(FᵀF − I)`, the Green–Lagrange strain) this is the
//! hyperelastic law of finite elasticity; with the small-strain kinematics (`e = ε(u)`) it is a
//! nonlinear small-strain law of the model's form `τ = ∂Φ/∂e`. At `e = 0` both reduce to
//! isotropic linear elasticity with the Lamé parameters of [`InvariantEnergy::small_strain_lame`].
//!
//! ## Stress and tangent from the invariants
//!
//! With `I₁ = tr C`, `I₂ = ½(I₁² − C:C)`, `J = √det C` and their gradients
//!
//! ```text
//! g₁ = ∂I₁/∂C = I,   g₂ = ∂I₂/∂C = I₁ I − C,   g_J = ∂J/∂C = ½ J C⁻¹,
//! ```
//!
//! the stress is `S = 2 Σ_a W_a g_a` and the tangent
//!
//! ```text
//! 𝕔 = ∂S/∂E = 4 Σ_ab W_ab g_a ⊗ g_b + 4 W₂ (I ⊗ I − 𝕀) + W_J J (C⁻¹ ⊗ C⁻¹ − 2 𝕀_{C⁻¹}),
//! ```
//!
//! where `W_a = ∂W/∂a`, `W_ab = ∂²W/∂a∂b`, `𝕀_ijkl = ½(δ_ik δ_jl + δ_il δ_jk)` and
//! `(𝕀_{C⁻¹})_ijkl = ½(C⁻¹_ik C⁻¹_jl + C⁻¹_il C⁻¹_jk)`. In 2D the law is in plane strain:
//! `C` is embedded as `diag(C₂ₓ₂, 1)` (`E_zz = 0`) and the in-plane rows are kept; the
//! out-of-plane stress `S_zz` is [`Material::out_of_plane_stress`].
//!
//! A strain with `det C ≤ 0` (an inverted element) or a non-finite one gives NaN stresses,
//! tangents and energies, which the nonlinear solvers detect (and cut the step back).

use nalgebra::Matrix3;

use crate::isotropic::IsotropicParameters;
use crate::voigt::{check_finite, voigt_pairs};
use crate::{Material, MaterialError, VoigtMatrix, VoigtVector};

/// The invariants `I₁ = tr C`, `I₂ = ½(I₁² − C:C)`, `J = √det C` of a right Cauchy–Green
/// tensor `C`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Invariants {
    /// `I₁ = tr C`.
    pub i1: f64,
    /// `I₂ = ½((tr C)² − C:C)`.
    pub i2: f64,
    /// `J = √det C = det F` (volume ratio).
    pub j: f64,
}

/// An isotropic strain energy `W(I₁, I₂, J)` per unit reference volume, with its first and
/// second derivatives: the one thing a user writes for a hyperelastic law of their own, wrapped
/// in [`Hyperelastic`] to become a [`Material`].
///
/// Implementations must be stress-free at `C = I` (`2W₁ + 4W₂ + W_J = 0` at `I₁ = I₂ = 3`,
/// `J = 1`) and their derivatives consistent with `energy` (checked for the built-in laws by
/// finite differences in the tests).
pub trait InvariantEnergy: Send + Sync + std::fmt::Debug {
    /// `W(I₁, I₂, J)`.
    fn energy(&self, invariants: &Invariants) -> f64;
    /// `(W₁, W₂, W_J) = (∂W/∂I₁, ∂W/∂I₂, ∂W/∂J)`.
    fn gradient(&self, invariants: &Invariants) -> [f64; 3];
    /// The symmetric matrix of second derivatives in the order `(I₁, I₂, J)`.
    fn hessian(&self, invariants: &Invariants) -> [[f64; 3]; 3];
    /// The Lamé parameters `(λ, μ)` of the linearisation at `C = I` (what a linear solve or a
    /// small load sees).
    fn small_strain_lame(&self) -> (f64, f64);
    /// A short name (`"neo-Hookean"`, ...).
    fn name(&self) -> String;
}

/// The compressible neo-Hookean energy
/// `W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²` (the form of FEBio's `neo-Hookean` and of
/// Bonet & Wood, *Nonlinear Continuum Mechanics for FEA*, §6.4.3), with Cauchy stress
/// `σ = μ/J (B − I) + λ ln J / J I`, `B = FFᵀ`. Linearised: isotropic elasticity with `λ`, `μ`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookean {
    lambda: f64,
    mu: f64,
}

impl NeoHookean {
    /// From the Lamé parameters (`μ > 0`, `3λ + 2μ > 0`).
    ///
    /// # Errors
    /// As [`IsotropicParameters::from_lame`].
    pub fn from_lame(lambda: f64, mu: f64) -> Result<Self, MaterialError> {
        let p = IsotropicParameters::from_lame(lambda, mu)?;
        Ok(Self { lambda: p.lambda(), mu: p.mu() })
    }

    /// From the small-strain Young's modulus `E > 0` and Poisson ratio `−1 < ν < ½`.
    ///
    /// # Errors
    /// As [`IsotropicParameters::new`].
    pub fn from_young_poisson(youngs_modulus: f64, poisson_ratio: f64) -> Result<Self, MaterialError> {
        let p = IsotropicParameters::new(youngs_modulus, poisson_ratio)?;
        Ok(Self { lambda: p.lambda(), mu: p.mu() })
    }

    /// `λ`.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// `μ`.
    pub fn mu(&self) -> f64 {
        self.mu
    }
}

impl InvariantEnergy for NeoHookean {
    fn energy(&self, inv: &Invariants) -> f64 {
        let l = inv.j.ln();
        0.5 * self.mu * (inv.i1 - 3.0) - self.mu * l + 0.5 * self.lambda * l * l
    }
    fn gradient(&self, inv: &Invariants) -> [f64; 3] {
        let l = inv.j.ln();
        [0.5 * self.mu, 0.0, (-self.mu + self.lambda * l) / inv.j]
    }
    fn hessian(&self, inv: &Invariants) -> [[f64; 3]; 3] {
        let l = inv.j.ln();
        let wjj = (self.mu + self.lambda * (1.0 - l)) / (inv.j * inv.j);
        [[0.0; 3], [0.0; 3], [0.0, 0.0, wjj]]
    }
    fn small_strain_lame(&self) -> (f64, f64) {
        (self.lambda, self.mu)
    }
    fn name(&self) -> String {
        format!("neo-Hookean (lambda = {}, mu = {})", self.lambda, self.mu)
    }
}

/// The compressible (coupled) Mooney–Rivlin energy
/// `W = c₁(I₁ − 3) + c₂(I₂ − 3) − 2(c₁ + 2c₂) ln J + λ/2 (ln J)²`, stress-free at `C = I`.
/// Linearised: isotropic elasticity with `μ = 2(c₁ + c₂)` and `λ₀ = λ + 4c₂`. With `c₂ = 0` it
/// is the neo-Hookean law with `μ = 2c₁`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MooneyRivlin {
    c1: f64,
    c2: f64,
    lambda: f64,
}

impl MooneyRivlin {
    /// From `c₁`, `c₂` and the volumetric coefficient `λ`; the linearisation must be admissible
    /// (`μ = 2(c₁ + c₂) > 0`, `3λ₀ + 2μ > 0` with `λ₀ = λ + 4c₂`), and `c₁`, `c₂`, `λ ≥ 0`.
    ///
    /// # Errors
    /// [`MaterialError::NonFinite`], [`MaterialError::InadmissibleLame`] (negative constants
    /// are reported here too), and the errors of [`IsotropicParameters::from_lame`].
    pub fn new(c1: f64, c2: f64, lambda: f64) -> Result<Self, MaterialError> {
        let c1 = check_finite(c1, "Mooney-Rivlin c1")?;
        let c2 = check_finite(c2, "Mooney-Rivlin c2")?;
        let lambda = check_finite(lambda, "Mooney-Rivlin lambda")?;
        if c1 < 0.0 || c2 < 0.0 || lambda < 0.0 {
            return Err(MaterialError::InadmissibleLame {
                lambda,
                mu: 2.0 * (c1 + c2),
                condition: "c1 >= 0, c2 >= 0 and lambda >= 0 (Mooney-Rivlin)",
            });
        }
        IsotropicParameters::from_lame(lambda + 4.0 * c2, 2.0 * (c1 + c2))?;
        Ok(Self { c1, c2, lambda })
    }

    /// `(c₁, c₂, λ)`.
    pub fn constants(&self) -> (f64, f64, f64) {
        (self.c1, self.c2, self.lambda)
    }
}

impl InvariantEnergy for MooneyRivlin {
    fn energy(&self, inv: &Invariants) -> f64 {
        let l = inv.j.ln();
        self.c1 * (inv.i1 - 3.0) + self.c2 * (inv.i2 - 3.0) - 2.0 * (self.c1 + 2.0 * self.c2) * l
            + 0.5 * self.lambda * l * l
    }
    fn gradient(&self, inv: &Invariants) -> [f64; 3] {
        let l = inv.j.ln();
        [self.c1, self.c2, (-2.0 * (self.c1 + 2.0 * self.c2) + self.lambda * l) / inv.j]
    }
    fn hessian(&self, inv: &Invariants) -> [[f64; 3]; 3] {
        let l = inv.j.ln();
        let wjj = (2.0 * (self.c1 + 2.0 * self.c2) + self.lambda * (1.0 - l)) / (inv.j * inv.j);
        [[0.0; 3], [0.0; 3], [0.0, 0.0, wjj]]
    }
    fn small_strain_lame(&self) -> (f64, f64) {
        (self.lambda + 4.0 * self.c2, 2.0 * (self.c1 + self.c2))
    }
    fn name(&self) -> String {
        format!("Mooney-Rivlin (c1 = {}, c2 = {}, lambda = {})", self.c1, self.c2, self.lambda)
    }
}

/// An isotropic hyperelastic [`Material`] from its energy `W(I₁, I₂, J)` (see the module docs:
/// the strain is the Green–Lagrange strain under finite-strain kinematics, the stress the
/// second Piola–Kirchhoff stress; in 2D plane strain).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hyperelastic<E> {
    energy: E,
}

impl<E: InvariantEnergy> Hyperelastic<E> {
    /// The law of `energy`.
    pub fn new(energy: E) -> Self {
        Self { energy }
    }

    /// The energy.
    pub fn energy(&self) -> &E {
        &self.energy
    }
}

/// The compressible neo-Hookean law from Young's modulus and Poisson ratio (small-strain
/// values), as a [`Material`].
///
/// # Errors
/// As [`NeoHookean::from_young_poisson`].
pub fn neo_hookean(
    youngs_modulus: f64,
    poisson_ratio: f64,
) -> Result<Hyperelastic<NeoHookean>, MaterialError> {
    Ok(Hyperelastic::new(NeoHookean::from_young_poisson(youngs_modulus, poisson_ratio)?))
}

/// The compressible Mooney–Rivlin law `(c₁, c₂, λ)` as a [`Material`].
///
/// # Errors
/// As [`MooneyRivlin::new`].
pub fn mooney_rivlin(c1: f64, c2: f64, lambda: f64) -> Result<Hyperelastic<MooneyRivlin>, MaterialError> {
    Ok(Hyperelastic::new(MooneyRivlin::new(c1, c2, lambda)?))
}

/// `C = I + 2E` (3×3, plane strain in 2D) from a Voigt strain with engineering shear; `None`
/// for a wrong length or a non-finite entry.
fn cauchy_green(d: usize, strain: &VoigtVector) -> Option<Matrix3<f64>> {
    let pairs = voigt_pairs(d).ok()?;
    if strain.len() != pairs.len() || strain.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut c = Matrix3::identity();
    for (r, &(i, j)) in pairs.iter().enumerate() {
        if i == j {
            c[(i, i)] += 2.0 * strain[r];
        } else {
            // engineering shear γ = 2E_ij: C_ij = 2E_ij = γ
            c[(i, j)] += strain[r];
            c[(j, i)] += strain[r];
        }
    }
    Some(c)
}

/// Invariants, `C⁻¹` and the gradients `(g₁, g₂, g_J)` at `C`; `None` if `det C ≤ 0`.
struct AtC {
    inv: Invariants,
    c_inv: Matrix3<f64>,
    g: [Matrix3<f64>; 3],
}

fn at_c(c: &Matrix3<f64>) -> Option<AtC> {
    let i1 = c.trace();
    let i2 = 0.5 * (i1 * i1 - c.component_mul(c).sum());
    let i3 = c.determinant();
    if i3.is_nan() || i3 <= 0.0 || !i3.is_finite() {
        return None;
    }
    let j = i3.sqrt();
    let c_inv = c.try_inverse()?;
    let id = Matrix3::identity();
    let g = [id, id * i1 - c, c_inv * (0.5 * j)];
    Some(AtC { inv: Invariants { i1, i2, j }, c_inv, g })
}

impl<E: InvariantEnergy> Hyperelastic<E> {
    /// The 3×3 second Piola–Kirchhoff stress `S = 2 Σ_a W_a g_a` at `C` (`None` if `det C ≤ 0`).
    pub fn second_piola_kirchhoff(&self, c: &Matrix3<f64>) -> Option<Matrix3<f64>> {
        let a = at_c(c)?;
        Some(self.stress_at(&a))
    }

    fn stress_at(&self, a: &AtC) -> Matrix3<f64> {
        let w = self.energy.gradient(&a.inv);
        (a.g[0] * w[0] + a.g[1] * w[1] + a.g[2] * w[2]) * 2.0
    }

    /// The Voigt tangent `∂S/∂E` at `a` over the index pairs `pairs`.
    fn tangent_at(&self, a: &AtC, pairs: &[(usize, usize)]) -> VoigtMatrix {
        let n = pairs.len();
        let w = self.energy.gradient(&a.inv);
        let h = self.energy.hessian(&a.inv);
        let mut t = VoigtMatrix::zeros(n, n);
        for (r, &(i, j)) in pairs.iter().enumerate() {
            for (s, &(k, l)) in pairs.iter().enumerate() {
                t[(r, s)] = self.tangent_entry(a, &w, &h, (i, j, k, l));
            }
        }
        // symmetric by construction; remove rounding asymmetry
        let tt = t.transpose();
        (t + tt) * 0.5
    }

    /// `𝕔_ijkl = ∂S_ij/∂E_kl` (module docs).
    fn tangent_entry(
        &self,
        a: &AtC,
        w: &[f64; 3],
        h: &[[f64; 3]; 3],
        (i, j, k, l): (usize, usize, usize, usize),
    ) -> f64 {
        let delta = |p: usize, q: usize| if p == q { 1.0 } else { 0.0 };
        let mut v = 0.0;
        for (p, hp) in h.iter().enumerate() {
            for (q, hpq) in hp.iter().enumerate() {
                if *hpq != 0.0 {
                    v += 4.0 * hpq * a.g[p][(i, j)] * a.g[q][(k, l)];
                }
            }
        }
        let sym_id = 0.5 * (delta(i, k) * delta(j, l) + delta(i, l) * delta(j, k));
        v += 4.0 * w[1] * (delta(i, j) * delta(k, l) - sym_id);
        let ci = &a.c_inv;
        let sym_ci = 0.5 * (ci[(i, k)] * ci[(j, l)] + ci[(i, l)] * ci[(j, k)]);
        v += w[2] * a.inv.j * (ci[(i, j)] * ci[(k, l)] - 2.0 * sym_ci);
        v
    }
}

impl<E: InvariantEnergy, const D: usize> Material<D> for Hyperelastic<E> {
    fn stress(&self, strain: &VoigtVector) -> VoigtVector {
        let n = D * (D + 1) / 2;
        let Some(pairs) = voigt_pairs(D).ok() else { return VoigtVector::from_element(n, f64::NAN) };
        let Some(a) = cauchy_green(D, strain).and_then(|c| at_c(&c)) else {
            return VoigtVector::from_element(n, f64::NAN);
        };
        let s = self.stress_at(&a);
        VoigtVector::from_iterator(n, pairs.iter().map(|&(i, j)| s[(i, j)]))
    }

    fn tangent(&self, strain: &VoigtVector) -> VoigtMatrix {
        let n = D * (D + 1) / 2;
        let Some(pairs) = voigt_pairs(D).ok() else { return VoigtMatrix::from_element(n, n, f64::NAN) };
        let Some(a) = cauchy_green(D, strain).and_then(|c| at_c(&c)) else {
            return VoigtMatrix::from_element(n, n, f64::NAN);
        };
        self.tangent_at(&a, pairs)
    }

    /// One evaluation of the invariants and `C⁻¹` for the stress, the energy and the tangent
    /// (the same values as the three separate calls).
    fn response(&self, strain: &VoigtVector, with_tangent: bool) -> (VoigtVector, f64, Option<VoigtMatrix>) {
        let n = D * (D + 1) / 2;
        let (Some(pairs), Some(a)) = (voigt_pairs(D).ok(), cauchy_green(D, strain).and_then(|c| at_c(&c)))
        else {
            return (
                VoigtVector::from_element(n, f64::NAN),
                f64::NAN,
                with_tangent.then(|| VoigtMatrix::from_element(n, n, f64::NAN)),
            );
        };
        let s = self.stress_at(&a);
        let stress = VoigtVector::from_iterator(n, pairs.iter().map(|&(i, j)| s[(i, j)]));
        (stress, self.energy.energy(&a.inv), with_tangent.then(|| self.tangent_at(&a, pairs)))
    }

    fn energy_density(&self, strain: &VoigtVector) -> f64 {
        match cauchy_green(D, strain).and_then(|c| at_c(&c)) {
            Some(a) => self.energy.energy(&a.inv),
            None => f64::NAN,
        }
    }

    fn out_of_plane_stress(&self, strain: &VoigtVector) -> f64 {
        if D != 2 {
            return 0.0;
        }
        match cauchy_green(D, strain).and_then(|c| at_c(&c)) {
            Some(a) => self.stress_at(&a)[(2, 2)],
            None => f64::NAN,
        }
    }

    fn name(&self) -> String {
        self.energy.name()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::isotropic;

    fn strain3(v: [f64; 6]) -> VoigtVector {
        VoigtVector::from_row_slice(&v)
    }

    /// `response` evaluates the invariants once and returns the stress, energy and tangent of
    /// the three separate calls, to the last bit, in 2D and 3D, for both laws; outside the
    /// domain (`det C ≤ 0`) all three are NaN.
    #[test]
    fn response_equals_the_separate_calls_bit_for_bit() {
        fn check<const D: usize>(law: &dyn Material<D>, strain: &VoigtVector) {
            let (stress, energy, tangent) = law.response(strain, true);
            let want = (law.stress(strain), law.energy_density(strain), law.tangent(strain));
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(stress.as_slice()), bits(want.0.as_slice()), "stress");
            assert_eq!(energy.to_bits(), want.1.to_bits(), "energy");
            let tangent = tangent.expect("asked for");
            assert_eq!(bits(tangent.as_slice()), bits(want.2.as_slice()), "tangent");
            let (_, _, none) = law.response(strain, false);
            assert!(none.is_none());
        }
        let nh = neo_hookean(10.0, 0.45).expect("test data");
        let mr = mooney_rivlin(1.2, 0.4, 30.0).expect("test data");
        let s2 = VoigtVector::from_row_slice(&[-0.21, 0.07, 0.13]);
        let s3 = strain3([-0.18, 0.05, 0.02, 0.04, -0.03, 0.11]);
        check::<2>(&nh, &s2);
        check::<2>(&mr, &s2);
        check::<3>(&nh, &s3);
        check::<3>(&mr, &s3);
        // det C ≤ 0: E_xx = −0.6 gives C_xx = −0.2
        let (stress, energy, tangent) = <Hyperelastic<NeoHookean> as Material<2>>::response(
            &nh,
            &VoigtVector::from_row_slice(&[-0.6, 0.0, 0.0]),
            true,
        );
        assert!(stress.iter().all(|v| v.is_nan()) && energy.is_nan());
        assert!(tangent.is_some_and(|t| t.iter().all(|v| v.is_nan())));
        // the default of the trait (a linear law) is the three calls as well
        let lin = crate::plane_strain(10.0, 0.3).expect("test data");
        check::<2>(&lin, &s2);
    }

    #[test]
    fn linearisation_at_zero_strain_is_isotropic_elasticity() {
        let nh = neo_hookean(1000.0, 0.3).expect("test data");
        let lin = isotropic(1000.0, 0.3).expect("test data");
        let t3 = <Hyperelastic<NeoHookean> as Material<3>>::tangent(&nh, &VoigtVector::zeros(6));
        let c3 = <crate::LinearElastic<3> as Material<3>>::tangent(&lin, &VoigtVector::zeros(6));
        assert!((t3 - c3).abs().max() < 1e-10);
        let mr = mooney_rivlin(100.0, 30.0, 500.0).expect("test data");
        let (l0, mu) = mr.energy().small_strain_lame();
        assert!((mu - 260.0).abs() < 1e-12 && (l0 - 620.0).abs() < 1e-12);
        let lin = crate::from_lame(l0, mu).expect("test data");
        let t = <Hyperelastic<MooneyRivlin> as Material<3>>::tangent(&mr, &VoigtVector::zeros(6));
        let c = <crate::LinearElastic<3> as Material<3>>::tangent(&lin, &VoigtVector::zeros(6));
        assert!((&t - &c).abs().max() < 1e-9, "{t} vs {c}");
    }

    /// stress = ∂Φ/∂e and tangent = ∂stress/∂e by central differences at a large strain.
    #[test]
    fn stress_and_tangent_are_derivatives_of_the_energy() {
        let laws: Vec<Box<dyn Material<3>>> = vec![
            Box::new(neo_hookean(10.0, 0.4).expect("test data")),
            Box::new(mooney_rivlin(2.0, 1.5, 30.0).expect("test data")),
        ];
        let e = strain3([0.21, -0.08, 0.13, 0.17, -0.09, 0.25]);
        for law in &laws {
            let s = law.stress(&e);
            let t = law.tangent(&e);
            let h = 1e-6;
            for r in 0..6 {
                let mut ep = e.clone();
                let mut em = e.clone();
                ep[r] += h;
                em[r] -= h;
                let ds = (law.energy_density(&ep) - law.energy_density(&em)) / (2.0 * h);
                assert!(
                    (ds - s[r]).abs() < 1e-7 * (1.0 + s[r].abs()),
                    "{}: dW/de{r} {ds} vs {}",
                    law.name(),
                    s[r]
                );
                let dt = (law.stress(&ep) - law.stress(&em)) / (2.0 * h);
                for q in 0..6 {
                    assert!(
                        (dt[q] - t[(q, r)]).abs() < 1e-6 * (1.0 + t[(q, r)].abs()),
                        "{}: tangent ({q},{r})",
                        law.name()
                    );
                }
            }
        }
    }

    #[test]
    fn plane_strain_is_the_3d_law_with_zero_out_of_plane_strain() {
        let nh = neo_hookean(10.0, 0.3).expect("test data");
        let e2 = VoigtVector::from_row_slice(&[0.1, -0.05, 0.2]);
        let e3 = strain3([0.1, -0.05, 0.0, 0.0, 0.0, 0.2]);
        let s2 = <Hyperelastic<NeoHookean> as Material<2>>::stress(&nh, &e2);
        let s3 = <Hyperelastic<NeoHookean> as Material<3>>::stress(&nh, &e3);
        assert!(
            (s2[0] - s3[0]).abs() < 1e-14 && (s2[1] - s3[1]).abs() < 1e-14 && (s2[2] - s3[5]).abs() < 1e-14
        );
        let szz = <Hyperelastic<NeoHookean> as Material<2>>::out_of_plane_stress(&nh, &e2);
        assert!((szz - s3[2]).abs() < 1e-14);
    }

    #[test]
    fn inverted_strain_and_bad_constants() {
        let nh = neo_hookean(10.0, 0.3).expect("test data");
        // C = I + 2E with E_xx = -0.6: C_xx = -0.2 < 0, det C < 0
        let s =
            <Hyperelastic<NeoHookean> as Material<3>>::stress(&nh, &strain3([-0.6, 0.0, 0.0, 0.0, 0.0, 0.0]));
        assert!(s.iter().all(|v| v.is_nan()));
        assert!(
            <Hyperelastic<NeoHookean> as Material<3>>::energy_density(&nh, &VoigtVector::zeros(5)).is_nan()
        );
        assert!(neo_hookean(-1.0, 0.3).is_err());
        assert!(neo_hookean(1.0, 0.5).is_err());
        assert!(mooney_rivlin(-1.0, 0.0, 1.0).is_err());
        assert!(mooney_rivlin(0.0, 0.0, 1.0).is_err());
        assert!(mooney_rivlin(f64::NAN, 0.0, 1.0).is_err());
    }
}
