//! One contact pipeline for static, quasi-static and dynamic analyses (docs/model.md §5, §7): the
//! static contact machinery built on a caller-assembled matrix and solved with a caller's load
//! ([`StaticContact::with_system_matrix`], [`StaticContact::solve_load`], what the dynamic
//! stepper uses) gives the solution of the model's own static problem when the caller's matrix
//! and load are the stiffness and the elastic load; bad input is a typed error.
#![allow(clippy::unwrap_used)]

use synovia_contact::operators::ContactPair;
use synovia_contact::{ContactParams, StaticContact};
use synovia_fem::assembly::{assemble_matrix, body_stiffnesses};
use synovia_fem::element::stiffness_into;
use synovia_fem::{ElasticParams, ElasticSolver, Model};
use synovia_mesh::math::{Real, Vector};
use synovia_pdas::Pdas;

fn pressed_block() -> (Model<2>, Vec<ContactPair<2>>) {
    synovia_contact::testing::block_on_bump(10, 3, |t| Vector::<2>::new(2e-4 * t, -1e-3)).unwrap()
}

#[test]
fn caller_matrix_and_load_reproduce_the_static_solve() {
    let (model, pairs) = pressed_block();
    let solver = Pdas::new(ContactParams::default().with_tolerance(1e-13));
    let statics = StaticContact::new(&model, &pairs, ElasticParams::default()).unwrap();
    let c0 = body_stiffnesses(&model).unwrap();
    let caller = StaticContact::with_system_matrix(&model, &pairs, ElasticParams::default(), |dofs, a| {
        assemble_matrix(&model, dofs, a, |b, _, geo, out| stiffness_into(geo, &c0[b], out))
    })
    .unwrap();
    // the elastic load case at t = 1, computed independently of the caller's StaticContact
    let elastic = ElasticSolver::new(&model, ElasticParams::default()).unwrap();
    let (load, lifts) = elastic.rhs(&model, 1.0).unwrap();
    let pre = statics.solve(&model, 1.0, &solver, None, None, None).unwrap();
    let g = statics.geometry().slip_bounds_from_pressure(&pre.solution.lambda_n);
    let active = pre.solution.lambda_n.iter().filter(|&&l| l > 0.0).count();
    assert!(active > 0 && active < pre.solution.lambda_n.len());
    for slip in [None, Some(&g[..])] {
        let a = statics.solve(&model, 1.0, &solver, slip, None, None).unwrap();
        let b = caller.solve_load(&load, &lifts, &solver, slip, None, None).unwrap();
        assert!(a.kkt.satisfied(1e-10) && b.kkt.satisfied(1e-10), "{:?} {:?}", a.kkt, b.kkt);
        let scale = a.solution.u.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let du = a.solution.u.iter().zip(&b.solution.u).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(du <= 1e-10 * scale, "friction {}: |ΔU| = {du:e}, scale {scale:e}", slip.is_some());
        let ln = a.solution.lambda_n.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let dl = a
            .solution
            .lambda_n
            .iter()
            .zip(&b.solution.lambda_n)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(dl <= 1e-9 * ln, "|ΔΛ_n| = {dl:e}");
        assert_eq!(a.cell_node, b.cell_node);
        for (x, y) in a.displacement[0].iter().zip(&b.displacement[0]) {
            assert!((x - y).norm() <= 1e-10 * scale.max(1e-3));
        }
    }
    // the caller's problem has no model load case; wrong sizes and non-finite loads are errors
    assert!(caller.solve(&model, 1.0, &solver, None, None, None).is_err());
    assert!(caller.solve_load(&load[1..], &lifts, &solver, None, None, None).is_err());
    assert!(caller.solve_load(&load, &lifts[1..], &solver, None, None, None).is_err());
    let mut bad = load.clone();
    bad[0] = Real::NAN;
    assert!(caller.solve_load(&bad, &lifts, &solver, None, None, None).is_err());
}

#[test]
fn a_matrix_that_is_not_positive_definite_is_an_error() {
    let (model, pairs) = pressed_block();
    let r = StaticContact::with_system_matrix(&model, &pairs, ElasticParams::default(), |dofs, a| {
        for k in 0..dofs.n_dofs() {
            a.add(k, k, -1.0)?;
        }
        Ok(())
    });
    assert!(r.is_err());
}
