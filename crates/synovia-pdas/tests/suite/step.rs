//! `PdasStep`, the single active-set step of PDAS: iterated by hand on a fixed problem (each
//! step warm-started from the last one's `U` and multipliers) it reaches PDAS's solution, with
//! the sets unchanged by the last step; from PDAS's solution one step returns it unchanged.

use crate::common;

use common::{assert_kkt, assert_same, tresca_2d, tresca_3d};
use synovia_contact::testing::OwnedProblem;
use synovia_contact::{ContactSolver, SolveContext};
use synovia_pdas::{Pdas, PdasStep};

fn steps_reach_pdas(owned: &OwnedProblem, label: &str) {
    let p = owned.problem();
    let pdas = Pdas::default().solve(&p, &SolveContext::new()).expect("pdas");
    let step = Pdas::default().active_set_step().expect("pdas has a step");
    let mut current = step.solve(&p, &SolveContext::new()).expect("first step");
    let mut taken = 1;
    while !current
        .report
        .history
        .last()
        .is_some_and(|h| h.set_changes == 0 && h.normal.max(h.tangential) <= 1e-10)
    {
        assert!(taken < 30, "{label}: {taken} steps");
        current = step.solve(&p, &SolveContext::warm(current.clone())).expect("step");
        assert_eq!(current.report.iterations, 1);
        taken += 1;
    }
    println!("{label}: {taken} steps, PDAS {} iterations", pdas.report.iterations);
    assert_kkt(&p, &current, label);
    assert_same(&pdas, &current, 1e-8, label);
    // from the solution, a step keeps it
    let again = PdasStep::default().solve(&p, &SolveContext::warm(pdas.clone())).expect("step");
    assert_eq!(again.report.history.last().map(|h| h.set_changes), Some(0), "{label}");
    assert_same(&pdas, &again, 1e-8, label);
}

#[test]
fn steps_reach_the_pdas_solution_2d() {
    steps_reach_pdas(&tresca_2d(), "2D Tresca");
}

#[test]
fn steps_reach_the_pdas_solution_3d() {
    steps_reach_pdas(&tresca_3d(), "3D Tresca");
}
