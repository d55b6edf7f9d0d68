//! A navigation tracker's frames as poses of a rigid partner (`synovia::rigid::PoseInput`): a
//! session whose rigid body follows poses given as quaternions solves exactly what the same
//! poses given as the body's angles (settable histories) solve, frictionless and with friction,
//! on one factorisation.

use std::sync::Arc;

use nalgebra::{UnitQuaternion, Vector3};
use synovia::prelude::*;
use synovia::rigid::{PoseInput, RigidBody};
use synovia::time::history::SharedValue;

/// A block clamped at its bottom, and a ball (radius 0.5, its centre 0.48 below the body's
/// reference point, so rotations move it) just above its top.
fn joint(body: RigidBody<3>) -> Result<JointModel<3>, Box<dyn std::error::Error>> {
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [8, 8, 4], [Grading::Uniform; 3])?;
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, isotropic(1.0e3, 0.3)?)?;
    joint.clamp("block", "bottom")?;
    let ball = Arc::new(SphereObstacle::new(Point::<3>::new(0.0, 0.0, 1.52), 0.5, false)?);
    joint.add_rigid_body(body)?;
    joint.contact_rigid_body("ball-block", "block", "top", "ball", ball, 0.3)?;
    Ok(joint)
}

/// Frames: translation of the reference point and the angles `(rx, ry, rz)` of `R = R_z R_x R_y`.
const FRAMES: [([f64; 3], [f64; 3]); 4] = [
    ([0.0, 0.0, -0.05], [0.0, 0.0, 0.0]),
    ([0.01, 0.02, -0.06], [0.05, -0.03, 0.2]),
    ([0.02, 0.03, -0.06], [0.1, -0.05, 0.4]),
    ([0.01, 0.02, -0.055], [0.05, 0.02, 0.1]),
];

#[test]
fn poses_from_quaternions_solve_what_the_same_angles_solve() -> Result<(), Box<dyn std::error::Error>> {
    let centre = Point::<3>::new(0.0, 0.0, 2.0);
    // A: the body's own angles through settable values
    let values: Vec<SharedValue> = (0..6).map(|_| SharedValue::new(0.0)).collect();
    let mut by_angles = RigidBody::<3>::new("ball", centre)?;
    for (dof, v) in values.iter().enumerate() {
        by_angles = by_angles.prescribe(dof, v.clone())?;
    }
    // B: the same poses as a tracker gives them, quaternions
    let input = PoseInput::<3>::new();
    let by_pose = RigidBody::<3>::new("ball", centre)?.prescribe_pose(&input);
    let (joint_a, joint_b) = (joint(by_angles)?, joint(by_pose)?);
    let (mut a, mut b) = (joint_a.prepare()?, joint_b.prepare()?);
    for (frame, &(t, q)) in FRAMES.iter().enumerate() {
        for k in 0..3 {
            values[k].set(t[k]);
            values[3 + k].set(q[k]);
        }
        // R = R_z(rz) R_x(rx) R_y(ry) as a quaternion product, independent of the library
        let rot = |axis: Vector3<f64>, angle: f64| {
            UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle)
        };
        let unit = rot(Vector3::z(), q[2]) * rot(Vector3::x(), q[0]) * rot(Vector3::y(), q[1]);
        input.set_quaternion(t, [unit.w, unit.i, unit.j, unit.k])?;
        let time = frame as f64;
        let (ra, rb) = if frame == 0 {
            (a.solve_static(time)?, b.solve_static(time)?)
        } else {
            (a.step(time)?, b.step(time)?)
        };
        assert!(ra.kkt < 1e-8 && rb.kkt < 1e-8, "frame {frame}: KKT {} {}", ra.kkt, rb.kkt);
        let (sa, sb) = (a.result().ok_or("no result")?, b.result().ok_or("no result")?);
        let scale = sa.solution.lambda_n.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0, "frame {frame}: the ball must touch the block");
        let diff = |x: &[f64], y: &[f64]| x.iter().zip(y).fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(diff(&sa.solution.lambda_n, &sb.solution.lambda_n) <= 1e-10 * scale, "frame {frame}");
        let lt = diff(&sa.solution.lambda_t, &sb.solution.lambda_t);
        assert!(lt <= 1e-9, "frame {frame}: Λ_t differ by {lt:e}");
        let u = |s: &synovia::contact::StaticContactResult<3>| -> Vec<f64> {
            s.displacement.iter().flatten().flat_map(|v| v.iter().copied().collect::<Vec<_>>()).collect()
        };
        let umax = u(sa).iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(diff(&u(sa), &u(sb)) <= 1e-10 * umax, "frame {frame}");
        // the records report the body's angles either way
        let (da, db) =
            (&a.record().ok_or("no record")?.rigid[0].dofs, &b.record().ok_or("no record")?.rigid[0].dofs);
        assert!(diff(da, db) < 1e-12, "frame {frame}: {da:?} vs {db:?}");
        if frame > 0 {
            let friction = b.record().ok_or("no record")?.pairs[0].tangential_force;
            assert!(friction > 0.0, "frame {frame}: the moving ball drags the surface");
        }
    }
    assert_eq!(b.factorizations(), 1);
    Ok(())
}
