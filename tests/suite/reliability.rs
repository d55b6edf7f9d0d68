//! Solver failure modes (issue 7): active-set cycling of PDAS is detected and the
//! `pdas-fallback` solver recovers; iteration limits without fallback give `NoConvergence`.

use synovia::contact_ops::kkt::check_kkt;
use synovia::contact_ops::testing::BlockOnFoundation;
use synovia::contact_ops::SparseRows;
use synovia::contact_ops::{ContactError, ContactParams, ContactSolver};
use synovia::contact_ops::{ContactProblem, NormalConstraints};
use synovia::linalg::{Ordering, SparseCholesky, SymmetricMatrix};
use synovia::pdas::Pdas;
use synovia::solvers::{by_name, PdasFallback};
use synovia::uzawa::DualMprgp;

/// A frictionless interface problem with `A = I` (n × n), `B_hn = c` (rows), `κ = 1`:
/// `S = c cᵀ`, `w = c F`.
struct Synthetic {
    system: SparseCholesky,
    load: Vec<f64>,
    normal: NormalConstraints,
}

impl Synthetic {
    fn new(c: &[Vec<f64>], load: Vec<f64>, gap: Vec<f64>) -> Self {
        let n = load.len();
        let mut matrix =
            SymmetricMatrix::from_columns(n, (0..n).map(|j| vec![j]).collect()).expect("pattern");
        for j in 0..n {
            matrix.add(j, j, 1.0).expect("diag");
        }
        let system = SparseCholesky::new(matrix, &Ordering::Amd).expect("factorise");
        let mut rows = SparseRows::new(n);
        for r in c {
            rows.push_row(r.iter().copied().enumerate());
        }
        let m = c.len();
        Self { system, load, normal: NormalConstraints { rows, weights: vec![1.0; m], gap } }
    }
    fn problem(&self) -> ContactProblem<'_> {
        ContactProblem {
            operator: &self.system,
            load: &self.load,
            normal: &self.normal,
            friction: None,
            border: None,
        }
    }
}

/// A 3 × 3 frictionless problem (found by a random search over `c`, `F`, `d` with one
/// decimal) on which plain PDAS (Newton-min) cycles through three active sets for ever: `S` is
/// symmetric positive definite but not an M-matrix.
fn cycling_problem() -> Synthetic {
    let c = vec![vec![0.5, 0.0, 0.7], vec![-0.5, 0.2, -0.5], vec![-1.0, 0.7, -0.4]];
    Synthetic::new(&c, vec![-0.1, 0.0, 0.5], vec![-1.0, 0.8, 0.1])
}

#[test]
fn pdas_cycling_is_detected_and_the_iteration_limit_still_gives_no_convergence() {
    let owned = cycling_problem();
    let p = owned.problem();
    let pdas = Pdas::default();
    let max = pdas.params.max_iterations;
    // no fallback configured: NoConvergence at the limit, with the whole residual history
    match pdas.solve(&p, &synovia::contact_ops::SolveContext::new()) {
        Err(ContactError::NoConvergence { solver, iterations, history }) => {
            assert_eq!(solver, "pdas");
            assert_eq!(iterations, max);
            assert_eq!(history.len(), max);
            assert!(history.iter().all(|h| h.set_changes > 0), "the sets never settle");
            println!("pdas: {iterations} iterations, last residuals {:?}", &history[max - 3..]);
        }
        other => panic!("expected NoConvergence, got {other:?}"),
    }
    let trace = pdas.solve_traced(&p, &synovia::contact_ops::SolveContext::new(), false);
    assert_eq!(trace.cycle_period, Some(3), "{trace:?}");
    assert!(trace.stagnation);
    assert!(matches!(trace.result, Err(ContactError::NoConvergence { iterations, .. }) if iterations == max));
    assert!(trace.last_iterate.is_some());
    // stop_on_cycling ends the doomed iteration as soon as the cycle is seen
    let early = pdas.solve_traced(&p, &synovia::contact_ops::SolveContext::new(), true);
    match early.result {
        Err(ContactError::NoConvergence { iterations, history, .. }) => {
            println!("cycle detected after {iterations} iterations");
            assert!(iterations <= 1 + 2 * 3, "{iterations}");
            assert_eq!(history.len(), iterations);
        }
        other => panic!("expected NoConvergence, got {other:?}"),
    }
}

#[test]
fn pdas_fallback_hands_a_cycling_problem_to_dual_mprgp_and_reports_it() {
    let owned = cycling_problem();
    let p = owned.problem();
    let solver = by_name("pdas-fallback").expect("solver");
    let sol = solver.solve(&p, &synovia::contact_ops::SolveContext::new()).expect("fallback solution");
    let kkt = check_kkt(&p, &sol.u, &sol.lambda_n, &sol.lambda_t);
    println!("report {:?}\nKKT {kkt:?}", sol.report);
    assert!(kkt.satisfied(1e-7), "{kkt:?}");
    assert_eq!(sol.report.solver, "dual-mprgp");
    assert!(sol.report.cycling_detected);
    let why = sol.report.fallback.as_deref().expect("fallback recorded");
    assert!(why.contains("cycle of period 3") && why.contains("dual-mprgp"), "{why}");
    // the same solution as dual-mprgp from a cold start
    let cold = DualMprgp::new(ContactParams::default().with_max_iterations(10_000))
        .solve(&p, &synovia::contact_ops::SolveContext::new())
        .expect("dual-mprgp");
    for (a, b) in sol.u.iter().zip(&cold.u).chain(sol.lambda_n.iter().zip(&cold.lambda_n)) {
        assert!((a - b).abs() <= 1e-8 * (1.0 + b.abs()), "{a} vs {b}");
    }
}

#[test]
fn pdas_fallback_is_plain_pdas_when_pdas_converges() {
    let owned = BlockOnFoundation { n: 8, slip_bound: Some(0.02), ..Default::default() }
        .build::<2>()
        .expect("problem");
    let p = owned.problem();
    let plain = Pdas::default().solve(&p, &synovia::contact_ops::SolveContext::new()).expect("pdas");
    let guarded =
        PdasFallback::default().solve(&p, &synovia::contact_ops::SolveContext::new()).expect("pdas-fallback");
    assert_eq!(guarded.report.solver, "pdas");
    assert!(guarded.report.fallback.is_none() && !guarded.report.cycling_detected);
    assert_eq!(plain.u, guarded.u);
    assert_eq!(plain.lambda_t, guarded.lambda_t);
}

#[test]
fn pdas_fallback_recovers_from_linearly_dependent_active_constraints() {
    let mut owned = BlockOnFoundation { n: 8, slip_bound: None, shift: 0.0, ..Default::default() }
        .build::<2>()
        .expect("problem");
    let mid = owned.normal.rows.nrows() / 2;
    let row: Vec<(usize, f64)> = owned.normal.rows.row(mid).collect();
    owned.normal.rows.push_row(row);
    owned.normal.weights.push(owned.normal.weights[mid]);
    owned.normal.gap.push(owned.normal.gap[mid]);
    let p = owned.problem();
    assert!(matches!(
        Pdas::default().solve(&p, &synovia::contact_ops::SolveContext::new()),
        Err(ContactError::Singular { .. })
    ));
    let sol =
        PdasFallback::default().solve(&p, &synovia::contact_ops::SolveContext::new()).expect("fallback");
    let kkt = check_kkt(&p, &sol.u, &sol.lambda_n, &sol.lambda_t);
    assert!(kkt.satisfied(1e-7), "{kkt:?}");
    let why = sol.report.fallback.as_deref().expect("fallback recorded");
    assert!(why.contains("singular"), "{why}");
    assert!(!sol.report.cycling_detected);
}

#[test]
fn pdas_fallback_passes_input_errors_through() {
    let mut owned = cycling_problem();
    owned.normal.gap[0] = f64::NAN;
    let e = PdasFallback::default().solve(&owned.problem(), &synovia::contact_ops::SolveContext::new());
    assert!(matches!(e, Err(ContactError::InvalidParameter(_))), "{e:?}");
}

/// Found by an exploratory property-test run with `PROPTEST_CASES=20000` (shrunk): a Tresca
/// problem with an almost vanishing load (`|U| ≈ 4e-6`, `g_c = 0.16`, no contact). `uzawa-mprgp`
/// used to stop on its absolute tangential residual (`≤ 1e-10` in `Λ_t`), which bounds the slip
/// of the sticking cells only by `1e-10/ρ`: relative to the tiny displacement scale the KKT
/// checker saw a stick-slip residual of ≈ 5e-7. It now also checks the KKT residuals relative to
/// the displacement scale before stopping; all solvers must pass.
#[test]
fn uzawa_mprgp_kkt_on_a_nearly_unloaded_tresca_problem() {
    let b = BlockOnFoundation {
        n: 5,
        push: 0.0,
        shift: 6.109005055206135e-6,
        curvature: 0.0,
        slip_bound: Some(0.16009151907989216),
        young: 0.5,
        poisson: 0.0,
        ..Default::default()
    };
    let owned = b.build::<2>().expect("problem");
    let p = owned.problem();
    for name in ["pdas", "dual-mprgp", "uzawa-mprgp"] {
        let sol = by_name(name)
            .expect("solver")
            .solve(&p, &synovia::contact_ops::SolveContext::new())
            .expect("solve");
        let kkt = check_kkt(&p, &sol.u, &sol.lambda_n, &sol.lambda_t);
        println!("{name}: {kkt:?}");
        assert!(kkt.satisfied(1e-7), "{name}: {kkt:?}");
    }
}

/// Found by an exploratory property-test run (`PROPTEST_CASES=20000`, random seed; 1 case in
/// 20 000):
/// a 2D Tresca block on which plain PDAS cycles through four active sets (slip-reversal
/// safeguard notwithstanding). The cycle is detected and `pdas-fallback` returns a KKT
/// solution through `dual-mprgp`.
#[test]
fn pdas_cycles_on_a_random_tresca_block_and_the_fallback_recovers() {
    let b = BlockOnFoundation {
        n: 8,
        push: 0.03766673799529499,
        shift: 0.02203312580045642,
        curvature: 0.04349773532142543,
        slip_bound: Some(0.04516927543383259),
        young: 2.100499261424239,
        poisson: 0.4417346432702067,
        jitter: 0.08220285046558384,
        seed: 7992037326756013494,
        gap_offset: 0.008440732165689854,
    };
    let owned = b.build::<2>().expect("problem");
    let p = owned.problem();
    let trace = Pdas::default().solve_traced(&p, &synovia::contact_ops::SolveContext::new(), false);
    assert!(
        matches!(trace.result, Err(ContactError::NoConvergence { iterations: 200, .. })),
        "{:?}",
        trace.result
    );
    assert_eq!(trace.cycle_period, Some(4));
    let sol =
        PdasFallback::default().solve(&p, &synovia::contact_ops::SolveContext::new()).expect("fallback");
    let kkt = check_kkt(&p, &sol.u, &sol.lambda_n, &sol.lambda_t);
    println!("{:?}\n{kkt:?}", sol.report.fallback);
    assert!(kkt.satisfied(1e-7), "{kkt:?}");
    assert!(sol.report.cycling_detected && sol.report.fallback.is_some());
    // the other solvers agree
    let dual = by_name("uzawa-mprgp")
        .expect("solver")
        .solve(&p, &synovia::contact_ops::SolveContext::new())
        .expect("uzawa");
    let scale = sol.u.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let du = sol.u.iter().zip(&dual.u).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs())) / scale;
    assert!(du < 1e-6, "{du}");
}
