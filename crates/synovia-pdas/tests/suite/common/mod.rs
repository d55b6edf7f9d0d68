//! Helpers shared by the integration tests.
#![allow(dead_code)]

use synovia_contact::testing::{BlockOnFoundation, OwnedProblem};
use synovia_contact::{check_kkt, ContactProblem, ContactSolution};

/// `max |a − b| / max |a|`.
pub fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

/// Asserts that the KKT conditions hold to `1e-8`, printing the report otherwise.
pub fn assert_kkt(problem: &ContactProblem<'_>, sol: &ContactSolution, label: &str) {
    let rep = check_kkt(problem, &sol.u, &sol.lambda_n, &sol.lambda_t);
    assert!(rep.satisfied(1e-8), "{label}: KKT violated: {rep:#?}\nsolver report: {:#?}", sol.report);
}

/// Asserts that two solutions agree to `tol` (relative) in `U`, `Λ_n` and `Λ_t`.
pub fn assert_same(a: &ContactSolution, b: &ContactSolution, tol: f64, label: &str) {
    let du = rel_diff(&a.u, &b.u);
    let dn = rel_diff(&a.lambda_n, &b.lambda_n);
    let dt = if a.lambda_t.is_empty() { 0.0 } else { rel_diff(&a.lambda_t, &b.lambda_t) };
    println!("{label}: relative differences U {du:.2e}, Λ_n {dn:.2e}, Λ_t {dt:.2e}");
    assert!(du <= tol && dn <= tol && dt <= tol, "{label}: U {du:e}, Λ_n {dn:e}, Λ_t {dt:e} > {tol:e}");
}

/// Frictionless block on a curved foundation.
pub fn frictionless(n: usize) -> BlockOnFoundation {
    BlockOnFoundation { n, slip_bound: None, shift: 0.0, ..Default::default() }
}

/// 2D Tresca case with both sticking and slipping cells (n = 16: 11 stick, 6 slip).
pub fn tresca_2d() -> OwnedProblem {
    let b = BlockOnFoundation { n: 16, shift: 0.01, slip_bound: Some(0.01), ..Default::default() };
    b.build::<2>().expect("2D Tresca problem")
}

/// 3D Tresca case with both sticking and slipping cells (n = 8: 61 stick, 20 slip).
pub fn tresca_3d() -> OwnedProblem {
    let b = BlockOnFoundation { n: 8, shift: 0.005, slip_bound: Some(0.005), ..Default::default() };
    b.build::<3>().expect("3D Tresca problem")
}
