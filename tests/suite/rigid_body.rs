//! Rigid bodies with mixed control (`synovia::rigid`): force-controlled degrees of freedom
//! reach equilibrium with the contact forces and the reactions of tied parts; prescribed ones
//! pose the body; a force nothing resists is refused.

use std::sync::Arc;

use synovia::prelude::*;
use synovia::rigid::RigidBody;

fn block2d() -> Result<JointModel<2>, Box<dyn std::error::Error>> {
    let mesh = rectangle(-1.0, 1.0, 0.0, 1.0, 16, 8, Grading::Uniform, Grading::Uniform)?;
    let mut joint = JointModel::<2>::new();
    joint.add_body("block", mesh, plane_strain(1.0e3, 0.3)?)?;
    Ok(joint)
}

/// A plate tied to the top of a block pushes it onto a rigid floor with a given force: the
/// floor carries exactly that force, and the same pose prescribed gives the same reactions.
#[test]
fn tied_plate_under_force_control_balances_the_floor() -> Result<(), Box<dyn std::error::Error>> {
    let mut joint = block2d()?;
    let plate = RigidBody::<2>::new("plate", Point::<2>::new(0.0, 1.0))?.force(1, Constant(-25.0))?;
    joint.add_rigid_body(plate)?;
    joint.tie_to_rigid_body("block", "top", "plate")?;
    let floor = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0))?;
    joint.contact_rigid("floor", "block", "bottom", floor, 0.0)?;
    let run = joint.run_static(0.0)?;
    let rec = &run.records[0];
    let floor_force = rec.pairs[0].force;
    assert!((floor_force[1] - 25.0).abs() < 1e-9 * 25.0, "floor force on the block {floor_force:?}");
    let rigid = &rec.rigid[0];
    assert!(rigid.balance_error < 1e-9, "{rigid:?}");
    assert!((rigid.reaction[1] - 25.0).abs() < 1e-9 * 25.0, "{rigid:?}");
    // the plate went down; compression of a block with a frictionless floor and a bonded
    // top lies between the uniaxial-strain and uniaxial-stress values of F / (E* w)
    let dy = rigid.dofs[1];
    let e = 1.0e3;
    let nu: f64 = 0.3;
    let stress_free = 25.0 / 2.0 / (e / (1.0 - nu * nu)); // plane strain, free sides
    let constrained = 25.0 / 2.0 * (1.0 + nu) * (1.0 - 2.0 * nu) / (e * (1.0 - nu));
    assert!(-dy < stress_free * 1.001 && -dy > constrained * 0.999, "dy = {dy}");

    // the same plate position prescribed: the same reaction
    let mut fixed = block2d()?;
    let plate = RigidBody::<2>::new("plate", Point::<2>::new(0.0, 1.0))?.prescribe(1, Constant(dy))?;
    fixed.add_rigid_body(plate)?;
    fixed.tie_to_rigid_body("block", "top", "plate")?;
    let floor = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0))?;
    fixed.contact_rigid("floor", "block", "bottom", floor, 0.0)?;
    let again = fixed.run_static(0.0)?;
    let r2 = &again.records[0].rigid[0];
    assert!((r2.reaction[1] - 25.0).abs() < 1e-8 * 25.0, "{r2:?}");
    assert!(r2.applied.iter().all(Option::is_none));
    Ok(())
}

/// A rigid cylinder, posed by a force along −y and a prescribed tilt, on a clamped block: the
/// contact carries the force, the moment about the rigid body's axis is that of the contact
/// forces, and a free rotation under zero moment centres the contact under the body.
#[test]
fn rigid_indenter_under_force_control() -> Result<(), Box<dyn std::error::Error>> {
    let mut joint = block2d()?;
    joint.clamp("block", "bottom")?;
    let centre = Point::<2>::new(0.1, 1.5);
    let indenter = RigidBody::<2>::new("indenter", centre)?.force(1, Constant(-4.0))?;
    joint.add_rigid_body(indenter)?;
    // the shape in the indenter's frame: a circle of radius 0.5 about its centre (touching y = 1)
    let shape = Arc::new(SphereObstacle::new(centre, 0.5, false)?);
    // starts 0.05 above the block: the driver moves it to first contact
    let lift = RigidBody::<2>::dof_index("ty")?;
    assert_eq!(lift, 1);
    joint.contact_rigid_body("indent", "block", "top", "indenter", shape, 0.0)?;
    let mut session = joint.prepare()?;
    for force_time in [0.0, 1.0] {
        let report = session.solve_static(force_time)?;
        assert!(report.kkt < 1e-8);
        let rec = session.record().ok_or("no record")?;
        let pair = &rec.pairs[0];
        assert!((pair.normal_force - 4.0).abs() < 5e-2, "{pair:?}"); // curved normals
        assert!((pair.force[1] + 4.0).abs() < 1e-9 * 4.0, "{pair:?}");
        let rigid = &rec.rigid[0];
        assert!(rigid.balance_error < 1e-9, "{rigid:?}");
        assert!(rigid.dofs[1] < 0.0);
        // the circle's normals pass through its centre: no moment about it (to the geometry
        // tolerance, 1e-6 of the model size, of the last rebuild)
        assert!(rigid.reaction[2].abs() < 1e-5 * 4.0, "{rigid:?}");
        let cop = pair.centre_of_pressure.ok_or("no contact")?;
        assert!((cop[0] - 0.1).abs() < 0.07, "centre of pressure {cop:?} (element size 0.125)");
    }
    assert_eq!(session.factorizations(), 1);
    Ok(())
}

/// A force-controlled degree of freedom that no pair or tie resists is refused with a message
/// that names it.
#[test]
fn unresisted_force_is_refused() -> Result<(), Box<dyn std::error::Error>> {
    let mut joint = block2d()?;
    joint.clamp("block", "bottom")?;
    let centre = Point::<2>::new(0.0, 1.5);
    // pushes sideways (+x): the circle never closes a gap on the top in that direction
    let indenter = RigidBody::<2>::new("indenter", centre)?.force(0, Constant(3.0))?;
    joint.add_rigid_body(indenter)?;
    let shape = Arc::new(SphereObstacle::new(centre, 0.4, false)?);
    joint.contact_rigid_body("indent", "block", "top", "indenter", shape, 0.0)?;
    let err = joint.run_static(0.0).err().ok_or("an unresisted force was accepted")?;
    let msg = err.to_string();
    assert!(msg.contains("`indenter`.tx") && msg.contains("not resisted"), "{msg}");
    Ok(())
}

/// Two discs of one rigid body (two condyles).
#[derive(Debug)]
struct TwoDiscs {
    centres: [Point<2>; 2],
    radius: f64,
}
impl TwoDiscs {
    fn nearest(&self, x: &Point<2>) -> (f64, Vector<2>) {
        let [a, b] = self.centres.map(|c| {
            let d = x - c;
            (d.norm() - self.radius, d / d.norm())
        });
        if a.0 <= b.0 {
            a
        } else {
            b
        }
    }
}
impl synovia::contact_ops::operators::SignedDistance<2> for TwoDiscs {
    fn distance(&self, x: &Point<2>) -> f64 {
        self.nearest(x).0
    }
    fn gradient(&self, x: &Point<2>) -> Vector<2> {
        self.nearest(x).1
    }
}

/// Two discs of one rigid body (a 2D "femur" with two condyles), pushed down with a force and
/// free to rotate under zero moment, start tilted so that one disc alone touches: one contact
/// region resists only one combination of translation and rotation (the Jacobian is of rank
/// one), and the iteration walks along the other until the second disc takes load. By symmetry
/// the equilibrium is level with the force shared equally (up to the mesh, whose triangles all
/// have their diagonal the same way: not mirror-symmetric).
#[test]
fn two_condyles_free_to_rotate_share_the_force() -> Result<(), Box<dyn std::error::Error>> {
    let mesh = rectangle(-1.0, 1.0, 0.0, 1.0, 32, 8, Grading::Uniform, Grading::Uniform)?;
    let mut joint = JointModel::<2>::new();
    joint.add_body("block", mesh, plane_strain(1.0e3, 0.3)?)?;
    joint.clamp("block", "bottom")?;
    let centre = Point::<2>::new(0.0, 1.5);
    let rz = RigidBody::<2>::dof_index("rz")?;
    let femur = RigidBody::<2>::new("femur", centre)?
        .force(1, Constant(-4.0))?
        // zero moment about the centre, started tilted by 0.02 rad: the right disc sinks by
        // 0.01, the left one lifts by 0.01
        .force_with_guess(rz, Constant(0.0), Constant(-0.02))?;
    joint.add_rigid_body(femur)?;
    let shape =
        Arc::new(TwoDiscs { centres: [Point::<2>::new(-0.5, 1.3), Point::<2>::new(0.5, 1.3)], radius: 0.3 });
    joint.contact_rigid_body("condyles", "block", "top", "femur", shape, 0.0)?;
    joint.search_distance("condyles", 0.5)?;
    joint.split_pair_report(
        "condyles",
        synovia::contact_ops::operators::PairSplit::new("right", "left", [0.0; 3], [1.0, 0.0, 0.0])?,
    )?;
    let mut session = joint.prepare()?;
    let report = session.solve_static(0.0)?;
    assert!(report.kkt < 1e-8);
    let rec = session.record().ok_or("no record")?;
    let rigid = &rec.rigid[0];
    assert!(rigid.balance_error < 1e-9, "{rigid:?}");
    assert!(rigid.dofs[rz].abs() < 1e-3, "nearly level: {rigid:?}");
    let side = |name: &str| rec.pairs[0].sides.iter().find(|s| s.name == name).map(|s| -s.force[1]);
    let (left, right) = (side("left").ok_or("no left side")?, side("right").ok_or("no right side")?);
    assert!((left - 2.0).abs() < 0.02 && (right - 2.0).abs() < 0.02, "left {left}, right {right}");
    assert!((left + right - 4.0).abs() < 1e-9, "left {left}, right {right}");
    Ok(())
}

/// Friction against a moving rigid body: a cylinder pressed onto a clamped block with a
/// constant force and dragged sideways by a prescribed translation far beyond the elastic
/// stick range. The slip is measured relative to the cylinder (docs/model.md §10), so every
/// loaded cell slips and the friction force on the block is the Tresca capacity `μ P` of the
/// previous level's pressure, along the motion; dragged back, it changes sign. (Measuring the
/// slip of the block's nodes alone would let them stick and carry almost no friction.)
#[test]
fn friction_follows_a_moving_rigid_partner() -> Result<(), Box<dyn std::error::Error>> {
    let mut joint = block2d()?;
    joint.clamp("block", "bottom")?;
    let centre = Point::<2>::new(0.0, 3.0);
    let drag = synovia::time::history::FnHistory::new(drag_at);
    let cylinder = RigidBody::<2>::new("cylinder", centre)?.prescribe(0, drag)?.force(1, Constant(-20.0))?;
    joint.add_rigid_body(cylinder)?;
    let shape = Arc::new(SphereObstacle::new(centre, 2.0, false)?);
    let mu = 0.2;
    joint.contact_rigid_body("drag", "block", "top", "cylinder", shape, mu)?;
    let mut session = joint.prepare()?;
    session.solve_static(0.0)?;
    let mut previous_normal = session.record().ok_or("no record")?.pairs[0].normal_force;
    for (t, direction) in [(1.0, 1.0), (2.0, 1.0), (3.0, -1.0)] {
        let report = session.step(t)?;
        assert!(report.kkt < 1e-8, "t = {t}: KKT {}", report.kkt);
        let rec = session.record().ok_or("no record")?;
        let pair = &rec.pairs[0];
        let rigid = &rec.rigid[0];
        assert!(rigid.balance_error < 1e-9, "{rigid:?}");
        assert!((rigid.dofs[0] - drag_at(t)).abs() < 1e-12, "{rigid:?}");
        // every loaded cell slips: the friction force is the capacity μ P(t_{i−1}) (its vector
        // sum a little below: the cylinder's normals fan out by up to 0.1 rad)
        assert!(pair.stick_area == 0.0 && pair.slip_area > 0.0, "t = {t}: {pair:?}");
        let capacity = mu * previous_normal;
        assert!(
            pair.tangential_force <= capacity * (1.0 + 1e-12) && pair.tangential_force > 0.995 * capacity,
            "t = {t}: friction {} vs μ P = {capacity}",
            pair.tangential_force
        );
        // on the block along the cylinder's motion, on the cylinder against it (the resultant
        // also holds the horizontal part of the normal forces on the tilted cylinder surface)
        assert!(pair.force[0] * direction > 0.9 * capacity, "t = {t}: {pair:?}");
        assert!(rigid.reaction[0] * direction < -0.9 * capacity, "t = {t}: {rigid:?}");
        // the dissipated work: the capacity times the slip, i.e. the drag of 0.05 less the block
        // surface's own tangential displacement, which changes when the friction load comes on
        // (t = 1) or reverses (t = 3) and not in steady sliding (t = 2)
        let work = rec.friction_dissipation;
        let steady = t == 2.0;
        let low = if steady { 0.95 } else { 0.5 };
        assert!(work > low * capacity * 0.05 && work < capacity * 0.05, "t = {t}: dissipation {work}");
        // the cylinder is held at its force: the vertical resultant carries it
        assert!((pair.force[1] + 20.0).abs() < 1e-8 * 20.0, "t = {t}: {pair:?}");
        previous_normal = pair.normal_force;
    }
    assert_eq!(session.factorizations(), 1);
    Ok(())
}

/// The cylinder's prescribed sideways translation: 0 until t = 0, out by 0.05 per unit time
/// to 0.1 at t = 2, then back.
fn drag_at(t: f64) -> f64 {
    match t {
        t if t <= 0.0 => 0.0,
        t if t <= 2.0 => 0.05 * t,
        t => 0.1 - 0.05 * (t - 2.0),
    }
}

/// A force-controlled body whose predictor starts a frictional level lifted off its partner:
/// the friction frozen from the previous level (Tresca, with the slip bounds of that level's
/// pressure) still gives reactions, but no normal force holds the body, so it is moved back
/// into contact along its force (not taken for a touching body with no stiffness, which had
/// made the secant jump or the level fail as unresisted).
#[test]
fn a_lifted_start_with_frozen_friction_returns_to_contact() -> Result<(), Box<dyn std::error::Error>> {
    let mut joint = block2d()?;
    joint.clamp("block", "bottom")?;
    let centre = Point::<2>::new(0.0, 3.0);
    let drag = synovia::time::history::FnHistory::new(drag_at);
    // the guess of the vertical coordinate jumps 0.5 up at t = 1: the level starts lifted off
    let lift = synovia::time::history::FnHistory::new(|t: f64| if t < 0.5 { 0.0 } else { 0.5 });
    let cylinder = RigidBody::<2>::new("cylinder", centre)?.prescribe(0, drag)?.force_with_guess(
        1,
        Constant(-20.0),
        lift,
    )?;
    joint.add_rigid_body(cylinder)?;
    let shape = Arc::new(SphereObstacle::new(centre, 2.0, false)?);
    joint.contact_rigid_body("drag", "block", "top", "cylinder", shape, 0.2)?;
    let mut session = joint.prepare()?;
    session.solve_static(0.0)?;
    let seated = session.record().ok_or("no record")?.rigid[0].dofs[1];
    let report = session.step(1.0)?;
    let rec = session.record().ok_or("no record")?;
    let rigid = &rec.rigid[0];
    println!("seated at {seated:.6}, after the lifted start {:.6}, {} solves", rigid.dofs[1], rigid.solves);
    assert!(report.kkt < 1e-8, "KKT {}", report.kkt);
    assert!(rigid.balance_error < 1e-9, "{rigid:?}");
    assert!((rigid.dofs[1] - seated).abs() < 0.05, "back in contact: {} vs {seated}", rigid.dofs[1]);
    assert!((rec.pairs[0].force[1] + 20.0).abs() < 1e-8 * 20.0, "{:?}", rec.pairs[0]);
    // the approach along the force and a few secant steps (measured 8; 19 when the friction
    // reactions counted as contact and the first steps saw no vertical stiffness)
    assert!(rigid.solves <= 12, "{} solves", rigid.solves);
    Ok(())
}

/// Dynamic runs pose rigid bodies whose coordinates are all prescribed (they used to be
/// ignored: a linear dynamic run finished here with a zero contact force, then they were
/// refused). With a density so small that the inertia terms are 1e-7 of the stiffness at this
/// step (`ρ/Δt² = 1e-4` against `E = 1e3`), the dynamic run is the quasi-static one: the
/// indenter's normal force and reaction at `t = 1` equal the quasi-static run's to 1e-5, for
/// the linear and the neo-Hookean law (small strain; tests/suite/dynamic_rigid.rs checks the
/// dynamics itself against an exact reference).
#[test]
fn rigid_bodies_in_dynamic_runs_press_as_in_quasistatic_runs() -> Result<(), Box<dyn std::error::Error>> {
    use synovia::material::neo_hookean;
    use synovia::time::history::FnHistory;
    let materials: [Arc<dyn Material<3>>; 2] =
        [Arc::new(isotropic(1.0e3, 0.3)?), Arc::new(neo_hookean(1.0e3, 0.3)?)];
    for material in materials {
        let mesh = box_mesh([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0], [4, 4, 2], [Grading::Uniform; 3])?;
        let mut joint = JointModel::<3>::new();
        joint.add_body("block", mesh, material)?;
        joint.clamp("block", "bottom")?;
        joint.set_density("block", 1e-6)?;
        let mut indenter = RigidBody::<3>::new("indenter", Point::<3>::new(0.0, 0.0, 3.0))?;
        for k in [0, 1, 3, 4, 5] {
            indenter = indenter.prescribe(k, Constant(0.0))?;
        }
        let indenter = indenter.prescribe(2, FnHistory::new(|t| -0.005 * t))?;
        joint.add_rigid_body(indenter)?;
        let shape = Arc::new(SphereObstacle::new(Point::<3>::new(0.0, 0.0, 3.0), 2.0, false)?);
        joint.contact_rigid_body("indent", "block", "top", "indenter", shape, 0.0)?;
        let dynamic = joint.run_dynamic(0.1, 10)?;
        let quasi = joint.run_quasistatic(&[0.5, 1.0])?;
        let (d, q) = (&dynamic.records[10], &quasi.records[1]);
        assert!((d.time - 1.0).abs() < 1e-12);
        let (fd, fq) = (d.pairs[0].normal_force, q.pairs[0].normal_force);
        assert!(fq > 0.0 && (fd - fq).abs() < 1e-5 * fq, "normal force: dynamic {fd}, quasi-static {fq}");
        let (rd, rq) = (&d.rigid[0], &q.rigid[0]);
        assert_eq!(rd.name, "indenter");
        assert!((rd.dofs[2] + 0.005).abs() < 1e-15, "{rd:?}");
        assert!((rd.reaction[2] - rq.reaction[2]).abs() < 1e-5 * fq, "reaction: {rd:?} {rq:?}");
        eprintln!(
            "{}: normal force dynamic {fd:.9}, quasi-static {fq:.9}",
            joint.model().bodies()[0].material.name()
        );
    }
    Ok(())
}

/// One force-controlled coordinate solved with the contact conditions (the default,
/// `ForceControlParams::bordered`; docs/model.md §10) gives the equilibrium the search over
/// trial solves finds, with fewer solves: a frictionless indenter (translation), the cylinder
/// dragged with friction against its motion (translation, slip relative to the moving body) and
/// two condyles turned by a moment (rotation). Both searches to a geometry tolerance of 1e-10
/// of the model size, so that they stop at the same pose.
#[test]
fn the_coordinate_solved_in_the_contact_solve_equals_the_trial_search(
) -> Result<(), Box<dyn std::error::Error>> {
    use synovia::rigid::ForceControlParams;
    type Build = fn() -> Result<JointModel<2>, Box<dyn std::error::Error>>;
    /// Per level the rigid body's coordinates and the pair's resultant; the solves of the run.
    type Run = (Vec<Vec<f64>>, Vec<[f64; 3]>, usize);
    fn indenter() -> Result<JointModel<2>, Box<dyn std::error::Error>> {
        let mut joint = block2d()?;
        joint.clamp("block", "bottom")?;
        let centre = Point::<2>::new(0.1, 1.5);
        joint.add_rigid_body(RigidBody::<2>::new("indenter", centre)?.force(1, Constant(-4.0))?)?;
        let shape = Arc::new(SphereObstacle::new(centre, 0.5, false)?);
        joint.contact_rigid_body("indent", "block", "top", "indenter", shape, 0.0)?;
        Ok(joint)
    }
    fn dragged() -> Result<JointModel<2>, Box<dyn std::error::Error>> {
        let mut joint = block2d()?;
        joint.clamp("block", "bottom")?;
        let centre = Point::<2>::new(0.0, 3.0);
        let drag = synovia::time::history::FnHistory::new(drag_at);
        joint.add_rigid_body(
            RigidBody::<2>::new("cylinder", centre)?.prescribe(0, drag)?.force(1, Constant(-20.0))?,
        )?;
        let shape = Arc::new(SphereObstacle::new(centre, 2.0, false)?);
        joint.contact_rigid_body("drag", "block", "top", "cylinder", shape, 0.2)?;
        Ok(joint)
    }
    fn turned() -> Result<JointModel<2>, Box<dyn std::error::Error>> {
        let mut joint = block2d()?;
        joint.clamp("block", "bottom")?;
        let centre = Point::<2>::new(0.0, 1.5);
        let rz = RigidBody::<2>::dof_index("rz")?;
        // pressed 0.01 into the block and held against the turn of the contact force about
        // the centre by a moment (1.5 then 2.0, clockwise)
        let femur = RigidBody::<2>::new("femur", centre)?
            .prescribe(1, Constant(-0.01))?
            .force(rz, synovia::time::history::FnHistory::new(|t: f64| -(1.5 + 0.5 * t)))?;
        joint.add_rigid_body(femur)?;
        let shape = Arc::new(SphereObstacle::new(Point::<2>::new(0.5, 1.3), 0.3, false)?);
        joint.contact_rigid_body("condyle", "block", "top", "femur", shape, 0.0)?;
        joint.search_distance("condyle", 0.5)?;
        Ok(joint)
    }
    /// Two condyles pressed by a force and free to turn under a moment (two coordinates).
    fn condyles() -> Result<JointModel<2>, Box<dyn std::error::Error>> {
        let mesh = rectangle(-1.0, 1.0, 0.0, 1.0, 32, 8, Grading::Uniform, Grading::Uniform)?;
        let mut joint = JointModel::<2>::new();
        joint.add_body("block", mesh, plane_strain(1.0e3, 0.3)?)?;
        joint.clamp("block", "bottom")?;
        let centre = Point::<2>::new(0.0, 1.5);
        let rz = RigidBody::<2>::dof_index("rz")?;
        let femur = RigidBody::<2>::new("femur", centre)?.force(1, Constant(-4.0))?.force_with_guess(
            rz,
            synovia::time::history::FnHistory::new(|t: f64| 0.2 * t),
            Constant(-0.02),
        )?;
        joint.add_rigid_body(femur)?;
        let shape = Arc::new(TwoDiscs {
            centres: [Point::<2>::new(-0.5, 1.3), Point::<2>::new(0.5, 1.3)],
            radius: 0.3,
        });
        joint.contact_rigid_body("condyles", "block", "top", "femur", shape, 0.0)?;
        joint.search_distance("condyles", 0.5)?;
        Ok(joint)
    }
    let cases: [(&str, Build, &[f64]); 4] = [
        ("indenter", indenter, &[0.0, 1.0]),
        ("dragged", dragged, &[0.0, 1.0, 2.0, 3.0]),
        ("turned", turned, &[0.0, 1.0]),
        ("condyles", condyles, &[0.0, 1.0]),
    ];
    for (name, build, times) in cases {
        let run = |bordered: bool| -> Result<Run, Box<dyn std::error::Error>> {
            let mut joint = build()?;
            joint.force_control(ForceControlParams {
                bordered,
                geometry_tolerance: 1e-10,
                ..ForceControlParams::default()
            });
            let mut session = joint.prepare()?;
            let (mut dofs, mut forces, mut solves) = (Vec::new(), Vec::new(), 0);
            for (i, &t) in times.iter().enumerate() {
                let report = if i == 0 { session.solve_static(t)? } else { session.step(t)? };
                assert!(report.kkt < 1e-8, "{name}, t = {t}: KKT {}", report.kkt);
                let rec = session.record().ok_or("no record")?;
                let rigid = &rec.rigid[0];
                assert!(rigid.balance_error < 1e-9, "{name}, t = {t}, bordered {bordered}: {rigid:?}");
                dofs.push(rigid.dofs.clone());
                forces.push(rec.pairs[0].force);
                println!(
                    "  {name} t = {t} bordered {bordered}: {} solves, dofs {:?}",
                    rigid.solves, rigid.dofs
                );
                solves += rigid.solves;
            }
            Ok((dofs, forces, solves))
        };
        let (dofs_b, forces_b, solves_b) = run(true)?;
        let (dofs_t, forces_t, solves_t) = run(false)?;
        println!("{name}: {solves_b} solves bordered, {solves_t} by trial solves");
        for (i, t) in times.iter().enumerate() {
            for (a, b) in dofs_b[i].iter().zip(&dofs_t[i]) {
                assert!(
                    (a - b).abs() <= 1e-9,
                    "{name}, t = {t}: coordinates {:?} vs {:?}",
                    dofs_b[i],
                    dofs_t[i]
                );
            }
            let scale = forces_t[i].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (a, b) in forces_b[i].iter().zip(&forces_t[i]) {
                assert!(
                    (a - b).abs() <= 1e-7 * scale,
                    "{name}, t = {t}: forces {:?} vs {:?}",
                    forces_b[i],
                    forces_t[i]
                );
            }
        }
        assert!(solves_b < solves_t, "{name}: {solves_b} solves bordered against {solves_t}");
    }
    Ok(())
}
