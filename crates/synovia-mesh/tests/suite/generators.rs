//! Mesh generators (`synovia_mesh::generators`): geometry, parts, orientation, convergence.

use crate::common;

use std::f64::consts::PI;

use common::*;
use synovia_mesh::generators::{
    ball, box_mesh, disc, half_disc, half_disc_refined, hemisphere, hemisphere_refined, layered_arc_2d,
    layered_cap_3d, nodes_1d, rectangle, Grading,
};
use synovia_mesh::{BoundaryKind, Mesh, MeshError, Point, Real};

const U: Grading = Grading::Uniform;

fn sizes(x: &[Real]) -> Vec<Real> {
    x.windows(2).map(|w| w[1] - w[0]).collect()
}

fn is_invalid<T: std::fmt::Debug>(r: Result<T, MeshError>) -> bool {
    matches!(r, Err(MeshError::InvalidParameter(_)))
}

/// Asserts that every boundary facet's outward normal points away from `center`.
fn assert_outward_from<const D: usize>(mesh: &Mesh<D>, center: &Point<D>) {
    for f in mesh.boundary_facets() {
        let n = mesh.facet_normal(&f.nodes);
        let x = mesh.facet_centroid(&f.nodes);
        assert!(n.dot(&(x - center)) > 0.0, "facet {:?} normal {n:?} at {x:?}", f.nodes);
    }
}

#[test]
fn nodes_1d_gradings_are_monotone_with_the_requested_ratios() -> Result<(), MeshError> {
    let x = nodes_1d(-1.0, 3.0, 8, U)?;
    assert_eq!((x[0], x[8]), (-1.0, 3.0));
    assert!(sizes(&x).iter().all(|h| (h - 0.5).abs() < 1e-14));

    for ratio in [0.8, 1.25, 1.0] {
        let x = nodes_1d(2.0, 5.0, 10, Grading::Geometric { ratio })?;
        assert_eq!((x[0], x[10]), (2.0, 5.0));
        let h = sizes(&x);
        assert!(h.iter().all(|&h| h > 0.0));
        for w in h.windows(2) {
            assert!((w[1] / w[0] - ratio).abs() < 1e-10, "ratio {} vs {ratio}", w[1] / w[0]);
        }
    }
    let low = sizes(&nodes_1d(0.0, 1.0, 6, Grading::TowardLow { ratio: 1.5 })?);
    let high = sizes(&nodes_1d(0.0, 1.0, 6, Grading::TowardHigh { ratio: 1.5 })?);
    for k in 0..5 {
        assert!((low[k + 1] / low[k] - 1.5).abs() < 1e-10);
        assert!((high[k] / high[k + 1] - 1.5).abs() < 1e-10);
        assert!((low[k] - high[5 - k]).abs() < 1e-14);
    }

    // Local refinement: cells in the window are ~ratio times smaller than far cells.
    let g = Grading::Refined { center: 0.5, width: 0.1, ratio: 8.0 };
    let x = nodes_1d(0.0, 2.0, 60, g)?;
    assert_eq!((x[0], x[60]), (0.0, 2.0));
    let h = sizes(&x);
    assert!(h.iter().all(|&h| h > 0.0));
    let (mut fine, mut coarse) = (0.0_f64, Real::INFINITY);
    for (k, &hk) in h.iter().enumerate() {
        let mid = 0.5 * (x[k] + x[k + 1]);
        if (mid - 0.5).abs() < 0.05 {
            fine = fine.max(hk);
        }
        if (mid - 0.5).abs() > 0.4 {
            coarse = coarse.min(hk);
        }
    }
    assert!(fine > 0.0 && coarse < Real::INFINITY);
    assert!((coarse / fine - 8.0).abs() < 0.5, "coarse/fine = {}", coarse / fine);
    // The sizes change gradually: about 20 % from one cell to the next at most.
    for w in h.windows(2) {
        let r = w[1] / w[0];
        assert!((1.0 / 1.3..=1.3).contains(&r), "size jump {r}");
    }
    Ok(())
}

#[test]
fn nodes_1d_rejects_nonsense() {
    assert!(is_invalid(nodes_1d(0.0, 1.0, 0, U)));
    assert!(is_invalid(nodes_1d(1.0, 1.0, 3, U)));
    assert!(is_invalid(nodes_1d(2.0, 1.0, 3, U)));
    assert!(is_invalid(nodes_1d(Real::NAN, 1.0, 3, U)));
    assert!(is_invalid(nodes_1d(0.0, Real::INFINITY, 3, U)));
    assert!(is_invalid(nodes_1d(0.0, 1.0, 3, Grading::Geometric { ratio: 0.0 })));
    assert!(is_invalid(nodes_1d(0.0, 1.0, 3, Grading::Geometric { ratio: Real::NAN })));
    assert!(is_invalid(nodes_1d(0.0, 1.0, 3, Grading::TowardLow { ratio: 0.5 })));
    assert!(is_invalid(nodes_1d(0.0, 1.0, 3, Grading::TowardHigh { ratio: -2.0 })));
    let bad_width = Grading::Refined { center: 0.5, width: 0.0, ratio: 2.0 };
    assert!(is_invalid(nodes_1d(0.0, 1.0, 3, bad_width)));
    let bad_ratio = Grading::Refined { center: 0.5, width: 0.1, ratio: 0.5 };
    assert!(is_invalid(nodes_1d(0.0, 1.0, 3, bad_ratio)));
    // So extreme that nodes coincide in floating point.
    assert!(is_invalid(nodes_1d(0.0, 1.0, 4, Grading::Geometric { ratio: 1e-300 })));
}

#[test]
fn rectangle_measure_and_parts_are_exact() -> Result<(), MeshError> {
    let gx = Grading::Geometric { ratio: 0.8 };
    let gy = Grading::Refined { center: 1.5, width: 0.5, ratio: 4.0 };
    let m = rectangle(-1.0, 2.0, 0.5, 2.5, 7, 9, gx, gy)?;
    assert_eq!(m.n_cells(), 2 * 7 * 9);
    assert_eq!(m.n_nodes(), 8 * 10);
    assert!(rel(m.measure(), 6.0) < 1e-12);
    for (name, len) in [("left", 2.0), ("right", 2.0), ("bottom", 3.0), ("top", 3.0)] {
        assert!(rel(part_measure(&m, name)?, len) < 1e-12, "{name}");
        assert_eq!(m.boundary_part(name)?.kind(), BoundaryKind::TractionFree);
    }
    // The grid is the tensor product of the 1D distributions.
    let xs = nodes_1d(-1.0, 2.0, 7, gx)?;
    let ys = nodes_1d(0.5, 2.5, 9, gy)?;
    for p in m.nodes() {
        assert!(xs.contains(&p[0]) && ys.contains(&p[1]), "{p:?}");
    }
    let on_bd = |p: &Point<2>| p[0] == -1.0 || p[0] == 2.0 || p[1] == 0.5 || p[1] == 2.5;
    assert_conforming(&m, on_bd);
    assert_outward_from(&m, &Point::<2>::new(0.5, 1.5));
    Ok(())
}

#[test]
fn box_measure_and_parts_are_exact() -> Result<(), MeshError> {
    let g = [U, Grading::TowardHigh { ratio: 1.3 }, Grading::TowardLow { ratio: 1.2 }];
    let m = box_mesh([0.0, -1.0, 1.0], [2.0, 0.5, 1.5], [3, 4, 2], g)?;
    assert_eq!(m.n_cells(), 6 * 3 * 4 * 2);
    assert!(rel(m.measure(), 1.5) < 1e-12);
    let faces =
        [("left", 0.75), ("right", 0.75), ("front", 1.0), ("back", 1.0), ("bottom", 3.0), ("top", 3.0)];
    for (name, area) in faces {
        assert!(rel(part_measure(&m, name)?, area) < 1e-12, "{name}");
    }
    let on_bd = |p: &Point<3>| {
        p[0] == 0.0 || p[0] == 2.0 || p[1] == -1.0 || p[1] == 0.5 || p[2] == 1.0 || p[2] == 1.5
    };
    assert_conforming(&m, on_bd);
    assert_outward_from(&m, &Point::<3>::new(1.0, -0.25, 1.25));
    Ok(())
}

#[test]
fn half_disc_converges_with_arc_on_circle_and_lowest_node() -> Result<(), MeshError> {
    let c = Point::<2>::new(0.5, 2.0);
    let r = 1.5;
    let exact = 0.5 * PI * r * r;
    let mut last_err = Real::INFINITY;
    for n in [2, 4, 8, 16] {
        let m = half_disc(c, r, n)?;
        let err = rel(m.measure(), exact);
        assert!(err < 0.7 * last_err, "n = {n}: error {err}, previous {last_err}");
        last_err = err;
        assert!(max_sphere_deviation(&m, "arc", &c, r)? < 1e-12);
        let top = m.boundary_part("top")?;
        assert!(top.nodes().iter().all(|&i| m.node(i)[1] == c[1]));
        assert!(rel(part_measure(&m, "top")?, 2.0 * r) < 1e-12);
        assert!(find_node(&m, &Point::<2>::new(c[0], c[1] - r), 0.0).is_some());
        assert_conforming(&m, |p| p[1] == c[1] || ((p - c).norm() - r).abs() < 1e-12);
        for f in m.boundary_part("arc")?.facets() {
            assert!(m.facet_normal(f).dot(&(m.facet_centroid(f) - c)) > 0.0);
        }
        for f in m.boundary_part("top")?.facets() {
            assert!((m.facet_normal(f) - Point::<2>::new(0.0, 1.0)).norm() < 1e-12);
        }
    }
    assert!(last_err < 5e-3, "{last_err}");
    Ok(())
}

#[test]
fn hemisphere_converges_with_cap_on_sphere_and_lowest_node() -> Result<(), MeshError> {
    let c = Point::<3>::new(0.1, -0.2, 1.0);
    let r: Real = 0.8;
    let exact = 2.0 * PI * r.powi(3) / 3.0;
    let mut last_err = Real::INFINITY;
    for n in [1, 2, 4, 6] {
        let m = hemisphere(c, r, n)?;
        let err = rel(m.measure(), exact);
        assert!(err < 0.7 * last_err, "n = {n}: error {err}, previous {last_err}");
        last_err = err;
        assert!(max_sphere_deviation(&m, "cap", &c, r)? < 1e-12);
        let top = m.boundary_part("top")?;
        assert!(top.nodes().iter().all(|&i| m.node(i)[2] == c[2]));
        assert!(find_node(&m, &Point::<3>::new(c[0], c[1], c[2] - r), 0.0).is_some());
        assert_conforming(&m, |p| p[2] == c[2] || ((p - c).norm() - r).abs() < 1e-12);
        for f in m.boundary_part("cap")?.facets() {
            assert!(m.facet_normal(f).dot(&(m.facet_centroid(f) - c)) > 0.0);
        }
        for f in top.facets() {
            assert!((m.facet_normal(f) - Point::<3>::new(0.0, 0.0, 1.0)).norm() < 1e-12);
        }
    }
    assert!(last_err < 0.05, "{last_err}");
    Ok(())
}

#[test]
fn disc_and_ball_converge_with_outward_normals() -> Result<(), MeshError> {
    let c2 = Point::<2>::new(-1.0, 3.0);
    let mut last = Real::INFINITY;
    for n in [1, 2, 4, 8] {
        let m = disc(c2, 2.0, n)?;
        let err = rel(m.measure(), PI * 4.0);
        assert!(err < 0.7 * last, "disc n = {n}: {err} vs {last}");
        last = err;
        assert!(max_sphere_deviation(&m, "boundary", &c2, 2.0)? < 1e-12);
        assert_eq!(m.boundary_part("boundary")?.n_facets(), m.boundary_facets().len());
        assert_outward_from(&m, &c2);
        assert_conforming(&m, |p| ((p - c2).norm() - 2.0).abs() < 1e-12);
        assert!(find_node(&m, &c2, 0.0).is_some());
        // Mirrored diagonals: no sliver at the corners of the mapped square.
        assert!(min_quality(&m) > 0.7, "disc n = {n}: min radius ratio {}", min_quality(&m));
    }
    let c3 = Point::<3>::new(0.5, 0.0, -2.0);
    let mut last = Real::INFINITY;
    for n in [1, 2, 4] {
        let m = ball(c3, 0.5, n)?;
        let err = rel(m.measure(), 4.0 * PI * 0.125 / 3.0);
        assert!(err < 0.7 * last, "ball n = {n}: {err} vs {last}");
        last = err;
        assert!(max_sphere_deviation(&m, "boundary", &c3, 0.5)? < 1e-12);
        assert_outward_from(&m, &c3);
        assert_conforming(&m, |p| ((p - c3).norm() - 0.5).abs() < 1e-12);
        for k in 0..3 {
            let mut pole = c3;
            pole[k] -= 0.5;
            assert!(find_node(&m, &pole, 0.0).is_some(), "pole {pole:?}");
        }
        assert!(min_quality(&m) > 0.5, "ball n = {n}: min radius ratio {}", min_quality(&m));
    }
    Ok(())
}

#[test]
fn half_disc_refined_resolves_the_contact_zone() -> Result<(), MeshError> {
    let c = Point::<2>::new(0.0, 1.0);
    let r = 1.0;
    let contact = Point::<2>::new(0.0, 0.0);
    let levels = 6;
    let coarse = half_disc(c, r, 4)?;
    let m = half_disc_refined(c, r, 4, contact, 0.3, levels)?;
    assert!(max_sphere_deviation(&m, "arc", &c, r)? < 1e-12);
    assert!(find_node(&m, &contact, 0.0).is_some());
    assert_conforming(&m, |p| p[1] == c[1] || ((p - c).norm() - r).abs() < 1e-12);
    assert!(m.boundary_part("top")?.nodes().iter().all(|&i| m.node(i)[1] == c[1]));
    // The area improves: the arc midpoints were put on the circle.
    let exact = 0.5 * PI;
    assert!(rel(m.measure(), exact) < rel(coarse.measure(), exact));

    let near = |x: &Point<2>| (x - contact).norm() < 0.15;
    let h_coarse = max_h_where(&coarse, |x| (x - contact).norm() < 0.3);
    let h_fine = max_h_where(&m, near);
    let expected = h_coarse / 2.0_f64.powf(levels as Real / 2.0);
    assert!(
        h_fine > 0.5 * expected && h_fine < 1.5 * expected,
        "contact-zone h {h_fine}, expected about {expected} (coarse {h_coarse})"
    );
    // Far from the contact zone the mesh stays coarse.
    let far = min_h_where(&m, |x| x[1] > 0.8);
    assert!(far > 4.0 * h_fine);
    Ok(())
}

#[test]
fn hemisphere_refined_resolves_the_contact_zone() -> Result<(), MeshError> {
    let c = Point::<3>::new(0.0, 0.0, 1.0);
    let r = 1.0;
    let contact = Point::<3>::zeros();
    let coarse = hemisphere(c, r, 2)?;
    let m = hemisphere_refined(c, r, 2, contact, 0.3, 3)?;
    assert!(max_sphere_deviation(&m, "cap", &c, r)? < 1e-12);
    assert!(find_node(&m, &contact, 0.0).is_some());
    assert_conforming(&m, |p| p[2] == c[2] || ((p - c).norm() - r).abs() < 1e-12);
    let h_coarse = max_h_where(&coarse, |x| (x - contact).norm() < 0.5);
    let h_fine = max_h_where(&m, |x| (x - contact).norm() < 0.15);
    assert!(h_fine <= 0.6 * h_coarse, "contact-zone h {h_fine}, coarse {h_coarse}");
    let exact = 2.0 * PI / 3.0;
    assert!(rel(m.measure(), exact) < rel(coarse.measure(), exact));
    Ok(())
}

#[test]
fn layered_arc_layers_share_nodes_and_converge() -> Result<(), MeshError> {
    let c = Point::<2>::new(0.2, 1.1);
    let radii = [1.0, 1.2, 1.3];
    let (t0, t1) = (-0.8 * PI, -0.2 * PI);
    let mut last = [Real::INFINITY; 2];
    for n_angle in [6, 12, 24] {
        let layers = layered_arc_2d(c, &radii, (t0, t1), n_angle, &[3, 2])?;
        assert_eq!(layers.len(), 2);
        for (k, m) in layers.iter().enumerate() {
            let exact = 0.5 * (t1 - t0) * (radii[k + 1].powi(2) - radii[k].powi(2));
            let err = rel(m.measure(), exact);
            assert!(err < 0.3 * last[k], "layer {k}, n = {n_angle}: {err} vs {}", last[k]);
            last[k] = err;
            assert!(max_sphere_deviation(m, "inner", &c, radii[k])? < 1e-12);
            assert!(max_sphere_deviation(m, "outer", &c, radii[k + 1])? < 1e-12);
            for f in m.boundary_part("outer")?.facets() {
                assert!(m.facet_normal(f).dot(&(m.facet_centroid(f) - c)) > 0.0);
            }
            for f in m.boundary_part("inner")?.facets() {
                assert!(m.facet_normal(f).dot(&(m.facet_centroid(f) - c)) < 0.0);
            }
            let tangent0 = Point::<2>::new(-t0.sin(), t0.cos());
            for f in m.boundary_part("side_start")?.facets() {
                assert!((m.facet_normal(f) + tangent0).norm() < 1e-12);
            }
            assert!(rel(part_measure(m, "side_end")?, radii[k + 1] - radii[k]) < 1e-12);
        }
        // The bonded interface: identical node positions.
        let outer = layers[0].boundary_part("outer")?.nodes();
        let inner = layers[1].boundary_part("inner")?.nodes();
        assert_eq!(outer.len(), n_angle + 1);
        assert_eq!(inner.len(), n_angle + 1);
        for &i in &outer {
            let p = layers[0].node(i);
            assert!(find_node(&layers[1], p, 1e-12).is_some_and(|j| inner.contains(&j)), "{p:?}");
        }
    }
    Ok(())
}

#[test]
fn layered_cap_layers_share_nodes_and_converge() -> Result<(), MeshError> {
    let c = Point::<3>::new(0.0, 0.0, 2.0);
    let radii = [1.0, 1.1, 1.25];
    let alpha: Real = 0.7;
    let mut last = [Real::INFINITY; 2];
    for n in [1, 2, 4] {
        let layers = layered_cap_3d(c, &radii, alpha, n, &[1, 2])?;
        assert_eq!(layers.len(), 2);
        for (k, m) in layers.iter().enumerate() {
            let exact = 2.0 * PI / 3.0 * (radii[k + 1].powi(3) - radii[k].powi(3)) * (1.0 - alpha.cos());
            let err = rel(m.measure(), exact);
            assert!(err < 0.5 * last[k], "layer {k}, n = {n}: {err} vs {}", last[k]);
            last[k] = err;
            assert!(max_sphere_deviation(m, "inner", &c, radii[k])? < 1e-12);
            assert!(max_sphere_deviation(m, "outer", &c, radii[k + 1])? < 1e-12);
            for &i in &m.boundary_part("rim")?.nodes() {
                let d = m.node(i) - c;
                let polar = (-d[2] / d.norm()).acos();
                assert!((polar - alpha).abs() < 1e-12, "rim node {i} at polar angle {polar}");
            }
            for f in m.boundary_part("outer")?.facets() {
                assert!(m.facet_normal(f).dot(&(m.facet_centroid(f) - c)) > 0.0);
            }
            for f in m.boundary_part("inner")?.facets() {
                assert!(m.facet_normal(f).dot(&(m.facet_centroid(f) - c)) < 0.0);
            }
            let pole = Point::<3>::new(c[0], c[1], c[2] - radii[k]);
            assert!(find_node(m, &pole, 0.0).is_some());
            let on_bd = |p: &Point<3>| {
                let d = p - c;
                radii[k..k + 2].iter().any(|&r| (d.norm() - r).abs() < 1e-12)
                    || ((-d[2] / d.norm()).acos() - alpha).abs() < 1e-12
            };
            assert_conforming(m, on_bd);
        }
        let outer = layers[0].boundary_part("outer")?.nodes();
        let inner = layers[1].boundary_part("inner")?.nodes();
        assert_eq!(outer.len(), inner.len());
        assert_eq!(outer.len(), (2 * n + 1) * (2 * n + 1));
        for &i in &outer {
            let p = layers[0].node(i);
            assert!(find_node(&layers[1], p, 1e-12).is_some_and(|j| inner.contains(&j)), "{p:?}");
        }
    }
    assert!(last.iter().all(|&e| e < 0.05), "{last:?}");
    Ok(())
}

#[test]
fn generators_reject_nonsense_parameters() {
    let o2 = Point::<2>::zeros();
    let o3 = Point::<3>::zeros();
    assert!(is_invalid(rectangle(0.0, 1.0, 0.0, 1.0, 0, 2, U, U)));
    assert!(is_invalid(rectangle(1.0, 0.0, 0.0, 1.0, 2, 2, U, U)));
    assert!(is_invalid(rectangle(0.0, 1.0, 0.0, Real::NAN, 2, 2, U, U)));
    assert!(is_invalid(box_mesh([0.0; 3], [1.0, 1.0, 0.0], [1; 3], [U; 3])));
    assert!(is_invalid(box_mesh([0.0; 3], [1.0; 3], [1, 0, 1], [U; 3])));
    assert!(is_invalid(disc(o2, 0.0, 2)));
    assert!(is_invalid(disc(o2, 1.0, 0)));
    assert!(is_invalid(disc(Point::<2>::new(Real::NAN, 0.0), 1.0, 2)));
    assert!(is_invalid(half_disc(o2, -1.0, 2)));
    assert!(is_invalid(ball(o3, Real::INFINITY, 2)));
    assert!(is_invalid(hemisphere(o3, 1.0, 0)));
    assert!(is_invalid(half_disc_refined(o2, 1.0, 2, o2, 0.0, 2)));
    assert!(is_invalid(hemisphere_refined(o3, 1.0, 2, o3, Real::NAN, 2)));
    let arc = |radii: &[Real], range: (Real, Real), na: usize, nr: &[usize]| {
        is_invalid(layered_arc_2d(o2, radii, range, na, nr))
    };
    assert!(arc(&[1.0], (0.0, 1.0), 4, &[]));
    assert!(arc(&[1.0, 2.0], (0.0, 1.0), 4, &[1, 1]));
    assert!(arc(&[1.0, 1.0], (0.0, 1.0), 4, &[1]));
    assert!(arc(&[0.0, 1.0], (0.0, 1.0), 4, &[1]));
    assert!(arc(&[1.0, 2.0], (1.0, 1.0), 4, &[1]));
    assert!(arc(&[1.0, 2.0], (0.0, 7.0), 4, &[1]));
    assert!(arc(&[1.0, 2.0], (0.0, 1.0), 0, &[1]));
    assert!(arc(&[1.0, 2.0], (0.0, 1.0), 4, &[0]));
    let cap = |radii: &[Real], alpha: Real, ns: usize, nr: &[usize]| {
        is_invalid(layered_cap_3d(o3, radii, alpha, ns, nr))
    };
    assert!(cap(&[1.0, 2.0], 0.0, 2, &[1]));
    assert!(cap(&[1.0, 2.0], PI, 2, &[1]));
    assert!(cap(&[1.0, 2.0], 1.0, 0, &[1]));
    assert!(cap(&[2.0, 1.0], 1.0, 2, &[1]));
    assert!(cap(&[1.0, 2.0, 3.0], 1.0, 2, &[1]));
}

#[test]
fn radius_ratio_is_one_for_regular_simplices_and_small_for_slivers() -> Result<(), MeshError> {
    let s3 = 3.0_f64.sqrt();
    let tri = Mesh::<2>::new(
        vec![Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.0), Point::<2>::new(0.5, 0.5 * s3)],
        vec![0, 1, 2],
    )?;
    assert!((tri.radius_ratio(0) - 1.0).abs() < 1e-12);
    let tet = Mesh::<3>::new(
        vec![
            Point::<3>::new(1.0, 1.0, 1.0),
            Point::<3>::new(1.0, -1.0, -1.0),
            Point::<3>::new(-1.0, 1.0, -1.0),
            Point::<3>::new(-1.0, -1.0, 1.0),
        ],
        vec![0, 2, 1, 3],
    )?;
    assert!((tet.radius_ratio(0) - 1.0).abs() < 1e-12, "{}", tet.radius_ratio(0));
    let flat = Mesh::<2>::new(
        vec![Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.0), Point::<2>::new(0.5, 0.01)],
        vec![0, 1, 2],
    )?;
    assert!(flat.radius_ratio(0) < 0.05);
    Ok(())
}
