//! Conforming local refinement by longest-edge bisection (`synovia_mesh::refine`).

use crate::common;

use std::collections::HashSet;

use common::*;
use synovia_mesh::generators::{box_mesh, disc, hemisphere, rectangle, Grading};
use synovia_mesh::refine::{
    refine_marked, refine_toward, refine_toward_within, refine_uniform, BoundaryProjection, SphereProjection,
    StraightMidpoint,
};
use synovia_mesh::{BoundaryKind, Mesh, MeshError, Point, Real};

const U: Grading = Grading::Uniform;

fn on_rectangle_boundary(p: &Point<2>, x1: Real, y1: Real) -> bool {
    let tol = 1e-12;
    p[0].abs() < tol || (p[0] - x1).abs() < tol || p[1].abs() < tol || (p[1] - y1).abs() < tol
}

fn on_unit_box_boundary(p: &Point<3>) -> bool {
    p.iter().any(|&x| x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12)
}

/// Part names, kinds and measures of a mesh.
fn part_summary<const D: usize>(mesh: &Mesh<D>) -> Result<Vec<(String, BoundaryKind, Real)>, MeshError> {
    mesh.boundary_parts()
        .iter()
        .map(|p| Ok((p.name().to_string(), p.kind(), part_measure(mesh, p.name())?)))
        .collect()
}

fn assert_parts_preserved<const D: usize>(before: &Mesh<D>, after: &Mesh<D>) -> Result<(), MeshError> {
    let (b, a) = (part_summary(before)?, part_summary(after)?);
    assert_eq!(b.len(), a.len());
    for ((nb, kb, mb), (na, ka, ma)) in b.iter().zip(&a) {
        assert_eq!(nb, na);
        assert_eq!(kb, ka);
        assert!(rel(*ma, *mb) < 1e-12, "part {nb}: measure {mb} became {ma}");
    }
    // Every boundary facet of the refined mesh is in some part (the parts covered the boundary).
    let sorted = |f: &[usize]| {
        let mut f = f.to_vec();
        f.sort_unstable();
        f
    };
    let in_parts: HashSet<Vec<usize>> =
        after.boundary_parts().iter().flat_map(|p| p.facets().map(sorted)).collect();
    let boundary: HashSet<Vec<usize>> = after.boundary_facets().iter().map(|f| sorted(&f.nodes)).collect();
    assert_eq!(in_parts, boundary);
    Ok(())
}

#[test]
fn refine_toward_2d_rectangle_is_conforming_graded_and_keeps_quality() -> Result<(), MeshError> {
    let coarse = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4, U, U)?;
    let q0 = min_quality(&coarse);
    let h0 = coarse.max_edge_length();
    let target = Point::<2>::new(0.5, 0.5);
    let region = |x: &Point<2>| (x - target).norm() <= 0.15;
    let fine = refine_toward(&coarse, region, 6, &StraightMidpoint)?;

    assert!(fine.n_cells() > 4 * coarse.n_cells(), "{} cells", fine.n_cells());
    assert_conforming(&fine, |p| on_rectangle_boundary(p, 2.0, 1.0));
    assert!(rel(fine.measure(), 2.0) < 1e-12, "area {}", fine.measure());
    assert!(rel(boundary_measure(&fine), 6.0) < 1e-12);
    assert_parts_preserved(&coarse, &fine)?;

    // Cells in the region shrink by sqrt(2) per level (6 levels: h0 / 8); far cells keep h0.
    let near = max_h_where(&fine, |x| (x - target).norm() < 0.1);
    let far = min_h_where(&fine, |x| (x - target).norm() > 1.0);
    assert!(near <= h0 / 8.0 * (1.0 + 1e-12), "near h {near}, coarse h {h0}");
    assert!(rel(far, h0) < 1e-12, "far h {far}, coarse h {h0}");

    // Longest-edge bisection keeps the shape: radius ratio bounded from below.
    let q = min_quality(&fine);
    assert!(q >= 0.75 * q0, "min radius ratio {q} after refinement, {q0} before");
    Ok(())
}

#[test]
fn refine_toward_3d_box_is_conforming_graded_and_keeps_quality() -> Result<(), MeshError> {
    let coarse = box_mesh([0.0; 3], [1.0; 3], [4, 4, 4], [U; 3])?;
    let q0 = min_quality(&coarse);
    let h0 = coarse.max_edge_length();
    let target = Point::<3>::new(0.3, 0.3, 0.3);
    let region = |x: &Point<3>| (x - target).norm() <= 0.15;
    let fine = refine_toward(&coarse, region, 3, &StraightMidpoint)?;

    assert!(fine.n_cells() > 3 * coarse.n_cells() / 2, "{} cells", fine.n_cells());
    assert_conforming(&fine, on_unit_box_boundary);
    assert!(rel(fine.measure(), 1.0) < 1e-12, "volume {}", fine.measure());
    assert!(rel(boundary_measure(&fine), 6.0) < 1e-12);
    assert_parts_preserved(&coarse, &fine)?;

    let near = max_h_where(&fine, |x| (x - target).norm() < 0.08);
    let far = min_h_where(&fine, |x| (x - target).norm() > 0.8);
    assert!(near <= 0.6 * h0, "near h {near}, coarse h {h0}");
    assert!(rel(far, h0) < 1e-12, "far h {far}, coarse h {h0}");

    let q = min_quality(&fine);
    assert!(q >= 0.75 * q0, "min radius ratio {q} after refinement, {q0} before");
    Ok(())
}

#[test]
fn refine_marked_single_cell_closure_is_conforming() -> Result<(), MeshError> {
    let m2 = rectangle(0.0, 1.0, 0.0, 1.0, 5, 5, U, U)?;
    for c in [0, 17, m2.n_cells() - 1] {
        let r = refine_marked(&m2, |k| k == c, &StraightMidpoint)?;
        assert!(r.n_cells() > m2.n_cells());
        assert_conforming(&r, |p| on_rectangle_boundary(p, 1.0, 1.0));
        assert!(rel(r.measure(), 1.0) < 1e-12);
        assert_parts_preserved(&m2, &r)?;
    }
    let m3 = box_mesh([0.0; 3], [1.0; 3], [3, 3, 3], [U; 3])?;
    for c in [0, 77, m3.n_cells() - 1] {
        let r = refine_marked(&m3, |k| k == c, &StraightMidpoint)?;
        assert!(r.n_cells() > m3.n_cells());
        assert_conforming(&r, on_unit_box_boundary);
        assert!(rel(r.measure(), 1.0) < 1e-12);
        assert_parts_preserved(&m3, &r)?;
    }
    // Nothing marked: the mesh comes back unchanged.
    let same = refine_marked(&m3, |_| false, &StraightMidpoint)?;
    assert_eq!(same.nodes(), m3.nodes());
    assert_eq!(same.cells_flat(), m3.cells_flat());
    Ok(())
}

#[test]
fn refine_uniform_halves_the_mesh_size() -> Result<(), MeshError> {
    let m2 = rectangle(0.0, 3.0, 0.0, 2.0, 3, 2, U, U)?;
    let r2 = refine_uniform(&m2, 1, &StraightMidpoint)?;
    assert_eq!(r2.n_cells(), 4 * m2.n_cells());
    assert!(rel(r2.max_edge_length(), 0.5 * m2.max_edge_length()) < 1e-12);
    assert!(rel(r2.measure(), 6.0) < 1e-12);
    assert_conforming(&r2, |p| on_rectangle_boundary(p, 3.0, 2.0));

    let m3 = box_mesh([0.0; 3], [1.0; 3], [2, 2, 2], [U; 3])?;
    let r3 = refine_uniform(&m3, 1, &StraightMidpoint)?;
    assert_eq!(r3.n_cells(), 8 * m3.n_cells());
    assert!(r3.max_edge_length() <= 0.5 * m3.max_edge_length() * (1.0 + 1e-12));
    assert!(rel(r3.measure(), 1.0) < 1e-12);
    assert_conforming(&r3, on_unit_box_boundary);
    assert_parts_preserved(&m3, &r3)?;
    Ok(())
}

#[test]
fn sphere_projection_keeps_refined_disc_round() -> Result<(), MeshError> {
    let c = Point::<2>::new(0.3, -0.2);
    let r = 1.5;
    let coarse = disc(c, r, 2)?;
    let proj = SphereProjection::new(c, r)?;
    let round = refine_uniform(&coarse, 2, &proj)?;
    assert!(max_sphere_deviation(&round, "boundary", &c, r)? < 1e-12);
    let exact = std::f64::consts::PI * r * r;
    assert!(rel(round.measure(), exact) < 0.5 * rel(coarse.measure(), exact));
    assert_conforming(&round, |p| ((p - c).norm() - r).abs() < 1e-12);

    // Straight midpoints keep the polygon: same area, boundary nodes no longer on the circle.
    let flat = refine_uniform(&coarse, 2, &StraightMidpoint)?;
    assert!(rel(flat.measure(), coarse.measure()) < 1e-12);
    assert!(max_sphere_deviation(&flat, "boundary", &c, r)? > 1e-3);
    Ok(())
}

/// A malicious projection that throws boundary midpoints through the body.
struct Flip;
impl BoundaryProjection<2> for Flip {
    fn midpoint(&self, a: &Point<2>, b: &Point<2>) -> Point<2> {
        -(a + b) * 5.0
    }
}

#[test]
fn inverting_projection_is_reported_not_hidden() -> Result<(), MeshError> {
    let m = rectangle(1.0, 2.0, 1.0, 2.0, 2, 2, U, U)?;
    let out = refine_uniform(&m, 1, &Flip);
    assert!(
        matches!(out, Err(MeshError::InvertedCell { .. }) | Err(MeshError::DegenerateCell { .. })),
        "{out:?}"
    );
    Ok(())
}

#[test]
fn no_levels_or_empty_region_return_the_input() -> Result<(), MeshError> {
    let m = rectangle(0.0, 1.0, 0.0, 1.0, 3, 3, U, U)?;
    let zero = refine_toward(&m, |_| true, 0, &StraightMidpoint)?;
    assert_eq!(zero, m);
    let none = m.refined_toward(|x| x[0] > 5.0, 4, &StraightMidpoint)?;
    assert_eq!(none, m);
    // A region smaller than a cell and away from its vertices still refines that cell.
    let tiny = Point::<2>::new(0.5, 0.5 + 1.0 / 12.0);
    let r = refine_toward(&m, |x| (x - tiny).norm() < 0.06, 1, &StraightMidpoint)?;
    assert!(r.n_cells() > m.n_cells());
    Ok(())
}

#[test]
fn overlapping_parts_are_all_carried_over() -> Result<(), MeshError> {
    let mut m = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, U, U)?;
    m.add_boundary_part("lower_half", BoundaryKind::Contact, |x, _| x[1] < 0.5)?;
    m.add_boundary_part("everything", BoundaryKind::Clamped, |_, _| true)?;
    let r = refine_toward(&m, |x| x[0] < 0.3 && x[1] < 0.3, 3, &StraightMidpoint)?;
    assert_parts_preserved(&m, &r)?;
    assert!(rel(part_measure(&r, "lower_half")?, 2.0) < 1e-12);
    assert_eq!(r.boundary_part("everything")?.n_facets(), r.boundary_facets().len());
    assert_eq!(r.boundary_part("lower_half")?.kind(), BoundaryKind::Contact);
    // Parts stay outward oriented.
    for f in r.boundary_part("lower_half")?.facets() {
        let n = r.facet_normal(f);
        let x = r.facet_centroid(f);
        assert!(n.dot(&(x - Point::<2>::new(0.5, 0.5))) > 0.0);
    }
    Ok(())
}

#[test]
fn sphere_projection_validates_and_projects() -> Result<(), MeshError> {
    assert!(matches!(SphereProjection::new(Point::<2>::zeros(), 0.0), Err(MeshError::InvalidParameter(_))));
    assert!(matches!(
        SphereProjection::new(Point::<3>::zeros(), Real::NAN),
        Err(MeshError::InvalidParameter(_))
    ));
    let p = SphereProjection::new(Point::<2>::new(1.0, 1.0), 2.0)?;
    let m = p.midpoint(&Point::<2>::new(3.0, 1.0), &Point::<2>::new(1.0, 3.0));
    assert!(((m - Point::<2>::new(1.0, 1.0)).norm() - 2.0).abs() < 1e-14);
    // One end off the circle: plain midpoint.
    let m = p.midpoint(&Point::<2>::new(3.0, 1.0), &Point::<2>::new(1.0, 2.0));
    assert_eq!(m, Point::<2>::new(2.0, 1.5));
    Ok(())
}

#[test]
fn sphere_projection_on_hemisphere_keeps_cap_round_and_top_flat() -> Result<(), MeshError> {
    let c = Point::<3>::new(0.2, -0.1, 0.7);
    let r = 0.9;
    let coarse = hemisphere(c, r, 1)?;
    let proj = SphereProjection::new(c, r)?;
    let fine = refine_uniform(&coarse, 1, &proj)?;
    assert!(fine.n_cells() >= 8 * coarse.n_cells());
    assert!(max_sphere_deviation(&fine, "cap", &c, r)? < 1e-12);
    let top = fine.boundary_part("top")?;
    assert!(top.nodes().iter().all(|&i| fine.node(i)[2] == c[2]));
    assert_conforming(&fine, |p| p[2] == c[2] || ((p - c).norm() - r).abs() < 1e-12);
    let exact = 2.0 * std::f64::consts::PI * r.powi(3) / 3.0;
    assert!(rel(fine.measure(), exact) < 0.6 * rel(coarse.measure(), exact));
    assert!(min_quality(&fine) > 0.25, "min radius ratio {}", min_quality(&fine));
    Ok(())
}

/// `refine_toward_within` is `refine_toward` under its cell limit, and stops with an error at
/// the first level above it (a region covering the whole mesh doubles the cells per level).
#[test]
fn refinement_within_a_cell_limit() -> Result<(), MeshError> {
    let o = Point::<3>::zeros();
    let mesh = hemisphere(o, 1.0, 2)?;
    let proj = SphereProjection::new(o, 1.0)?;
    let everywhere = |_: &Point<3>| true;
    let free = refine_toward(&mesh, everywhere, 3, &proj)?;
    let within = refine_toward_within(&mesh, everywhere, 3, &proj, free.n_cells())?;
    assert_eq!(within.n_cells(), free.n_cells());
    assert!(within.cells().eq(free.cells()));
    assert!(free.n_cells() >= 4 * mesh.n_cells(), "{} from {}", free.n_cells(), mesh.n_cells());
    match refine_toward_within(&mesh, everywhere, 3, &proj, free.n_cells() - 1) {
        Err(MeshError::InvalidParameter(m)) => assert!(m.contains("after level 3 of 3"), "{m}"),
        other => panic!("expected the cell limit, got {:?}", other.map(|m| m.n_cells())),
    }
    match refine_toward_within(&mesh, everywhere, 30, &proj, 2 * mesh.n_cells()) {
        Err(MeshError::InvalidParameter(m)) => assert!(m.contains("more than the limit"), "{m}"),
        other => panic!("expected the cell limit, got {:?}", other.map(|m| m.n_cells())),
    }
    Ok(())
}
