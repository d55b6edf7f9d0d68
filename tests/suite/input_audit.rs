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

/// Public constructors of meshes, generators, load histories, sparse matrices and run
/// parameters: every bad input below is a typed error whose message names the entity (checked
/// by a fragment of the message), never a panic and never an accepted model.
#[test]
fn public_constructors_reject_bad_input_with_named_errors() {
    use std::panic::{catch_unwind, AssertUnwindSafe};
    use synovia::time::history::Periodic;
    let square = || {
        vec![
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(0.0, 1.0),
            Point::<2>::new(1.0, 1.0),
        ]
    };
    let triangle = || square()[..3].to_vec();
    let tet = || {
        vec![
            Point::<3>::zeros(),
            Point::<3>::new(1.0, 0.0, 0.0),
            Point::<3>::new(0.0, 1.0, 0.0),
            Point::<3>::new(0.0, 0.0, 1.0),
        ]
    };
    let err = |r: Result<(), String>| r.err().unwrap_or_default();
    let mesh2 = |nodes: Vec<Point<2>>, cells: Vec<usize>| {
        Mesh::<2>::new(nodes, cells).map(|_| ()).map_err(|e| e.to_string())
    };
    let block_joint = || {
        let mut j = JointModel::<2>::new();
        let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 4, 2, Grading::Uniform, Grading::Uniform).expect("mesh");
        let b = j.add_body("block", mesh, plane_strain(1.0, 0.3).expect("m")).expect("b");
        (j, b)
    };
    type Case<'a> = (&'a str, Box<dyn Fn() -> Result<(), String> + 'a>, &'a str);
    let cases: Vec<Case> = vec![
        ("ragged cell array", Box::new(move || mesh2(square(), vec![0, 1, 2, 3])), "3"),
        ("repeated node in a cell", Box::new(move || mesh2(square(), vec![0, 0, 1])), "node 0"),
        ("no cells", Box::new(move || mesh2(square(), vec![])), "no cells"),
        ("node in no cell", Box::new(move || mesh2(square(), vec![0, 1, 2])), "node 3"),
        ("duplicated cell", Box::new(move || mesh2(triangle(), vec![0, 1, 2, 0, 1, 2])), "cells 1 and 0"),
        (
            "folded (overlapping) cells",
            Box::new(move || mesh2(square(), vec![0, 1, 2, 0, 1, 3])),
            "cells 1 and 0",
        ),
        (
            "NaN coordinate",
            Box::new(move || {
                mesh2(
                    vec![
                        Point::<2>::new(f64::NAN, 0.0),
                        Point::<2>::new(1.0, 0.0),
                        Point::<2>::new(0.0, 1.0),
                    ],
                    vec![0, 1, 2],
                )
            }),
            "node 0",
        ),
        (
            "zero-area triangle",
            Box::new(move || {
                mesh2(
                    vec![Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.0), Point::<2>::new(2.0, 0.0)],
                    vec![0, 1, 2],
                )
            }),
            "cell 0",
        ),
        (
            "duplicated tetrahedron",
            Box::new(move || {
                Mesh::<3>::new(tet(), vec![0, 1, 2, 3, 0, 1, 2, 3]).map(|_| ()).map_err(|e| e.to_string())
            }),
            "cells 1 and 0",
        ),
        (
            "flat tetrahedron",
            Box::new(move || {
                let mut n = tet();
                n[3] = Point::<3>::new(0.3, 0.3, 0.0);
                Mesh::<3>::new(n, vec![0, 1, 2, 3]).map(|_| ()).map_err(|e| e.to_string())
            }),
            "cell 0",
        ),
        (
            "rectangle with 0 cells",
            Box::new(|| {
                rectangle(0.0, 1.0, 0.0, 1.0, 0, 2, Grading::Uniform, Grading::Uniform)
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            }),
            "number of cells",
        ),
        (
            "rectangle x1 < x0",
            Box::new(|| {
                rectangle(1.0, 0.0, 0.0, 1.0, 2, 2, Grading::Uniform, Grading::Uniform)
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            }),
            "a < b",
        ),
        (
            "grading ratio NaN",
            Box::new(|| {
                rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Grading::Geometric { ratio: f64::NAN }, Grading::Uniform)
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            }),
            "ratio",
        ),
        (
            "history times decreasing",
            Box::new(|| {
                PiecewiseLinear::new(&[(1.0, 0.0), (0.0, 1.0)]).map(|_| ()).map_err(|e| e.to_string())
            }),
            "increase",
        ),
        (
            "history NaN value",
            Box::new(|| {
                PiecewiseLinear::new(&[(0.0, f64::NAN), (1.0, 1.0)]).map(|_| ()).map_err(|e| e.to_string())
            }),
            "point 0",
        ),
        (
            "periodic period 0",
            Box::new(|| Periodic::new(Constant(1.0), 0.0).map(|_| ()).map_err(|e| e.to_string())),
            "period",
        ),
        (
            "Poisson ratio ½",
            Box::new(|| plane_strain(1.0, 0.5).map(|_| ()).map_err(|e| e.to_string())),
            "0.5",
        ),
        (
            "Young's modulus ∞",
            Box::new(|| isotropic(f64::INFINITY, 0.3).map(|_| ()).map_err(|e| e.to_string())),
            "Young",
        ),
        (
            "sparse matrix not symmetric",
            Box::new(|| {
                let m = sprs::CsMat::<f64>::new((2, 2), vec![0, 1, 2], vec![1, 0], vec![1.0, 2.0]);
                synovia::fem::SymmetricMatrix::from_sprs(&m).map(|_| ()).map_err(|e| e.to_string())
            }),
            "not symmetric",
        ),
        (
            "sparse matrix NaN entry",
            Box::new(|| {
                let m = sprs::CsMat::<f64>::new((2, 2), vec![0, 1, 2], vec![0, 1], vec![f64::NAN, 2.0]);
                synovia::fem::SymmetricMatrix::from_sprs(&m).map(|_| ()).map_err(|e| e.to_string())
            }),
            "(0, 0)",
        ),
        (
            "negative density",
            Box::new(move || {
                let (mut j, b) = block_joint();
                j.set_density(b, -1.0).map(|_| ()).map_err(|e| e.to_string())
            }),
            "density",
        ),
        (
            "zero contact tolerance",
            Box::new(move || {
                let (mut j, b) = block_joint();
                j.prescribe_field(b, "top", ComponentMask::ALL, |_, _| Vector::<2>::new(0.0, -0.01))
                    .map_err(|e| e.to_string())?;
                let floor = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0))
                    .map_err(|e| e.to_string())?;
                j.contact_rigid("floor", b, "bottom", floor, 0.0).map_err(|e| e.to_string())?;
                j.contact_params(ContactParams::default().with_tolerance(0.0));
                j.run_static(0.0).map(|_| ()).map_err(|e| e.to_string())
            }),
            "tolerance",
        ),
        (
            "dynamic Δt = NaN",
            Box::new(move || {
                let (mut j, b) = block_joint();
                j.set_density(b, 1.0).map_err(|e| e.to_string())?;
                j.clamp(b, "bottom").map_err(|e| e.to_string())?;
                j.run_dynamic(f64::NAN, 3).map(|_| ()).map_err(|e| e.to_string())
            }),
            "Δt",
        ),
        (
            "quasi-static times decreasing",
            Box::new(move || {
                let (mut j, b) = block_joint();
                j.clamp(b, "bottom").map_err(|e| e.to_string())?;
                j.run_quasistatic(&[1.0, 0.0]).map(|_| ()).map_err(|e| e.to_string())
            }),
            "increase",
        ),
        (
            "unknown solver",
            Box::new(move || {
                let (mut j, _) = block_joint();
                j.solver("newton-raphson").map(|_| ()).map_err(|e| e.to_string())
            }),
            "newton-raphson",
        ),
    ];
    let mut errors = 0;
    for (what, f, fragment) in &cases {
        let out = catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|_| panic!("{what}: panicked"));
        let msg = err(out);
        assert!(!msg.is_empty(), "{what}: accepted");
        assert!(msg.contains(fragment), "{what}: message `{msg}` does not name `{fragment}`");
        errors += 1;
    }
    println!("public constructors: {} bad inputs, {errors} typed errors, 0 panics", cases.len());
}
