//! Re-solve sessions of nonlinear models (`JointModel::prepare` on a neo-Hookean block in
//! finite strain, docs/nonlinear.md): a sequence of `JointSession::step` calls is
//! `run_quasistatic` one frame at a time (with Coulomb friction against a fixed rigid sphere,
//! and with a rigid indenter whose vertical translation is force-controlled), and
//! `solve_static` from the last frame reaches `run_static`'s solution (frictionless, from the
//! reference configuration) in fewer Newton iterations.

use std::sync::Arc;

use synovia::fem::Kinematics;
use synovia::material::neo_hookean;
use synovia::prelude::*;
use synovia::rigid::RigidBody;
use synovia::time::history::FnHistory;

type Error = Box<dyn std::error::Error>;

const E: f64 = 1.0e3;
const NU: f64 = 0.3;
const RADIUS: f64 = 2.0;

/// A neo-Hookean block `[-1, 1]² × [0, 1]` (finite strain) on a rigid sphere under its
/// bottom, its top pushed down and sheared by `(0.006, −0.002, −0.03) t`; Coulomb `mu`.
fn block_on_sphere(mu: f64) -> Result<JointModel<3>, Error> {
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [8, 8, 4], [Grading::Uniform; 3])?;
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, Arc::new(neo_hookean(E, NU)?) as Arc<dyn Material<3>>)?;
    joint.set_kinematics("block", Kinematics::FiniteStrain)?;
    joint.prescribe("block", "top", Vector::<3>::new(0.006, -0.002, -0.03), FnHistory::new(|t| t))?;
    let sphere = SphereObstacle::new(Point::<3>::new(0.1, 0.05, -RADIUS), RADIUS, false)?;
    joint.contact_rigid("bump", "block", "bottom", sphere, mu)?;
    Ok(joint)
}

/// A neo-Hookean block (clamped bottom) under a rigid spherical indenter: `tx` and the
/// rotations prescribed, `tz` loaded by `−force · t`; Coulomb `mu`.
fn block_under_indenter(force: f64, mu: f64) -> Result<JointModel<3>, Error> {
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [8, 8, 4], [Grading::Uniform; 3])?;
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, Arc::new(neo_hookean(E, NU)?) as Arc<dyn Material<3>>)?;
    joint.set_kinematics("block", Kinematics::FiniteStrain)?;
    joint.clamp("block", "bottom")?;
    let indenter = RigidBody::<3>::new("indenter", Point::<3>::new(0.0, 0.0, 3.0))?
        .prescribe(0, FnHistory::new(|t| 0.01 * t))?
        .prescribe(1, Constant(0.0))?
        .force_with_guess(2, FnHistory::new(move |t| -force * t), Constant(0.0))?
        .prescribe(3, Constant(0.0))?
        .prescribe(4, Constant(0.0))?
        .prescribe(5, Constant(0.0))?;
    joint.add_rigid_body(indenter)?;
    let shape = Arc::new(SphereObstacle::new(Point::<3>::new(0.1, -0.05, 1.0 + RADIUS), RADIUS, false)?);
    joint.contact_rigid_body("indent", "block", "top", "indenter", shape, mu)?;
    Ok(joint)
}

/// Displacements, `Λ_n` and `Λ_t` of one level.
type Level = (Vec<Vec<Vector<3>>>, Vec<f64>, Vec<f64>);

fn max_abs(u: &[Vec<Vector<3>>]) -> f64 {
    u.iter().flatten().map(|v| v.amax()).fold(0.0, f64::max)
}

fn max_diff(a: &[Vec<Vector<3>>], b: &[Vec<Vector<3>>]) -> f64 {
    a.iter().flatten().zip(b.iter().flatten()).map(|(x, y)| (x - y).amax()).fold(0.0, f64::max)
}

/// The session's steps against the run, level by level: displacements, `Λ_n`, tangential
/// multipliers (relative 1e-12: the same levels from the same states).
fn steps_equal_the_run(joint: &JointModel<3>, times: &[f64]) -> Result<(), Error> {
    let mut levels: Vec<Level> = Vec::new();
    let run = joint.run_quasistatic_with(times, |view| {
        let r = view.result;
        levels.push((r.displacement.clone(), r.solution.lambda_n.clone(), r.solution.lambda_t.clone()));
        Ok(())
    })?;
    let mut session = joint.prepare()?;
    assert!(session.result().is_none());
    for (level, &t) in times.iter().enumerate() {
        let report = session.step(t)?;
        assert_eq!(report.step, level);
        assert_eq!(report.warm_started, level > 0);
        let r = session.result().ok_or("no result")?;
        let (u, ln, lt) = &levels[level];
        let du = max_diff(u, &r.displacement) / max_abs(u);
        let lmax = ln.iter().copied().fold(0.0, f64::max);
        assert!(lmax > 0.0, "level {level}: no contact");
        let dl = ln.iter().zip(&r.solution.lambda_n).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / lmax;
        assert_eq!(lt.len(), r.solution.lambda_t.len(), "level {level}: friction cells");
        let dt = lt.iter().zip(&r.solution.lambda_t).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        let record = session.record().ok_or("no record")?;
        let rigid = match (record.rigid.first(), run.records[level].rigid.first()) {
            (Some(a), Some(b)) => (a.dofs[2] - b.dofs[2]).abs(),
            _ => 0.0,
        };
        eprintln!(
            "level {level}: displacements {du:.1e}, Λ_n {dl:.1e}, Λ_t {dt:.1e}, tz {rigid:.1e}, {} friction cells, {} Newton iterations, KKT {:.1e}",
            lt.len() / 2,
            report.iterations,
            report.kkt
        );
        assert!(du < 1e-12 && dl < 1e-12 && dt < 1e-12 && rigid < 1e-12, "level {level}");
        assert!(report.kkt < 1e-8, "level {level}: KKT {}", report.kkt);
    }
    assert!(session.factorizations() > 0);
    // the times must increase
    assert!(session.step(times[0]).is_err());
    Ok(())
}

#[test]
fn session_steps_equal_the_quasi_static_run_with_friction() -> Result<(), Error> {
    let joint = block_on_sphere(0.3)?;
    assert!(joint.is_nonlinear());
    steps_equal_the_run(&joint, &[0.25, 0.5, 0.75, 1.0])
}

#[test]
fn session_steps_equal_the_run_with_a_force_controlled_indenter() -> Result<(), Error> {
    let joint = block_under_indenter(20.0, 0.2)?;
    steps_equal_the_run(&joint, &[0.4, 0.7, 1.0])
}

/// `solve_static` after frames at other loads: the frictionless static solution at `t` from the
/// last displacement equals `run_static(t)` (from the reference configuration) to the Newton
/// tolerance, in fewer Newton iterations; `reset` forgets the state (the next solve is cold).
#[test]
fn session_static_solve_is_warm_and_equals_run_static() -> Result<(), Error> {
    let joint = block_on_sphere(0.0)?;
    let cold = joint.run_static(1.0)?;
    let cold_iterations = cold.records[0].iterations;
    let mut session = joint.prepare()?;
    session.solve_static(0.8)?;
    session.step(0.9)?;
    let report = session.solve_static(1.0)?;
    assert!(report.warm_started);
    assert_eq!(report.step, 0);
    let r = session.result().ok_or("no result")?;
    let u_cold = &cold.displacement;
    let du = max_diff(u_cold, &r.displacement) / max_abs(u_cold);
    let lc = &cold.contact.as_ref().ok_or("no contact")?.solution.lambda_n;
    let lmax = lc.iter().copied().fold(0.0, f64::max);
    let dl = lc.iter().zip(&r.solution.lambda_n).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / lmax;
    eprintln!(
        "static at t = 1 after frames at 0.8 and 0.9: displacements {du:.1e}, Λ_n {dl:.1e}; Newton iterations {} warm vs {cold_iterations} cold; KKT {:.1e}",
        report.iterations, report.kkt
    );
    assert!(du < 1e-6 && dl < 1e-6, "{du:e} {dl:e}");
    assert!(report.iterations < cold_iterations, "{} vs {cold_iterations}", report.iterations);
    session.reset();
    assert!(session.result().is_none());
    let again = session.solve_static(1.0)?;
    assert!(!again.warm_started);
    let r = session.result().ok_or("no result")?;
    assert!(max_diff(u_cold, &r.displacement) / max_abs(u_cold) < 1e-12);
    Ok(())
}
