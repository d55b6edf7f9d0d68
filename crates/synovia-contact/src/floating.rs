//! Semi-coercive contact problems (docs/model.md §4): bodies that only the contact holds.
//!
//! A body without Dirichlet data (a floating patella, an implant held by contact alone) leaves
//! rigid motions `R` (the kernel of `A`) free. The contact problem
//! `min_{B_hn U ≤ d} L(U)`, `L(U) = ½ Uᵀ A U − Fᵀ U + j(U)`, then has a solution if and only if
//! the load's rigid part can be balanced by admissible contact forces (Fichera's condition):
//!
//! ```text
//! Rᵀ F = Rᵀ Cᵀ ν   for some ν = (κ Λ_n, Λ_t),  Λ_n ≥ 0,  ‖Λ_t,r‖ ≤ 1.
//! ```
//!
//! [`check_balance`] tests this before any solve (a non-negative least-squares problem in the
//! few rigid-mode unknowns; the friction bound is relaxed, so the test is necessary, not
//! sufficient, with friction) and returns [`ContactError::Unbalanced`] when the load pulls the
//! bodies away or slides them off.
//!
//! The solve itself is a proximal-point iteration with the diagonal spring `S` of
//! [`synovia_fem::Stabilisation`] (positive on the kernel):
//!
//! ```text
//! U_{k+1} = argmin_{B_hn U ≤ d} L(U) + ½ (U − U_k)ᵀ S (U − U_k),
//! ```
//!
//! i.e. the contact problem with `A + S` (factorised once) and load `F + S U_k`. A fixed point
//! is a minimiser of `L` (the optimality conditions coincide when `S (U_{k+1} − U_k) = 0`);
//! the equilibrium residual of the original problem is exactly `−S (U_{k+1} − U_k)`, which
//! is the stopping test. With `S = ε diag(A)`, `ε = 10⁻⁵` (`Stabilisation::EPSILON`), the iteration contracts by about
//! `ε ×` (number of nodes) per step on the modes the contact restrains.

use synovia_fem::Stabilisation;

use crate::error::ContactError;
use crate::problem::{FrictionConstraints, NormalConstraints};

/// Checks Fichera's condition `Rᵀ F ∈ {Rᵀ Cᵀ ν : Λ_n ≥ 0}` (friction rows as free-sign
/// columns) for the kernel `R` of `stabilisation`: `Ok(())` if the rigid part of `load` can be
/// balanced by contact forces to `1e-8 ‖F‖`, [`ContactError::Unbalanced`] otherwise, whose
/// `force` is `net_force(δ_F)` of the unbalanced load `δ_F = Σ_m δ_m r_m`
/// (`δ = Rᵀ F − Rᵀ Cᵀ ν*`, the residual of the non-negative least-squares fit), i.e. the net
/// Cartesian force that nothing holds.
pub fn check_balance(
    stabilisation: &Stabilisation,
    load: &[f64],
    normal: &NormalConstraints,
    friction: Option<&FrictionConstraints>,
    net_force: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Result<(), ContactError> {
    let modes: Vec<&Vec<f64>> = stabilisation.components.iter().flat_map(|c| c.modes.iter()).collect();
    let m = modes.len();
    if m == 0 {
        return Ok(());
    }
    let target: Vec<f64> = modes.iter().map(|r| dot(r, load)).collect();
    let load_norm = load.iter().map(|f| f * f).sum::<f64>().sqrt();
    // columns: normal rows (ν ≥ 0), friction rows with both signs
    let mut columns: Vec<Vec<f64>> = Vec::new();
    // ν = κ Λ_n: the column of ν_r is (C R)_r·, the weights are already in ν.
    push_mode_columns(&mut columns, &modes, &normal.rows, false);
    if let Some(f) = friction {
        push_mode_columns(&mut columns, &modes, &f.rows, true);
    }
    let (x, residual) = nnls(&columns, &target);
    let target_norm = target.iter().map(|g| g * g).sum::<f64>().sqrt();
    if residual <= 1e-8 * load_norm.max(f64::MIN_POSITIVE) || target_norm == 0.0 {
        return Ok(());
    }
    let delta = fit_residual(target, &columns, &x);
    let mut unbalanced = vec![0.0; load.len()];
    add_modes(&mut unbalanced, 1.0, &delta, &modes);
    let bodies = stabilisation.components.iter().flat_map(|c| c.bodies.iter().cloned()).collect();
    Err(ContactError::Unbalanced { bodies, force: net_force(&unbalanced), residual, load: target_norm })
}

/// The load `F` with the part of its rigid-body load that no normal contact force can balance
/// withheld (docs/model.md §4, §7.1): with the orthonormal kernel vectors `r_m` of
/// `stabilisation`, `t = Rᵀ F` and the non-negative least-squares fit
/// `ν* = argmin_{ν ≥ 0} ‖Rᵀ B_hnᵀ ν − t‖` ([`nnls`]), the unbalanced part is
/// `δ = t − Rᵀ B_hnᵀ ν*` and the returned load is
///
/// ```text
/// F_w = F − Σ_m δ_m r_m,      so that   Rᵀ F_w = Rᵀ B_hnᵀ ν*   (balanced by normal contact).
/// ```
///
/// For a body held by friction, `δ` is the tangential load that friction must carry, and the
/// frictionless problem with `F_w` gives the normal pressure from which the Coulomb fixed point
/// starts (`synovia_time::quasistatic`). Also returns `‖δ‖`. A coercive model (no modes)
/// returns `F` unchanged.
pub fn withhold_unbalanced(
    stabilisation: &Stabilisation,
    load: &[f64],
    normal: &NormalConstraints,
) -> (Vec<f64>, f64) {
    let modes: Vec<&Vec<f64>> = stabilisation.components.iter().flat_map(|c| c.modes.iter()).collect();
    if modes.is_empty() {
        return (load.to_vec(), 0.0);
    }
    let target: Vec<f64> = modes.iter().map(|r| dot(r, load)).collect();
    let mut columns = Vec::new();
    push_mode_columns(&mut columns, &modes, &normal.rows, false);
    let (x, _) = nnls(&columns, &target);
    let delta = fit_residual(target, &columns, &x);
    let mut out = load.to_vec();
    add_modes(&mut out, -1.0, &delta, &modes);
    let norm = delta.iter().map(|d| d * d).sum::<f64>().sqrt();
    (out, norm)
}

/// Appends the non-zero columns `(Rᵀ C_rᵀ)` of the rows `C_r` in the rigid modes `R` (row by
/// row; with `both_signs` each column's negative first, for the free-sign friction rows).
fn push_mode_columns(
    columns: &mut Vec<Vec<f64>>,
    modes: &[&Vec<f64>],
    rows: &synovia_linalg::SparseRows,
    both_signs: bool,
) {
    let per_mode: Vec<Vec<f64>> = modes.iter().map(|r| rows.mul(r)).collect();
    for row in 0..rows.nrows() {
        let col: Vec<f64> = per_mode.iter().map(|pm| pm[row]).collect();
        if col.iter().any(|c| *c != 0.0) {
            if both_signs {
                columns.push(col.iter().map(|c| -c).collect());
            }
            columns.push(col);
        }
    }
}

/// `δ = t − Σ_j x_j a_j`: the part of the rigid-body load `t` that the fitted contact
/// columns `a_j` with the coefficients `x_j` do not balance.
fn fit_residual(mut target: Vec<f64>, columns: &[Vec<f64>], x: &[f64]) -> Vec<f64> {
    for (xj, col) in x.iter().zip(columns) {
        for (d, c) in target.iter_mut().zip(col) {
            *d -= xj * c;
        }
    }
    target
}

/// `y += s Σ_m δ_m r_m`: a load in the rigid modes `r_m` with the coefficients `δ`.
fn add_modes(y: &mut [f64], s: f64, delta: &[f64], modes: &[&Vec<f64>]) {
    for (d, r) in delta.iter().zip(modes) {
        for (yi, rv) in y.iter_mut().zip(r.iter()) {
            *yi += s * d * rv;
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Non-negative least squares `min_{x ≥ 0} ‖Σ_j x_j a_j − b‖₂` (Lawson–Hanson active set) for
/// a few rows (`b.len()` = number of rigid modes) and any number of columns `a_j`. Returns
/// `x` and the residual norm.
///
/// Hand-written: the NNLS crates on crates.io are unmaintained or pull in BLAS; the problem
/// here has at most six rows per floating component.
pub fn nnls(columns: &[Vec<f64>], b: &[f64]) -> (Vec<f64>, f64) {
    let m = b.len();
    let n = columns.len();
    let mut x = vec![0.0; n];
    let mut passive: Vec<usize> = Vec::new();
    let residual_of = |x: &[f64]| -> Vec<f64> {
        let mut r = b.to_vec();
        for (j, xj) in x.iter().enumerate() {
            if *xj != 0.0 {
                for i in 0..m {
                    r[i] -= xj * columns[j][i];
                }
            }
        }
        r
    };
    let scale = columns.iter().flat_map(|c| c.iter()).fold(0.0_f64, |a, v| a.max(v.abs()))
        * b.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let tol = 1e-12 * scale.max(f64::MIN_POSITIVE);
    for _outer in 0..3 * n.max(1) + 10 {
        let r = residual_of(&x);
        let w: Vec<f64> = columns.iter().map(|c| dot(c, &r)).collect();
        let candidate = (0..n)
            .filter(|j| !passive.contains(j))
            .max_by(|&a, &b| w[a].total_cmp(&w[b]))
            .filter(|&j| w[j] > tol);
        let Some(j) = candidate else { break };
        passive.push(j);
        for _inner in 0..3 * n.max(1) + 10 {
            let z = least_squares(columns, &passive, b);
            if passive.iter().zip(&z).all(|(_, zj)| *zj > 0.0) {
                for (p, zj) in passive.iter().zip(&z) {
                    x[*p] = *zj;
                }
                break;
            }
            let mut alpha = f64::INFINITY;
            for (p, zj) in passive.iter().zip(&z) {
                if *zj <= 0.0 {
                    let a = x[*p] / (x[*p] - zj);
                    alpha = alpha.min(a);
                }
            }
            let alpha = if alpha.is_finite() { alpha.clamp(0.0, 1.0) } else { 0.0 };
            for (p, zj) in passive.iter().zip(&z) {
                x[*p] += alpha * (zj - x[*p]);
            }
            passive.retain(|&p| x[p] > 1e-14 * x.iter().fold(0.0_f64, |a, v| a.max(*v)));
            for (j, xj) in x.iter_mut().enumerate() {
                if !passive.contains(&j) {
                    *xj = 0.0;
                }
            }
            if passive.is_empty() {
                break;
            }
        }
    }
    let r = residual_of(&x);
    let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    (x, norm)
}

/// Minimum-norm least-squares solution on the columns `passive` (SVD).
fn least_squares(columns: &[Vec<f64>], passive: &[usize], b: &[f64]) -> Vec<f64> {
    let m = b.len();
    let a = nalgebra::DMatrix::from_fn(m, passive.len(), |i, j| columns[passive[j]][i]);
    let rhs = nalgebra::DVector::from_column_slice(b);
    let svd = a.svd(true, true);
    let smax = svd.singular_values.iter().fold(0.0_f64, |a, v| a.max(*v));
    match svd.solve(&rhs, 1e-12 * smax.max(f64::MIN_POSITIVE)) {
        Ok(z) => z.iter().copied().collect(),
        Err(_) => vec![0.0; passive.len()],
    }
}

#[cfg(test)]
mod tests {
    use super::nnls;

    #[test]
    fn nnls_matches_hand_solutions() {
        // b inside the cone of the columns: exact.
        let cols = vec![vec![1.0, 0.0], vec![0.0, 1.0], vec![1.0, 1.0]];
        let (x, r) = nnls(&cols, &[2.0, 3.0]);
        assert!(r < 1e-12, "{r}");
        assert!(x.iter().all(|v| *v >= 0.0));
        // b outside: best is the projection onto the cone.
        let (x, r) = nnls(&cols, &[-1.0, 2.0]);
        assert!((r - 1.0).abs() < 1e-12, "{r} {x:?}");
        assert!((x[1] - 2.0).abs() < 1e-12);
        // all columns point away
        let (_, r) = nnls(&[vec![1.0, 0.0]], &[-3.0, 4.0]);
        assert!((r - 5.0).abs() < 1e-12);
    }
}
