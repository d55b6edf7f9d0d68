//! The active-set strategies of the Newton iteration give the same solution: the neo-Hookean
//! Hertz problems of `hertz_small_load.rs` (a half-disc in 2D, a hemisphere in 3D, finite
//! strain, pressed on a rigid flat) with Coulomb friction 0.3 frozen per level and a sideways
//! motion of the top, solved with `ActiveSetStrategy::Nested` (the contact solved to
//! convergence in every Newton iteration), `::Combined` (one PDAS step per Newton
//! iteration) and `::Outer` (the sets fixed while Newton converges, then updated): displacements and multipliers agree to 1e-8, both satisfy the KKT conditions
//! to 1e-8. A strategy the solver cannot run is refused with a typed error.

use std::sync::Arc;

use synovia_contact::obstacle::PlaneObstacle;
use synovia_contact::operators::ContactPair;
use synovia_contact::ContactSolver;
use synovia_fem::{ElasticParams, Kinematics, Model};
use synovia_material::neo_hookean;
use synovia_mesh::generators::{half_disc_refined, hemisphere_refined};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::BoundaryKind;
use synovia_nonlinear::{
    ActiveSetStrategy, LoadControl, NewtonParams, NonlinearContact, NonlinearError, NonlinearResult,
};
use synovia_pdas::{AuPdas, Pdas};

use crate::common::{finite_strain, level_times, max_rel};

fn model_2d(push: f64) -> (Model<2>, Vec<ContactPair<2>>) {
    let mut mesh = half_disc_refined(Point::<2>::new(0.0, 1.0), 1.0, 8, Point::<2>::new(0.0, 0.0), 0.25, 9)
        .expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[1] < 0.3 && n[1] < 0.0)
        .expect("contact");
    let mut model = Model::new();
    let b = model.add_body("disc", mesh, Arc::new(neo_hookean(10.0, 0.3).expect("law"))).expect("body");
    model.prescribe(b, "top", move |_, t| Vector::<2>::new(0.3 * push * t, -push * t)).expect("push");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("flat");
    (model, vec![ContactPair::rigid("disc-flat", b, "contact", Arc::new(flat)).with_friction(0.3)])
}

fn model_3d(push: f64) -> (Model<3>, Vec<ContactPair<3>>) {
    let mut mesh = hemisphere_refined(Point::<3>::new(0.0, 0.0, 1.0), 1.0, 4, Point::<3>::zeros(), 0.15, 12)
        .expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[2] < 0.15 && n[2] < 0.0)
        .expect("contact");
    let mut model = Model::new();
    let b = model.add_body("ball", mesh, Arc::new(neo_hookean(10.0, 0.3).expect("law"))).expect("body");
    model
        .prescribe(b, "top", move |_, t| Vector::<3>::new(0.3 * push * t, 0.15 * push * t, -push * t))
        .expect("push");
    let flat = PlaneObstacle::new(Point::<3>::zeros(), Vector::<3>::new(0.0, 0.0, 1.0)).expect("flat");
    (model, vec![ContactPair::rigid("ball-flat", b, "contact", Arc::new(flat)).with_friction(0.3)])
}

fn solve<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    levels: usize,
    strategy: ActiveSetStrategy,
) -> NonlinearResult<D> {
    let params = NewtonParams::default().with_active_sets(strategy);
    let mut nl = finite_strain(model, pairs, params);
    let results = nl.run(model, &level_times(levels), &Pdas::default(), |_| Ok(())).expect("converges");
    for r in &results {
        assert!(r.contact.kkt.max() <= 1e-8, "{strategy:?}: KKT {:e}", r.contact.kkt.max());
        assert!(r.report.residual() <= 1e-10, "{strategy:?}: residual {:e}", r.report.residual());
    }
    results.into_iter().last().expect("levels")
}

fn agree<const D: usize>(model: &Model<D>, pairs: &[ContactPair<D>], levels: usize) {
    let nested = solve(model, pairs, levels, ActiveSetStrategy::Nested);
    let n = &nested.contact.solution;
    assert!(n.report.slip > 0, "friction cells: {:?}", n.report);
    for strategy in [ActiveSetStrategy::Combined, ActiveSetStrategy::Outer] {
        let other = solve(model, pairs, levels, strategy);
        let c = &other.contact.solution;
        let du = max_rel(&c.u, &n.u);
        let dn = max_rel(&c.lambda_n, &n.lambda_n);
        let dt = max_rel(&c.lambda_t, &n.lambda_t);
        println!(
            "{D}D: Newton iterations of the last level nested {} / {strategy:?} {}, |Δu| {du:.1e}, |ΔΛ_n| {dn:.1e}, |ΔΛ_t| {dt:.1e}",
            nested.report.total_iterations, other.report.total_iterations
        );
        assert!(du <= 1e-8 && dn <= 1e-8 && dt <= 1e-8, "{D}D {strategy:?}: {du:e} {dn:e} {dt:e}");
    }
}

#[test]
fn combined_and_outer_equal_nested_2d_with_friction() {
    let (model, pairs) = model_2d(0.02);
    agree(&model, &pairs, 3);
}

#[test]
fn combined_and_outer_equal_nested_3d_with_friction() {
    let (model, pairs) = model_3d(0.01);
    agree(&model, &pairs, 2);
}

#[test]
fn a_strategy_the_solver_cannot_run_is_refused() {
    let (model, pairs) = model_2d(1e-3);
    let params = NewtonParams::default().with_active_sets(ActiveSetStrategy::Combined);
    let mut nl =
        NonlinearContact::new(&model, &pairs, &[Kinematics::FiniteStrain], ElasticParams::default(), params)
            .expect("set-up");
    // AU-PDAS has no single active-set step
    assert!(AuPdas::default().active_set_step().is_none());
    let err = nl.step_to(&model, 1.0, &AuPdas::default()).expect_err("refused");
    assert!(matches!(err, NonlinearError::InvalidParameter(ref m) if m.contains("active-set step")), "{err}");
    let mut outer = NonlinearContact::new(
        &model,
        &pairs,
        &[Kinematics::FiniteStrain],
        ElasticParams::default(),
        NewtonParams::default().with_active_sets(ActiveSetStrategy::Outer),
    )
    .expect("set-up");
    let err = outer.step_to(&model, 1.0, &AuPdas::default()).expect_err("refused");
    assert!(matches!(err, NonlinearError::InvalidParameter(ref m) if m.contains("Outer")), "{err}");
    // the Combined strategy under load control
    nl.step_to(&model, 1.0, &Pdas::default()).expect("level");
    let resultant = |_: &synovia_contact::operators::ContactGeometry<2>, l: &[f64]| l.iter().sum::<f64>();
    let mut control =
        LoadControl { resultant: &resultant, target: 1.0, tolerance: 1e-6, slope: 1.0, trials: 0 };
    let err = nl.step_controlled(&model, 1.1, &Pdas::default(), &mut control).expect_err("refused");
    assert!(matches!(err, NonlinearError::InvalidParameter(ref m) if m.contains("load control")), "{err}");
}
