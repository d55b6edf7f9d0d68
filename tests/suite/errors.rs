//! Bad input gets a typed error naming the culprit, never a panic or a NaN.

use std::sync::Arc;

use synovia::prelude::*;
use synovia_fem::FemError;

fn unit_square() -> (Vec<Point<2>>, Vec<usize>) {
    (
        vec![
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(1.0, 1.0),
            Point::<2>::new(0.0, 1.0),
        ],
        vec![0, 1, 2, 0, 2, 3],
    )
}

#[test]
fn inverted_element_is_named() {
    let (nodes, mut cells) = unit_square();
    cells.swap(4, 5); // second triangle clockwise
    match Mesh::<2>::new(nodes.clone(), cells.clone()) {
        Err(MeshError::InvertedCell { cell, .. }) => assert_eq!(cell, 1),
        other => panic!("expected InvertedCell, got {other:?}"),
    }
    let (mesh, flipped) = Mesh::<2>::new_with_repair(nodes, cells).expect("repairable");
    assert_eq!(flipped, 1);
    assert!(mesh.inverted_cells().is_empty());
}

#[test]
fn degenerate_element_is_named() {
    let nodes = vec![
        Point::<3>::new(0.0, 0.0, 0.0),
        Point::<3>::new(1.0, 0.0, 0.0),
        Point::<3>::new(0.0, 1.0, 0.0),
        Point::<3>::new(0.0, 0.0, 1.0),
        Point::<3>::new(1.0, 1.0, 0.0),
    ];
    // cell 1 is flat (all in z = 0)
    let err = Mesh::<3>::new(nodes, vec![0, 1, 2, 3, 0, 1, 4, 2]).expect_err("degenerate");
    assert!(matches!(err, MeshError::DegenerateCell { cell: 1, .. }), "{err:?}");
    assert!(err.to_string().contains("cell 1"));
}

#[test]
fn non_finite_coordinates_and_bad_indices_are_rejected() {
    let (mut nodes, cells) = unit_square();
    nodes[2][1] = f64::NAN;
    assert!(matches!(Mesh::<2>::new(nodes, cells.clone()), Err(MeshError::NonFiniteNode { node: 2 })));
    let (nodes, mut cells) = unit_square();
    cells[5] = 9;
    assert!(matches!(Mesh::<2>::new(nodes, cells), Err(MeshError::NodeOutOfRange { cell: 1, node: 9, .. })));
}

#[test]
fn non_physical_materials_are_rejected() {
    assert!(matches!(plane_strain(0.0, 0.3), Err(MaterialError::NonPositiveYoungsModulus { .. })));
    assert!(matches!(isotropic(-1.0, 0.3), Err(MaterialError::NonPositiveYoungsModulus { .. })));
    for nu in [0.5, -1.0, 0.7, -1.5] {
        let e = isotropic(1.0, nu).expect_err("nu out of range");
        assert!(matches!(e, MaterialError::PoissonRatioOutOfRange { .. }), "{e:?}");
        assert!(e.to_string().contains(&format!("{nu}")), "{e}");
    }
    assert!(isotropic(f64::NAN, 0.3).is_err());
    assert!(plane_stress(1.0, f64::INFINITY).is_err());
}

fn block(parts: &[(&str, BoundaryKind)]) -> Mesh<2> {
    let mut m = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
    for (p, k) in parts {
        m.set_part_kind(p, *k).expect("part");
    }
    m
}

#[test]
fn body_without_dirichlet_data_is_semi_coercive() {
    let mesh = block(&[("top", BoundaryKind::Traction)]);
    let mut model = Model::<2>::new();
    let b = model
        .add_body("floating patella", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok")))
        .expect("body");
    model.traction(b, "top", |_, n, _| -n).expect("traction");
    match solve_elastic(&model, 0.0) {
        Err(FemError::SemiCoercive { bodies, free_modes }) => {
            assert_eq!(bodies, vec!["floating patella".to_string()]);
            assert_eq!(free_modes, 3);
        }
        other => panic!("expected SemiCoercive, got {other:?}"),
    }
    // one roller (u·n = 0 on the bottom) still leaves the horizontal translation free
    let mesh = block(&[("bottom", BoundaryKind::Symmetry)]);
    let mut model = Model::<2>::new();
    model.add_body("sliding", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    match solve_elastic(&model, 0.0) {
        Err(FemError::SemiCoercive { free_modes, .. }) => assert_eq!(free_modes, 1),
        other => panic!("expected SemiCoercive, got {other:?}"),
    }
    // a single clamped point-like part: a clamped bottom is enough
    let mesh = block(&[("bottom", BoundaryKind::Clamped)]);
    let mut model = Model::<2>::new();
    model.add_body("held", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    assert!(solve_elastic(&model, 0.0).is_ok());
}

#[test]
fn missing_boundary_data_is_reported() {
    let mesh = block(&[("bottom", BoundaryKind::Clamped), ("top", BoundaryKind::Traction)]);
    let mut model = Model::<2>::new();
    model.add_body("b", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    match solve_elastic(&model, 0.0) {
        Err(FemError::MissingBoundaryData { part, .. }) => assert_eq!(part, "top"),
        other => panic!("expected MissingBoundaryData, got {other:?}"),
    }
    // data for a part of the wrong kind
    let mesh = block(&[("bottom", BoundaryKind::Clamped)]);
    let mut model = Model::<2>::new();
    let b = model.add_body("b", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    assert!(matches!(
        model.prescribe(b, "bottom", |_, _| Vector::<2>::zeros()),
        Err(FemError::BoundaryKindMismatch { .. })
    ));
    assert!(matches!(model.traction(b, "nowhere", |_, n, _| *n), Err(FemError::Mesh { .. })));
}

#[test]
fn non_finite_loads_are_reported_with_position() {
    let mesh = block(&[("bottom", BoundaryKind::Clamped)]);
    let mut model = Model::<2>::new();
    let b = model.add_body("b", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    model
        .body_force(b, |x, _| if x[0] > 0.5 { Vector::<2>::new(f64::NAN, 0.0) } else { Vector::<2>::zeros() })
        .expect("force");
    match solve_elastic(&model, 0.0) {
        Err(FemError::NonFiniteData { what, x, .. }) => {
            assert!(what.contains("body force"));
            assert!(x[0] > 0.5);
        }
        other => panic!("expected NonFiniteData, got {other:?}"),
    }
}

#[test]
fn contradictory_constraints_are_reported() {
    let mesh = block(&[("bottom", BoundaryKind::Clamped), ("left", BoundaryKind::Prescribed)]);
    let mut model = Model::<2>::new();
    let b = model.add_body("b", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    // the corner (0, 0) is clamped and prescribed to 0.1
    model.prescribe(b, "left", |_, _| Vector::<2>::new(0.1, 0.0)).expect("prescribe");
    match solve_elastic(&model, 0.0) {
        Err(FemError::ConflictingConstraints { node, residual, .. }) => {
            assert_eq!(node, 0);
            assert!((residual - 0.1).abs() < 1e-12);
        }
        other => panic!("expected ConflictingConstraints, got {other:?}"),
    }
}

#[test]
fn unmatched_bonded_interface_names_the_nodes() {
    let left = rectangle(0.0, 0.5, 0.0, 1.0, 2, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
    let right = rectangle(0.5, 1.0, 0.0, 1.0, 2, 5, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut model = Model::<2>::new();
    let m = Arc::new(plane_strain(1.0, 0.3).expect("ok"));
    let a = model.add_body("a", left, m.clone()).expect("body");
    let b = model.add_body("b", right, m).expect("body");
    model.tie(a, "right", b, "left").expect("tie");
    match solve_elastic(&model, 0.0) {
        Err(FemError::UnmatchedInterface(info)) => {
            assert!(!info.unmatched_a.is_empty() && !info.unmatched_b.is_empty());
        }
        other => panic!("expected UnmatchedInterface, got {other:?}"),
    }
}

#[test]
fn duplicate_bodies_and_unknown_bodies_are_errors() {
    let mut model = Model::<2>::new();
    let m = Arc::new(plane_strain(1.0, 0.3).expect("ok"));
    model.add_body("a", block(&[]), m.clone()).expect("body");
    assert!(matches!(model.add_body("a", block(&[]), m), Err(FemError::DuplicateBody(_))));
    assert!(matches!(model.body_id("zz"), Err(FemError::UnknownBody(_))));
    assert!(matches!(solve_elastic(&Model::<2>::new(), 0.0), Err(FemError::NoBodies)));
}
