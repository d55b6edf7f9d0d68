//! A contact node pressed into a concave edge of a rigid triangle surface, with the contact
//! geometry rebuilt on the deformed configuration (finite strain, `GeometryUpdate::Converged`).
//!
//! That is how `tkr3d --neo-hookean --friction 0.04` stopped at its 14 % pose (issue 20,
//! docs/nonlinear.md "A node in a concave corner"): insert node 7144, pressed at ≈ 335 MPa into
//! a concave corner of the femoral component's faceted surface, took the normal of one face in
//! one geometry pass, slid along that face's plane into the other face, took the other face's
//! normal in the next pass and slid back — "the contact geometry on the deformed configuration
//! did not settle in 20 rebuilds". One row per node against a face's plane has no fixed point
//! there: the node's force lies strictly inside the cone of the two faces' normals.
//!
//! Here a neo-Hookean block with a roof ridge (slope 0.4 on both sides) is pushed up into a
//! groove of an open triangle surface whose faces rise at 0.1 and 0.25 toward the crease: only
//! the ridge's nodes reach the crease, and the groove's asymmetry puts their force off the
//! bisector. On the faceted surface the level stops exactly as the tkr3d cycle did (the
//! ridge nodes' normals alternating between the faces); with the concave edge rounded by a
//! fillet ([`SurfaceObstacle::with_concave_fillet`]) the passes settle, the KKT residual of the
//! final solution on the final geometry is at rounding level, the ridge nodes rest on the
//! fillet (within the fillet's deficit of the faceted surface, no deeper), and their forces lie
//! in the cone of the two faces' normals.
#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use synovia_contact::obstacle::SignedDistance;
use synovia_contact::operators::ContactPair;
use synovia_contact::SurfaceObstacle;
use synovia_fem::{ElasticParams, Kinematics, Model};
use synovia_material::neo_hookean;
use synovia_mesh::generators::{box_mesh, Grading};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::{BoundaryKind, TriangleSurface};
use synovia_nonlinear::{NewtonParams, NonlinearContact, NonlinearError, NonlinearResult};
use synovia_pdas::Pdas;

const E: Real = 10.0;
const NU: Real = 0.3;
/// Slopes of the groove's faces toward the crease (x > 0 and x < 0) and of the block's roof.
const S1: Real = 0.10;
const S2: Real = 0.25;
const ROOF: Real = 0.4;
/// The upward push of the block's bottom.
const PUSH: Real = 0.02;

/// The groove: the open surface `z = 1 − S1 x` (x ≥ 0), `z = 1 + S2 x` (x < 0) over
/// `[-2, 2]²`, normals down (the free space below it).
fn groove() -> SurfaceObstacle {
    let v = |x: Real, y: Real| Point::<3>::new(x, y, if x >= 0.0 { 1.0 - S1 * x } else { 1.0 + S2 * x });
    let vertices = vec![v(-2.0, -2.0), v(0.0, -2.0), v(2.0, -2.0), v(-2.0, 2.0), v(0.0, 2.0), v(2.0, 2.0)];
    let triangles = vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
    let mut surface = TriangleSurface::new(vertices, triangles).unwrap();
    if surface.normal(0)[2] > 0.0 {
        surface = surface.flipped();
    }
    SurfaceObstacle::new(surface).unwrap()
}

/// The block `[-1, 1] × [-0.5, 0.5] × [0, 1]` with its top raised to the ridge
/// `z = 1 − ROOF |x|` … mapped as `z ↦ z (1 − ROOF |x|)`, its bottom pushed up by `PUSH t`.
fn model(obstacle: SurfaceObstacle) -> (Model<3>, Vec<ContactPair<3>>) {
    let mut mesh = box_mesh([-1.0, -0.5, 0.0], [1.0, 0.5, 1.0], [8, 4, 4], [Grading::Uniform; 3]).unwrap();
    mesh.map_nodes(|p| Point::<3>::new(p[0], p[1], p[2] * (1.0 - ROOF * p[0].abs()))).unwrap();
    mesh.set_part_kind("bottom", BoundaryKind::Prescribed).unwrap();
    mesh.set_part_kind("top", BoundaryKind::Contact).unwrap();
    let mut model = Model::new();
    let b = model.add_body("block", mesh, Arc::new(neo_hookean(E, NU).unwrap())).unwrap();
    model.prescribe(b, "bottom", |_, t| Vector::<3>::new(0.0, 0.0, PUSH * t)).unwrap();
    let pairs = vec![ContactPair::rigid("block-groove", b, "top", Arc::new(obstacle))];
    (model, pairs)
}

#[allow(clippy::type_complexity)]
fn solve(
    obstacle: SurfaceObstacle,
) -> (Model<3>, Result<(NonlinearContact<3>, NonlinearResult<3>), NonlinearError>) {
    let (model, pairs) = model(obstacle);
    let mut nl = NonlinearContact::new(
        &model,
        &pairs,
        &[Kinematics::FiniteStrain],
        ElasticParams::default(),
        NewtonParams::default(),
    )
    .unwrap();
    let result = nl.step_to(&model, 1.0, &Pdas::default());
    (model, result.map(|r| (nl, r)))
}

#[test]
fn faceted_concave_edge_does_not_settle() {
    let (_, result) = solve(groove());
    let Err(NonlinearError::NoConvergence { reason, .. }) = result else {
        panic!("the faceted groove settled: {:?}", result.map(|(_, r)| r.report.iterations.len()));
    };
    eprintln!("faceted: {reason}");
    assert!(reason.contains("did not settle"), "{reason}");
}

#[test]
fn filleted_concave_edge_settles_with_the_node_in_the_corner() {
    let radius = 0.05;
    let rounded = groove().with_concave_fillet(radius, Real::INFINITY).unwrap();
    assert_eq!(rounded.filleted_edges(), 1);
    let deficit = rounded.fillet_deficit();
    let shape = Arc::new(rounded);
    let faceted = groove();
    let (model, result) = solve(Arc::unwrap_or_clone(shape.clone()));
    let (nl, level) = result.unwrap();
    let kkt = level.contact.kkt.max();
    let geometry = nl.geometry();
    let lambda = &level.contact.solution.lambda_n;
    let disp = &level.contact.displacement;
    let mesh = &model.bodies()[0].mesh;
    // the faces' normals into the obstacle (up)
    let n1 = Vector::<3>::new(S1, 0.0, 1.0).normalize();
    let n2 = Vector::<3>::new(-S2, 0.0, 1.0).normalize();
    let mut ridge = 0;
    for (r, node) in geometry.nodes.iter().enumerate() {
        let i = node.node.1;
        let x = mesh.nodes()[i] + disp[0][i];
        let (phi, _) = shape.distance_and_gradient(&x);
        let phi_faceted = faceted.distance(&x);
        if lambda[r] > 0.0 {
            // on the rounded surface (its gap at the tolerance of the passes) and no deeper
            // into the faceted one than the fillet's deficit
            assert!(phi.abs() < 1e-6, "node {i}: φ = {phi:e} on the rounded surface");
            assert!(phi_faceted > -deficit - 1e-6, "node {i}: φ = {phi_faceted:e} on the facets");
        } else {
            assert!(phi > -1e-6, "node {i} inactive at φ = {phi:e}");
        }
        if mesh.nodes()[i][0].abs() < 1e-12 {
            // a ridge node: loaded, its force −Λ n_r in the cone of the faces' normals,
            // strictly inside it (neither face's row alone holds it)
            assert!(lambda[r] > 0.0, "ridge node {i} not in contact");
            let n = node.normal;
            let cross = |a: &Vector<3>, b: &Vector<3>| a.cross(b)[1];
            let (a, b) = (cross(&n2, &n), cross(&n, &n1));
            eprintln!(
                "ridge node {i}: Λ = {:.4e}, n = {n:?}, φ = {phi:.2e}, faceted φ = {phi_faceted:.2e}",
                lambda[r]
            );
            assert!(a > 1e-3 && b > 1e-3, "normal {n:?} not inside the cone of {n1:?}, {n2:?}");
            ridge += 1;
        }
    }
    assert_eq!(ridge, 5, "the ridge's nodes");
    eprintln!("filleted (radius {radius}, deficit {deficit:.2e}): KKT {kkt:.1e}");
    assert!(kkt < 1e-10, "KKT {kkt:e}");
}
