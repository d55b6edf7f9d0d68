//! Rigid obstacles for [`crate::discretisation::RigidObstacle`]: signed distances `φ` with their
//! gradients (docs/model.md §5: the gap of a node against an obstacle is `d_r = φ(x_r)`).

use std::fmt;
use std::sync::Arc;

use synovia_mesh::math::{Point, Real, Vector};

use crate::error::ContactError;

/// A rigid obstacle given by a signed distance `φ` (positive in the free space outside the
/// obstacle, negative inside) and its gradient.
pub trait SignedDistance<const D: usize>: Send + Sync + fmt::Debug {
    /// `φ(x)`.
    fn distance(&self, x: &Point<D>) -> Real;
    /// `∇φ(x)`: the unit normal of the obstacle surface pointing into the free space.
    fn gradient(&self, x: &Point<D>) -> Vector<D>;
    /// `(φ(x), ∇φ(x))` in one query (default: [`SignedDistance::distance`] and
    /// [`SignedDistance::gradient`]); shapes whose two values come from the same search (a
    /// closest point on a surface) override it.
    fn distance_and_gradient(&self, x: &Point<D>) -> (Real, Vector<D>) {
        (self.distance(x), self.gradient(x))
    }
    /// A query bounded by `reach`: `(φ(x), ∇φ(x))` exactly where `φ(x) ≤ reach` (inside the
    /// obstacle too); where `φ(x) > reach`, any `d` with `reach < d ≤ φ(x)` and a unit vector
    /// (a lower bound of the distance: what a contact row beyond its search distance needs,
    /// [`RigidObstacle::search_distance`](crate::discretisation::RigidObstacle)). Shapes whose
    /// exact query costs more the farther the point (a finely tessellated surface) answer far
    /// points from a coarser one (docs/model.md (5.23)). Default:
    /// [`SignedDistance::distance_and_gradient`].
    fn distance_and_gradient_within(&self, x: &Point<D>, reach: Real) -> (Real, Vector<D>) {
        let _ = reach;
        self.distance_and_gradient(x)
    }
    /// Checks the obstacle's parameters (finite, positive radius, unit directions); the
    /// error names the offending parameter. [`ContactGeometry::new`](crate::operators::ContactGeometry::new) calls it for every rigid
    /// pair and reports a failure as [`ContactError::InvalidPair`]. Default: no check.
    fn validate(&self) -> Result<(), String> {
        Ok(())
    }
}

/// `Err` naming `what` unless every entry of `v` is finite.
fn check_finite(what: &str, v: &[Real]) -> Result<(), String> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("{what} {v:?} is not finite"))
    }
}

/// `Err` unless `v` is a finite unit vector (within 1e-9).
fn check_unit(what: &str, v: &[Real]) -> Result<(), String> {
    check_finite(what, v)?;
    let n = v.iter().map(|x| x * x).sum::<Real>().sqrt();
    if (n - 1.0).abs() > 1e-9 {
        return Err(format!("{what} {v:?} must be a unit vector (length {n:e})"));
    }
    Ok(())
}

/// `Err` unless `r` is finite and positive.
fn check_radius(r: Real) -> Result<(), String> {
    if r.is_finite() && r > 0.0 {
        Ok(())
    } else {
        Err(format!("radius {r} must be finite and > 0"))
    }
}

/// The half-space `{(x − p) · n < 0}` is the obstacle; `n` points into the free space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneObstacle<const D: usize> {
    /// A point of the plane.
    pub point: Point<D>,
    /// Unit normal pointing out of the obstacle.
    pub normal: Vector<D>,
}

impl<const D: usize> PlaneObstacle<D> {
    /// A plane through `point` with normal `normal` (normalised; error if zero).
    pub fn new(point: Point<D>, normal: Vector<D>) -> Result<Self, ContactError> {
        let len = normal.norm();
        if !(len.is_finite() && len > 0.0) || point.iter().any(|x| !x.is_finite()) {
            return Err(ContactError::InvalidParameter(
                "plane obstacle needs a finite point and a non-zero normal".into(),
            ));
        }
        Ok(Self { point, normal: normal / len })
    }
}

impl<const D: usize> SignedDistance<D> for PlaneObstacle<D> {
    fn distance(&self, x: &Point<D>) -> Real {
        (x - self.point).dot(&self.normal)
    }
    fn gradient(&self, _x: &Point<D>) -> Vector<D> {
        self.normal
    }
    fn validate(&self) -> Result<(), String> {
        check_finite("plane point", self.point.as_slice())?;
        check_unit("plane normal", self.normal.as_slice())
    }
}

/// A rigid ball (circle in 2D) `|x − c| ≤ R`, or with `cavity = true` the outside of it (a
/// spherical socket whose inside is free).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereObstacle<const D: usize> {
    /// Centre.
    pub center: Point<D>,
    /// Radius `R > 0`.
    pub radius: Real,
    /// `true`: the body moves inside the sphere (socket); `false`: outside (ball).
    pub cavity: bool,
}

impl<const D: usize> SphereObstacle<D> {
    /// A ball (`cavity = false`) or spherical socket (`cavity = true`); error if the centre
    /// is not finite or the radius not finite and positive.
    pub fn new(center: Point<D>, radius: Real, cavity: bool) -> Result<Self, ContactError> {
        let s = Self { center, radius, cavity };
        s.validate().map_err(|m| ContactError::InvalidParameter(format!("sphere obstacle: {m}")))?;
        Ok(s)
    }
}

impl<const D: usize> SignedDistance<D> for SphereObstacle<D> {
    fn validate(&self) -> Result<(), String> {
        check_finite("sphere centre", self.center.as_slice())?;
        check_radius(self.radius)
    }
    fn distance(&self, x: &Point<D>) -> Real {
        let r = (x - self.center).norm();
        if self.cavity {
            self.radius - r
        } else {
            r - self.radius
        }
    }
    fn gradient(&self, x: &Point<D>) -> Vector<D> {
        let v = x - self.center;
        let r = v.norm();
        let g = if r > 0.0 { v / r } else { Vector::<D>::zeros() };
        if self.cavity {
            -g
        } else {
            g
        }
    }
}

/// A rigid infinite cylinder in 3D `dist(x, axis) ≤ R` (or its outside with `cavity`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderObstacle {
    /// A point of the axis.
    pub point: Point<3>,
    /// Unit axis direction.
    pub axis: Vector<3>,
    /// Radius.
    pub radius: Real,
    /// `true`: the free space is inside the cylinder.
    pub cavity: bool,
}

impl CylinderObstacle {
    /// A cylinder about the axis through `point` along `axis` (normalised); error if the point
    /// or axis is not finite, the axis is zero, or the radius not finite and positive.
    pub fn new(point: Point<3>, axis: Vector<3>, radius: Real, cavity: bool) -> Result<Self, ContactError> {
        let bad = |m: String| ContactError::InvalidParameter(format!("cylinder obstacle: {m}"));
        check_finite("cylinder axis", axis.as_slice()).map_err(bad)?;
        let len = axis.norm();
        if len <= 0.0 {
            return Err(bad("axis is zero".into()));
        }
        let s = Self { point, axis: axis / len, radius, cavity };
        s.validate().map_err(bad)?;
        Ok(s)
    }
}

impl SignedDistance<3> for CylinderObstacle {
    fn validate(&self) -> Result<(), String> {
        check_finite("cylinder point", self.point.as_slice())?;
        check_unit("cylinder axis", self.axis.as_slice())?;
        check_radius(self.radius)
    }
    fn distance(&self, x: &Point<3>) -> Real {
        let v = x - self.point;
        let r = (v - self.axis * v.dot(&self.axis)).norm();
        if self.cavity {
            self.radius - r
        } else {
            r - self.radius
        }
    }
    fn gradient(&self, x: &Point<3>) -> Vector<3> {
        let v = x - self.point;
        let radial = v - self.axis * v.dot(&self.axis);
        let r = radial.norm();
        let g = if r > 0.0 { radial / r } else { Vector::<3>::zeros() };
        if self.cavity {
            -g
        } else {
            g
        }
    }
}

/// A user-defined obstacle from a closure returning `(φ(x), ∇φ(x))`.
pub struct FnObstacle<const D: usize> {
    f: DistanceFn<D>,
}

/// A closure `x ↦ (φ(x), ∇φ(x))`.
pub type DistanceFn<const D: usize> = Arc<dyn Fn(&Point<D>) -> (Real, Vector<D>) + Send + Sync>;

impl<const D: usize> FnObstacle<D> {
    /// Wraps `f(x) = (φ(x), ∇φ(x))`.
    pub fn new(f: impl Fn(&Point<D>) -> (Real, Vector<D>) + Send + Sync + 'static) -> Self {
        Self { f: Arc::new(f) }
    }
}

impl<const D: usize> fmt::Debug for FnObstacle<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("FnObstacle")
    }
}

impl<const D: usize> SignedDistance<D> for FnObstacle<D> {
    fn distance(&self, x: &Point<D>) -> Real {
        (self.f)(x).0
    }
    fn gradient(&self, x: &Point<D>) -> Vector<D> {
        (self.f)(x).1
    }
}
