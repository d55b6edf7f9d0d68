//! Input audit of the contact set-up (issue 7): obstacle parameters (NaN/∞, zero or negative
//! radius, zero or non-unit axis), node-to-node parts whose normals point the wrong way, and
//! duplicated nodes in a contact part give errors naming the entity, never a panic.

use std::sync::Arc;

use synovia::contact_ops::operators::{
    ContactGeometry, ContactPair, CylinderObstacle, PlaneObstacle, SignedDistance, SphereObstacle,
};
use synovia::contact_ops::ContactError;
use synovia::prelude::*;

fn block_2d() -> (Model<2>, BodyId) {
    let mut mesh = rectangle(0.0, 1.0, 0.0, 0.5, 4, 2, Grading::Uniform, Grading::Uniform).expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("part");
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    (model, b)
}

fn geometry_error<const D: usize>(model: &Model<D>, pair: ContactPair<D>) -> (String, String) {
    match ContactGeometry::new(model, &[pair]) {
        Err(ContactError::InvalidPair { pair, reason }) => (pair, reason),
        other => panic!("expected InvalidPair, got {other:?}"),
    }
}

#[test]
fn obstacle_constructors_reject_non_finite_and_degenerate_parameters() {
    let p2 = Point::<2>::new(0.0, 0.0);
    let cases: Vec<(&str, Result<(), ContactError>)> = vec![
        ("sphere NaN centre", SphereObstacle::new(Point::<2>::new(f64::NAN, 0.0), 1.0, false).map(|_| ())),
        ("sphere ∞ radius", SphereObstacle::new(p2, f64::INFINITY, false).map(|_| ())),
        ("sphere NaN radius", SphereObstacle::new(p2, f64::NAN, true).map(|_| ())),
        ("sphere zero radius", SphereObstacle::new(p2, 0.0, false).map(|_| ())),
        ("sphere negative radius", SphereObstacle::new(p2, -1.0, true).map(|_| ())),
        (
            "cylinder zero axis",
            CylinderObstacle::new(Point::<3>::zeros(), Vector::<3>::zeros(), 1.0, false).map(|_| ()),
        ),
        (
            "cylinder NaN axis",
            CylinderObstacle::new(Point::<3>::zeros(), Vector::<3>::new(f64::NAN, 0.0, 1.0), 1.0, false)
                .map(|_| ()),
        ),
        (
            "cylinder ∞ point",
            CylinderObstacle::new(Point::<3>::new(f64::INFINITY, 0.0, 0.0), Vector::<3>::z(), 1.0, false)
                .map(|_| ()),
        ),
        (
            "cylinder zero radius",
            CylinderObstacle::new(Point::<3>::zeros(), Vector::<3>::z(), 0.0, true).map(|_| ()),
        ),
        ("plane zero normal", PlaneObstacle::new(p2, Vector::<2>::zeros()).map(|_| ())),
        ("plane NaN point", PlaneObstacle::new(Point::<2>::new(0.0, f64::NAN), Vector::<2>::y()).map(|_| ())),
        ("plane ∞ normal", PlaneObstacle::new(p2, Vector::<2>::new(f64::INFINITY, 1.0)).map(|_| ())),
    ];
    for (what, r) in cases {
        match r {
            Err(ContactError::InvalidParameter(msg)) => println!("{what}: {msg}"),
            other => panic!("{what}: expected InvalidParameter, got {other:?}"),
        }
    }
    // valid ones, with the axis normalised
    let c =
        CylinderObstacle::new(Point::<3>::zeros(), Vector::<3>::new(0.0, 0.0, 2.0), 0.5, false).expect("ok");
    assert_eq!(c.axis, Vector::<3>::z());
    assert!(SphereObstacle::new(p2, 2.0, true).is_ok());
}

#[test]
fn obstacles_built_from_fields_are_validated_with_the_pair_named() {
    let (model, b) = block_2d();
    for (radius, centre) in [(0.0, 0.0), (-1.0, 0.0), (f64::NAN, 0.0), (1.0, f64::INFINITY)] {
        let ball = SphereObstacle { center: Point::<2>::new(0.5, centre - 1.0), radius, cavity: false };
        assert!(ball.validate().is_err());
        let (pair, reason) = geometry_error(&model, ContactPair::rigid("ball", b, "bottom", Arc::new(ball)));
        println!("radius {radius}, centre {centre}: {reason}");
        assert_eq!(pair, "ball");
        assert!(reason.contains("obstacle") && (reason.contains("radius") || reason.contains("centre")));
    }
    let tilted = PlaneObstacle { point: Point::<2>::new(0.0, -0.1), normal: Vector::<2>::new(0.0, 2.0) };
    let (_, reason) = geometry_error(&model, ContactPair::rigid("flat", b, "bottom", Arc::new(tilted)));
    assert!(reason.contains("unit"), "{reason}");
}

#[test]
fn cylinder_with_zero_or_non_unit_axis_is_rejected_in_3d() {
    let mesh = box_mesh([0.0; 3], [1.0, 1.0, 0.5], [2, 2, 1], [Grading::Uniform; 3]).expect("mesh");
    let mut model = Model::<3>::new();
    let b = model.add_body("block", mesh, Arc::new(isotropic(1.0, 0.3).expect("ok"))).expect("body");
    for axis in [Vector::<3>::zeros(), Vector::<3>::new(1.0, 1.0, 0.0)] {
        let cyl =
            CylinderObstacle { point: Point::<3>::new(0.0, 0.5, -1.0), axis, radius: 0.9, cavity: false };
        let (pair, reason) = geometry_error(&model, ContactPair::rigid("roller", b, "bottom", Arc::new(cyl)));
        println!("axis {axis:?}: {reason}");
        assert_eq!(pair, "roller");
        assert!(reason.contains("cylinder axis"), "{reason}");
    }
}

#[test]
fn node_to_node_part_facing_away_from_its_partner_is_rejected() {
    // two matching blocks; the pair uses the *top* of the upper block, whose normals point
    // away from the lower block: every node is a whole block height behind its partner
    let lower = rectangle(0.0, 1.0, -0.5, 0.0, 4, 2, Grading::Uniform, Grading::Uniform).expect("mesh");
    let upper = rectangle(0.0, 1.0, 0.0, 0.5, 4, 2, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut model = Model::<2>::new();
    let m = Arc::new(plane_strain(1.0, 0.3).expect("ok"));
    let u = model.add_body("upper", upper, m.clone()).expect("body");
    let l = model.add_body("lower", lower, m).expect("body");
    let (pair, reason) = geometry_error(&model, ContactPair::node_to_node("wrong-side", u, "top", l, "top"));
    println!("{reason}");
    assert_eq!(pair, "wrong-side");
    assert!(reason.contains("part `top`") && reason.contains("point away"), "{reason}");
    // the correct pair is accepted
    assert!(ContactGeometry::new(&model, &[ContactPair::node_to_node("ok", u, "bottom", l, "top")]).is_ok());
}

#[test]
fn duplicated_node_in_a_contact_part_is_named() {
    // two unit squares side by side that do not share their nodes at x = 1 (an unmerged seam)
    let p = |x: f64, y: f64| Point::<2>::new(x, y);
    let nodes = vec![
        p(0.0, 0.0),
        p(1.0, 0.0),
        p(1.0, 1.0),
        p(0.0, 1.0),
        p(1.0, 0.0),
        p(2.0, 0.0),
        p(2.0, 1.0),
        p(1.0, 1.0),
    ];
    let cells = vec![0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
    let mut mesh = Mesh::<2>::new(nodes, cells).expect("mesh");
    mesh.add_boundary_part("bottom", BoundaryKind::Contact, |x, n| x[1] < 1e-12 && n[1] < 0.0).expect("part");
    let mut model = Model::<2>::new();
    let b = model.add_body("seamed", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    let floor = PlaneObstacle::new(Point::<2>::new(0.0, -0.01), Vector::<2>::y()).expect("plane");
    let (pair, reason) = geometry_error(&model, ContactPair::rigid("floor", b, "bottom", Arc::new(floor)));
    println!("{reason}");
    assert_eq!(pair, "floor");
    assert!(reason.contains("nodes 1 and 4") && reason.contains("duplicated"), "{reason}");
}
