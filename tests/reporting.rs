//! Per-pair reporting: resultant force, moment about the origin, centre of pressure and mean
//! pressure agree with their definitions on problems whose statics are known.

use synovia::fem::ComponentMask;
use synovia::prelude::*;

/// A block `[0, 1] × [0, ½]` on the rigid flat `y = 0`, its top pushed down by
/// `δ(x) = 0.01 + 0.01 x` (more on the right): all contact forces are vertical, so the moment
/// about the origin is `M_z = x_cop F_y` and the centre of pressure lies right of the middle.
#[test]
fn moment_and_centre_of_pressure_of_a_tilted_punch() {
    let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 16, 8, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let b = joint.add_body("block", mesh, plane_strain(1.0e3, 0.3).expect("material")).expect("body");
    joint
        .prescribe_field(b, "top", ComponentMask::ALL, |x, _t| Vector::<2>::new(0.0, -(0.01 + 0.01 * x[0])))
        .expect("top");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
    joint.contact_rigid("flat", b, "bottom", flat, 0.0).expect("pair");
    let run = joint.run_static(0.0).expect("solve");
    let p = &run.records[0].pairs[0];
    let fy = p.force[1];
    assert!(
        fy > 0.0 && (fy - p.normal_force).abs() < 1e-12 * fy,
        "vertical forces: {:?} vs {}",
        p.force,
        p.normal_force
    );
    let cop = p.centre_of_pressure.expect("in contact");
    assert!(cop[0] > 0.5 && cop[0] < 1.0 && cop[1].abs() < 1e-12, "centre of pressure {cop:?}");
    assert!(
        (p.moment[2] - cop[0] * fy).abs() < 1e-12 * fy,
        "M_z {} vs x_cop F_y {}",
        p.moment[2],
        cop[0] * fy
    );
    assert_eq!((p.moment[0], p.moment[1]), (0.0, 0.0));
    assert!((p.mean_pressure - p.normal_force / p.contact_area).abs() < 1e-15 * p.mean_pressure);
    assert!(p.mean_pressure < p.peak_pressure);
}

/// A block pressed on a rigid ball centred below `(c_x, c_y)`: by symmetry of the ball, every
/// normal force points through the ball's centre, so the moment about that centre vanishes —
/// about the origin `M = c × F` — and the centre of pressure lies near the ball's top.
#[test]
fn forces_on_a_ball_pass_through_its_centre() {
    let centre = Point::<3>::new(0.1, -0.05, -2.0);
    let mesh = box_mesh([-0.5, -0.5, 0.0], [0.5, 0.5, 0.5], [8, 8, 4], [Grading::Uniform; 3]).expect("mesh");
    let mut joint = JointModel::<3>::new();
    let b = joint.add_body("block", mesh, isotropic(1.0e3, 0.3).expect("material")).expect("body");
    joint.prescribe(b, "top", Vector::<3>::new(0.0, 0.0, -1.0), Constant(0.02)).expect("top");
    joint
        .contact_rigid("ball", b, "bottom", SphereObstacle::new(centre, 2.0, false).expect("ball"), 0.0)
        .expect("pair");
    let run = joint.run_static(0.0).expect("solve");
    let p = &run.records[0].pairs[0];
    let f = Vector::<3>::new(p.force[0], p.force[1], p.force[2]);
    let expected = centre.cross(&f);
    let scale = f.norm() * centre.norm();
    for k in 0..3 {
        assert!((p.moment[k] - expected[k]).abs() < 1e-9 * scale, "M {:?} vs c × F {expected:?}", p.moment);
    }
    let cop = p.centre_of_pressure.expect("in contact");
    assert!((cop[0] - centre.x).abs() < 0.1 && (cop[1] - centre.y).abs() < 0.1, "centre of pressure {cop:?}");
}
