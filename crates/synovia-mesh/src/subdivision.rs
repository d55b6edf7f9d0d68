//! Loop subdivision of triangle surfaces with sharp creases: a smooth rigid contact partner
//! from a faceted STL (docs/meshing.md, "Smoothing a faceted partner").
//!
//! A decimated implant surface is flat between its vertices: its edges are creases of a few
//! degrees, each a line of concentrated pressure when an elastic body is pressed against it,
//! and below the facet size a finer elastic mesh resolves those creases instead of the
//! implant's shape. One level of Loop's scheme (C. Loop, "Smooth subdivision surfaces based on
//! triangles", MSc thesis, University of Utah, 1987) splits each triangle into four and
//! moves the points to weighted averages of their neighbours; the levels converge to a surface
//! with continuous tangent planes (C² away from extraordinary vertices). The rules, with `n`
//! the number of edges at a vertex `v` with neighbours `v_i`:
//!
//! * a smooth edge `ab` between the triangles `abc` and `bad`: new point
//!   `e = 3/8 (a + b) + 1/8 (c + d)`;
//! * a smooth vertex: `v' = (1 − n β) v + β Σ v_i`,
//!   `β = (5/8 − (3/8 + cos(2π/n)/4)²) / n`;
//! * a crease edge (dihedral angle above the crease angle, or a boundary edge): `e = (a + b)/2`;
//! * a vertex on exactly two crease edges to `a` and `b`: `v' = 3/4 v + 1/8 (a + b)` (the
//!   cubic B-spline rule along the crease), unless the crease turns there by more than the
//!   crease angle; on one, or more than two, crease edges, or at such a turn (a corner):
//!   `v' = v`.
//!
//! Crease edges keep their polyline under subdivision (the sharp rims and box cuts of an
//! implant stay sharp); the smooth parts move by `O(h² κ)` (facet size `h`, curvature `κ`).
//! Hand-written: no maintained Rust crate offers Loop subdivision with crease rules on an
//! indexed triangle mesh (the OpenSubdiv ports are young), and the scheme is short.

use std::collections::HashMap;

use crate::math::{Point, Real, Vector};
use crate::surface::{SurfaceError, TriangleSurface};

impl TriangleSurface {
    /// `levels` levels of Loop subdivision with sharp creases (see the [module
    /// documentation](crate::subdivision)): every triangle becomes `4^levels` triangles; an
    /// edge whose two triangles' normals differ by more than `crease_angle` (radians), and
    /// every boundary edge, stays a crease. The orientation is kept.
    ///
    /// # Errors
    /// [`SurfaceError::InvalidParameter`] for `levels > 4` (256 × the triangles) or a crease
    /// angle outside `[0, π]`; [`SurfaceError::NonManifoldEdge`] and
    /// [`SurfaceError::InconsistentOrientation`] ([`TriangleSurface::check_manifold`]);
    /// the errors of [`TriangleSurface::new`] if a level makes a triangle degenerate.
    pub fn loop_subdivided(&self, levels: usize, crease_angle: Real) -> Result<Self, SurfaceError> {
        if !(0.0..=std::f64::consts::PI).contains(&crease_angle) {
            return Err(SurfaceError::InvalidParameter(format!(
                "crease angle {crease_angle} rad must lie in [0, π]"
            )));
        }
        self.subdivided(levels, Some(crease_angle.cos()))
    }

    /// `levels` levels of midpoint subdivision: the same triangles and vertex numbering as
    /// [`TriangleSurface::loop_subdivided`] (vertex `i` of both is the same point of the
    /// scheme), with the points left where they are (each triangle split at its edge
    /// midpoints): the same geometry, finer. Vertex by vertex, the distance between the two
    /// surfaces' points bounds how far subdivision moved the surface (used by
    /// `SurfaceObstacle::smoothed_solid`).
    ///
    /// # Errors
    /// As [`TriangleSurface::loop_subdivided`].
    pub fn midpoint_subdivided(&self, levels: usize) -> Result<Self, SurfaceError> {
        self.subdivided(levels, None)
    }

    /// `levels` (at most 4) levels of [`TriangleSurface::loop_level`] on a checked manifold.
    fn subdivided(&self, levels: usize, crease_cos: Option<Real>) -> Result<Self, SurfaceError> {
        if levels > 4 {
            return Err(SurfaceError::InvalidParameter(format!(
                "{levels} levels of subdivision asked; at most 4 (256 times the triangles)"
            )));
        }
        self.check_manifold()?;
        let mut surface = self.clone();
        for _ in 0..levels {
            surface = surface.loop_level(crease_cos)?;
        }
        Ok(surface)
    }

    /// One level of [`TriangleSurface::loop_subdivided`] on a checked manifold; an edge is a
    /// crease when the cosine between its triangles' normals is below `crease_cos`; `None`:
    /// midpoint subdivision (every edge split at its midpoint, no point moves).
    fn loop_level(&self, crease_cos: Option<Real>) -> Result<Self, SurfaceError> {
        let (crease_cos, linear) = match crease_cos {
            Some(c) => (c, false),
            None => (Real::INFINITY, true),
        };
        let v = self.vertices();
        let tris = self.triangles();
        let normals: Vec<Vector<3>> = (0..tris.len()).map(|t| self.normal(t)).collect();
        // each undirected edge: its index, and the vertex opposite it in each triangle
        struct Edge {
            index: usize,
            opposite: [usize; 2],
            triangles: [usize; 2],
            count: usize,
        }
        let mut edges: HashMap<(usize, usize), Edge> = HashMap::with_capacity(3 * tris.len() / 2 + 1);
        let mut tri_edges = Vec::with_capacity(tris.len());
        for (t, tri) in tris.iter().enumerate() {
            let mut ids = [0usize; 3];
            for k in 0..3 {
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let next = edges.len();
                let e = edges.entry((a.min(b), a.max(b))).or_insert(Edge {
                    index: next,
                    opposite: [c, c],
                    triangles: [t, t],
                    count: 0,
                });
                if e.count == 1 {
                    e.opposite[1] = c;
                    e.triangles[1] = t;
                }
                e.count += 1;
                ids[k] = e.index;
            }
            tri_edges.push(ids);
        }
        let n_v = v.len();
        let mut edge_points = vec![Point::<3>::zeros(); edges.len()];
        let mut neighbour_sum = vec![Vector::<3>::zeros(); n_v];
        let mut valence = vec![0usize; n_v];
        let mut crease_neighbours = vec![[0usize; 2]; n_v];
        let mut creases = vec![0usize; n_v];
        // in the order the edges were numbered (a map's order would change the sums' rounding
        // from run to run)
        let mut ordered: Vec<(&(usize, usize), &Edge)> = edges.iter().collect();
        ordered.sort_unstable_by_key(|(_, e)| e.index);
        for (&(a, b), e) in ordered {
            let crease = e.count == 1 || normals[e.triangles[0]].dot(&normals[e.triangles[1]]) < crease_cos;
            edge_points[e.index] = if crease {
                (v[a] + v[b]) / 2.0
            } else {
                (v[a] + v[b]) * 0.375 + (v[e.opposite[0]] + v[e.opposite[1]]) * 0.125
            };
            for (p, q) in [(a, b), (b, a)] {
                neighbour_sum[p] += v[q];
                valence[p] += 1;
                if crease {
                    if creases[p] < 2 {
                        crease_neighbours[p][creases[p]] = q;
                    }
                    creases[p] += 1;
                }
            }
        }
        let mut vertices: Vec<Point<3>> = (0..n_v)
            .map(|p| match (creases[p], valence[p]) {
                _ if linear => v[p],
                (_, 0) => v[p],
                (0, n) => {
                    let n = n as Real;
                    let c = 0.375 + (2.0 * std::f64::consts::PI / n).cos() / 4.0;
                    let beta = (0.625 - c * c) / n;
                    v[p] * (1.0 - n * beta) + neighbour_sum[p] * beta
                }
                (2, _) => {
                    // a crease polyline a–v–b: smooth unless it turns by more than the angle
                    let [a, b] = crease_neighbours[p];
                    let turn = (v[p] - v[a]).angle(&(v[b] - v[p]));
                    if turn.cos() < crease_cos {
                        v[p]
                    } else {
                        v[p] * 0.75 + (v[a] + v[b]) * 0.125
                    }
                }
                _ => v[p],
            })
            .collect();
        vertices.extend(edge_points);
        let mut triangles = Vec::with_capacity(4 * tris.len());
        for (tri, ids) in tris.iter().zip(&tri_edges) {
            let [e01, e12, e20] = ids.map(|i| n_v + i);
            triangles.push([tri[0], e01, e20]);
            triangles.push([tri[1], e12, e01]);
            triangles.push([tri[2], e20, e12]);
            triangles.push([e01, e12, e20]);
        }
        TriangleSurface::new(vertices, triangles)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest distance of a vertex from the sphere `|x| = r`.
    fn sphere_error(s: &TriangleSurface, r: Real) -> Real {
        s.vertices().iter().map(|p| (p.norm() - r).abs()).fold(0.0, Real::max)
    }

    /// The largest angle between the normals of two triangles sharing an edge.
    fn max_turn(s: &TriangleSurface) -> Real {
        let mut worst: Real = 0.0;
        let mut by_edge: HashMap<(usize, usize), usize> = HashMap::new();
        for (t, tri) in s.triangles().iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if let Some(&u) = by_edge.get(&(a.min(b), a.max(b))) {
                    worst = worst.max(s.normal(u).angle(&s.normal(t)));
                } else {
                    by_edge.insert((a.min(b), a.max(b)), t);
                }
            }
        }
        worst
    }

    #[test]
    fn subdivided_icosphere_stays_on_the_sphere_and_turns_smoothly() {
        // an icosphere (vertices on the unit sphere, edges h ≈ 0.3): Loop's surface is smooth
        // (the largest normal turn across an edge halves per level, as the edges do) and
        // stays within O(h²) of the sphere it samples; the solid stays closed and outward
        let sphere = TriangleSurface::icosphere(Point::<3>::zeros(), 1.0, 2).expect("icosphere");
        let mut turn = max_turn(&sphere);
        for levels in 1..=3 {
            let s = sphere.loop_subdivided(levels, 0.5).expect("subdivided");
            assert_eq!(s.len(), sphere.len() * 4usize.pow(levels as u32));
            s.check_closed().expect("closed, outward");
            let t = max_turn(&s);
            assert!(t < 0.6 * turn, "level {levels}: turn {t} vs {turn}");
            turn = t;
        }
        // the distance to the sphere is second order in the control mesh's edge length:
        // halving the icosphere's edges divides it by ≈ 4
        let error_at = |k: usize| {
            let control = TriangleSurface::icosphere(Point::<3>::zeros(), 1.0, k).expect("icosphere");
            sphere_error(&control.loop_subdivided(3, 0.5).expect("subdivided"), 1.0)
        };
        let (e2, e3, e4) = (error_at(2), error_at(3), error_at(4));
        eprintln!("distance to the sphere: {e2:.3e} {e3:.3e} {e4:.3e}");
        assert!(e2 < 0.03 && e3 / e2 < 0.3 && e4 / e3 < 0.3, "{e2} {e3} {e4}");
        // the same surface every time, to the last bit (a run repeated gives the same figures)
        let first = sphere.loop_subdivided(2, 0.5).expect("subdivided");
        for _ in 0..4 {
            assert_eq!(sphere.loop_subdivided(2, 0.5).expect("subdivided"), first);
        }
    }

    #[test]
    fn midpoint_subdivision_keeps_the_geometry_and_numbers_points_as_loop() {
        let sphere = TriangleSurface::icosphere(Point::<3>::zeros(), 1.0, 1).expect("icosphere");
        let linear = sphere.midpoint_subdivided(2).expect("midpoints");
        let smooth = sphere.loop_subdivided(2, 0.5).expect("loop");
        assert_eq!(linear.triangles(), smooth.triangles());
        assert!((linear.area() - sphere.area()).abs() < 1e-12 * sphere.area());
        assert!((linear.signed_volume() - sphere.signed_volume()).abs() < 1e-12);
        // Loop moves each point by less than the control mesh's edge length
        let moved = linear.vertices().iter().zip(smooth.vertices()).map(|(a, b)| (a - b).norm());
        assert!(moved.fold(0.0, Real::max) < 0.1);
    }

    #[test]
    fn creases_keep_a_cube_sharp_and_smooth_faces_flat() {
        // a cube (12 triangles): every cube edge is a 90° crease and every vertex a corner,
        // so subdivision keeps the cube exactly (edges on the cube's edges, faces flat); the
        // face diagonals are smooth edges of flat faces and stay in the face planes
        let corners: Vec<Point<3>> = (0..8)
            .map(|i| Point::<3>::new((i & 1) as Real, ((i >> 1) & 1) as Real, ((i >> 2) & 1) as Real))
            .collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let triangles: Vec<[usize; 3]> =
            quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        let cube = TriangleSurface::new(corners, triangles).expect("cube");
        cube.check_closed().expect("cube closed");
        let s = cube.loop_subdivided(3, 0.5).expect("subdivided");
        s.check_closed().expect("subdivided cube closed");
        for p in s.vertices() {
            // every point on the cube's surface: one coordinate 0 or 1, all in [0, 1]
            assert!(p.iter().all(|x| (-1e-12..=1.0 + 1e-12).contains(x)), "{p:?}");
            assert!(p.iter().any(|x| x.abs() < 1e-12 || (x - 1.0).abs() < 1e-12), "{p:?}");
        }
        assert!((s.signed_volume() - 1.0).abs() < 1e-12, "volume {}", s.signed_volume());
        // with no creases (angle π) the cube rounds off and shrinks
        let round = cube.loop_subdivided(3, std::f64::consts::PI).expect("rounded");
        assert!(round.signed_volume() < 0.8, "{}", round.signed_volume());
    }

    #[test]
    fn open_patch_keeps_its_boundary_polyline_and_bad_parameters_are_refused() {
        // an open square of two triangles: boundary edges are creases, the corners stay
        let s = TriangleSurface::new(
            vec![
                Point::<3>::new(0.0, 0.0, 0.0),
                Point::<3>::new(1.0, 0.0, 0.0),
                Point::<3>::new(1.0, 1.0, 0.0),
                Point::<3>::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .expect("square");
        let d = s.loop_subdivided(2, 0.5).expect("subdivided");
        assert_eq!(d.len(), 32);
        assert_eq!(d.boundary_edges().len(), 16);
        assert!(d.vertices().iter().all(|p| p.z == 0.0));
        assert!((d.area() - 1.0).abs() < 1e-12);
        assert!(matches!(s.loop_subdivided(5, 0.5), Err(SurfaceError::InvalidParameter(_))));
        assert!(matches!(s.loop_subdivided(1, -0.1), Err(SurfaceError::InvalidParameter(_))));
        assert!(matches!(s.loop_subdivided(1, Real::NAN), Err(SurfaceError::InvalidParameter(_))));
    }
}
