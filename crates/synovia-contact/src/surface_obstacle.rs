//! Rigid obstacles defined by a triangle surface (an implant component from an STL file):
//! the signed distance `φ` and its gradient by closest-point queries on an R*-tree of the
//! triangles (docs/model.md §5: the gap of a contact node is `d_r = φ(x_r)`).
//!
//! The sign follows the angle-weighted pseudo-normal of the closest feature (Bærentzen and
//! Aanæs, "Signed distance computation using the angle weighted pseudonormal", IEEE TVCG 11
//! (2005)): with `c` the closest point of the surface to `x` on a face, an edge or a vertex,
//! and `n_c` the face normal, the sum of the two face normals of the edge, or the sum of the
//! face normals of the vertex weighted by their angles there,
//!
//! `φ(x) = sign((x − c) · n_c) |x − c|`, `∇φ(x) = (x − c) / φ(x)` (`n_c / |n_c|` on the surface).
//!
//! For a closed, consistently oriented surface with outward normals this is the exact signed
//! distance, negative inside the solid. For an open surface (an articular patch) the free space
//! is the side its normals point to.
//!
//! A pose `x ↦ R x + t` places the surface without rebuilding the tree: queries are mapped
//! into the surface's frame and the gradient back ([`SurfaceObstacle::set_pose`]).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use nalgebra::{Rotation3, Vector3};
use rstar::{RTree, AABB};
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::{SurfaceError, TriangleSurface};

use crate::error::ContactError;
use crate::obstacle::SignedDistance;
use crate::search::{closest, FacetEntry};

/// The closest point of a [`SurfaceObstacle`] to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// The closest point (world frame).
    pub point: Point<3>,
    /// The triangle it lies on (one of them, on an edge or a vertex).
    pub triangle: usize,
    /// The signed distance `φ` (positive on the normals' side).
    pub distance: Real,
    /// `∇φ`: unit vector from the surface to the query point (the pseudo-normal on the
    /// surface), world frame.
    pub gradient: Vector<3>,
}

/// A rigid obstacle bounded by a triangle surface (see the [module documentation](self)).
#[derive(Debug, Clone)]
pub struct SurfaceObstacle {
    surface: Arc<TriangleSurface>,
    tree: RTree<FacetEntry>,
    face_normals: Vec<Vector3<Real>>,
    vertex_normals: Vec<Vector3<Real>>,
    edge_normals: HashMap<(usize, usize), Vector3<Real>>,
    rotation: Rotation3<Real>,
    translation: Vector3<Real>,
    /// A smoothed surface's control surface and the bound `δ` on the distance between the two
    /// ([`SurfaceObstacle::smoothed_solid`]).
    coarse: Option<(Box<SurfaceObstacle>, Real)>,
    /// Concave edges rounded by fillets ([`SurfaceObstacle::with_concave_fillet`]).
    fillet: Option<Arc<Fillet>>,
    /// Far answers of bounded queries, kept for the next ones
    /// ([`SignedDistance::distance_and_gradient_within`]); shared by clones (they hold
    /// points in the surface's own frame, valid for every pose).
    far: Arc<Mutex<FarAnswers>>,
}

/// Far answers of bounded queries in a grid of cubes of side `reach / 2` (surface frame): at
/// most [`FAR_PER_CELL`] per cube (the oldest replaced), at most [`FAR_CELLS`] cubes (a full
/// grid is emptied); a query with another reach empties it.
#[derive(Debug, Default)]
struct FarAnswers {
    reach: Real,
    cells: HashMap<[i64; 3], Vec<FarAnswer>>,
}

impl FarAnswers {
    fn cell(&self, y: &Vector3<Real>) -> [i64; 3] {
        let h = 0.5 * self.reach;
        [(y.x / h).floor() as i64, (y.y / h).floor() as i64, (y.z / h).floor() as i64]
    }
}

/// A bounded query's answer beyond its reach: the query point in the surface's frame, `φ₀ > reach`
/// there, and the gradient (surface frame).
#[derive(Debug, Clone, Copy)]
struct FarAnswer {
    local: Vector3<Real>,
    distance: Real,
    gradient: Vector3<Real>,
}

/// Far answers kept per cube of the grid.
const FAR_PER_CELL: usize = 8;
/// Cubes of the grid of far answers kept (at most 2¹⁶ × 8 answers of 80 bytes: 42 MB).
const FAR_CELLS: usize = 1 << 16;

/// A concave edge of the surface rounded by a circular fillet
/// ([`SurfaceObstacle::with_concave_fillet`]), in the surface's frame.
#[derive(Debug, Clone, Copy)]
struct FilletEdge {
    /// One end of the edge.
    a: Vector3<Real>,
    /// Unit direction from `a` to the other end.
    u: Vector3<Real>,
    /// Length of the edge.
    len: Real,
    /// Unit normals of the two faces (into the free space).
    n1: Vector3<Real>,
    n2: Vector3<Real>,
    /// `n1 · n2`.
    c: Real,
    /// The fillet's radius at this edge.
    radius: Real,
    /// The fillet's axis relative to the edge, `radius (n1 + n2) / (1 + n1 · n2)` (the line at
    /// the distance `radius` from both faces' planes, on the free side).
    axis: Vector3<Real>,
}

impl FilletEdge {
    /// The signed distance to the fillet and its gradient at `x` (surface frame), if `x` lies
    /// in the fillet's zone: beside the edge (its projection on the edge's line within the
    /// edge) and in the cone `axis − β₁ n₁ − β₂ n₂ (β ≥ 0)` about the fillet's axis, where the
    /// closest point of the rounded surface lies on the fillet.
    fn distance(&self, x: &Vector3<Real>) -> Option<(Real, Vector3<Real>)> {
        let w = x - self.a;
        let s = w.dot(&self.u);
        if !(0.0..=self.len).contains(&s) {
            return None;
        }
        let q = w - self.u * s - self.axis;
        let qq = q.norm();
        if qq <= 1e-12 * self.radius {
            return None;
        }
        // q = −β₁ n₁ − β₂ n₂: [1 c; c 1] β = −(q·n₁, q·n₂)
        let (q1, q2) = (q.dot(&self.n1), q.dot(&self.n2));
        let det = 1.0 - self.c * self.c;
        let b1 = (-q1 + self.c * q2) / det;
        let b2 = (-q2 + self.c * q1) / det;
        if b1 < 0.0 || b2 < 0.0 {
            return None;
        }
        Some((self.radius - qq, -q / qq))
    }
}

/// The fillets of a surface's concave edges and, per triangle, the fillets that may hold the
/// closest point of a query whose closest point on the faceted surface lies on that triangle
/// (the concave edges incident to its vertices).
#[derive(Debug)]
struct Fillet {
    edges: Vec<FilletEdge>,
    near: Vec<Vec<u32>>,
    /// The largest distance between a fillet and its edge, `max radius (1 / cos(θ/2) − 1)`:
    /// the rounded distance is within it of the faceted one, and it bounds the jumps of the
    /// rounded distance at the edges' ends.
    deficit: Real,
}

impl SurfaceObstacle {
    /// An obstacle bounded by `surface`, which must be a consistently oriented manifold (open
    /// or closed); its normals point into the free space.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] with the surface's error
    /// ([`TriangleSurface::check_manifold`]).
    pub fn new(surface: TriangleSurface) -> Result<Self, ContactError> {
        surface.check_manifold().map_err(surface_error)?;
        Ok(Self::build(surface))
    }

    /// An obstacle bounded by the closed `surface` (a solid: the free space is outside).
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] with the surface's error
    /// ([`TriangleSurface::check_closed_solid`]: open, non-manifold, inconsistent, inward, or
    /// crossing itself — a self-intersecting surface has no well-defined inside).
    pub fn solid(surface: TriangleSurface) -> Result<Self, ContactError> {
        surface.check_closed_solid().map_err(surface_error)?;
        Ok(Self::build(surface))
    }

    /// An obstacle bounded by the closed `control` surface smoothed by `levels` levels of Loop
    /// subdivision ([`TriangleSurface::loop_subdivided`], edges sharper than `crease_angle`
    /// (radians) kept): a decimated implant STL without the creases at its edges.
    ///
    /// The control surface is kept for far queries
    /// ([`SignedDistance::distance_and_gradient_within`]): every vertex of the smoothed surface
    /// is a point of the same-numbered midpoint subdivision of the control surface moved by
    /// at most `m`, and every point of a triangle is within its longest edge `h` of its
    /// vertices, so the two surfaces are within `δ = m + h` of each other (Hausdorff) and their
    /// signed distances differ by at most `δ`; where the control surface is farther than
    /// `reach + δ`, the smoothed one is farther than `reach`, and `φ_control − δ` is the lower
    /// bound returned.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`]: the control surface is no closed solid
    /// ([`SurfaceObstacle::solid`]), the subdivision's parameters are invalid, or the smoothed
    /// surface is no closed solid (it crosses itself: fewer levels or a smaller crease angle).
    pub fn smoothed_solid(
        control: TriangleSurface,
        levels: usize,
        crease_angle: Real,
    ) -> Result<Self, ContactError> {
        control.check_closed_solid().map_err(surface_error)?;
        let smooth = control.loop_subdivided(levels, crease_angle).map_err(surface_error)?;
        if levels == 0 {
            return Ok(Self::build(smooth));
        }
        let linear = control.midpoint_subdivided(levels).map_err(surface_error)?;
        let moved =
            linear.vertices().iter().zip(smooth.vertices()).map(|(a, b)| (a - b).norm()).fold(0.0, Real::max);
        let longest = (0..smooth.len())
            .map(|t| {
                let [a, b, c] = smooth.corners(t);
                (a - b).norm().max((b - c).norm()).max((c - a).norm())
            })
            .fold(0.0, Real::max);
        smooth.check_closed_solid().map_err(surface_error)?;
        let mut obstacle = Self::build(smooth);
        obstacle.coarse = Some((Box::new(Self::build(control)), moved + longest));
        Ok(obstacle)
    }

    /// The bound `δ` on the distance between a smoothed surface and its control surface
    /// ([`SurfaceObstacle::smoothed_solid`]; `None` for other obstacles).
    pub fn smoothing_bound(&self) -> Option<Real> {
        self.coarse.as_ref().map(|(_, delta)| *delta)
    }

    fn build(surface: TriangleSurface) -> Self {
        let v = surface.vertices();
        let mut face_normals = Vec::with_capacity(surface.len());
        let mut vertex_normals = vec![Vector3::zeros(); v.len()];
        let mut edge_normals: HashMap<(usize, usize), Vector3<Real>> = HashMap::new();
        let mut entries = Vec::with_capacity(surface.len());
        for (t, tri) in surface.triangles().iter().enumerate() {
            let n = surface.normal(t);
            face_normals.push(n);
            for k in 0..3 {
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let angle = (v[b] - v[a]).angle(&(v[c] - v[a]));
                vertex_normals[a] += angle * n;
                *edge_normals.entry((a.min(b), a.max(b))).or_insert_with(Vector3::zeros) += n;
            }
            let corners = surface.corners(t);
            let mut lo = [Real::INFINITY; 3];
            let mut hi = [Real::NEG_INFINITY; 3];
            for p in &corners {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
            entries.push(FacetEntry {
                facet: t,
                corners,
                n_corners: 3,
                envelope: AABB::from_corners(lo, hi),
            });
        }
        Self {
            surface: Arc::new(surface),
            tree: RTree::bulk_load(entries),
            face_normals,
            vertex_normals,
            edge_normals,
            rotation: Rotation3::identity(),
            translation: Vector3::zeros(),
            coarse: None,
            fillet: None,
            far: Arc::default(),
        }
    }

    /// The obstacle with its concave edges rounded by circular fillets of radius `radius`
    /// (surface units): where two faces meet at an edge that the free space sees as a convex
    /// corner (the solid's inner corner, e.g. a groove), the signed distance is that of the
    /// surface with the corner filled by a cylinder of radius `radius` tangent to both faces.
    /// Its gradient is then continuous across the edge: a contact node pressed into such a
    /// corner has a closest point and a normal that move continuously with it, where on the
    /// faceted surface its normal jumps between the two faces' normals (docs/nonlinear.md,
    /// "A node in a concave corner"). Near an edge whose faces are narrow the radius is
    /// reduced so that the fillet touches each face within half its height over the edge. The
    /// rounded surface lies within `radius (1 / cos(θ/2) − 1)` of the faceted one (`θ` the
    /// angle between the faces' normals; [`SurfaceObstacle::fillet_deficit`]); the radius of
    /// an edge is also cut so that this offset stays within `max_deficit` (a sharp inner
    /// corner, `θ` near 90° or beyond, gets a small fillet: at `θ = 127°` a fillet of radius
    /// `r` lies `1.2 r` off the corner). Fillets are per edge: at a vertex where concave edges
    /// meet, the distance is the least of theirs (a fillet ends at the ends of its edge).
    /// Replaces any fillet set before; `radius = 0` removes them.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] for a radius that is negative or not finite, or a
    /// `max_deficit` that is not positive (`Real::INFINITY`: no bound).
    pub fn with_concave_fillet(mut self, radius: Real, max_deficit: Real) -> Result<Self, ContactError> {
        if !(radius.is_finite() && radius >= 0.0) || max_deficit.is_nan() || max_deficit <= 0.0 {
            return Err(ContactError::InvalidParameter(format!(
                "surface obstacle: fillet radius {radius} must be finite and ≥ 0, its largest offset {max_deficit} > 0"
            )));
        }
        self.fillet = None;
        if radius > 0.0 {
            self.fillet = Some(Arc::new(self.concave_fillets(radius, max_deficit)));
        }
        // kept far answers were measured without (or with other) fillets
        self.far = Arc::default();
        Ok(self)
    }

    /// The bound on the distance between the rounded and the faceted surface
    /// ([`SurfaceObstacle::with_concave_fillet`]; 0 without fillets).
    pub fn fillet_deficit(&self) -> Real {
        self.fillet.as_ref().map_or(0.0, |f| f.deficit)
    }

    /// The number of concave edges rounded ([`SurfaceObstacle::with_concave_fillet`]).
    pub fn filleted_edges(&self) -> usize {
        self.fillet.as_ref().map_or(0, |f| f.edges.len())
    }

    fn concave_fillets(&self, radius: Real, max_deficit: Real) -> Fillet {
        let surface = &self.surface;
        let v = surface.vertices();
        let tris = surface.triangles();
        // edge → the triangles on it with their vertex opposite the edge
        let mut sides: HashMap<(usize, usize), Vec<(usize, usize)>> = HashMap::new();
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b, o) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                sides.entry((a.min(b), a.max(b))).or_default().push((t, o));
            }
        }
        let mut keys: Vec<_> = sides.keys().copied().collect();
        keys.sort_unstable();
        let mut edges = Vec::new();
        let mut ends = Vec::new();
        let mut deficit: Real = 0.0;
        for key in keys {
            let [(t1, o1), (t2, o2)] = sides[&key][..] else { continue };
            let (a, b) = (v[key.0], v[key.1]);
            let (n1, n2) = (self.face_normals[t1], self.face_normals[t2]);
            let c = n1.dot(&n2);
            // concave: each face's far vertex on the free side of the other face's plane
            let concave = n1.dot(&(v[o2] - a)) > 0.0 && n2.dot(&(v[o1] - a)) > 0.0;
            if !(concave && c > -1.0 + 1e-9 && c < 1.0 - 1e-12) {
                continue;
            }
            let e = b - a;
            let len = e.norm();
            if len <= 0.0 {
                continue;
            }
            let u = e / len;
            // the fillet touches each face at radius tan(θ/2) from the edge: within half
            // the face's height over the edge
            let height = |o: usize| (v[o] - a - u * (v[o] - a).dot(&u)).norm();
            let half_angle_tan = ((1.0 - c) / (1.0 + c)).sqrt();
            // the fillet lies r (1/cos(θ/2) − 1) off the edge: at most max_deficit
            let offset = (2.0 / (1.0 + c)).sqrt() - 1.0;
            let r = radius.min(0.5 * height(o1).min(height(o2)) / half_angle_tan).min(max_deficit / offset);
            if r.is_nan() || r <= 0.0 {
                continue;
            }
            deficit = deficit.max(r * offset);
            edges.push(FilletEdge { a, u, len, n1, n2, c, radius: r, axis: (n1 + n2) * (r / (1.0 + c)) });
            ends.push(key);
        }
        // per triangle: the fillets of the edges incident to its vertices
        let mut at_vertex: Vec<Vec<u32>> = vec![Vec::new(); v.len()];
        for (i, &(p, q)) in ends.iter().enumerate() {
            let i = u32::try_from(i).unwrap_or(u32::MAX);
            at_vertex[p].push(i);
            at_vertex[q].push(i);
        }
        let near = tris
            .iter()
            .map(|tri| {
                let mut list: Vec<u32> = tri.iter().flat_map(|&k| at_vertex[k].iter().copied()).collect();
                list.sort_unstable();
                list.dedup();
                list
            })
            .collect();
        Fillet { edges, near, deficit }
    }

    /// The surface (in its own frame).
    pub fn surface(&self) -> &TriangleSurface {
        &self.surface
    }
    /// Places the surface by `x ↦ R x + t` (replaces the previous pose; the tree is kept).
    pub fn set_pose(&mut self, rotation: Rotation3<Real>, translation: Vector<3>) {
        self.rotation = rotation;
        self.translation = translation;
    }
    /// [`SurfaceObstacle::set_pose`] by value.
    #[must_use]
    pub fn with_pose(mut self, rotation: Rotation3<Real>, translation: Vector<3>) -> Self {
        self.set_pose(rotation, translation);
        self
    }
    /// The pose `(R, t)`.
    pub fn pose(&self) -> (Rotation3<Real>, Vector<3>) {
        (self.rotation, self.translation)
    }

    /// The closest point of the surface to `x` with the signed distance and its gradient
    /// (see the [module documentation](self)).
    pub fn closest_point(&self, x: &Point<3>) -> SurfacePoint {
        let local = self.rotation.inverse() * (x - self.translation);
        let (c, t, distance, gradient_local) = self.closest_local(&local);
        SurfacePoint {
            point: self.rotation * c + self.translation,
            triangle: t,
            distance,
            gradient: self.rotation * gradient_local,
        }
    }

    /// The closest point, its triangle, `φ` and `∇φ` of a point in the surface's own frame.
    fn closest_local(&self, local: &Vector3<Real>) -> (Vector3<Real>, usize, Real, Vector3<Real>) {
        let query = [local.x, local.y, local.z];
        let Some(entry) = self.tree.nearest_neighbor(&query) else {
            // the constructors reject empty surfaces; stay total anyway
            return (*local, 0, Real::INFINITY, Vector3::z());
        };
        let t = entry.facet;
        let (w, c) = closest(&entry.corners[..3], local);
        let tri = self.surface.triangles()[t];
        let on: Vec<usize> = (0..3).filter(|&k| w[k] > 0.0).collect();
        let pseudo = match on.as_slice() {
            [k] => self.vertex_normals[tri[*k]],
            [a, b] => {
                let (i, j) = (tri[*a], tri[*b]);
                self.edge_normals.get(&(i.min(j), i.max(j))).copied().unwrap_or(self.face_normals[t])
            }
            _ => self.face_normals[t],
        };
        let d = local - c;
        let len = d.norm();
        let side = if d.dot(&pseudo) < 0.0 { -1.0 } else { 1.0 };
        let gradient_local = if len > 1e-12 * (1.0 + c.norm()) {
            d * (side / len)
        } else {
            pseudo.try_normalize(0.0).unwrap_or(self.face_normals[t])
        };
        let (mut distance, mut gradient, mut point) = (side * len, gradient_local, c);
        // the rounded surface lies on the free side of the faceted one, within the fillets'
        // deficit of it: the least distance, never more than the deficit below the faceted
        // one (two surfaces within δ of each other have signed distances within δ). The bound
        // also rejects a fillet whose zone (an unbounded cone behind its edge) reaches through
        // a thin part of the solid to points beside another face sharing a vertex with it.
        if let Some(fillet) = &self.fillet {
            let lowest = distance - fillet.deficit * (1.0 + 1e-9) - 1e-15;
            for &e in fillet.near.get(t).map_or(&[][..], Vec::as_slice) {
                let Some(edge) = fillet.edges.get(e as usize) else { continue };
                if let Some((df, gf)) = edge.distance(local) {
                    if df < distance && df >= lowest {
                        distance = df;
                        gradient = gf;
                        point = local - gf * df;
                    }
                }
            }
        }
        (point, t, distance, gradient)
    }
}

fn surface_error(e: SurfaceError) -> ContactError {
    ContactError::InvalidParameter(format!("surface obstacle: {e}"))
}

impl SignedDistance<3> for SurfaceObstacle {
    fn distance(&self, x: &Point<3>) -> Real {
        self.closest_point(x).distance
    }
    fn gradient(&self, x: &Point<3>) -> Vector<3> {
        self.closest_point(x).gradient
    }
    fn distance_and_gradient(&self, x: &Point<3>) -> (Real, Vector<3>) {
        let p = self.closest_point(x);
        (p.distance, p.gradient)
    }
    /// Smoothed surfaces ([`SurfaceObstacle::smoothed_solid`]) answer points farther than
    /// `reach + δ` from the control surface with `φ_control − δ`. Other surfaces keep the
    /// exact answers beyond the reach, `(y₀, φ₀ = φ(y₀), ∇φ(y₀))` in the surface's frame (a
    /// grid of cubes of side `reach / 2`, at most 8 per cube and 2¹⁶ cubes), and answer a
    /// point `y` (surface frame) from those in its cube: `φ` is 1-Lipschitz, so
    /// `φ(y) ≥ max φ₀ − |y − y₀|`, and that bound with its gradient is returned when it
    /// exceeds `reach` — no search for the contact nodes far from a partner that moves little
    /// from pose to pose (the closest-point search visits more triangles the farther the
    /// point). Such answers depend on the queries before (any bound in `(reach, φ]` is one).
    /// Otherwise the exact [`SignedDistance::distance_and_gradient`].
    fn distance_and_gradient_within(&self, x: &Point<3>, reach: Real) -> (Real, Vector<3>) {
        let local = self.rotation.inverse() * (x - self.translation);
        // the rounded distance jumps by at most the fillets' deficit at the ends of their edges
        let deficit = self.fillet_deficit();
        if let Some((coarse, delta)) = &self.coarse {
            let (_, _, d, g) = coarse.closest_local(&local);
            let delta = delta + deficit;
            if d - delta > reach {
                return (d - delta, self.rotation * g);
            }
            return self.distance_and_gradient(x);
        }
        let usable = reach.is_finite() && reach > 0.0;
        if usable {
            let far = self.far.lock().unwrap_or_else(|e| e.into_inner());
            if far.reach == reach {
                let best = far.cells.get(&far.cell(&local)).and_then(|kept| {
                    kept.iter()
                        .map(|a| (a.distance - deficit - (local - a.local).norm(), a.gradient))
                        .max_by(|a, b| a.0.total_cmp(&b.0))
                });
                if let Some((bound, gradient)) = best.filter(|(b, _)| *b > reach) {
                    return (bound, self.rotation * gradient);
                }
            }
        }
        let (_, _, distance, gradient) = self.closest_local(&local);
        if usable && distance > reach {
            let mut far = self.far.lock().unwrap_or_else(|e| e.into_inner());
            if far.reach != reach || far.cells.len() >= FAR_CELLS {
                *far = FarAnswers { reach, cells: HashMap::new() };
            }
            let cell = far.cell(&local);
            let kept = far.cells.entry(cell).or_default();
            if kept.len() >= FAR_PER_CELL {
                kept.remove(0);
            }
            kept.push(FarAnswer { local, distance, gradient });
        }
        (distance, self.rotation * gradient)
    }
    fn validate(&self) -> Result<(), String> {
        if self.translation.iter().chain(self.rotation.matrix().iter()).all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err("surface obstacle pose is not finite".into())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The groove `z = 1 − 0.1 x` (x ≥ 0), `z = 1 + 0.25 x` (x < 0), normals down: its crease
    /// at x = 0 is concave (the free space below is a convex wedge).
    fn groove() -> TriangleSurface {
        let v =
            |x: Real, y: Real| Point::<3>::new(x, y, if x >= 0.0 { 1.0 - 0.1 * x } else { 1.0 + 0.25 * x });
        let vertices =
            vec![v(-2.0, -2.0), v(0.0, -2.0), v(2.0, -2.0), v(-2.0, 2.0), v(0.0, 2.0), v(2.0, 2.0)];
        let surface = TriangleSurface::new(vertices, vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]])
            .expect("surface");
        if surface.normal(0)[2] > 0.0 {
            surface.flipped()
        } else {
            surface
        }
    }

    /// A concave edge rounded by a fillet: the distance is continuous with a continuous
    /// gradient across the crease's bisector (where the faceted one jumps between the faces'
    /// normals) and across the fillet's tangent lines, never above the faceted distance, and
    /// `radius (1/cos(θ/2) − 1)` below it at the crease; a convex edge (the groove turned
    /// over) and points away from the edge are unchanged.
    #[test]
    fn concave_fillet_is_continuous_and_below_the_faceted_distance() {
        let radius: Real = 0.05;
        let faceted = SurfaceObstacle::new(groove()).expect("open surface");
        let rounded = faceted.clone().with_concave_fillet(radius, Real::INFINITY).expect("fillet");
        assert_eq!(rounded.filleted_edges(), 1);
        let (n1, n2): (Vector3<Real>, Vector3<Real>) =
            (Vector3::new(0.1, 0.0, 1.0).normalize(), Vector3::new(-0.25, 0.0, 1.0).normalize());
        let half = 0.5 * n1.dot(&n2).acos();
        assert!((rounded.fillet_deficit() - radius * (1.0 / half.cos() - 1.0)).abs() < 1e-15);
        // at the crease: the bisector, the deficit below the faceted surface
        let crease = Point::<3>::new(0.0, 0.3, 1.0);
        let (d, g) = rounded.distance_and_gradient(&crease);
        assert!((d + rounded.fillet_deficit()).abs() < 1e-14, "φ = {d:e}");
        assert!((g + (n1 + n2).normalize()).norm() < 1e-14, "∇φ = {g:?}");
        // along a line across the groove below the crease (free space) and one above it
        // (inside): continuous, 1-Lipschitz, gradients turning continuously
        for z in [0.999, 1.0005] {
            let mut last: Option<(Real, Vector<3>)> = None;
            let h = 1e-4;
            for k in -400..=400 {
                let x = Point::<3>::new(Real::from(k) * h, -0.7, z);
                let (d, g) = rounded.distance_and_gradient(&x);
                assert!(d <= faceted.distance(&x) + 1e-15, "above the faceted distance at {x:?}");
                assert!((g.norm() - 1.0).abs() < 1e-12);
                if let Some((d0, g0)) = last {
                    assert!((d - d0).abs() <= h * (1.0 + 1e-9), "jump of φ at {x:?}");
                    assert!((g - g0).norm() < 0.05, "jump of ∇φ at {x:?}: {g0:?} → {g:?}");
                }
                last = Some((d, g));
            }
        }
        // the faceted gradient jumps across the bisector below the crease
        let bisector = (n1 + n2).normalize();
        let below = crease - bisector * 1e-3;
        let side = Vector3::new(1.0, 0.0, 0.0) * 1e-6;
        let (ga, gb) = (faceted.gradient(&(below + side)), faceted.gradient(&(below - side)));
        assert!((ga - gb).norm() > 0.3, "{ga:?} {gb:?}");
        // far from the edge: unchanged
        for x in [Point::<3>::new(0.5, 0.0, 0.9), Point::<3>::new(-0.5, 0.2, 0.8)] {
            assert_eq!(rounded.distance_and_gradient(&x), faceted.distance_and_gradient(&x));
        }
        // the same edge seen from the other side is convex: nothing rounded
        let ridge = SurfaceObstacle::new(groove().flipped())
            .expect("open surface")
            .with_concave_fillet(radius, Real::INFINITY);
        assert_eq!(ridge.expect("fillet").filleted_edges(), 0);
        // a bound on the offset cuts the radius
        let bounded = faceted.clone().with_concave_fillet(radius, 1e-4).expect("fillet");
        assert!((bounded.fillet_deficit() - 1e-4).abs() < 1e-15, "{}", bounded.fillet_deficit());
        assert!(faceted.clone().with_concave_fillet(-1.0, 1.0).is_err());
        assert!(faceted.clone().with_concave_fillet(Real::NAN, 1.0).is_err());
        assert!(faceted.with_concave_fillet(radius, 0.0).is_err());
    }

    /// Bounded queries of a surface that moves a little from pose to pose (a rigid partner
    /// over a gait cycle): within the reach they equal the exact query of a fresh obstacle
    /// (no kept answers) bit for bit, beyond it they are lower bounds `reach < d ≤ φ` with
    /// unit gradients, and after the first pose most far points are answered from the kept
    /// answers (bounds strictly below `φ`) instead of a search; the grid stays bounded.
    #[test]
    fn kept_far_answers_are_lower_bounds_and_near_answers_exact() {
        let centre = Point::<3>::new(0.3, -0.2, 0.1);
        let surface = TriangleSurface::icosphere(centre, 2.0, 3).expect("icosphere");
        let moving = SurfaceObstacle::solid(surface.clone()).expect("solid");
        let fresh = SurfaceObstacle::solid(surface).expect("solid");
        let mut state: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 10.0 - 5.0
        };
        let points: Vec<Point<3>> = (0..600).map(|_| Point::<3>::new(next(), next(), next())).collect();
        let reach = 0.5;
        let mut moving = moving;
        let mut fresh = fresh;
        let mut from_kept = Vec::new();
        for pose in 0..6 {
            let angle = 0.01 * pose as Real;
            let rotation = Rotation3::from_axis_angle(&Vector3::z_axis(), angle);
            let shift = Vector::<3>::new(0.02 * pose as Real, -0.01 * pose as Real, 0.0);
            moving.set_pose(rotation, shift);
            fresh.set_pose(rotation, shift);
            let (mut near, mut kept) = (0, 0);
            for x in &points {
                let (d, g) = fresh.distance_and_gradient(x);
                let (db, gb) = moving.distance_and_gradient_within(x, reach);
                assert!((gb.norm() - 1.0).abs() < 1e-12, "unit gradient");
                if d <= reach {
                    assert_eq!((d, g), (db, gb), "within reach at {x:?}, pose {pose}");
                    near += 1;
                } else {
                    assert!(db > reach && db <= d, "{db} not in ({reach}, {d}] at pose {pose}");
                    kept += usize::from(db < d);
                }
            }
            assert!(near > 20, "{near} points within reach");
            from_kept.push(kept);
        }
        // at the first pose only from other points' answers in the same cube
        assert!(
            from_kept[1..].iter().all(|&k| k > 300 && k > 2 * from_kept[0]),
            "from kept bounds: {from_kept:?}"
        );
        let far = moving.far.lock().expect("lock");
        assert!(far.cells.len() <= FAR_CELLS && far.cells.values().all(|c| c.len() <= FAR_PER_CELL));
    }
}
