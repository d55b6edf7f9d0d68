//! Friction laws `F_c(x, |[u'_t]|)` (docs/model.md §3): the Coulomb coefficient, possibly depending on
//! the slip speed (static-to-kinetic decrease). User-replaceable through [`FrictionLaw`].

use std::fmt;
use std::sync::Arc;

use synovia_mesh::math::{Real, Vector};

use crate::error::ContactError;
use crate::operators::ContactGeometry;

/// A Coulomb friction coefficient as a function of the slip speed `v = |[u'_t]| ≥ 0`.
pub trait FrictionLaw: Send + Sync + fmt::Debug {
    /// `F_c(v) ≥ 0`.
    fn coefficient(&self, slip_speed: f64) -> f64;
}

/// The projection `π_r` onto the closed ball of radius `r ≥ 0` in `R^c`, applied in place
/// (docs/model.md §3, §5): `π_r(v) = v` if `‖v‖ ≤ r`, `π_r(v) = v / (‖v‖ / r)` otherwise. With
/// `r = 1` it is the `π` of the friction condition `Λ_t − π(Λ_t + ρ B_Ht (U − U_prev)) = 0`:
/// onto `[−1, 1]` for one tangential component (2D), onto the unit disc for two (3D). The one
/// implementation used by the solvers (`synovia-pdas`, `synovia-uzawa`) and the KKT check
/// ([`crate::check_kkt`]).
///
/// A radius `r = 0` maps every finite `v` to 0; a non-finite norm leaves `v` to the division
/// (NaN stays NaN, so a broken iterate is not hidden).
pub fn project_on_disc(v: &mut [f64], radius: f64) {
    let n = v.iter().map(|a| a * a).sum::<f64>().sqrt();
    if n > radius {
        let s = n / radius;
        v.iter_mut().for_each(|a| *a /= s);
    }
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

/// The friction law `F_c` of every contact pair of a [`ContactGeometry`] and the Coulomb slip
/// bounds they give (docs/model.md §3): `g_c,r = F_c(|[u'_t]|_r) |Λ_n,r|` at each contact node
/// `r`. Shared by the quasi-static and the dynamic steppers (`synovia-time`).
///
/// A pair without a law set uses its constant coefficient [`crate::operators::ContactPair::friction`]
/// (`g_c,r = F_c |Λ_n,r|`, bit for bit [`ContactGeometry::slip_bounds_from_pressure`]).
#[derive(Debug, Clone)]
pub struct PairFrictionLaws {
    names: Vec<String>,
    laws: Vec<Option<Arc<dyn FrictionLaw>>>,
}

impl PairFrictionLaws {
    /// The pairs of `geometry`, each with its constant coefficient.
    pub fn new<const D: usize>(geometry: &ContactGeometry<D>) -> Self {
        let names: Vec<String> = geometry.pairs.iter().map(|(n, _)| n.clone()).collect();
        let laws = vec![None; names.len()];
        Self { names, laws }
    }

    /// Replaces the law of the pair named `pair` (also for a pair built frictionless).
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] for an unknown pair name.
    pub fn set(&mut self, pair: &str, law: Arc<dyn FrictionLaw>) -> Result<(), ContactError> {
        let i = self
            .names
            .iter()
            .position(|n| n == pair)
            .ok_or_else(|| ContactError::InvalidParameter(format!("unknown contact pair `{pair}`")))?;
        self.laws[i] = Some(law);
        Ok(())
    }

    /// The law set for pair `index` (`None`: the pair's constant coefficient).
    pub fn law(&self, index: usize) -> Option<&Arc<dyn FrictionLaw>> {
        self.laws.get(index).and_then(Option::as_ref)
    }

    /// Whether any pair can have friction: a law set, or a positive constant coefficient.
    pub fn any_friction<const D: usize>(&self, geometry: &ContactGeometry<D>) -> bool {
        self.laws.iter().any(Option::is_some) || geometry.nodes.iter().any(|n| n.friction > 0.0)
    }

    /// The slip bounds `g_c,r = F_c(v_r) |p_r|` per contact node from the pressures `p_r` and
    /// the slip speeds `v_r` (docs/model.md §3). A coefficient that is not finite and positive
    /// gives `g_c,r = 0` (no friction there).
    pub fn slip_bounds<const D: usize>(
        &self,
        geometry: &ContactGeometry<D>,
        pressure: &[Real],
        slip_speed: &[Real],
    ) -> Vec<Real> {
        geometry
            .nodes
            .iter()
            .enumerate()
            .map(|(r, node)| {
                let p = pressure.get(r).copied().unwrap_or(0.0);
                match self.law(node.pair) {
                    None => node.friction * p.abs(),
                    Some(law) => {
                        let f = law.coefficient(slip_speed.get(r).copied().unwrap_or(0.0));
                        if f.is_finite() && f > 0.0 {
                            f * p.abs()
                        } else {
                            0.0
                        }
                    }
                }
            })
            .collect()
    }
}

/// The slip speed `|[u'_t]|_r ≈ ‖(I − n_r n_rᵀ)([u^new](s_r) − [u^old](s_r))‖ / Δt` per contact node
/// of `geometry` from two nodal displacement levels `[body][node]` and the time between them
/// (relative to a moving partner: `[u^old]` is [`ContactGeometry::slip_origin`])
/// (docs/model.md §3, §7). A node the displacements do not fit, or `Δt` not finite and positive,
/// gives 0.
pub fn slip_speeds<const D: usize>(
    geometry: &ContactGeometry<D>,
    new: &[Vec<Vector<D>>],
    old: &[Vec<Vector<D>>],
    dt: Real,
) -> Vec<Real> {
    (0..geometry.len())
        .map(|r| {
            if !(dt.is_finite() && dt > 0.0) {
                return 0.0;
            }
            let node = &geometry.nodes[r];
            let v = geometry.jump(r, new).unwrap_or_else(Vector::<D>::zeros)
                - geometry.slip_origin(r, old).unwrap_or_else(Vector::<D>::zeros);
            let vt = v - node.normal * node.normal.dot(&v);
            vt.norm() / dt
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_on_the_disc_is_the_nearest_point() {
        // inside: unchanged (bit for bit)
        let mut v = [0.3, -0.4];
        project_on_disc(&mut v, 1.0);
        assert_eq!(v, [0.3, -0.4]);
        // outside: (3, 4) → (0.6, 0.8), exactly representable division by 5
        let mut v = [3.0, 4.0];
        project_on_disc(&mut v, 1.0);
        assert_eq!(v, [0.6, 0.8]);
        // one component: the interval [−r, r]
        let mut v = [-7.0];
        project_on_disc(&mut v, 2.0);
        assert_eq!(v, [-2.0]);
        // radius 0: the origin
        let mut v = [1.0, -2.0];
        project_on_disc(&mut v, 0.0);
        assert_eq!(v, [0.0, 0.0]);
        // optimality of the projection: (v − π(v))·(w − π(v)) ≤ 0 for every w of the disc
        let v0 = [1.7, -0.9];
        let mut p = v0;
        project_on_disc(&mut p, 1.0);
        assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - 1.0).abs() < 1e-15);
        for k in 0..64 {
            let a = k as f64 * std::f64::consts::TAU / 64.0;
            for r in [0.0, 0.5, 1.0] {
                let w = [r * a.cos(), r * a.sin()];
                let ip = (v0[0] - p[0]) * (w[0] - p[0]) + (v0[1] - p[1]) * (w[1] - p[1]);
                assert!(ip <= 1e-15, "variational inequality violated: {ip}");
            }
        }
    }

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
