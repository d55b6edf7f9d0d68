//! Helpers shared by the integration tests of synovia-mesh.
#![allow(dead_code)]

use std::collections::HashMap;

use synovia_mesh::{CellOrientation, Mesh, MeshError, Point, Real};

/// Number of cells containing each facet (sorted node list).
pub fn facet_counts<const D: usize>(mesh: &Mesh<D>) -> HashMap<Vec<usize>, usize> {
    let mut count = HashMap::new();
    for cell in mesh.cells() {
        for opp in 0..=D {
            let mut f: Vec<usize> = (0..=D).filter(|&k| k != opp).map(|k| cell[k]).collect();
            f.sort_unstable();
            *count.entry(f).or_insert(0) += 1;
        }
    }
    count
}

/// Asserts that the mesh is conforming: every facet is shared by at most two cells, and every
/// facet of a single cell has all its nodes on the domain boundary (`on_boundary`), so there is
/// no hanging node. Also asserts that every cell is positively oriented.
pub fn assert_conforming<const D: usize>(mesh: &Mesh<D>, on_boundary: impl Fn(&Point<D>) -> bool) {
    for (f, &n) in &facet_counts(mesh) {
        assert!(n <= 2, "facet {f:?} is shared by {n} cells");
        if n == 1 {
            for &v in f {
                assert!(
                    on_boundary(mesh.node(v)),
                    "facet {f:?} has one cell but node {v} at {:?} is inside the domain",
                    mesh.node(v)
                );
            }
        }
    }
    for c in 0..mesh.n_cells() {
        assert_eq!(mesh.cell_orientation(c), CellOrientation::Positive, "cell {c}");
        assert!(mesh.cell_measure(c) > 0.0, "cell {c}");
    }
}

/// Total measure of the facets of a part.
pub fn part_measure<const D: usize>(mesh: &Mesh<D>, name: &str) -> Result<Real, MeshError> {
    let part = mesh.boundary_part(name)?;
    Ok(part.facets().map(|f| mesh.facet_measure(f)).sum())
}

/// Total measure of all boundary facets.
pub fn boundary_measure<const D: usize>(mesh: &Mesh<D>) -> Real {
    mesh.boundary_facets().iter().map(|f| mesh.facet_measure(&f.nodes)).sum()
}

/// Smallest radius ratio of the mesh.
pub fn min_quality<const D: usize>(mesh: &Mesh<D>) -> Real {
    (0..mesh.n_cells()).map(|c| mesh.radius_ratio(c)).fold(Real::INFINITY, Real::min)
}

/// Longest edge of a cell.
pub fn cell_h<const D: usize>(mesh: &Mesh<D>, c: usize) -> Real {
    let p = mesh.cell_points(c);
    let mut h: Real = 0.0;
    for i in 0..=D {
        for j in 0..i {
            h = h.max((p[i] - p[j]).norm());
        }
    }
    h
}

/// Largest cell size among the cells whose centroid satisfies `select` (0 if none).
pub fn max_h_where<const D: usize>(mesh: &Mesh<D>, select: impl Fn(&Point<D>) -> bool) -> Real {
    (0..mesh.n_cells())
        .filter(|&c| select(&mesh.cell_centroid(c)))
        .map(|c| cell_h(mesh, c))
        .fold(0.0, Real::max)
}

/// Smallest cell size among the cells whose centroid satisfies `select` (∞ if none).
pub fn min_h_where<const D: usize>(mesh: &Mesh<D>, select: impl Fn(&Point<D>) -> bool) -> Real {
    (0..mesh.n_cells())
        .filter(|&c| select(&mesh.cell_centroid(c)))
        .map(|c| cell_h(mesh, c))
        .fold(Real::INFINITY, Real::min)
}

/// Index of a node at `p` (within `tol`), if any.
pub fn find_node<const D: usize>(mesh: &Mesh<D>, p: &Point<D>, tol: Real) -> Option<usize> {
    mesh.nodes().iter().position(|q| (q - p).norm() <= tol)
}

/// Largest deviation `| |x − c| − r |` over the nodes of a part.
pub fn max_sphere_deviation<const D: usize>(
    mesh: &Mesh<D>,
    part: &str,
    c: &Point<D>,
    r: Real,
) -> Result<Real, MeshError> {
    Ok(mesh
        .boundary_part(part)?
        .nodes()
        .iter()
        .map(|&i| ((mesh.node(i) - c).norm() - r).abs())
        .fold(0.0, Real::max))
}

/// Relative difference.
pub fn rel(a: Real, b: Real) -> Real {
    (a - b).abs() / b.abs()
}
