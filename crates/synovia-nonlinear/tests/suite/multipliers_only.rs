//! The multiplier-only solve of a caller's load ([`StaticContact::solve_load_multipliers`]) and
//! its completion ([`StaticContact::complete_load`]), what the load control of a Newton
//! iteration uses for its trial solves: the multipliers are those of the full solve
//! ([`StaticContact::solve_load`]) to 1e-12, and the completed displacement is the full solve's.
#![allow(clippy::unwrap_used)]

use synovia_contact::operators::ContactPair;
use synovia_contact::{ContactParams, StaticContact, StaticContactResult};
use synovia_fem::assembly::{assemble_matrix, body_stiffnesses};
use synovia_fem::element::stiffness_into;
use synovia_fem::{ElasticParams, ElasticSolver, Model};
use synovia_mesh::math::{Real, Vector};
use synovia_pdas::Pdas;

/// A block pressed by its top onto a shallow bump (partial contact), with friction.
fn pressed_block() -> (Model<2>, Vec<ContactPair<2>>) {
    synovia_contact::testing::block_on_bump(12, 4, |t| Vector::<2>::new(2e-4 * t, -1e-3 * t)).unwrap()
}

fn max_abs(x: &[Real]) -> Real {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

fn max_diff(a: &[Real], b: &[Real]) -> Real {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// The completed result equals the full solve's: multipliers to 1e-12, displacements (reduced
/// and nodal) to 1e-12 relative, the same KKT residuals.
fn assert_same(full: &StaticContactResult<2>, completed: &StaticContactResult<2>, what: &str) {
    let (a, b) = (&full.solution, &completed.solution);
    let ln = max_abs(&a.lambda_n).max(Real::MIN_POSITIVE);
    assert!(max_diff(&a.lambda_n, &b.lambda_n) <= 1e-12 * ln, "{what}: Λ_n");
    let lt = max_abs(&a.lambda_t).max(Real::MIN_POSITIVE);
    assert!(max_diff(&a.lambda_t, &b.lambda_t) <= 1e-12 * lt, "{what}: Λ_t");
    let scale = max_abs(&a.u);
    assert!(scale > 0.0);
    let du = max_diff(&a.u, &b.u);
    assert!(du <= 1e-12 * scale, "{what}: |ΔU| = {du:e}, scale {scale:e}");
    for (x, y) in full.displacement[0].iter().zip(&completed.displacement[0]) {
        assert!((x - y).norm() <= 1e-12 * scale, "{what}: nodal displacement");
    }
    assert!(completed.kkt.satisfied(1e-10), "{what}: {:?}", completed.kkt);
    assert_eq!(full.cell_node, completed.cell_node);
}

/// The pressed block, its contact machinery on the assembled stiffness, the plain elastic
/// solver (for the right-hand sides) and a tight PDAS.
fn contact_setup() -> (Model<2>, StaticContact<2>, ElasticSolver<2>, Pdas) {
    let (model, pairs) = pressed_block();
    let solver = Pdas::new(ContactParams::default().with_tolerance(1e-13));
    let c0 = body_stiffnesses(&model).unwrap();
    let contact = StaticContact::with_system_matrix(&model, &pairs, ElasticParams::default(), |dofs, a| {
        assemble_matrix(&model, dofs, a, |b, _, geo, out| stiffness_into(geo, &c0[b], out))
    })
    .unwrap();
    let elastic = ElasticSolver::new(&model, ElasticParams::default()).unwrap();
    (model, contact, elastic, solver)
}

#[test]
fn multiplier_only_solve_and_completion_equal_the_full_solve() {
    let (model, contact, elastic, solver) = contact_setup();
    // two loads of a search over the approach (the prescribed push at t = 0.8 and t = 1)
    let (load_a, lifts_a) = elastic.rhs(&model, 0.8).unwrap();
    let (load_b, lifts_b) = elastic.rhs(&model, 1.0).unwrap();
    let first = contact.solve_load(&load_b, &lifts_b, &solver, None, None, None).unwrap();
    let active = first.solution.lambda_n.iter().filter(|&&l| l > 0.0).count();
    assert!(active > 0 && active < first.solution.lambda_n.len());
    let g = contact.geometry().slip_bounds_from_pressure(&first.solution.lambda_n);
    for slip in [None, Some(&g[..])] {
        let what = if slip.is_some() { "Tresca" } else { "frictionless" };
        let full_a = contact.solve_load(&load_a, &lifts_a, &solver, slip, None, None).unwrap();
        let full_b =
            contact.solve_load(&load_b, &lifts_b, &solver, slip, None, Some(&full_a.solution)).unwrap();
        // the trials: multipliers only (no displacement), the second warm-started from the first
        let (ma, _) = contact.solve_load_multipliers(&load_a, &lifts_a, &solver, slip, None, None).unwrap();
        assert!(ma.u.is_empty(), "{what}: a multiplier-only solve has no displacement");
        let (mb, _) =
            contact.solve_load_multipliers(&load_b, &lifts_b, &solver, slip, None, Some(&ma)).unwrap();
        assert!(mb.u.is_empty());
        let ln = max_abs(&full_b.solution.lambda_n);
        assert!(max_diff(&full_a.solution.lambda_n, &ma.lambda_n) <= 1e-12 * ln, "{what}: trial a Λ_n");
        assert!(max_diff(&full_b.solution.lambda_n, &mb.lambda_n) <= 1e-12 * ln, "{what}: trial b Λ_n");
        if slip.is_some() {
            assert!(!mb.lambda_t.is_empty());
            let lt = max_abs(&full_b.solution.lambda_t);
            assert!(max_diff(&full_b.solution.lambda_t, &mb.lambda_t) <= 1e-12 * lt, "{what}: Λ_t");
        }
        // the accepted trial (the last one solved: its A⁻¹ F is kept), then the other one (its
        // A⁻¹ F is solved again)
        let done_b = contact.complete_load(&load_b, &lifts_b, slip, None, mb).unwrap();
        assert_same(&full_b, &done_b, what);
        let done_a = contact.complete_load(&load_a, &lifts_a, slip, None, ma.clone()).unwrap();
        assert_same(&full_a, &done_a, what);
    }
    // a solution that does not fit, a load of the wrong size: errors
    let (ma, _) = contact.solve_load_multipliers(&load_a, &lifts_a, &solver, None, None, None).unwrap();
    assert!(contact.complete_load(&load_a, &lifts_a, Some(&g), None, ma.clone()).is_err());
    assert!(contact.complete_load(&load_a[1..], &lifts_a, None, None, ma).is_err());
    assert!(contact.solve_load_multipliers(&load_a, &lifts_a[1..], &solver, None, None, None).is_err());
}

/// A load in the span of the loads solved before on the same factorisation (the trials of a
/// load control are affine in the approach) takes its forward half from theirs, no solve
/// (`SolveContext::forward_counts`): its multipliers and completed displacement equal those of
/// the load solved on its own to 1e-12; a load outside the span is solved.
#[test]
fn a_load_in_the_span_of_earlier_trials_is_recycled_and_equals_its_own_solve() {
    let (model, contact, elastic, solver) = contact_setup();
    let (load_a, lifts_a) = elastic.rhs(&model, 0.8).unwrap();
    let (load_b, lifts_b) = elastic.rhs(&model, 1.0).unwrap();
    // the trial between them: its load an affine combination of theirs (the push is linear in t)
    let s = 0.37;
    let load_c: Vec<Real> = load_a.iter().zip(&load_b).map(|(a, b)| a + s * (b - a)).collect();
    let lifts_c: Vec<Vector<2>> = lifts_a.iter().zip(&lifts_b).map(|(a, b)| a + (b - a) * s).collect();
    // the reference: load c solved on its own
    contact.context().clear();
    let (own, _) = contact.solve_load_multipliers(&load_c, &lifts_c, &solver, None, None, None).unwrap();
    let own_done = contact.complete_load(&load_c, &lifts_c, None, None, own.clone()).unwrap();
    assert_eq!(contact.context().forward_counts(), (0, 1));
    // a solved, then b and c from its forward half
    contact.context().clear();
    let (ma, _) = contact.solve_load_multipliers(&load_a, &lifts_a, &solver, None, None, None).unwrap();
    let (mb, _) = contact.solve_load_multipliers(&load_b, &lifts_b, &solver, None, None, Some(&ma)).unwrap();
    let (mc, _) = contact.solve_load_multipliers(&load_c, &lifts_c, &solver, None, None, Some(&mb)).unwrap();
    // the push is proportional to t here, so b is a multiple of a: a solved, b and c recycled
    assert_eq!(contact.context().forward_counts(), (2, 1), "b and c recycled, a solved");
    let ln = max_abs(&own.lambda_n);
    assert!(ln > 0.0);
    assert!(max_diff(&own.lambda_n, &mc.lambda_n) <= 1e-12 * ln, "recycled trial: Λ_n");
    let done = contact.complete_load(&load_c, &lifts_c, None, None, mc).unwrap();
    assert_same(&own_done, &done, "recycled trial");
    // a load outside the span (a sideways push) is solved
    let side: Vec<Real> =
        load_a.iter().enumerate().map(|(i, a)| if i % 2 == 0 { 1.1 * a } else { *a }).collect();
    let _ = contact.solve_load_multipliers(&side, &lifts_a, &solver, None, None, None).unwrap();
    assert_eq!(contact.context().forward_counts(), (2, 2), "a load outside the span is solved");
}
