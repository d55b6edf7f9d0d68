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
//! of these systems is 10⁻¹⁵–10⁻¹³). Otherwise, if `r` is a new direction (`‖r‖ ≥ 10⁻¹⁰ ‖F‖`)
//! and the basis is not empty, the direction itself is solved (after a second Gram–Schmidt
//! pass): `q = r/‖r‖`, `z = A⁻¹ q`, `ρ = ‖A z − q‖` measured by one product with `A`, and
//! `A⁻¹ F = Z c + ‖r‖ z` (the bound above with `ρ`, else a direct solve of `F`) — one solve,
//! where `z = (A⁻¹ F − Z c)/‖r‖` from a solve of `F` would lose digits to cancellation for a
//! small `‖r‖` (e.g. a small tangential shift added to a normal load) and need a second,
//! refining one. The first direction is `q = F/‖F‖`, `z = A⁻¹ F/‖F‖` from the solve of `F`.
//! A direction whose `ρ` exceeds `10⁻¹³` gets one step of iterative refinement (one more
//! solve), and the bound decides with the measured `ρ` in any case.

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
        self.solved += 1;
        if self.capacity > 0 && rnorm >= NEW_DIRECTION * norm && !self.basis.is_empty() {
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
            // the new direction q = r/‖r‖ is solved itself, z = A⁻¹ q: no cancellation (as
            // in z = (A⁻¹ F − Z c)/‖r‖ for a small ‖r‖, which needed a refinement step, i.e.
            // a second solve), and A⁻¹ F = Z c + ‖r‖ z within the residual bound
            let inv = 1.0 / rnorm;
            residual.iter_mut().for_each(|v| *v *= inv);
            let (z, rho) = self.solve_direction(operator, &residual)?;
            self.basis.push(residual);
            self.solutions.push(z);
            self.residuals.push(rho);
            coeffs.push(rnorm);
            let bound = coeffs.iter().zip(&self.residuals).map(|(c, r)| c.abs() * r).sum::<f64>();
            if bound <= RECYCLED_RESIDUAL * norm {
                let mut x = vec![0.0; n];
                for (c, z) in coeffs.iter().zip(&self.solutions) {
                    axpy(*c, z, &mut x);
                }
                return Ok(x);
            }
            let mut x = load.to_vec();
            operator.solve_in_place(&mut x)?;
            return Ok(x);
        }
        let mut x = load.to_vec();
        operator.solve_in_place(&mut x)?;
        if self.capacity > 0 && rnorm >= NEW_DIRECTION * norm {
            // the first direction: q = F/‖F‖, z = A⁻¹ q from the solve of F
            let inv = 1.0 / rnorm;
            residual.iter_mut().for_each(|v| *v *= inv);
            let mut z: Vec<f64> = x.iter().map(|v| v * inv).collect();
            let mut az = operator.apply(&z);
            let mut rho = residual_norm(&az, &residual);
            if rho > REFINE_ABOVE {
                refine(operator, &residual, &mut z, &mut az)?;
                rho = residual_norm(&az, &residual);
            }
            self.basis.push(residual);
            self.solutions.push(z);
            self.residuals.push(rho);
        }
        Ok(x)
    }

    /// `z = A⁻¹ q` for a unit direction `q` and its residual `ρ = ‖A z − q‖` (one product with
    /// `A`), with one step of iterative refinement when `ρ` exceeds [`REFINE_ABOVE`].
    fn solve_direction(
        &self,
        operator: &dyn FactorisedOperator,
        q: &[f64],
    ) -> Result<(Vec<f64>, f64), LinalgError> {
        let mut z = q.to_vec();
        operator.solve_in_place(&mut z)?;
        let mut az = operator.apply(&z);
        let mut rho = residual_norm(&az, q);
        if rho > REFINE_ABOVE {
            refine(operator, q, &mut z, &mut az)?;
            rho = residual_norm(&az, q);
        }
        Ok((z, rho))
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
/// One step of iterative refinement of `z ≈ A⁻¹ q` with `az = A z`: `z ← z + A⁻¹ (q − A z)`
/// (one solve), `az` updated.
fn refine(
    operator: &dyn FactorisedOperator,
    q: &[f64],
    z: &mut [f64],
    az: &mut Vec<f64>,
) -> Result<(), LinalgError> {
    let mut correction: Vec<f64> = q.iter().zip(az.iter()).map(|(q, a)| q - a).collect();
    operator.solve_in_place(&mut correction)?;
    z.iter_mut().zip(&correction).for_each(|(z, c)| *z += c);
    *az = operator.apply(z);
    Ok(())
}

fn residual_norm(a: &[f64], q: &[f64]) -> f64 {
    a.iter().zip(q).map(|(a, q)| (a - q) * (a - q)).sum::<f64>().sqrt()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    y.iter_mut().zip(x).for_each(|(y, x)| *y += a * x);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Ordering, SparseCholesky, SymmetricMatrix};
    use std::sync::atomic::{AtomicUsize, Ordering as AtomicOrdering};

    /// A factorised operator that counts its solves.
    #[derive(Debug)]
    struct Counting {
        op: SparseCholesky,
        solves: AtomicUsize,
    }

    impl FactorisedOperator for Counting {
        fn n(&self) -> usize {
            self.op.n()
        }
        fn apply(&self, x: &[f64]) -> Vec<f64> {
            self.op.apply(x)
        }
        fn diagonal(&self) -> Vec<f64> {
            self.op.diagonal()
        }
        fn key(&self) -> u64 {
            self.op.key()
        }
        fn solve_in_place(&self, b: &mut [f64]) -> Result<(), LinalgError> {
            self.solves.fetch_add(1, AtomicOrdering::Relaxed);
            self.op.solve_in_place(b)
        }
    }

    /// `tridiag(−1, 2 + 10⁻³, −1)` of size `n` (condition number ≈ 4·10³).
    fn matrix(n: usize) -> SymmetricMatrix {
        let columns = (0..n).map(|j| if j + 1 < n { vec![j, j + 1] } else { vec![j] }).collect();
        let mut a = SymmetricMatrix::from_columns(n, columns).expect("pattern");
        for j in 0..n {
            a.add(j, j, 2.001).expect("diagonal");
            if j + 1 < n {
                a.add(j + 1, j, -1.0).expect("off-diagonal");
            }
        }
        a
    }

    /// A load that adds a small new direction to a solved one (`F₂ = F₁ + 10⁻⁶ G`, as a small
    /// tangential shift added to a normal load) takes one solve, the direction's own, and
    /// `A⁻¹ F₂` has a relative residual `‖A x − F₂‖ / ‖F₂‖ ≤ 10⁻¹²` and equals the direct
    /// solve to 1e-12; the direction is kept, so `F₁ + 3·10⁻⁶ G` is recycled without a solve.
    #[test]
    fn a_small_new_direction_takes_one_solve() {
        let n = 400;
        let op = Counting {
            op: SparseCholesky::new(matrix(n), &Ordering::Amd).expect("factor"),
            solves: AtomicUsize::new(0),
        };
        let f1: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.01).sin()).collect();
        let g: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let load = |e: f64| -> Vec<f64> { f1.iter().zip(&g).map(|(a, b)| a + e * b).collect() };
        let direct = |f: &[f64]| {
            let mut x = f.to_vec();
            op.op.solve_in_place(&mut x).expect("solve");
            x
        };
        let check = |x: &[f64], f: &[f64]| {
            let ax = op.op.apply(x);
            let res = ax.iter().zip(f).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
            assert!(res <= 1e-12 * dot(f, f).sqrt(), "relative residual {:e}", res / dot(f, f).sqrt());
            let want = direct(f);
            let scale = want.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let err = x.iter().zip(&want).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs())) / scale;
            assert!(err < 1e-12, "differs from the direct solve by {err:e}");
        };
        let mut sub = LoadSubspace::new(4);
        let x1 = sub.solve(&op, &f1).expect("first");
        check(&x1, &f1);
        let before = op.solves.load(AtomicOrdering::Relaxed);
        let f2 = load(1e-6);
        let x2 = sub.solve(&op, &f2).expect("second");
        assert_eq!(op.solves.load(AtomicOrdering::Relaxed) - before, 1, "one solve for the new direction");
        check(&x2, &f2);
        assert_eq!((sub.len(), sub.counts()), (2, (0, 2)));
        let before = op.solves.load(AtomicOrdering::Relaxed);
        let f3 = load(3e-6);
        let x3 = sub.solve(&op, &f3).expect("recycled");
        assert_eq!(op.solves.load(AtomicOrdering::Relaxed), before, "recycled");
        assert_eq!(sub.counts(), (1, 2));
        check(&x3, &f3);
    }
}
