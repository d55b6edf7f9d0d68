//! `Mesh::map_nodes`: a rigid motion keeps the cells, parts and boundary facets (with their
//! outward normals moved along) and the mesh stays valid; a map that inverts or flattens a
//! cell is refused and leaves the mesh as it was.

use synovia_mesh::generators::{box_mesh, rectangle, Grading};
use synovia_mesh::{Mesh, MeshError, Point};

const U: Grading = Grading::Uniform;

#[test]
fn a_rotation_keeps_the_topology_and_moves_the_normals() -> Result<(), MeshError> {
    let mut mesh = rectangle(0.0, 2.0, 0.0, 1.0, 8, 5, U, U)?;
    let before = mesh.clone();
    let facets_before = mesh.boundary_facets();
    let (s, c) = (0.7_f64.sin(), 0.7_f64.cos());
    let rotate = |x: &Point<2>| Point::<2>::new(c * x[0] - s * x[1] + 3.0, s * x[0] + c * x[1] - 1.0);
    mesh.map_nodes(rotate)?;
    assert_eq!(mesh.cells_flat(), before.cells_flat());
    assert_eq!(mesh.boundary_facets(), facets_before, "same facets, same outward node order");
    // the moved mesh is what a fresh construction from the moved nodes gives
    let fresh = Mesh::new(before.nodes().iter().map(rotate).collect(), before.cells_flat().to_vec())?;
    assert_eq!(fresh.boundary_facets(), facets_before);
    for f in &facets_before {
        let (n0, n1) = (before.facet_normal(&f.nodes), mesh.facet_normal(&f.nodes));
        let turned = synovia_mesh::Vector::<2>::new(c * n0[0] - s * n0[1], s * n0[0] + c * n0[1]);
        assert!((n1 - turned).norm() < 1e-14, "normal turned with the mesh");
    }
    for part in before.boundary_parts() {
        let moved = mesh.boundary_part(part.name())?;
        assert_eq!(moved.facets().collect::<Vec<_>>(), part.facets().collect::<Vec<_>>());
    }
    Ok(())
}

#[test]
fn an_inverting_or_flattening_map_is_refused_and_changes_nothing() -> Result<(), MeshError> {
    let mut mesh = box_mesh([0.0; 3], [1.0; 3], [3; 3], [U; 3])?;
    let before = mesh.clone();
    let mirrored = mesh.map_nodes(|x| Point::<3>::new(-x[0], x[1], x[2]));
    assert!(matches!(mirrored, Err(MeshError::InvertedCell { .. })), "{mirrored:?}");
    assert_eq!(mesh.nodes(), before.nodes(), "left unchanged");
    let flat = mesh.map_nodes(|x| Point::<3>::new(x[0], x[1], 0.0));
    assert!(matches!(flat, Err(MeshError::DegenerateCell { .. })), "{flat:?}");
    let nan = mesh.map_nodes(|x| Point::<3>::new(x[0], f64::NAN, x[2]));
    assert!(matches!(nan, Err(MeshError::NonFiniteNode { .. })), "{nan:?}");
    assert_eq!(mesh.nodes(), before.nodes(), "left unchanged");
    assert_eq!(mesh.boundary_facets(), before.boundary_facets());
    Ok(())
}
