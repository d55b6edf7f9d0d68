//! The Uzawa–MPRGP and dual MPRGP/MPGP contact solvers on the block-on-foundation problems:
//! KKT conditions, agreement of the two solvers, warm starts, errors.

use synovia_contact::testing::{BlockOnFoundation, OwnedProblem};
use synovia_contact::{
    check_kkt, ContactError, ContactParams, ContactProblem, ContactSolution, ContactSolver,
};
use synovia_uzawa::{DualMprgp, SchurOperator, UzawaMprgp};

fn build(dim: usize, cfg: BlockOnFoundation) -> OwnedProblem {
    let r = if dim == 2 { cfg.build::<2>() } else { cfg.build::<3>() };
    match r {
        Ok(p) => p,
        Err(e) => panic!("building the {dim}D test problem failed: {e}"),
    }
}

/// Frictionless, or Tresca with both sticking and slipping cells (2D: 16 × 8 cells, 3D: 8 × 8 × 4).
fn problem(dim: usize, friction: bool) -> OwnedProblem {
    let n = if dim == 2 { 16 } else { 8 };
    let slip_bound = friction.then_some(0.02);
    build(
        dim,
        BlockOnFoundation { n, push: 0.02, shift: 0.03, curvature: 0.5, slip_bound, ..Default::default() },
    )
}

fn params(tolerance: f64) -> ContactParams {
    ContactParams::default().with_tolerance(tolerance).with_max_iterations(2000).with_rho_scale(1.0)
}

fn uzawa(tolerance: f64) -> UzawaMprgp {
    UzawaMprgp { params: params(tolerance), inner_tolerance: 1e-13, max_inner: 2000 }
}

fn dual(tolerance: f64) -> DualMprgp {
    DualMprgp { params: params(tolerance) }
}

fn solve_checked(
    solver: &dyn ContactSolver,
    p: &ContactProblem<'_>,
    warm: Option<&ContactSolution>,
) -> ContactSolution {
    let context = synovia_contact::SolveContext::new().with_start(warm.cloned(), false);
    let sol = match solver.solve(p, &context) {
        Ok(s) => s,
        Err(e) => panic!("{} failed: {e}", solver.name()),
    };
    let kkt = check_kkt(p, &sol.u, &sol.lambda_n, &sol.lambda_t);
    assert!(kkt.satisfied(1e-7), "{}: KKT violated: {kkt:#?}", solver.name());
    let r = &sol.report;
    println!(
        "{:>12}: {:4} iterations, {:5} inner, {:4} solves, active {:3}, stick {:3}, slip {:3}, {:.1} ms, KKT {:.1e}",
        r.solver,
        r.iterations,
        r.inner_iterations,
        r.linear_solves,
        r.active,
        r.stick,
        r.slip,
        r.time_s * 1e3,
        kkt.max()
    );
    assert_eq!(r.solver, solver.name());
    assert_eq!(r.history.len(), r.iterations);
    sol
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().chain(b).fold(0.0_f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

fn assert_agree(a: &ContactSolution, b: &ContactSolution, tol: f64) {
    let (du, dn, dt) =
        (rel_diff(&a.u, &b.u), rel_diff(&a.lambda_n, &b.lambda_n), rel_diff(&a.lambda_t, &b.lambda_t));
    println!("agreement: U {du:.1e}, Λ_n {dn:.1e}, Λ_t {dt:.1e}");
    assert!(du <= tol && dn <= tol && dt <= tol, "solvers disagree: U {du:e}, Λ_n {dn:e}, Λ_t {dt:e}");
}

fn frictionless(dim: usize) {
    let owned = problem(dim, false);
    let p = owned.problem();
    let a = solve_checked(&dual(1e-10), &p, None);
    let b = solve_checked(&uzawa(1e-10), &p, None);
    assert_eq!(b.report.iterations, 1, "frictionless Uzawa takes one outer iteration");
    assert!(a.report.active > 0 && a.report.active < p.n_normal(), "partial contact wanted");
    assert!(a.lambda_t.is_empty() && b.lambda_t.is_empty());
    assert_agree(&a, &b, 1e-8);
}

#[test]
fn frictionless_2d() {
    frictionless(2);
}

#[test]
fn frictionless_3d() {
    frictionless(3);
}

fn tresca(dim: usize) {
    let owned = problem(dim, true);
    let p = owned.problem();
    let a = solve_checked(&dual(1e-12), &p, None);
    let b = solve_checked(&uzawa(1e-12), &p, None);
    for s in [&a, &b] {
        assert!(s.report.stick > 0 && s.report.slip > 0, "stick and slip cells wanted: {:?}", s.report);
        assert!(s.report.active > 0 && s.report.active < p.n_normal());
        assert_eq!(s.report.stick + s.report.slip, p.n_tangential() / p.components());
    }
    assert_agree(&a, &b, 1e-6);
}

#[test]
fn tresca_2d() {
    tresca(2);
}

#[test]
fn tresca_3d() {
    tresca(3);
}

#[test]
fn warm_start_reuses_the_solution() {
    for dim in [2, 3] {
        let owned = problem(dim, true);
        let p = owned.problem();
        let cold = solve_checked(&dual(1e-10), &p, None);
        let warm = solve_checked(&dual(1e-10), &p, Some(&cold));
        assert!(warm.report.iterations < cold.report.iterations.max(2), "dual: warm start did not help");
        let cold_u = solve_checked(&uzawa(1e-10), &p, None);
        let warm_u = solve_checked(&uzawa(1e-10), &p, Some(&cold_u));
        assert!(warm_u.report.iterations * 5 < cold_u.report.iterations, "Uzawa: warm start did not help");
        // a slightly different load from the previous solution
        let moved = build(
            dim,
            BlockOnFoundation {
                n: if dim == 2 { 16 } else { 8 },
                push: 0.021,
                shift: 0.03,
                curvature: 0.5,
                slip_bound: Some(0.02),
                ..Default::default()
            },
        );
        let q = moved.problem();
        let next = solve_checked(&uzawa(1e-10), &q, Some(&cold_u));
        let next_d = solve_checked(&dual(1e-10), &q, Some(&cold));
        assert_agree(&next, &next_d, 1e-5);
    }
}

#[test]
fn too_few_iterations_is_no_convergence() {
    for dim in [2, 3] {
        let owned = problem(dim, true);
        let p = owned.problem();
        let few = ContactParams::default().with_tolerance(1e-12).with_max_iterations(3).with_rho_scale(1.0);
        let solvers: [Box<dyn ContactSolver>; 2] = [
            Box::new(DualMprgp { params: few }),
            Box::new(UzawaMprgp { params: few, inner_tolerance: 1e-12, max_inner: 100 }),
        ];
        for s in &solvers {
            match s.solve(&p, &synovia_contact::SolveContext::new()) {
                Err(ContactError::NoConvergence { solver, iterations, history }) => {
                    assert_eq!(solver, s.name());
                    assert_eq!(iterations, 3);
                    assert_eq!(history.len(), 3);
                    assert!(history.iter().enumerate().all(|(i, r)| r.iteration == i + 1));
                    assert!(history.iter().any(|r| r.normal > 1e-12 || r.tangential > 1e-12));
                    println!("{solver}: {:?}", history.last());
                }
                other => panic!("{}: expected NoConvergence, got {other:?}", s.name()),
            }
        }
    }
}

#[test]
fn invalid_parameters_and_warm_starts() {
    let owned = problem(2, true);
    let p = owned.problem();
    let bad = ContactParams::default().with_tolerance(0.0);
    assert!(matches!(
        DualMprgp { params: bad }.solve(&p, &synovia_contact::SolveContext::new()),
        Err(ContactError::InvalidParameter(_))
    ));
    assert!(matches!(
        UzawaMprgp::new(bad).solve(&p, &synovia_contact::SolveContext::new()),
        Err(ContactError::InvalidParameter(_))
    ));
    let no_inner = UzawaMprgp { max_inner: 0, ..UzawaMprgp::default() };
    assert!(matches!(
        no_inner.solve(&p, &synovia_contact::SolveContext::new()),
        Err(ContactError::InvalidParameter(_))
    ));
    // a warm start of another problem
    let other = problem(2, false);
    let sol = solve_checked(&dual(1e-10), &other.problem(), None);
    assert!(matches!(
        dual(1e-10).solve(&p, &synovia_contact::SolveContext::warm(sol.clone())),
        Err(ContactError::InvalidParameter(_))
    ));
    assert!(matches!(
        uzawa(1e-10).solve(&p, &synovia_contact::SolveContext::warm(sol.clone())),
        Err(ContactError::InvalidParameter(_))
    ));
}

#[test]
fn infeasible_constraint_is_reported() {
    // an extra normal row acting on no unknown with a negative gap: 0 ≤ d < 0 cannot hold
    for dim in [2, 3] {
        let mut owned = problem(dim, true);
        owned.normal.rows.push_row(std::iter::empty());
        owned.normal.weights.push(0.1);
        owned.normal.gap.push(-0.01);
        let p = owned.problem();
        for s in [&dual(1e-10) as &dyn ContactSolver, &uzawa(1e-10)] {
            match s.solve(&p, &synovia_contact::SolveContext::new()) {
                Err(ContactError::Infeasible(msg)) => println!("{dim}D {}: {msg}", s.name()),
                other => panic!("{dim}D {}: expected Infeasible, got {other:?}", s.name()),
            }
        }
        // with a positive gap the same row is harmless: its multiplier stays 0
        let last = owned.normal.gap.len() - 1;
        owned.normal.gap[last] = 0.01;
        let p = owned.problem();
        let a = solve_checked(&dual(1e-10), &p, None);
        let b = solve_checked(&uzawa(1e-10), &p, None);
        assert_eq!(a.lambda_n[last], 0.0);
        assert_eq!(b.lambda_n[last], 0.0);
        assert_agree(&a, &b, 1e-6);
    }
}

#[test]
fn matrix_free_schur_complement_matches_dense() {
    let owned = problem(3, true);
    let p = owned.problem();
    let (ctx_dense, ctx_free) = (synovia_contact::SolveContext::new(), synovia_contact::SolveContext::new());
    let mut dense = SchurOperator::with_storage(p, &ctx_dense, true).expect("dense S");
    let mut free = SchurOperator::with_storage(p, &ctx_free, false).expect("matrix-free S");
    assert!(dense.is_dense() && !free.is_dense());
    let m = dense.n_rows();
    let v: Vec<f64> = (0..m).map(|i| ((i * 37) % 11) as f64 / 11.0 - 0.5).collect();
    let (mut a, mut b) = (vec![0.0; m], vec![0.0; m]);
    dense.apply(&v, &mut a).expect("dense product");
    free.apply(&v, &mut b).expect("matrix-free product");
    assert!(rel_diff(&a, &b) < 1e-12, "{}", rel_diff(&a, &b));
    let mn = p.n_normal();
    let (mut a, mut b) = (vec![0.0; mn], vec![0.0; mn]);
    dense.apply_block(0..mn, mn..m, &v[mn..], &mut a).expect("dense block");
    free.apply_block(0..mn, mn..m, &v[mn..], &mut b).expect("matrix-free block");
    assert!(rel_diff(&a, &b) < 1e-12);
    // the matrix-free diagonal is a positive lower bound of diag S
    let (d, l) = (dense.diagonal(), free.diagonal());
    assert!(d.iter().zip(&l).all(|(d, l)| *l > 0.0 && *l <= d * (1.0 + 1e-12)));
    assert_eq!(free.solves(), 1 + 2);
    assert!(dense.apply(&v[1..], &mut vec![0.0; m]).is_err());
}
