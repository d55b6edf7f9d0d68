//! Frictionless contact: KKT, partial contact, few iterations, mesh independence.

use crate::common;

use common::{assert_kkt, assert_same, frictionless};
use synovia_contact::{ContactSolution, ContactSolver};
use synovia_pdas::{AuPdas, Pdas};

fn check_partial(sol: &ContactSolution, m: usize, label: &str) {
    println!(
        "{label}: {} iterations, {} of {m} rows active, {} linear solves, history {:?}",
        sol.report.iterations, sol.report.active, sol.report.linear_solves, sol.report.history
    );
    assert!(sol.report.active > 0 && sol.report.active < m, "{label}: active {}", sol.report.active);
    let pressed = sol.lambda_n.iter().filter(|l| **l > 0.0).count();
    assert!(pressed > 0 && pressed < m);
    assert!(sol.report.iterations <= 6, "{label}: {} iterations", sol.report.iterations);
    assert_eq!(sol.report.stick + sol.report.slip, 0);
    assert!(sol.lambda_t.is_empty());
}

#[test]
fn frictionless_2d() {
    let owned = frictionless(16).build::<2>().expect("problem");
    let p = owned.problem();
    let sol = Pdas::default().solve(&p, &synovia_contact::SolveContext::new()).expect("pdas");
    assert_kkt(&p, &sol, "pdas 2D frictionless");
    check_partial(&sol, p.n_normal(), "pdas 2D frictionless");
    assert_eq!(sol.report.solver, "pdas");
    assert_eq!(sol.report.history.len(), sol.report.iterations);

    // AU-PDAS reduces to PDAS without friction
    let au = AuPdas::default().solve(&p, &synovia_contact::SolveContext::new()).expect("au-pdas");
    assert_kkt(&p, &au, "au-pdas 2D frictionless");
    assert_eq!(au.report.iterations, sol.report.iterations);
    assert_same(&sol, &au, 1e-12, "au-pdas vs pdas, 2D frictionless");
}

#[test]
fn frictionless_3d() {
    let owned = frictionless(8).build::<3>().expect("problem");
    let p = owned.problem();
    let sol = Pdas::default().solve(&p, &synovia_contact::SolveContext::new()).expect("pdas");
    assert_kkt(&p, &sol, "pdas 3D frictionless");
    check_partial(&sol, p.n_normal(), "pdas 3D frictionless");
    let au = AuPdas::default().solve(&p, &synovia_contact::SolveContext::new()).expect("au-pdas");
    assert_kkt(&p, &au, "au-pdas 3D frictionless");
    assert_same(&sol, &au, 1e-12, "au-pdas vs pdas, 3D frictionless");
}

#[test]
fn frictionless_rho_independence() {
    let owned = frictionless(16).build::<2>().expect("problem");
    let p = owned.problem();
    let sols: Vec<ContactSolution> = [1e-2, 1.0, 1e2]
        .iter()
        .map(|&rho_scale| {
            let mut s = Pdas::default();
            s.params.rho_scale = rho_scale;
            let sol = s.solve(&p, &synovia_contact::SolveContext::new()).expect("pdas");
            assert_kkt(&p, &sol, &format!("rho_scale {rho_scale}"));
            println!("rho_scale {rho_scale}: {} iterations", sol.report.iterations);
            sol
        })
        .collect();
    assert_same(&sols[1], &sols[0], 1e-8, "rho 1 vs 1e-2");
    assert_same(&sols[1], &sols[2], 1e-8, "rho 1 vs 1e2");
}

#[test]
fn mesh_independence_2d() {
    let mut its = Vec::new();
    for n in [8, 16, 32, 64] {
        let owned = frictionless(n).build::<2>().expect("problem");
        let p = owned.problem();
        let sol = Pdas::default().solve(&p, &synovia_contact::SolveContext::new()).expect("pdas");
        assert_kkt(&p, &sol, &format!("n = {n}"));
        println!(
            "n = {n:3}: {} PDAS iterations, {} of {} rows active, {} solves, {:.1} ms",
            sol.report.iterations,
            sol.report.active,
            p.n_normal(),
            sol.report.linear_solves,
            sol.report.time_s * 1e3
        );
        its.push(sol.report.iterations);
    }
    println!("iterations for n = 8, 16, 32, 64: {its:?}");
    assert!(its[3] <= its[0] + 3, "iterations grow with refinement: {its:?}");
}
