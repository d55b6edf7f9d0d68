//! Friction laws `F_c(x, |[u'_t]|)` (docs/model.md §3): the Coulomb coefficient, possibly depending on
//! the slip speed (static-to-kinetic decrease). User-replaceable through [`FrictionLaw`].

use std::fmt;

/// A Coulomb friction coefficient as a function of the slip speed `v = |[u'_t]| ≥ 0`.
pub trait FrictionLaw: Send + Sync + fmt::Debug {
    /// `F_c(v) ≥ 0`.
    fn coefficient(&self, slip_speed: f64) -> f64;
}

/// A constant coefficient `F_c(v) = μ`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantFriction(pub f64);

impl FrictionLaw for ConstantFriction {
    fn coefficient(&self, _slip_speed: f64) -> f64 {
        self.0
    }
}

/// The exponential static-to-kinetic law `F_c(v) = μ_k + (μ_s − μ_k) exp(−v / v_c)` (docs/model.md §3,
/// the report's Fig. 1): `μ_s` at rest, decreasing to `μ_k` over the characteristic speed `v_c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExponentialFriction {
    /// Static coefficient `μ_s`.
    pub static_coefficient: f64,
    /// Kinetic coefficient `μ_k`.
    pub kinetic_coefficient: f64,
    /// Characteristic slip speed `v_c > 0`.
    pub characteristic_speed: f64,
}

impl FrictionLaw for ExponentialFriction {
    fn coefficient(&self, slip_speed: f64) -> f64 {
        let (s, k) = (self.static_coefficient, self.kinetic_coefficient);
        k + (s - k) * (-slip_speed.abs() / self.characteristic_speed).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_law_goes_from_static_to_kinetic() {
        let law = ExponentialFriction {
            static_coefficient: 0.3,
            kinetic_coefficient: 0.1,
            characteristic_speed: 0.01,
        };
        assert!((law.coefficient(0.0) - 0.3).abs() < 1e-15);
        assert!((law.coefficient(1.0) - 0.1).abs() < 1e-12);
        let mid = law.coefficient(0.01);
        assert!((mid - (0.1 + 0.2 / std::f64::consts::E)).abs() < 1e-15);
        assert_eq!(ConstantFriction(0.2).coefficient(5.0), 0.2);
    }
}
