//! The fast-path pieces of `StaticContact` (issue 6) against plain solves: multipliers-only
//! solves completed afterwards, and loads recycled from the solved-load subspace.

use synovia::contact::StaticContact;
use synovia::contact_ops::ContactSolution;
use synovia::prelude::*;
use synovia_models::hertz::{hertz2d_model, Hertz2d};

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

fn two_discs() -> (Model<2>, Vec<synovia::contact_ops::operators::ContactPair<2>>) {
    let (model, pairs) =
        hertz2d_model(&Hertz2d { e2: Some(1.0), push: 0.02, levels: 7, ..Default::default() })
            .expect("model");
    (model, pairs.into_iter().map(|p| p.with_friction(0.3)).collect())
}

/// `solve_multipliers` + `complete` gives what `solve` gives: frictionless and Tresca, the
/// same multipliers, displacement, coarse iterations and KKT conditions.
#[test]
fn multipliers_then_complete_equals_a_full_solve() {
    let (model, pairs) = two_discs();
    let sc = StaticContact::new(&model, &pairs, ElasticParams::default()).expect("factorise");
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let normal = sc.solve(&model, 0.0, solver.as_ref(), None, None, None).expect("normal");
    let gc = sc.geometry().slip_bounds_from_pressure(&normal.solution.lambda_n);
    let active = normal.solution.lambda_n.iter().filter(|l| **l > 0.0).count();
    assert!(active >= 5, "too few contact nodes: {active} of {}", gc.len());
    for (t, slip) in [(0.0, None), (2e-4, Some(&gc[..]))] {
        let full = sc.solve(&model, t, solver.as_ref(), slip, None, None).expect("full");
        let (sol, coarse) =
            sc.solve_multipliers(&model, t, solver.as_ref(), slip, None, None).expect("multipliers");
        assert!(sol.u.is_empty(), "no displacement in a multipliers-only solve");
        assert_eq!(coarse, full.coarse_iterations);
        let done = sc.complete(&model, t, slip, None, sol).expect("complete");
        assert!(max_rel(&done.solution.lambda_n, &full.solution.lambda_n) < 1e-12);
        assert!(max_rel(&done.solution.lambda_t, &full.solution.lambda_t) < 1e-12);
        assert!(max_rel(&done.solution.u, &full.solution.u) < 1e-12);
        assert_eq!(done.cell_node, full.cell_node);
        assert_eq!(done.solution.lambda_t.is_empty(), slip.is_none());
        assert!(done.kkt.satisfied(1e-10), "t = {t}: {:?}", done.kkt);
        assert!((done.kkt.max() - full.kkt.max()).abs() < 1e-10);
    }
    // a solution that does not fit the problem is an error
    let bad = ContactSolution {
        u: Vec::new(),
        lambda_n: vec![0.0; normal.solution.lambda_n.len() + 1],
        lambda_t: Vec::new(),
        report: Default::default(),
    };
    assert!(sc.complete(&model, 0.0, None, None, bad).is_err());
}

/// The loads of `hertz2d_model` are `F(t) = F₀ + t F₁` (push and sideways shift of the top):
/// after two solves every further `A⁻¹ F` is recycled, and the results equal those of a fresh
/// factorisation (no recycling) to rounding.
#[test]
fn recycled_loads_give_the_solves_of_a_fresh_factorisation() {
    let (model, pairs) = two_discs();
    let sc = StaticContact::new(&model, &pairs, ElasticParams::default()).expect("factorise");
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let normal = sc.solve(&model, 0.0, solver.as_ref(), None, None, None).expect("normal");
    let gc = sc.geometry().slip_bounds_from_pressure(&normal.solution.lambda_n);
    sc.solve(&model, 1e-4, solver.as_ref(), Some(&gc), None, None).expect("second load");
    assert_eq!(sc.load_solves(), (0, 2));
    for (k, t) in [3e-4, -2e-4, 5e-4].into_iter().enumerate() {
        let recycled = sc.solve(&model, t, solver.as_ref(), Some(&gc), None, None).expect("recycled");
        assert_eq!(sc.load_solves(), (k + 1, 2), "t = {t}: A⁻¹F recycled");
        let fresh = StaticContact::new(&model, &pairs, ElasticParams::default()).expect("fresh");
        let direct = fresh.solve(&model, t, solver.as_ref(), Some(&gc), None, None).expect("direct");
        assert_eq!(fresh.load_solves(), (0, 1));
        let (eu, el) = (
            max_rel(&recycled.solution.u, &direct.solution.u),
            max_rel(&recycled.solution.lambda_n, &direct.solution.lambda_n),
        );
        assert!(eu < 1e-11 && el < 1e-11, "t = {t}: U differs by {eu:e}, Λ_n by {el:e}");
        assert!(recycled.kkt.satisfied(1e-10));
    }
}
