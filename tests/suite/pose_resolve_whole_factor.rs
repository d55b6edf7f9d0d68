//! Pose re-solves on the whole-factor path of a large candidate surface (issue 17,
//! `pose_resolve_3d`): a block under a tessellated ball (`SurfaceObstacle`) given as a rigid
//! partner, no dense interface block (`max_dofs = 0`), gap screening, a search distance —
//! the Schur columns from kept unit solves with sparse right-hand sides, the far nodes from
//! the kept far answers of the surface. Each pose of one session (warm-started, kept solves
//! and answers from the poses before) equals a fresh session's solve of that pose alone to
//! 1e-10, frictionless and with friction.

use std::sync::Arc;

use synovia::contact_ops::SurfaceObstacle;
use synovia::mesh::TriangleSurface;
use synovia::prelude::*;
use synovia::rigid::{PoseInput, RigidBody};

/// Reference point of the ball's body; the ball's centre is 0.48 below it.
const CENTRE: [f64; 3] = [0.0, 0.0, 2.0];

fn joint(input: &PoseInput<3>, friction: f64) -> Result<JointModel<3>, Box<dyn std::error::Error>> {
    let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [12, 12, 6], [Grading::Uniform; 3])?;
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, isotropic(1.0e3, 0.3)?)?;
    joint.clamp("block", "bottom")?;
    // a fresh surface (and so fresh kept far answers) for every model
    let ball = TriangleSurface::icosphere(Point::<3>::new(0.0, 0.0, 1.52), 0.5, 3)?;
    let shape = Arc::new(SurfaceObstacle::solid(ball)?);
    let body = RigidBody::<3>::new("ball", Point::<3>::from(CENTRE))?.prescribe_pose(input);
    joint.add_rigid_body(body)?;
    joint.contact_rigid_body("ball-block", "block", "top", "ball", shape, friction)?;
    joint.search_distance("ball-block", 0.1)?;
    joint.interface_block(
        synovia::linalg::InterfaceBlockParams::default().with_max_dofs(0).with_screened_dofs(0),
    );
    joint.screening_band(Some(0.05))?;
    Ok(joint)
}

/// Poses: translation of the reference point and an axis–angle rotation about z.
const POSES: [([f64; 3], f64); 5] = [
    ([0.0, 0.0, -0.05], 0.0),
    ([0.05, 0.02, -0.055], 0.1),
    ([0.12, 0.05, -0.06], 0.2),
    ([0.2, 0.1, -0.06], 0.3),
    ([0.25, 0.05, -0.055], 0.2),
];

fn set(input: &PoseInput<3>, pose: ([f64; 3], f64)) -> Result<(), Box<dyn std::error::Error>> {
    input.set_axis_angle(pose.0, [0.0, 0.0, 1.0], pose.1)?;
    Ok(())
}

#[test]
fn pose_resolves_on_the_whole_factor_equal_fresh_solves() -> Result<(), Box<dyn std::error::Error>> {
    for friction in [0.0, 0.3] {
        let input = PoseInput::<3>::new();
        let joint_a = joint(&input, friction)?;
        let mut session = joint_a.prepare()?;
        for (k, &pose) in POSES.iter().enumerate() {
            set(&input, pose)?;
            let report = session.solve_static(k as f64)?;
            assert!(report.kkt < 1e-8, "pose {k}: KKT {}", report.kkt);
            let a = session.result().ok_or("no result")?;
            // the same pose alone, from scratch
            let fresh_input = PoseInput::<3>::new();
            let joint_b = joint(&fresh_input, friction)?;
            let mut fresh = joint_b.prepare()?;
            set(&fresh_input, pose)?;
            fresh.solve_static(k as f64)?;
            let b = fresh.result().ok_or("no result")?;
            let scale = b.solution.lambda_n.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            assert!(scale > 0.0, "pose {k}: the ball must touch the block");
            let diff = |x: &[f64], y: &[f64]| {
                assert_eq!(x.len(), y.len());
                x.iter().zip(y).fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()))
            };
            // the record's strain energy (½ Uᵀ A U: the block is clamped, no lift) equals the
            // element loop over the displacements
            let energy = session.record().ok_or("no record")?.strain_energy;
            let looped = synovia::fem::post::total_strain_energy(joint_a.model(), &a.displacement)?;
            assert!(looped > 0.0, "pose {k}: strained");
            assert!(
                (energy - looped).abs() <= 1e-12 * looped,
                "pose {k}, μ = {friction}: strain energy {energy:e} vs element loop {looped:e}"
            );
            let dn = diff(&a.solution.lambda_n, &b.solution.lambda_n);
            assert!(dn <= 1e-10 * scale, "pose {k}, μ = {friction}: Λ_n differ by {dn:e} (max {scale:e})");
            let u = |s: &synovia::contact::StaticContactResult<3>| -> Vec<f64> {
                s.displacement.iter().flatten().flat_map(|v| v.iter().copied().collect::<Vec<_>>()).collect()
            };
            let umax = u(b).iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let du = diff(&u(a), &u(b));
            assert!(du <= 1e-10 * umax, "pose {k}, μ = {friction}: u differs by {du:e} (max {umax:e})");
        }
    }
    Ok(())
}

/// With a non-zero prescribed displacement (the top of a block pushed onto a bump) the
/// strain energy of a contact solve is the element loop itself (the reduced `½ Ũᵀ A Ũ` would
/// miss the lift), bit for bit (without one: the test above).
#[test]
fn strain_energy_of_a_solve_with_and_without_lifts() -> Result<(), Box<dyn std::error::Error>> {
    use synovia::contact::StaticContact;
    use synovia::contact_ops::testing::block_on_bump;
    let solver = synovia::solvers::by_name("pdas")?;
    let (model, pairs) = block_on_bump(16, 4, |t| Vector::<2>::new(0.01 * t, -0.02 * t))?;
    let contact = StaticContact::new(&model, &pairs, ElasticParams::default())?;
    let res = contact.solve(&model, 1.0, solver.as_ref(), None, None, None)?;
    let looped = synovia::fem::post::total_strain_energy(&model, &res.displacement)?;
    assert!(looped > 0.0);
    assert_eq!(contact.strain_energy(&model, &res)?.to_bits(), looped.to_bits());
    Ok(())
}
