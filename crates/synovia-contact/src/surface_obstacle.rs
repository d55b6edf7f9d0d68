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
use std::sync::Arc;

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
        }
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
        (c, t, side * len, gradient_local)
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
    /// `reach + δ` from the control surface with `φ_control − δ` (the closest-point search on
    /// a fine surface visits more triangles the farther the point); others as
    /// [`SignedDistance::distance_and_gradient`].
    fn distance_and_gradient_within(&self, x: &Point<3>, reach: Real) -> (Real, Vector<3>) {
        if let Some((coarse, delta)) = &self.coarse {
            let local = self.rotation.inverse() * (x - self.translation);
            let (_, _, d, g) = coarse.closest_local(&local);
            if d - delta > reach {
                return (d - delta, self.rotation * g);
            }
        }
        self.distance_and_gradient(x)
    }
    fn validate(&self) -> Result<(), String> {
        if self.translation.iter().chain(self.rotation.matrix().iter()).all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err("surface obstacle pose is not finite".into())
        }
    }
}
