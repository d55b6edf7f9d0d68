//! Triangle surfaces in 3D: the data-defined shapes of implants and bones (STL files, read by
//! `synovia-io`), used as rigid contact partners (`synovia-contact`'s `SurfaceObstacle`) and as
//! input of volume meshing.
//!
//! A [`TriangleSurface`] is an indexed triangle soup with shared vertices. It is **closed**
//! when every edge belongs to exactly two triangles, and **consistently oriented** when those
//! two triangles traverse the edge in opposite directions; a closed, consistently oriented
//! surface with a positive [`TriangleSurface::signed_volume`] has outward normals (right-hand
//! rule on the vertex order). An **open** surface (an articular patch) has boundary edges; its
//! triangles' normals tell which side is free space.

use std::collections::HashMap;

use thiserror::Error;

use crate::math::{Point, Real, Vector};

/// Errors of triangle surfaces: the checks name the offending triangle, edge or vertex and
/// where it is.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SurfaceError {
    /// No triangles.
    #[error("the surface has no triangles")]
    Empty,
    /// A vertex coordinate is NaN or infinite.
    #[error("surface vertex {vertex} has a non-finite coordinate (NaN or ±∞)")]
    NonFiniteVertex {
        /// Vertex index.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {vertex}, but the surface has {n_vertices} vertices")]
    VertexOutOfRange {
        /// Triangle index.
        triangle: usize,
        /// The bad vertex index.
        vertex: usize,
        /// Number of vertices.
        n_vertices: usize,
    },
    /// A triangle with (numerically) zero area.
    #[error("triangle {triangle} is degenerate (area {area:e}, vertices {vertices:?}) near ({}, {}, {})", at[0], at[1], at[2])]
    DegenerateTriangle {
        /// Triangle index.
        triangle: usize,
        /// Its area.
        area: Real,
        /// Its vertices.
        vertices: [usize; 3],
        /// Its centroid.
        at: [Real; 3],
    },
    /// A closed surface was needed, the surface has boundary edges.
    #[error(
        "the surface is open: {boundary_edges} edges belong to one triangle only, e.g. the edge between \
         vertices {} and {} at ({:.6e}, {:.6e}, {:.6e}); a closed surface is needed here (close the holes \
         in the mesh editor, or use the surface as an open contact patch)",
        edge[0], edge[1], at[0], at[1], at[2]
    )]
    Open {
        /// Number of boundary edges.
        boundary_edges: usize,
        /// One boundary edge.
        edge: [usize; 2],
        /// Its midpoint.
        at: [Real; 3],
    },
    /// An edge shared by more than two triangles.
    #[error(
        "the surface is not a manifold: the edge between vertices {} and {} at ({:.6e}, {:.6e}, {:.6e}) belongs \
         to {triangles} triangles",
        edge[0], edge[1], at[0], at[1], at[2]
    )]
    NonManifoldEdge {
        /// The edge.
        edge: [usize; 2],
        /// Number of triangles on it.
        triangles: usize,
        /// Its midpoint.
        at: [Real; 3],
    },
    /// Two neighbouring triangles traverse their common edge in the same direction.
    #[error(
        "the surface is not consistently oriented: triangles {} and {} traverse their common edge \
         {}–{} in the same direction (at ({:.6e}, {:.6e}, {:.6e})); re-orient the normals in the mesh editor",
        triangles[0], triangles[1], edge[0], edge[1], at[0], at[1], at[2]
    )]
    InconsistentOrientation {
        /// The two triangles.
        triangles: [usize; 2],
        /// Their common edge.
        edge: [usize; 2],
        /// Its midpoint.
        at: [Real; 3],
    },
    /// Two triangles that are not neighbours intersect.
    #[error(
        "the surface intersects itself: triangles {} and {} cross near ({:.6e}, {:.6e}, {:.6e})",
        triangles[0], triangles[1], at[0], at[1], at[2]
    )]
    SelfIntersection {
        /// The two triangles.
        triangles: [usize; 2],
        /// A point where they cross.
        at: [Real; 3],
    },
    /// A parameter (tolerance, subdivision, radius) is invalid.
    #[error("invalid surface parameter: {0}")]
    InvalidParameter(String),
}

/// A triangle surface in 3D with shared vertices (see the [module documentation](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleSurface {
    vertices: Vec<Point<3>>,
    triangles: Vec<[usize; 3]>,
}

/// Relative area below which a triangle counts as degenerate (of the squared bounding-box
/// diagonal).
const DEGENERATE_AREA: Real = 1e-14;

impl TriangleSurface {
    /// A surface from vertices and triangles (vertex indices in the order that gives the
    /// normal by the right-hand rule). Checks finiteness, indices and non-degenerate
    /// triangles; unused vertices are allowed.
    ///
    /// # Errors
    /// [`SurfaceError::Empty`], [`SurfaceError::NonFiniteVertex`],
    /// [`SurfaceError::VertexOutOfRange`], [`SurfaceError::DegenerateTriangle`].
    pub fn new(vertices: Vec<Point<3>>, triangles: Vec<[usize; 3]>) -> Result<Self, SurfaceError> {
        if triangles.is_empty() {
            return Err(SurfaceError::Empty);
        }
        if let Some(vertex) = vertices.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(SurfaceError::NonFiniteVertex { vertex });
        }
        let n = vertices.len();
        for (triangle, t) in triangles.iter().enumerate() {
            if let Some(&vertex) = t.iter().find(|&&v| v >= n) {
                return Err(SurfaceError::VertexOutOfRange { triangle, vertex, n_vertices: n });
            }
        }
        let surface = Self { vertices, triangles };
        let diag = surface.bounding_box().map_or(0.0, |(lo, hi)| (hi - lo).norm());
        let tiny = DEGENERATE_AREA * diag * diag;
        for (triangle, t) in surface.triangles.iter().enumerate() {
            let area = surface.area_vector(triangle).norm();
            if area.is_nan() || area <= tiny || t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                let c = surface.centroid(triangle);
                return Err(SurfaceError::DegenerateTriangle {
                    triangle,
                    area,
                    vertices: *t,
                    at: [c.x, c.y, c.z],
                });
            }
        }
        Ok(surface)
    }

    /// A surface from a triangle soup (three corner points per triangle, as STL stores it):
    /// corners closer than `tolerance` (absolute) are merged into one vertex.
    ///
    /// # Errors
    /// As [`TriangleSurface::new`]; [`SurfaceError::InvalidParameter`] for a negative or
    /// non-finite tolerance.
    pub fn from_soup(corners: &[[Point<3>; 3]], tolerance: Real) -> Result<Self, SurfaceError> {
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(SurfaceError::InvalidParameter(format!(
                "merge tolerance {tolerance} must be finite and ≥ 0"
            )));
        }
        if let Some(vertex) = corners.iter().flatten().position(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(SurfaceError::NonFiniteVertex { vertex });
        }
        // grid hashing with cells of the tolerance: a corner is compared with the vertices of
        // its cell and the 26 neighbours
        let cell = if tolerance > 0.0 { tolerance } else { 1.0 };
        let key = |p: &Point<3>| -> [i64; 3] {
            if tolerance > 0.0 {
                [(p.x / cell).floor() as i64, (p.y / cell).floor() as i64, (p.z / cell).floor() as i64]
            } else {
                [p.x.to_bits() as i64, p.y.to_bits() as i64, p.z.to_bits() as i64]
            }
        };
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        let mut vertices: Vec<Point<3>> = Vec::new();
        let mut triangles = Vec::with_capacity(corners.len());
        for tri in corners {
            let mut t = [0usize; 3];
            for (slot, p) in t.iter_mut().zip(tri) {
                let k = key(p);
                let mut found = None;
                if tolerance > 0.0 {
                    'search: for dx in -1..=1 {
                        for dy in -1..=1 {
                            for dz in -1..=1 {
                                if let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                                    if let Some(&v) =
                                        list.iter().find(|&&v| (vertices[v] - p).norm() <= tolerance)
                                    {
                                        found = Some(v);
                                        break 'search;
                                    }
                                }
                            }
                        }
                    }
                } else if let Some(list) = grid.get(&k) {
                    found = list.first().copied();
                }
                *slot = found.unwrap_or_else(|| {
                    vertices.push(*p);
                    grid.entry(k).or_default().push(vertices.len() - 1);
                    vertices.len() - 1
                });
            }
            triangles.push(t);
        }
        Self::new(vertices, triangles)
    }

    /// The vertices.
    pub fn vertices(&self) -> &[Point<3>] {
        &self.vertices
    }
    /// The triangles (vertex indices, right-hand rule gives the normal).
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }
    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }
    /// `true` if there are no triangles (never, for a surface built by the constructors).
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }
    /// The corner points of triangle `t`.
    pub fn corners(&self, t: usize) -> [Point<3>; 3] {
        let [a, b, c] = self.triangles[t];
        [self.vertices[a], self.vertices[b], self.vertices[c]]
    }
    /// `½ (b − a) × (c − a)`: the area times the unit normal of triangle `t`.
    pub fn area_vector(&self, t: usize) -> Vector<3> {
        let [a, b, c] = self.corners(t);
        0.5 * (b - a).cross(&(c - a))
    }
    /// The unit normal of triangle `t` (right-hand rule).
    pub fn normal(&self, t: usize) -> Vector<3> {
        self.area_vector(t).normalize()
    }
    /// The centroid of triangle `t`.
    pub fn centroid(&self, t: usize) -> Point<3> {
        let [a, b, c] = self.corners(t);
        (a + b + c) / 3.0
    }
    /// Total area `Σ |½ (b − a) × (c − a)|`.
    pub fn area(&self) -> Real {
        (0..self.len()).map(|t| self.area_vector(t).norm()).sum()
    }
    /// The signed enclosed volume `⅙ Σ a · (b × c)` (divergence theorem): positive for a
    /// closed surface with outward normals, negative with inward ones; meaningless for an
    /// open one.
    pub fn signed_volume(&self) -> Real {
        self.triangles
            .iter()
            .map(|&[a, b, c]| self.vertices[a].dot(&self.vertices[b].cross(&self.vertices[c])) / 6.0)
            .sum()
    }
    /// Axis-aligned bounding box `(min, max)` of the vertices used by triangles.
    pub fn bounding_box(&self) -> Option<(Point<3>, Point<3>)> {
        let mut it = self.triangles.iter().flatten().map(|&v| self.vertices[v]);
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.inf(&p), hi.sup(&p))))
    }
    /// The surface mapped by `x ↦ R x + t` (`R` a rotation: orientation is kept).
    pub fn transformed(&self, rotation: &nalgebra::Rotation3<Real>, translation: &Vector<3>) -> Self {
        Self {
            vertices: self.vertices.iter().map(|p| rotation * p + translation).collect(),
            triangles: self.triangles.clone(),
        }
    }
    /// The surface scaled by `factor` about the origin (unit conversion, e.g. 1e-3 from mm to
    /// m).
    ///
    /// # Errors
    /// [`SurfaceError::InvalidParameter`] unless `factor` is finite and > 0.
    pub fn scaled(&self, factor: Real) -> Result<Self, SurfaceError> {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(SurfaceError::InvalidParameter(format!(
                "scale factor {factor} must be finite and > 0"
            )));
        }
        Ok(Self {
            vertices: self.vertices.iter().map(|p| p * factor).collect(),
            triangles: self.triangles.clone(),
        })
    }
    /// The same surface with every triangle's orientation reversed (normals flipped).
    pub fn flipped(&self) -> Self {
        Self {
            vertices: self.vertices.clone(),
            triangles: self.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
        }
    }

    /// Each undirected edge `(min, max)` with the triangles on it and whether each traverses it
    /// from `min` to `max`.
    fn edge_map(&self) -> HashMap<(usize, usize), Vec<(usize, bool)>> {
        let mut edges: HashMap<(usize, usize), Vec<(usize, bool)>> =
            HashMap::with_capacity(3 * self.len() / 2 + 1);
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                edges.entry((a.min(b), a.max(b))).or_default().push((t, a < b));
            }
        }
        edges
    }
    fn midpoint(&self, a: usize, b: usize) -> [Real; 3] {
        let m = (self.vertices[a] + self.vertices[b]) / 2.0;
        [m.x, m.y, m.z]
    }
    /// The boundary edges (on one triangle only), in the direction their triangle traverses
    /// them, sorted.
    pub fn boundary_edges(&self) -> Vec<[usize; 2]> {
        let mut out: Vec<[usize; 2]> = self
            .edge_map()
            .into_iter()
            .filter(|(_, on)| on.len() == 1)
            .map(|((a, b), on)| if on[0].1 { [a, b] } else { [b, a] })
            .collect();
        out.sort_unstable();
        out
    }
    /// Checks that the surface is a manifold (no edge on more than two triangles) and
    /// consistently oriented; open surfaces pass.
    ///
    /// # Errors
    /// [`SurfaceError::NonManifoldEdge`], [`SurfaceError::InconsistentOrientation`].
    pub fn check_manifold(&self) -> Result<(), SurfaceError> {
        let mut edges: Vec<_> = self.edge_map().into_iter().collect();
        edges.sort_unstable_by_key(|(e, _)| *e);
        for ((a, b), on) in edges {
            if on.len() > 2 {
                return Err(SurfaceError::NonManifoldEdge {
                    edge: [a, b],
                    triangles: on.len(),
                    at: self.midpoint(a, b),
                });
            }
            if on.len() == 2 && on[0].1 == on[1].1 {
                return Err(SurfaceError::InconsistentOrientation {
                    triangles: [on[0].0, on[1].0],
                    edge: [a, b],
                    at: self.midpoint(a, b),
                });
            }
        }
        Ok(())
    }
    /// Checks that the surface is closed, a manifold and consistently oriented with outward
    /// normals (positive [`TriangleSurface::signed_volume`]) — what a solid needs.
    ///
    /// # Errors
    /// [`SurfaceError::Open`], the errors of [`TriangleSurface::check_manifold`], and
    /// [`SurfaceError::InvalidParameter`] for inward normals.
    pub fn check_closed(&self) -> Result<(), SurfaceError> {
        self.check_manifold()?;
        let boundary = self.boundary_edges();
        if let Some(&[a, b]) = boundary.first() {
            return Err(SurfaceError::Open {
                boundary_edges: boundary.len(),
                edge: [a, b],
                at: self.midpoint(a, b),
            });
        }
        let v = self.signed_volume();
        if v.is_nan() || v <= 0.0 {
            return Err(SurfaceError::InvalidParameter(format!(
                "the closed surface has inward normals (signed volume {v:e}); flip its orientation"
            )));
        }
        Ok(())
    }

    /// The icosphere: an icosahedron whose faces are split `4^subdivisions` times, projected
    /// on the sphere of `radius` about `center`, outward normals; every vertex lies on the
    /// sphere. `subdivisions ≤ 7` (327 680 triangles).
    ///
    /// # Errors
    /// [`SurfaceError::InvalidParameter`] for a radius that is not finite and > 0, or more
    /// than 7 subdivisions.
    pub fn icosphere(center: Point<3>, radius: Real, subdivisions: usize) -> Result<Self, SurfaceError> {
        if !(radius.is_finite() && radius > 0.0) || center.iter().any(|x| !x.is_finite()) {
            return Err(SurfaceError::InvalidParameter(format!(
                "icosphere needs a finite centre and a radius > 0, got {radius}"
            )));
        }
        if subdivisions > 7 {
            return Err(SurfaceError::InvalidParameter(format!("{subdivisions} subdivisions: at most 7")));
        }
        let phi = (1.0 + 5.0_f64.sqrt()) / 2.0;
        let mut unit: Vec<Vector<3>> = [
            [-1.0, phi, 0.0],
            [1.0, phi, 0.0],
            [-1.0, -phi, 0.0],
            [1.0, -phi, 0.0],
            [0.0, -1.0, phi],
            [0.0, 1.0, phi],
            [0.0, -1.0, -phi],
            [0.0, 1.0, -phi],
            [phi, 0.0, -1.0],
            [phi, 0.0, 1.0],
            [-phi, 0.0, -1.0],
            [-phi, 0.0, 1.0],
        ]
        .iter()
        .map(|v| Vector::<3>::new(v[0], v[1], v[2]).normalize())
        .collect();
        let mut triangles: Vec<[usize; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..subdivisions {
            let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
            let mut midpoint = |a: usize, b: usize, unit: &mut Vec<Vector<3>>| {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    unit.push((unit[a] + unit[b]).normalize());
                    unit.len() - 1
                })
            };
            let mut next = Vec::with_capacity(4 * triangles.len());
            for &[a, b, c] in &triangles {
                let ab = midpoint(a, b, &mut unit);
                let bc = midpoint(b, c, &mut unit);
                let ca = midpoint(c, a, &mut unit);
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            triangles = next;
        }
        let vertices = unit.iter().map(|u| center + radius * u).collect();
        Self::new(vertices, triangles)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_is_closed_outward_and_converges_to_the_ball() {
        let r = 2.0;
        let mut last_err = Real::INFINITY;
        for k in 0..4 {
            let s = TriangleSurface::icosphere(Point::<3>::new(1.0, -1.0, 0.5), r, k).expect("icosphere");
            assert_eq!(s.len(), 20 * 4usize.pow(k as u32));
            s.check_closed().expect("closed");
            let exact = 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
            // translation-invariant: the signed volume of a closed surface
            let err = (s.signed_volume() - exact).abs() / exact;
            assert!(err < last_err / 3.0, "volume error {err} after {last_err}");
            last_err = err;
        }
        assert!(last_err < 0.02);
    }

    #[test]
    fn open_flipped_and_non_manifold_surfaces_are_named() {
        let s = TriangleSurface::icosphere(Point::<3>::zeros(), 1.0, 1).expect("icosphere");
        // drop one triangle: three boundary edges
        let mut tris = s.triangles().to_vec();
        tris.pop();
        let open = TriangleSurface::new(s.vertices().to_vec(), tris).expect("open");
        assert_eq!(open.boundary_edges().len(), 3);
        assert!(matches!(open.check_closed(), Err(SurfaceError::Open { boundary_edges: 3, .. })));
        open.check_manifold().expect("an open patch is still a manifold");
        // inward normals
        assert!(matches!(s.flipped().check_closed(), Err(SurfaceError::InvalidParameter(_))));
        // one triangle flipped: inconsistent
        let mut tris = s.triangles().to_vec();
        tris[3] = [tris[3][0], tris[3][2], tris[3][1]];
        let bad = TriangleSurface::new(s.vertices().to_vec(), tris).expect("soup");
        assert!(matches!(bad.check_closed(), Err(SurfaceError::InconsistentOrientation { .. })));
        // a triangle twice: three edges on three triangles
        let mut tris = s.triangles().to_vec();
        tris.push(tris[0]);
        let dup = TriangleSurface::new(s.vertices().to_vec(), tris).expect("soup");
        assert!(matches!(dup.check_closed(), Err(SurfaceError::NonManifoldEdge { triangles: 3, .. })));
        let msg = open.check_closed().expect_err("open").to_string();
        assert!(msg.contains("open") && msg.contains("3 edges"), "{msg}");
    }

    #[test]
    fn soup_merges_corners_and_rejects_bad_input() {
        let s = TriangleSurface::icosphere(Point::<3>::zeros(), 1.0, 2).expect("icosphere");
        let soup: Vec<[Point<3>; 3]> = (0..s.len()).map(|t| s.corners(t)).collect();
        let merged = TriangleSurface::from_soup(&soup, 1e-9).expect("merge");
        assert_eq!(merged.vertices().len(), s.vertices().len());
        merged.check_closed().expect("closed after merging");
        let exact = TriangleSurface::from_soup(&soup, 0.0).expect("exact merge");
        assert_eq!(exact.vertices().len(), s.vertices().len());
        assert!(matches!(TriangleSurface::from_soup(&soup, -1.0), Err(SurfaceError::InvalidParameter(_))));
        let mut nan = soup.clone();
        nan[2][1].x = Real::NAN;
        assert!(matches!(TriangleSurface::from_soup(&nan, 0.0), Err(SurfaceError::NonFiniteVertex { .. })));
        let flat = [[Point::<3>::zeros(), Point::<3>::new(1.0, 0.0, 0.0), Point::<3>::new(2.0, 0.0, 0.0)]];
        assert!(matches!(
            TriangleSurface::from_soup(&flat, 0.0),
            Err(SurfaceError::DegenerateTriangle { .. })
        ));
        assert!(matches!(TriangleSurface::from_soup(&[], 0.0), Err(SurfaceError::Empty)));
    }
}
