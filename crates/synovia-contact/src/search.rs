//! Contact search: the closest master facet of a point, with an R*-tree of facet bounding boxes.
//!
//! [`FacetSearch`] indexes the facets of a master contact surface (segments in 2D, triangles in
//! 3D) in an R*-tree ([`rstar`], bulk-loaded in `O(n log n)` for `n` facets). A query
//! ([`FacetSearch::project`]) visits only the facets whose bounding box meets the ball of the
//! search radius around the point (`O(log n + k)`, `k` the facets found), so pairing `m` slave
//! nodes costs `O((n + m) log n)`: near-linear in the number of contact facets.
//!
//! # The projection rule
//!
//! For a point `x` (a slave node) the candidates are the facets within the search distance
//! (default: within `r₀ + h_max` of `x`, `r₀` the distance to the nearest facet and `h_max` the
//! largest facet diameter) that face the slave surface (`n_l · n_k < 0` for the slave normal
//! `n_k`, when given). Among them:
//!
//! 1. a facet that contains the orthogonal projection of `x` (barycentric coordinates
//!    `≥ −10⁻⁶`) wins; among several (a concave master corner, or a point above a shared
//!    vertex) the one with the smallest `|signed distance|`;
//! 2. otherwise (a point in the wedge outside a convex master edge or vertex) the facet with
//!    the closest point — provided that point is not on the rim of the master part (a vertex in
//!    one facet only in 2D, a rim edge or rim vertex in 3D): a point whose closest master point
//!    is on the rim lies beyond the master surface and has no partner ([`None`]).
//!
//! The result carries the barycentric weights `w_j ≥ 0` (`Σ w_j = 1`) of the master point on
//! the facet's nodes, the facet's outward unit normal and the signed distance
//! `(x − x_master) · n_l` (positive outside body `l`).

use std::collections::{HashMap, HashSet};

use nalgebra::Vector3;
use rstar::{PointDistance, RTree, RTreeObject, AABB};
use synovia_mesh::math::{Point, Real, Vector};

/// Tolerance on the barycentric coordinates for "the projection lies in the facet".
const INSIDE_TOL: Real = 1e-6;

/// One facet in the tree: its corners embedded in 3D (`z = 0` in 2D) and bounding box.
#[derive(Debug, Clone)]
pub(crate) struct FacetEntry {
    pub(crate) facet: usize,
    pub(crate) corners: [Vector3<Real>; 3],
    pub(crate) n_corners: usize,
    pub(crate) envelope: AABB<[Real; 3]>,
}

impl RTreeObject for FacetEntry {
    type Envelope = AABB<[Real; 3]>;
    fn envelope(&self) -> Self::Envelope {
        self.envelope
    }
}

impl PointDistance for FacetEntry {
    fn distance_2(&self, point: &[Real; 3]) -> Real {
        let x = Vector3::new(point[0], point[1], point[2]);
        let (_, p) = closest(&self.corners[..self.n_corners], &x);
        (x - p).norm_squared()
    }
}

/// Closest point of a segment (2 corners) or triangle (3 corners) to `x`: barycentric weights
/// (clamped, `≥ 0`, sum 1) and the point.
pub(crate) fn closest(c: &[Vector3<Real>], x: &Vector3<Real>) -> ([Real; 3], Vector3<Real>) {
    if c.len() == 2 {
        let t = segment_parameter(&c[0], &c[1], x).clamp(0.0, 1.0);
        return ([1.0 - t, t, 0.0], c[0] + (c[1] - c[0]) * t);
    }
    // Ericson, Real-Time Collision Detection, §5.1.5
    let (a, b, cc) = (c[0], c[1], c[2]);
    let ab = b - a;
    let ac = cc - a;
    let ap = x - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return ([1.0, 0.0, 0.0], a);
    }
    let bp = x - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return ([0.0, 1.0, 0.0], b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return ([1.0 - v, v, 0.0], a + ab * v);
    }
    let cp = x - cc;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return ([0.0, 0.0, 1.0], cc);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return ([1.0 - w, 0.0, w], a + ac * w);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return ([0.0, 1.0 - w, w], b + (cc - b) * w);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    ([1.0 - v - w, v, w], a + ab * v + ac * w)
}

/// `t` of the orthogonal projection `a + t (b − a)` of `x` on the line through `a`, `b`.
fn segment_parameter(a: &Vector3<Real>, b: &Vector3<Real>, x: &Vector3<Real>) -> Real {
    let e = b - a;
    let l2 = e.norm_squared();
    if l2 > 0.0 {
        (x - a).dot(&e) / l2
    } else {
        0.0
    }
}

/// Barycentric coordinates of the orthogonal projection of `x` on the line / plane of the
/// facet (not clamped).
fn projection_barycentric(c: &[Vector3<Real>], x: &Vector3<Real>) -> [Real; 3] {
    if c.len() == 2 {
        let t = segment_parameter(&c[0], &c[1], x);
        return [1.0 - t, t, 0.0];
    }
    let v0 = c[1] - c[0];
    let v1 = c[2] - c[0];
    let v2 = x - c[0];
    let (d00, d01, d11) = (v0.dot(&v0), v0.dot(&v1), v1.dot(&v1));
    let (d20, d21) = (v2.dot(&v0), v2.dot(&v1));
    let den = d00 * d11 - d01 * d01;
    if den <= 0.0 {
        return [Real::NAN; 3];
    }
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    [1.0 - v - w, v, w]
}

fn embed<const D: usize>(x: &Point<D>) -> Vector3<Real> {
    let mut v = Vector3::zeros();
    for k in 0..D.min(3) {
        v[k] = x[k];
    }
    v
}

/// A candidate master facet of a query: (inside, key, facet, weights, closest point).
type Candidate = (bool, Real, usize, [Real; 3], Vector3<Real>);

/// The projection of a point onto its master facet ([`FacetSearch::project`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Projection<const D: usize> {
    /// Index of the facet (in the order given to [`FacetSearch::new`]).
    pub facet: usize,
    /// `(master node, weight w_j)` of the master point, `w_j ≥ 0`, `Σ w_j = 1` (zero weights
    /// left out).
    pub weights: Vec<(usize, Real)>,
    /// The master point `Σ w_j x_j`.
    pub point: Point<D>,
    /// Outward unit normal `n_l` of the master facet.
    pub normal: Vector<D>,
    /// `(x − x_master) · n_l`: positive outside the master body.
    pub signed_distance: Real,
    /// `true` if the orthogonal projection lies in the facet (rule 1 of the module docs),
    /// `false` for a closest point on an interior edge or vertex (rule 2).
    pub inside: bool,
}

/// An R*-tree over the facets of a master contact surface (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct FacetSearch<const D: usize> {
    facets: Vec<Vec<usize>>,
    normals: Vec<Vector<D>>,
    tree: RTree<FacetEntry>,
    rim_vertices: HashSet<usize>,
    rim_edges: HashSet<(usize, usize)>,
    max_diameter: Real,
}

impl<const D: usize> FacetSearch<D> {
    /// Indexes `facets` (each `D` node indices into `positions`, oriented so that
    /// [`synovia_mesh::Mesh::facet_normal`]'s rule gives the outward normal: `(b − a)^⊥` in 2D,
    /// `(b − a) × (c − a)` in 3D). Degenerate facets (zero measure) are skipped.
    pub fn new(positions: &[Point<D>], facets: &[Vec<usize>]) -> Self {
        let mut entries = Vec::with_capacity(facets.len());
        let mut normals = Vec::with_capacity(facets.len());
        let mut max_diameter: Real = 0.0;
        let mut edge_count: HashMap<(usize, usize), usize> = HashMap::new();
        let mut vertex_count: HashMap<usize, usize> = HashMap::new();
        for (fi, f) in facets.iter().enumerate() {
            let n = area_normal(positions, f);
            let len = n.norm();
            normals.push(if len > 0.0 { n / len } else { n });
            let mut corners = [Vector3::zeros(); 3];
            let mut lo = [Real::INFINITY; 3];
            let mut hi = [Real::NEG_INFINITY; 3];
            for (k, &i) in f.iter().enumerate().take(3) {
                corners[k] = embed(&positions[i]);
                for a in 0..3 {
                    lo[a] = lo[a].min(corners[k][a]);
                    hi[a] = hi[a].max(corners[k][a]);
                }
            }
            for a in 0..f.len().min(3) {
                for b in 0..a {
                    max_diameter = max_diameter.max((corners[a] - corners[b]).norm());
                }
            }
            if D == 2 {
                for &i in f {
                    *vertex_count.entry(i).or_insert(0) += 1;
                }
            } else {
                for a in 0..f.len() {
                    let (i, j) = (f[a], f[(a + 1) % f.len()]);
                    *edge_count.entry((i.min(j), i.max(j))).or_insert(0) += 1;
                }
            }
            if len > 0.0 && len.is_finite() {
                entries.push(FacetEntry {
                    facet: fi,
                    corners,
                    n_corners: f.len().min(3),
                    envelope: AABB::from_corners(lo, hi),
                });
            }
        }
        let mut rim_vertices = HashSet::new();
        let mut rim_edges = HashSet::new();
        if D == 2 {
            rim_vertices.extend(vertex_count.into_iter().filter(|&(_, c)| c == 1).map(|(i, _)| i));
        } else {
            for ((i, j), c) in edge_count {
                if c == 1 {
                    rim_edges.insert((i, j));
                    rim_vertices.insert(i);
                    rim_vertices.insert(j);
                }
            }
        }
        Self {
            facets: facets.to_vec(),
            normals,
            tree: RTree::bulk_load(entries),
            rim_vertices,
            rim_edges,
            max_diameter,
        }
    }

    /// Number of indexed facets.
    pub fn len(&self) -> usize {
        self.tree.size()
    }
    /// `true` if no facet is indexed.
    pub fn is_empty(&self) -> bool {
        self.tree.size() == 0
    }
    /// The largest facet diameter `h_max`.
    pub fn max_diameter(&self) -> Real {
        self.max_diameter
    }

    /// The master point of `x` (see the [module docs](self)): `facing` is the slave normal
    /// `n_k` (facets with `n_l · n_k ≥ 0` are ignored), `search_distance` the largest distance
    /// `|x − x_master|` accepted (`None`: unbounded). `None` if no facet qualifies.
    pub fn project(
        &self,
        x: &Point<D>,
        facing: Option<&Vector<D>>,
        search_distance: Option<Real>,
    ) -> Option<Projection<D>> {
        let xe = embed(x);
        let q = [xe[0], xe[1], xe[2]];
        let faces = |f: usize| facing.is_none_or(|nk| self.normals[f].dot(nk) < 0.0);
        let radius = match search_distance {
            Some(s) => s,
            None => {
                // exact distance to the nearest facing facet, plus one facet for rule 1
                let nearest = self.tree.nearest_neighbor_iter(&q).find(|e| faces(e.facet))?;
                nearest.distance_2(&q).sqrt() + self.max_diameter
            }
        };
        if !(radius.is_finite() && radius >= 0.0) {
            return None;
        }
        let env = AABB::from_corners(
            [q[0] - radius, q[1] - radius, q[2] - radius],
            [q[0] + radius, q[1] + radius, q[2] + radius],
        );
        let mut best: Option<Candidate> = None;
        for e in self.tree.locate_in_envelope_intersecting(&env) {
            if !faces(e.facet) {
                continue;
            }
            let c = &e.corners[..e.n_corners];
            let (wc, p) = closest(c, &xe);
            let dist = (xe - p).norm();
            if search_distance.is_some_and(|s| dist > s) {
                continue;
            }
            let wu = projection_barycentric(c, &xe);
            let inside = wu.iter().take(e.n_corners).all(|&w| w >= -INSIDE_TOL);
            let key = if inside { (xe - p).dot(&embed(&self.normals[e.facet])).abs() } else { dist };
            let better = match &best {
                None => true,
                Some((bi, bk, bf, _, _)) => {
                    (inside && !bi) || (inside == *bi && (key < *bk || (key == *bk && e.facet < *bf)))
                }
            };
            if better {
                best = Some((inside, key, e.facet, wc, p));
            }
        }
        let (inside, _, f, w, p) = best?;
        let nodes = &self.facets[f];
        if !inside {
            let support: Vec<usize> =
                nodes.iter().zip(&w).filter(|(_, &wk)| wk > 1e-12).map(|(&i, _)| i).collect();
            let on_rim = match support.as_slice() {
                [i] => self.rim_vertices.contains(i),
                [i, j] => self.rim_edges.contains(&((*i).min(*j), (*i).max(*j))),
                _ => false,
            };
            if on_rim {
                return None;
            }
        }
        let weights: Vec<(usize, Real)> =
            nodes.iter().zip(&w).filter(|(_, &wk)| wk > 0.0).map(|(&i, &wk)| (i, wk)).collect();
        let point = Point::<D>::from_fn(|a, _| p[a]);
        let normal = self.normals[f];
        Some(Projection {
            facet: f,
            weights,
            point,
            normal,
            signed_distance: (x - point).dot(&normal),
            inside,
        })
    }
}

/// Area-weighted normal of a facet at the given positions (re-exported from synovia-mesh).
pub use synovia_mesh::mesh::facet_area_normal_at as area_normal;

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2D master polyline: the top of a body below, `y = 0` for `x ∈ [0, 1]` then a convex
    /// corner going down to `(2, −1)`; facets oriented with outward normal up / up-right.
    fn polyline() -> (Vec<Point<2>>, Vec<Vec<usize>>) {
        let pos = vec![Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 0.0), Point::<2>::new(2.0, -1.0)];
        (pos, vec![vec![1, 0], vec![2, 1]])
    }

    #[test]
    fn projection_on_segments_gives_weights_normal_and_distance() {
        let (pos, facets) = polyline();
        let s = FacetSearch::new(&pos, &facets);
        assert_eq!(s.len(), 2);
        let down = Vector::<2>::new(0.0, -1.0);
        let p = s.project(&Point::<2>::new(0.25, 0.1), Some(&down), None).expect("paired");
        assert_eq!(p.facet, 0);
        assert!(p.inside);
        let w: HashMap<usize, Real> = p.weights.iter().copied().collect();
        assert!((w[&0] - 0.75).abs() < 1e-14 && (w[&1] - 0.25).abs() < 1e-14, "{w:?}");
        assert!((p.normal - Vector::<2>::new(0.0, 1.0)).norm() < 1e-14);
        assert!((p.signed_distance - 0.1).abs() < 1e-14);
        // penetrated node: negative distance
        let p = s.project(&Point::<2>::new(0.5, -0.02), Some(&down), None).expect("paired");
        assert!((p.signed_distance + 0.02).abs() < 1e-14);
        // a search distance too small drops the node
        assert!(s.project(&Point::<2>::new(0.5, 0.3), Some(&down), Some(0.2)).is_none());
        // a node facing the same way as the master does not pair
        assert!(s.project(&Point::<2>::new(0.5, 0.1), Some(&-down), None).is_none());
    }

    #[test]
    fn convex_corner_wedge_pairs_and_rim_drops() {
        let (pos, facets) = polyline();
        let s = FacetSearch::new(&pos, &facets);
        let n = Vector::<2>::new(-1.0, -1.0).normalize();
        // in the wedge above the convex corner (1, 0): closest point is the interior vertex
        let p = s.project(&Point::<2>::new(1.05, 0.1), Some(&n), None).expect("paired");
        assert!(!p.inside);
        assert_eq!(p.weights, vec![(1, 1.0)]);
        // beyond the rim vertex (0, 0): no partner
        assert!(s.project(&Point::<2>::new(-0.1, 0.1), Some(&Vector::<2>::new(0.0, -1.0)), None).is_none());
        // exactly above the rim vertex: inside within the tolerance
        assert!(s.project(&Point::<2>::new(0.0, 0.1), Some(&Vector::<2>::new(0.0, -1.0)), None).is_some());
    }

    #[test]
    fn projection_on_triangles() {
        // unit square z = 0 cut into two triangles, normal +z
        let pos = vec![
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 0.0, 0.0),
            Point::<3>::new(1.0, 1.0, 0.0),
            Point::<3>::new(0.0, 1.0, 0.0),
        ];
        let facets = vec![vec![0, 1, 2], vec![0, 2, 3]];
        let s = FacetSearch::new(&pos, &facets);
        let down = Vector::<3>::new(0.0, 0.0, -1.0);
        let x = Point::<3>::new(0.7, 0.2, 0.05);
        let p = s.project(&x, Some(&down), None).expect("paired");
        assert_eq!(p.facet, 0);
        let mut interp = Point::<3>::zeros();
        for &(j, w) in &p.weights {
            assert!(w > 0.0);
            interp += pos[j] * w;
        }
        assert!((interp - Point::<3>::new(0.7, 0.2, 0.0)).norm() < 1e-14);
        assert!((p.weights.iter().map(|w| w.1).sum::<Real>() - 1.0).abs() < 1e-14);
        assert!((p.signed_distance - 0.05).abs() < 1e-14);
        // outside the square: beyond the rim edge y = 0
        assert!(s.project(&Point::<3>::new(0.5, -0.1, 0.05), Some(&down), None).is_none());
        // fixed search distance
        assert!(s.project(&x, Some(&down), Some(0.01)).is_none());
        assert!(s.project(&x, Some(&down), Some(0.06)).is_some());
    }
}
