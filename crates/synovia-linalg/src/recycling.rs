//! Recycled solves: `A⁻¹ F` for a load `F` in the span of loads already solved.
//!
//! Loads of a joint model are mostly combinations of a few fixed patterns: a load history
//! `F(t) = Σ_i h_i(t) F_i`, a prescribed motion `u_p(t) = Σ_i δ_i(t) e_i` (its lift load is
//! linear in the `δ_i`), a force turned with a body frame. [`LoadSubspace`] keeps an
//! orthonormal basis `Q` of the loads solved so far, their solutions `Z ≈ A⁻¹ Q` and the
//! residual norms `ρ_j = ‖A z_j − q_j‖`. For a new load it computes `c = Qᵀ F` and
//! `r = F − Q c` (modified Gram–Schmidt). Since
//!
//! ```text
//! A (Z c) − F = Σ_j c_j (A z_j − q_j) − r,   so   ‖A (Z c) − F‖ ≤ Σ_j |c_j| ρ_j + ‖r‖,
//! ```
//!
//! the recycled solution `Z c` (O(m n) work for `m` directions, no solve with the factor) is
//! used when that bound is at most `τ ‖F‖` (`τ = 10⁻¹²`, the backward error of a direct solve
//! of these systems is 10⁻¹⁵–10⁻¹³). Otherwise the load is solved with the factor and, if
//! `r` is a new direction, `q = r/‖r‖`, `z = (A⁻¹ F − Z c)/‖r‖` are appended (after a second
//! Gram–Schmidt pass) with `ρ = ‖A z − q‖` measured by one product with `A` — a direction
//! derived from a small `‖r‖` loses digits to cancellation, and `ρ` says how many: above
//! `10⁻¹³` the direction gets one step of iterative refinement (one more solve, once per
//! direction), and the bound decides with the measured `ρ` in any case.

use crate::error::LinalgError;
use crate::operator::FactorisedOperator;

/// Relative residual bound `‖A x − F‖ / ‖F‖` of a recycled solution.
const RECYCLED_RESIDUAL: f64 = 1e-12;
/// Residual `‖A z − q‖` of a new direction above which `z` gets one step of iterative
/// refinement (a direct solve of these systems reaches 10⁻¹⁵–10⁻¹³).
const REFINE_ABOVE: f64 = 1e-13;
/// Smallest relative residual `‖r‖ / ‖F‖` of a load whose direction is added to the basis.
const NEW_DIRECTION: f64 = 1e-10;

/// Orthonormal loads `Q`, their solutions `Z ≈ A⁻¹ Q` and residuals for one factorisation.
#[derive(Debug, Clone, Default)]
pub struct LoadSubspace {
    basis: Vec<Vec<f64>>,
    solutions: Vec<Vec<f64>>,
    residuals: Vec<f64>,
    capacity: usize,
    reused: usize,
    solved: usize,
}

impl LoadSubspace {
    /// An empty subspace holding at most `capacity` directions (when full, the oldest is
    /// dropped; 0 disables recycling).
    pub fn new(capacity: usize) -> Self {
        Self { capacity, ..Self::default() }
    }

    /// Number of directions held.
    pub fn len(&self) -> usize {
        self.basis.len()
    }
    /// `true` if no direction is held.
    pub fn is_empty(&self) -> bool {
        self.basis.is_empty()
    }
    /// `(reused, solved)`: loads answered from the subspace and loads solved with the factor.
    pub fn counts(&self) -> (usize, usize) {
        (self.reused, self.solved)
    }
    /// Forgets every direction (call when `A` changes).
    pub fn clear(&mut self) {
        self.basis.clear();
        self.solutions.clear();
        self.residuals.clear();
    }

    /// `A⁻¹ load` for the factorised operator `operator`: from the subspace when the
    /// residual bound of the [module documentation](self) allows it, otherwise by a solve with
    /// the operator (the load's new direction is then kept).
    ///
    /// # Errors
    /// [`LinalgError::InvalidParameter`] if `load` and `operator` do not have the same
    /// dimension or `load` is not finite; the solve's errors.
    pub fn solve(
        &mut self,
        operator: &dyn FactorisedOperator,
        load: &[f64],
    ) -> Result<Vec<f64>, LinalgError> {
        let n = operator.n();
        if load.len() != n || load.iter().any(|v| !v.is_finite()) {
            return Err(LinalgError::InvalidParameter(format!(
                "load of length {} (finite entries needed) for an operator of dimension {n}",
                load.len(),
            )));
        }
        if self.basis.first().is_some_and(|q| q.len() != n) {
            self.clear();
        }
        let norm = dot(load, load).sqrt();
        if norm == 0.0 {
            self.reused += 1;
            return Ok(vec![0.0; n]);
        }
        let mut coeffs = vec![0.0; self.basis.len()];
        let mut residual = load.to_vec();
        self.orthogonalise(&mut coeffs, &mut residual);
        let mut rnorm = dot(&residual, &residual).sqrt();
        let bound = rnorm + coeffs.iter().zip(&self.residuals).map(|(c, r)| c.abs() * r).sum::<f64>();
        if bound <= RECYCLED_RESIDUAL * norm {
            let mut x = vec![0.0; n];
            for (c, z) in coeffs.iter().zip(&self.solutions) {
                axpy(*c, z, &mut x);
            }
            self.reused += 1;
            return Ok(x);
        }
        let mut x = load.to_vec();
        operator.solve_in_place(&mut x)?;
        self.solved += 1;
        if self.capacity > 0 && rnorm >= NEW_DIRECTION * norm {
            if self.basis.len() == self.capacity {
                // make room first, so that the new load lies in the span it leaves
                self.basis.remove(0);
                self.solutions.remove(0);
                self.residuals.remove(0);
                coeffs = vec![0.0; self.basis.len()];
                residual.copy_from_slice(load);
                self.orthogonalise(&mut coeffs, &mut residual);
            }
            // second Gram–Schmidt pass ("twice is enough") for an orthonormal basis
            self.orthogonalise(&mut coeffs, &mut residual);
            rnorm = dot(&residual, &residual).sqrt();
            let mut z = x.clone();
            for (c, zj) in coeffs.iter().zip(&self.solutions) {
                axpy(-c, zj, &mut z);
            }
            let inv = 1.0 / rnorm;
            residual.iter_mut().for_each(|v| *v *= inv);
            z.iter_mut().for_each(|v| *v *= inv);
            let mut az = operator.apply(&z);
            let mut rho = residual_norm(&az, &residual);
            if rho > REFINE_ABOVE {
                // cancellation in z (a small ‖r‖): one step of iterative refinement,
                // z ← z + A⁻¹ (q − A z), one more solve for this direction only
                let mut correction: Vec<f64> = residual.iter().zip(&az).map(|(q, a)| q - a).collect();
                operator.solve_in_place(&mut correction)?;
                z.iter_mut().zip(&correction).for_each(|(z, c)| *z += c);
                az = operator.apply(&z);
                rho = residual_norm(&az, &residual);
            }
            self.basis.push(residual);
            self.solutions.push(z);
            self.residuals.push(rho);
        }
        Ok(x)
    }

    /// One modified Gram–Schmidt pass of `residual` against the basis, accumulating the
    /// coefficients.
    fn orthogonalise(&self, coeffs: &mut [f64], residual: &mut [f64]) {
        for (c, q) in coeffs.iter_mut().zip(&self.basis) {
            let a = dot(q, residual);
            *c += a;
            axpy(-a, q, residual);
        }
    }
}

/// `‖a − q‖₂`.
fn residual_norm(a: &[f64], q: &[f64]) -> f64 {
    a.iter().zip(q).map(|(a, q)| (a - q) * (a - q)).sum::<f64>().sqrt()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    y.iter_mut().zip(x).for_each(|(y, x)| *y += a * x);
}
