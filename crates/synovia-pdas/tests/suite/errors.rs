//! Error paths: no convergence, infeasible and singular problems, bad parameters.

use crate::common;

use common::{frictionless, tresca_2d};
use synovia_contact::{ContactError, ContactParams, ContactSolver};
use synovia_pdas::{AuPdas, Pdas};

fn solvers(params: ContactParams) -> [Box<dyn ContactSolver>; 2] {
    [Box::new(Pdas { params }), Box::new(AuPdas { params })]
}

#[test]
fn max_iterations_gives_no_convergence_with_history() {
    let owned = tresca_2d();
    let p = owned.problem();
    let needed =
        Pdas::default().solve(&p, &synovia_contact::SolveContext::new()).expect("pdas").report.iterations;
    assert!(needed > 1);
    for s in solvers(ContactParams::default().with_max_iterations(1)) {
        match s.solve(&p, &synovia_contact::SolveContext::new()) {
            Err(ContactError::NoConvergence { solver, iterations, history }) => {
                println!("{solver}: {iterations} iteration(s), history {history:?}");
                assert_eq!(solver, s.name());
                assert_eq!(iterations, 1);
                assert_eq!(history.len(), 1);
                assert_eq!(history[0].iteration, 1);
            }
            other => panic!("{}: expected NoConvergence, got {other:?}", s.name()),
        }
    }
}

#[test]
fn empty_row_with_negative_gap_is_infeasible() {
    let mut owned = frictionless(8).build::<2>().expect("problem");
    let m = owned.normal.rows.nrows();
    // a contact node whose displacement is fully prescribed: B_hn row = 0, but d < 0
    owned.normal.rows.push_row(std::iter::empty());
    owned.normal.weights.push(0.1);
    owned.normal.gap.push(-1e-3);
    let p = owned.problem();
    for s in solvers(ContactParams::default()) {
        match s.solve(&p, &synovia_contact::SolveContext::new()) {
            Err(ContactError::Infeasible(msg)) => {
                println!("{}: {msg}", s.name());
                assert!(msg.contains(&format!("normal row {m}")), "{msg}");
            }
            other => panic!("{}: expected Infeasible, got {other:?}", s.name()),
        }
    }
}

#[test]
fn empty_row_with_nonnegative_gap_is_harmless() {
    let mut owned = frictionless(8).build::<2>().expect("problem");
    owned.normal.rows.push_row(std::iter::empty());
    owned.normal.weights.push(0.1);
    owned.normal.gap.push(0.0);
    let p = owned.problem();
    let sol = Pdas::default().solve(&p, &synovia_contact::SolveContext::new()).expect("pdas");
    common::assert_kkt(&p, &sol, "empty row, d = 0");
    assert_eq!(sol.lambda_n.last().copied(), Some(0.0));
}

#[test]
fn duplicated_active_row_is_singular() {
    let mut owned = frictionless(8).build::<2>().expect("problem");
    // duplicate the middle row (it is in contact): two identical active constraints
    let mid = owned.normal.rows.nrows() / 2;
    let row: Vec<(usize, f64)> = owned.normal.rows.row(mid).collect();
    owned.normal.rows.push_row(row);
    owned.normal.weights.push(owned.normal.weights[mid]);
    owned.normal.gap.push(owned.normal.gap[mid]);
    let p = owned.problem();
    for s in solvers(ContactParams::default()) {
        match s.solve(&p, &synovia_contact::SolveContext::new()) {
            Err(ContactError::Singular { solver, iteration, size }) => {
                println!("{solver}: singular at iteration {iteration}, size {size}");
                assert_eq!(solver, s.name());
            }
            other => panic!("{}: expected Singular, got {other:?}", s.name()),
        }
    }
}

#[test]
fn invalid_parameters_are_rejected() {
    let owned = tresca_2d();
    let p = owned.problem();
    let bad = [
        ContactParams::default().with_rho_scale(0.0),
        ContactParams::default().with_rho_scale(f64::NAN),
        ContactParams::default().with_tolerance(-1.0),
        ContactParams::default().with_max_iterations(0),
    ];
    for params in bad {
        for s in solvers(params) {
            assert!(
                matches!(
                    s.solve(&p, &synovia_contact::SolveContext::new()),
                    Err(ContactError::InvalidParameter(_))
                ),
                "{} accepted {params:?}",
                s.name()
            );
        }
    }
    // a warm start of the wrong size
    let mut sol = Pdas::default().solve(&p, &synovia_contact::SolveContext::new()).expect("pdas");
    sol.lambda_n.pop();
    assert!(matches!(
        Pdas::default().solve(&p, &synovia_contact::SolveContext::warm(sol.clone())),
        Err(ContactError::InvalidParameter(_))
    ));
}
