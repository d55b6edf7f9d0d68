//! `JointModel::run_dynamic` with a nonlinear model (docs/model.md (12.2)): a Kelvin–Voigt
//! block with a neo-Hookean elastic part in finite strain, thrown onto a rigid floor with
//! friction, runs through the Newton iteration of every step and gives exactly what the
//! `NonlinearDynamicStepper` gives when driven by hand with the same data; a body without a
//! density is a typed error naming it.

use std::sync::Arc;

use synovia::nonlinear::NewtonParams;
use synovia::prelude::*;
use synovia::time::dynamic::{DynamicBody, DynamicParams};
use synovia::time::nonlinear_dynamic::NonlinearDynamicStepper;
use synovia_fem::Kinematics;
use synovia_material::neo_hookean;

const DT: Real = 2e-3;

fn block() -> Mesh<2> {
    rectangle(-0.5, 0.5, 0.02, 0.52, 12, 6, Grading::Uniform, Grading::Uniform).expect("mesh")
}

fn kelvin_voigt() -> KelvinVoigt<2> {
    let viscous: Arc<dyn Material<2>> = Arc::new(plane_strain(0.5, 0.3).expect("viscosity"));
    KelvinVoigt::new(Arc::new(neo_hookean(50.0, 0.3).expect("law")), Some(viscous), 1.0, 0.0).expect("KV")
}

fn floor() -> PlaneObstacle<2> {
    PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::y()).expect("plane")
}

fn joint(with_density: bool) -> JointModel<2> {
    let mut jm = JointModel::<2>::new();
    let b = if with_density {
        jm.add_body("block", block(), kelvin_voigt()).expect("body")
    } else {
        let law: Arc<dyn Material<2>> = Arc::new(neo_hookean(50.0, 0.3).expect("law"));
        jm.add_body("block", block(), law).expect("body")
    };
    jm.set_kinematics(b, Kinematics::FiniteStrain).expect("kinematics");
    jm.body_force(b, Vector::<2>::new(0.0, -9.81), Constant(1.0)).expect("gravity");
    jm.contact_rigid("floor", b, "bottom", floor(), 0.2).expect("contact");
    jm.initial_velocity(b, Vector::<2>::new(0.5, -2.0)).expect("velocity");
    jm.newton_params(NewtonParams::default().with_tolerance(1e-12));
    jm
}

#[test]
fn joint_model_runs_the_nonlinear_dynamic_scheme() {
    let jm = joint(true);
    assert!(jm.is_nonlinear());
    let steps = 60;
    let mut seen = 0;
    let run = jm
        .run_dynamic_with(DT, steps, |v| {
            seen += 1;
            assert_eq!(v.n_steps, steps + 1);
            Ok(())
        })
        .expect("run_dynamic");
    assert_eq!(seen, steps + 1);
    assert_eq!(run.records.len(), steps + 1);
    // the same scheme driven by hand
    let kv = kelvin_voigt();
    let body = DynamicBody::from_kelvin_voigt(&kv).expect("dynamic data");
    let model = jm.model();
    let mut st = NonlinearDynamicStepper::new(
        model,
        &[body],
        jm.pairs(),
        &[Kinematics::FiniteStrain],
        DynamicParams::new(DT),
        NewtonParams::default().with_tolerance(1e-12),
    )
    .expect("stepper");
    let n = model.bodies()[0].mesh.n_nodes();
    st.set_initial_state(model, None, Some(&[vec![Vector::<2>::new(0.5, -2.0); n]])).expect("initial");
    let solver = jm.build_solver().expect("solver");
    let mut contact_steps = 0;
    for rec in &run.records[1..] {
        let by_hand = st.step(model, solver.as_ref()).expect("step");
        assert!((by_hand.pairs[0].normal_force - rec.pairs[0].normal_force).abs() <= 1e-12);
        assert!((by_hand.kinetic_energy - rec.kinetic_energy).abs() <= 1e-12 * by_hand.kinetic_energy);
        contact_steps += usize::from(rec.pairs[0].normal_force > 0.0);
    }
    let diff = st.displacement()[0]
        .iter()
        .zip(&run.displacement[0])
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, Real::max);
    println!("run_dynamic vs the stepper by hand: {diff:.2e}; {contact_steps} contact steps");
    assert_eq!(diff, 0.0);
    assert!(contact_steps > 10);
    assert!(run.contact.is_some_and(|c| c.kkt.max() < 1e-8));
}

#[test]
fn a_nonlinear_body_without_density_is_named() {
    match joint(false).run_dynamic(DT, 5) {
        Err(JointError::Invalid(m)) => assert!(m.contains("`block` has no density"), "{m}"),
        other => panic!("expected a typed error, got {other:?}"),
    }
}
