//! Self-intersection of triangle surfaces: [`TriangleSurface::check_self_intersection`] and
//! [`TriangleSurface::check_closed_solid`].
//!
//! **Broad phase**: a uniform grid of cubes about twice the mean triangle size; each triangle
//! is entered in the cells its bounding box covers, and a pair of triangles whose boxes
//! overlap is tested once (in the cell holding the lower corner of the boxes' overlap).
//!
//! **Narrow phase**: two triangles that are not coplanar intersect exactly when an edge of one
//! crosses the other (the end points of their common segment lie on edges), so each pair costs
//! six segment–triangle tests (orientation determinants, then barycentric coordinates of the
//! crossing point in the projection that drops the normal's largest component). An edge in the
//! other triangle's plane (coplanar pairs) is tested in that projection (an end inside the
//! triangle, or a crossing of one of its edges).
//! Touching within `1e-12` of the surface's size counts as crossing.
//!
//! **Neighbours**: triangles sharing an edge are not tested (on a manifold they meet only along
//! that edge); triangles sharing one vertex are tested for crossings away from that vertex, so
//! a surface folded through a vertex is found.

use crate::math::{Point, Real, Vector};
use crate::surface::{SurfaceError, TriangleSurface};

/// Relative tolerance (of the bounding-box diagonal) of the crossing tests.
const TOLERANCE: Real = 1e-12;

fn corner_min(t: &[Point<3>; 3]) -> [Real; 3] {
    std::array::from_fn(|k| t[0][k].min(t[1][k]).min(t[2][k]))
}
fn corner_max(t: &[Point<3>; 3]) -> [Real; 3] {
    std::array::from_fn(|k| t[0][k].max(t[1][k]).max(t[2][k]))
}

/// Orientation of `d` relative to the plane of `a, b, c` (6 × signed tetrahedron volume).
fn orient(a: &Point<3>, b: &Point<3>, c: &Point<3>, d: &Point<3>) -> Real {
    (b - a).cross(&(c - a)).dot(&(d - a))
}

/// The two coordinates kept when projecting along the largest component of `n`.
fn projection(n: &Vector<3>) -> (usize, usize) {
    let (ax, ay, az) = (n.x.abs(), n.y.abs(), n.z.abs());
    if ax >= ay && ax >= az {
        (1, 2)
    } else if ay >= az {
        (2, 0)
    } else {
        (0, 1)
    }
}

/// Whether the 2D point `p` lies in the 2D triangle `t` (within `eps`, in units of twice the
/// triangle's area).
fn inside_2d(t: &[[Real; 2]; 3], p: [Real; 2], eps: Real) -> bool {
    let cross = |a: [Real; 2], b: [Real; 2], c: [Real; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let area = cross(t[0], t[1], t[2]);
    if area == 0.0 {
        return false;
    }
    let s = area.signum();
    (0..3).all(|k| s * cross(t[k], t[(k + 1) % 3], p) >= -eps * area.abs())
}

/// Crossing point of 2D segments `p q` and `r s`, if they cross (touching within `eps` counts).
fn segments_2d(p: [Real; 2], q: [Real; 2], r: [Real; 2], s: [Real; 2], eps: Real) -> Option<Real> {
    let d = [q[0] - p[0], q[1] - p[1]];
    let e = [s[0] - r[0], s[1] - r[1]];
    let den = d[0] * e[1] - d[1] * e[0];
    if den == 0.0 {
        return None;
    }
    let w = [r[0] - p[0], r[1] - p[1]];
    let t = (w[0] * e[1] - w[1] * e[0]) / den;
    let u = (w[0] * d[1] - w[1] * d[0]) / den;
    (t >= -eps && t <= 1.0 + eps && u >= -eps && u <= 1.0 + eps).then_some(t)
}

/// Where segment `p q` meets triangle `t` (non-coplanar case), if it does.
fn segment_triangle(p: &Point<3>, q: &Point<3>, t: &[Point<3>; 3], eps: Real) -> Option<Point<3>> {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let scale = n.norm();
    if scale == 0.0 {
        return None;
    }
    let dp = orient(&t[0], &t[1], &t[2], p) / scale;
    let dq = orient(&t[0], &t[1], &t[2], q) / scale;
    let len = (q - p).norm();
    let tol = eps * len.max(1.0e-300);
    if (dp > tol && dq > tol) || (dp < -tol && dq < -tol) {
        return None;
    }
    let (i, j) = projection(&n);
    let t2 = [[t[0][i], t[0][j]], [t[1][i], t[1][j]], [t[2][i], t[2][j]]];
    if dp.abs() <= tol && dq.abs() <= tol {
        // the segment lies in the triangle's plane: an end inside, or a crossing of an edge
        let (p2, q2) = ([p[i], p[j]], [q[i], q[j]]);
        for (x, x2) in [(p, p2), (q, q2)] {
            if inside_2d(&t2, x2, 1e-9) {
                return Some(*x);
            }
        }
        return (0..3)
            .find_map(|k| segments_2d(p2, q2, t2[k], t2[(k + 1) % 3], 1e-9).map(|s| p + (q - p) * s));
    }
    let s = dp / (dp - dq);
    let x = p + (q - p) * s.clamp(0.0, 1.0);
    inside_2d(&t2, [x[i], x[j]], 1e-9).then_some(x)
}

/// Where triangles `a` and `b` cross (a point of both), if they do; a crossing within
/// `exclude_r` of `exclude` (their shared vertex) does not count.
fn triangles_cross(
    a: &[Point<3>; 3],
    b: &[Point<3>; 3],
    eps: Real,
    exclude: Option<(&Point<3>, Real)>,
) -> Option<Point<3>> {
    let away = |x: &Point<3>| exclude.is_none_or(|(v, r)| (x - v).norm() > r);
    let na = (a[1] - a[0]).cross(&(a[2] - a[0]));
    let nb = (b[1] - b[0]).cross(&(b[2] - b[0]));
    let (la, lb) = (na.norm(), nb.norm());
    if la == 0.0 || lb == 0.0 {
        return None;
    }
    // b entirely on one side of a's plane (or the reverse): no crossing
    let side = |t: &[Point<3>; 3], n: &Vector<3>, l: Real, o: &Point<3>, scale: Real| {
        let d: Vec<Real> = t.iter().map(|x| n.dot(&(x - o)) / l).collect();
        let tol = eps * scale;
        d.iter().all(|&v| v > tol) || d.iter().all(|&v| v < -tol)
    };
    let size = |t: &[Point<3>; 3]| (t[1] - t[0]).norm().max((t[2] - t[0]).norm()).max((t[2] - t[1]).norm());
    let scale = size(a).max(size(b));
    if side(b, &na, la, &a[0], scale) || side(a, &nb, lb, &b[0], scale) {
        return None;
    }
    for (s, t) in [(a, b), (b, a)] {
        for k in 0..3 {
            if let Some(x) = segment_triangle(&s[k], &s[(k + 1) % 3], t, eps) {
                if away(&x) {
                    return Some(x);
                }
            }
        }
    }
    None
}

impl TriangleSurface {
    /// Checks that no two triangles cross, except neighbours along their common edge or
    /// vertex (see the [module documentation](crate::intersect)): a grid broad phase and
    /// segment–triangle tests, `O(n)` for a surface of evenly sized triangles.
    ///
    /// # Errors
    /// [`SurfaceError::SelfIntersection`] naming the two triangles (lowest first triangle
    /// index) and a point where they cross.
    pub fn check_self_intersection(&self) -> Result<(), SurfaceError> {
        match self.self_intersections().first() {
            None => Ok(()),
            Some(&(triangles, at)) => Err(SurfaceError::SelfIntersection { triangles, at }),
        }
    }

    /// Every pair of crossing triangles (as [`TriangleSurface::check_self_intersection`]
    /// finds them), sorted, with a point where they cross; empty when the surface does not
    /// cross itself.
    pub fn self_intersections(&self) -> Vec<([usize; 2], [Real; 3])> {
        let Some((lo, hi)) = self.bounding_box() else { return Vec::new() };
        let diag = (hi - lo).norm();
        let n = self.len();
        if n < 2 || diag == 0.0 {
            return Vec::new();
        }
        let corners: Vec<[Point<3>; 3]> = (0..n).map(|t| self.corners(t)).collect();
        let boxes: Vec<([Real; 3], [Real; 3])> =
            corners.iter().map(|c| (corner_min(c), corner_max(c))).collect();
        // cell: twice the mean box extent, at least diag / 2^10 per axis budget
        let mean: Real =
            boxes.iter().map(|(a, b)| (0..3).map(|k| b[k] - a[k]).fold(0.0, Real::max)).sum::<Real>()
                / n as Real;
        let max_cells_axis = 1024.0;
        let h = (2.0 * mean).max(diag / max_cells_axis).max(Real::MIN_POSITIVE);
        let dims: [usize; 3] = std::array::from_fn(|k| (((hi[k] - lo[k]) / h).floor() as usize + 1).max(1));
        let cell_of = |x: Real, k: usize| (((x - lo[k]) / h).floor().max(0.0) as usize).min(dims[k] - 1);
        let key = |c: [usize; 3]| (c[0] * dims[1] + c[1]) * dims[2] + c[2];
        let mut cells: std::collections::HashMap<usize, Vec<usize>> = std::collections::HashMap::new();
        for (t, (a, b)) in boxes.iter().enumerate() {
            let (c0, c1): ([usize; 3], [usize; 3]) =
                (std::array::from_fn(|k| cell_of(a[k], k)), std::array::from_fn(|k| cell_of(b[k], k)));
            for i in c0[0]..=c1[0] {
                for j in c0[1]..=c1[1] {
                    for k in c0[2]..=c1[2] {
                        cells.entry(key([i, j, k])).or_default().push(t);
                    }
                }
            }
        }
        let eps = TOLERANCE;
        let touch = eps * diag;
        let mut found: Vec<([usize; 2], [Real; 3])> = Vec::new();
        let mut keys: Vec<usize> = cells.keys().copied().collect();
        keys.sort_unstable();
        for cell in keys {
            let list = &cells[&cell];
            for (x, &s) in list.iter().enumerate() {
                for &t in &list[x + 1..] {
                    let (sa, sb) = boxes[s];
                    let (ta, tb) = boxes[t];
                    if (0..3).any(|k| sa[k] > tb[k] + touch || ta[k] > sb[k] + touch) {
                        continue;
                    }
                    // test the pair once: in the cell of the overlap's lower corner
                    let low: [usize; 3] = std::array::from_fn(|k| cell_of(sa[k].max(ta[k]), k));
                    if key(low) != cell {
                        continue;
                    }
                    let (ts, tt) = (self.triangles()[s], self.triangles()[t]);
                    let shared: Vec<usize> = ts.iter().copied().filter(|v| tt.contains(v)).collect();
                    let hit = match shared.len() {
                        0 => triangles_cross(&corners[s], &corners[t], eps, None),
                        1 => {
                            let v = &self.vertices()[shared[0]];
                            // a crossing counts when it is clearly away from the shared vertex
                            let size = corners[s]
                                .iter()
                                .chain(&corners[t])
                                .map(|x| (x - v).norm())
                                .fold(0.0, Real::max);
                            triangles_cross(&corners[s], &corners[t], eps, Some((v, 1e-6 * size)))
                        }
                        _ => None,
                    };
                    if let Some(p) = hit {
                        found.push(([s.min(t), s.max(t)], [p.x, p.y, p.z]));
                    }
                }
            }
        }
        found.sort_unstable_by_key(|(pair, _)| *pair);
        found
    }

    /// Checks everything a solid's boundary needs: closed, a manifold, consistently oriented
    /// with outward normals ([`TriangleSurface::check_closed`]) and not crossing itself
    /// ([`TriangleSurface::check_self_intersection`]).
    ///
    /// # Errors
    /// The errors of both checks.
    pub fn check_closed_solid(&self) -> Result<(), SurfaceError> {
        self.check_closed()?;
        self.check_self_intersection()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn merged(a: &TriangleSurface, b: &TriangleSurface) -> TriangleSurface {
        let mut v = a.vertices().to_vec();
        let off = v.len();
        v.extend_from_slice(b.vertices());
        let mut t = a.triangles().to_vec();
        t.extend(b.triangles().iter().map(|x| x.map(|i| i + off)));
        TriangleSurface::new(v, t).expect("soup")
    }

    #[test]
    fn spheres_pass_and_overlapping_spheres_fail() {
        let s = TriangleSurface::icosphere(Point::<3>::zeros(), 1.0, 3).expect("icosphere");
        s.check_self_intersection().expect("a sphere does not cross itself");
        s.check_closed_solid().expect("a solid");
        // two disjoint spheres in one surface: closed, no crossing
        let far = TriangleSurface::icosphere(Point::<3>::new(3.0, 0.0, 0.0), 1.0, 2).expect("far");
        merged(&s, &far).check_closed_solid().expect("two separate solids");
        // overlapping spheres: closed and a manifold, but crossing
        let near = TriangleSurface::icosphere(Point::<3>::new(1.2, 0.3, 0.1), 1.0, 2).expect("near");
        let both = merged(&s, &near);
        both.check_closed().expect("closed and manifold");
        let e = both.check_self_intersection().expect_err("crossing");
        let SurfaceError::SelfIntersection { triangles: [a, b], at } = e.clone() else { panic!("{e}") };
        assert!(a < s.len() && b >= s.len(), "one triangle of each sphere: {a} {b}");
        // the point lies on both spheres (up to the facets' chord error)
        let p = Point::<3>::new(at[0], at[1], at[2]);
        assert!((p.norm() - 1.0).abs() < 0.05, "{p}");
        assert!(((p - Point::<3>::new(1.2, 0.3, 0.1)).norm() - 1.0).abs() < 0.05, "{p}");
        assert!(matches!(both.check_closed_solid(), Err(SurfaceError::SelfIntersection { .. })));
        assert!(e.to_string().contains("intersects itself"), "{e}");
    }

    #[test]
    fn folded_surfaces_fail() {
        // a strip of two squares folded back through the first: the second square's triangles
        // pierce the first one's
        let v = vec![
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 0.0, 0.0),
            Point::<3>::new(1.0, 1.0, 0.0),
            Point::<3>::new(0.0, 1.0, 0.0),
            // folded back over (and through) the first square
            Point::<3>::new(0.2, 0.0, 0.3),
            Point::<3>::new(0.2, 1.0, -0.3),
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]];
        let s = TriangleSurface::new(v, t).expect("strip");
        s.check_manifold().expect("a manifold");
        let e = s.check_self_intersection().expect_err("folded");
        assert!(matches!(e, SurfaceError::SelfIntersection { .. }), "{e}");
        // the same strip unfolded (flat) passes, and bent by 90° passes
        let flat = vec![
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 0.0, 0.0),
            Point::<3>::new(1.0, 1.0, 0.0),
            Point::<3>::new(0.0, 1.0, 0.0),
            Point::<3>::new(2.0, 0.0, 0.0),
            Point::<3>::new(2.0, 1.0, 0.0),
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]];
        TriangleSurface::new(flat.clone(), t.clone()).expect("flat").check_self_intersection().expect("flat");
        let mut bent = flat.clone();
        bent[4] = Point::<3>::new(1.0, 0.0, 1.0);
        bent[5] = Point::<3>::new(1.0, 1.0, 1.0);
        TriangleSurface::new(bent, t.clone()).expect("bent").check_self_intersection().expect("bent");
        // folded flat onto itself around the shared vertex 1 only (coplanar overlap)
        let mut over = flat;
        over[4] = Point::<3>::new(0.5, 0.1, 0.0);
        over[5] = Point::<3>::new(0.6, 0.9, 0.0);
        let tri = vec![[0, 1, 2], [0, 2, 3], [1, 4, 5]];
        let e =
            TriangleSurface::new(over, tri).expect("over").check_self_intersection().expect_err("overlap");
        assert!(matches!(e, SurfaceError::SelfIntersection { .. }), "{e}");
    }

    #[test]
    fn a_triangle_piercing_another_is_found() {
        let v = vec![
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 0.0, 0.0),
            Point::<3>::new(0.0, 1.0, 0.0),
            Point::<3>::new(0.2, 0.2, -1.0),
            Point::<3>::new(0.3, 0.2, 1.0),
            Point::<3>::new(0.2, 0.3, 1.0),
        ];
        let s = TriangleSurface::new(v.clone(), vec![[0, 1, 2], [3, 4, 5]]).expect("pair");
        let Err(SurfaceError::SelfIntersection { triangles, at }) = s.check_self_intersection() else {
            panic!("not found")
        };
        assert_eq!(triangles, [0, 1]);
        assert!(at[2].abs() < 1e-12, "{at:?}");
        // lifted above: no crossing
        let lifted: Vec<Point<3>> = v
            .iter()
            .enumerate()
            .map(|(i, p)| if i >= 3 { p + Vector::<3>::new(0.0, 0.0, 2.5) } else { *p })
            .collect();
        TriangleSurface::new(lifted, vec![[0, 1, 2], [3, 4, 5]])
            .expect("pair")
            .check_self_intersection()
            .expect("apart");
    }
}
