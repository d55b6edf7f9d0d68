//! `NewtonParams::linear_bodies_by_stiffness`: the internal force and tangent of the linear
//! bodies (small strain, constant stiffness) as products with their kept stiffness
//! (`synovia_fem::linear_bodies`) instead of the element loop. The Newton solves with and
//! without it are the same to rounding (same iterations, displacements and multipliers), and a
//! linear law routed through the Newton path still equals the linear path.

use std::sync::Arc;

use synovia_contact::obstacle::PlaneObstacle;
use synovia_contact::operators::ContactPair;
use synovia_contact::StaticContact;
use synovia_fem::{ElasticParams, Kinematics, Model};
use synovia_material::{neo_hookean, plane_strain, Material};
use synovia_mesh::generators::{half_disc_refined, rectangle, Grading};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::BoundaryKind;
use synovia_nonlinear::{NewtonParams, NonlinearContact, NonlinearResult};
use synovia_pdas::Pdas;

/// A half-disc pressed on a rigid flat by its top (material `disc`), and a separate block
/// (linear, small strain) clamped at its bottom and pushed sideways at its top.
fn model(disc: Arc<dyn Material<2>>, push: f64) -> (Model<2>, Vec<ContactPair<2>>) {
    let mut mesh = half_disc_refined(Point::<2>::new(0.0, 1.0), 1.0, 8, Point::<2>::new(0.0, 0.0), 0.25, 9)
        .expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[1] < 0.3 && n[1] < 0.0)
        .expect("contact");
    let mut model = Model::new();
    let b = model.add_body("disc", mesh, disc).expect("body");
    model.prescribe(b, "top", move |_, t| Vector::<2>::new(0.0, -push * t)).expect("push");
    let mut block = rectangle(2.0, 3.0, 0.0, 1.0, 8, 8, Grading::Uniform, Grading::Uniform).expect("block");
    block.set_part_kind("bottom", BoundaryKind::Prescribed).expect("bottom");
    block.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    let linear: Arc<dyn Material<2>> = Arc::new(plane_strain(50.0, 0.25).expect("law"));
    let k = model.add_body("block", block, linear).expect("block");
    model.prescribe(k, "bottom", |_, _| Vector::<2>::zeros()).expect("clamp");
    model.prescribe(k, "top", move |_, t| Vector::<2>::new(0.5 * push * t, 0.0)).expect("shear");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("flat");
    (model, vec![ContactPair::rigid("disc-flat", b, "contact", Arc::new(flat))])
}

fn solve(
    model: &Model<2>,
    pairs: &[ContactPair<2>],
    kin: &[Kinematics],
    on: bool,
) -> Vec<NonlinearResult<2>> {
    let params = NewtonParams::default().with_linear_bodies_by_stiffness(on);
    let mut nl = NonlinearContact::new(model, pairs, kin, ElasticParams::default(), params).expect("set-up");
    nl.run(model, &[0.5, 1.0], &Pdas::default(), |_| Ok(())).expect("converges")
}

/// The largest nodal difference relative to the largest nodal value of `b`.
fn max_rel(a: &[Vec<Vector<2>>], b: &[Vec<Vector<2>>]) -> f64 {
    let scale = b.iter().flatten().fold(0.0_f64, |m, v| m.max(v.norm()));
    a.iter().flatten().zip(b.iter().flatten()).fold(0.0_f64, |m, (x, y)| m.max((x - y).norm())) / scale
}

#[test]
fn products_with_the_kept_stiffness_give_the_same_newton_solve() {
    let (model, pairs) = model(Arc::new(neo_hookean(10.0, 0.3).expect("law")), 0.1);
    let kin = [Kinematics::FiniteStrain, Kinematics::SmallStrain];
    let on = solve(&model, &pairs, &kin, true);
    let off = solve(&model, &pairs, &kin, false);
    for (a, b) in on.iter().zip(&off) {
        let (ia, ib) = (&a.report.iterations, &b.report.iterations);
        assert_eq!(ia.len(), ib.len(), "Newton iterations {ia:?} vs {ib:?}");
        let du = max_rel(&a.contact.displacement, &b.contact.displacement);
        let lmax = b.contact.solution.lambda_n.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let dl = a
            .contact
            .solution
            .lambda_n
            .iter()
            .zip(&b.contact.solution.lambda_n)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
            / lmax;
        println!("t = {}: {} iterations, displacement {du:.1e}, multipliers {dl:.1e}", a.time, ia.len());
        assert!(du < 1e-10 && dl < 1e-10, "displacement {du:e}, multipliers {dl:e}");
        // the block is loaded: its (linear) internal force takes part in the balance
        assert!(a.contact.displacement[1].iter().any(|u| u.norm() > 1e-3));
    }
}

#[test]
fn linear_law_through_newton_with_kept_stiffness_equals_the_linear_path() {
    let (model, pairs) = model(Arc::new(plane_strain(10.0, 0.3).expect("law")), 1e-3);
    let kin = [Kinematics::SmallStrain, Kinematics::SmallStrain];
    let newton = solve(&model, &pairs, &kin, true);
    let last = newton.last().expect("levels");
    let sc = StaticContact::new(&model, &pairs, ElasticParams::default()).expect("set-up");
    let linear = sc.solve(&model, 1.0, &Pdas::default(), None, None, None).expect("solve");
    let du = max_rel(&last.contact.displacement, &linear.displacement);
    println!("linear law through Newton vs the linear path: displacement {du:.1e}");
    assert!(du < 1e-8, "displacement {du:e}");
}
