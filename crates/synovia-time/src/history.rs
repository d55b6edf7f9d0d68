//! Load histories and prescribed rigid motions (docs/model.md §1, §7: loads `F(t)`, `P(t)` and prescribed
//! displacements `u₂(t)` that vary in time).
//!
//! A [`LoadHistory`] is a scalar amplitude `h(t)`. Loads and prescribed displacements of a
//! [`Model`](synovia_fem::Model) are closures of `(x, t)`; a history enters them by scaling a
//! fixed field, e.g. `F(x, t) = h(t) F̂(x)`:
//!
//! ```
//! use synovia_mesh::math::Vector;
//! use synovia_time::history::{scaled, LoadHistory, PiecewiseLinear};
//!
//! // push 0 → 1 → 0 over t ∈ [0, 2], constant before and after
//! let h = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)])?;
//! assert_eq!(h.value(0.5), 0.5);
//! let u2 = scaled(h, Vector::<2>::new(0.0, -0.01)); // u₂(x, t) = h(t) (0, −0.01)
//! assert_eq!(u2(&synovia_mesh::math::Point::<2>::zeros(), 1.0), Vector::<2>::new(0.0, -0.01));
//! # Ok::<(), synovia_time::TimeError>(())
//! ```
//!
//! Implementations: [`Constant`], [`PiecewiseLinear`] (a table with linear interpolation and
//! constant extrapolation), [`FnHistory`] (any closure), [`Periodic`] (wraps another history
//! with period `T`), [`SharedValue`] (a value set between solves, for interactive use).
//! `Arc<H>`, `Box<H>` and `&H` of a history are histories too.
//!
//! [`RigidMotion`] prescribes the exact rigid displacement of a boundary part (a rotation by
//! `θ(t)` about a centre plus a translation `T(t)`), for use with
//! [`Model::prescribe`](synovia_fem::Model::prescribe).

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering as AtomicOrdering};
use std::sync::Arc;

use synovia_mesh::math::{Point, Real, Vector};

use crate::error::TimeError;

/// A scalar amplitude `h(t)` of a load or prescribed displacement (docs/model.md §7).
pub trait LoadHistory: Send + Sync + fmt::Debug {
    /// `h(t)`.
    fn value(&self, t: Real) -> Real;
}

impl<H: LoadHistory + ?Sized> LoadHistory for Arc<H> {
    fn value(&self, t: Real) -> Real {
        (**self).value(t)
    }
}

impl<H: LoadHistory + ?Sized> LoadHistory for Box<H> {
    fn value(&self, t: Real) -> Real {
        (**self).value(t)
    }
}

impl<H: LoadHistory + ?Sized> LoadHistory for &H {
    fn value(&self, t: Real) -> Real {
        (**self).value(t)
    }
}

/// A constant amplitude `h(t) = c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constant(pub Real);

impl LoadHistory for Constant {
    fn value(&self, _t: Real) -> Real {
        self.0
    }
}

/// A settable amplitude shared between clones: `h(t) = v`, the value last stored with
/// [`SharedValue::set`] (independent of `t`).
///
/// This is the history for interactive use (navigation): build the model with `SharedValue`
/// histories, keep clones of them, and change the loads or prescribed displacements between
/// solves with [`SharedValue::set`] — the model reads the current value at every solve, so
/// nothing is rebuilt or refactorised. The value is stored in an `Arc<AtomicU64>` (bit pattern
/// of the `f64`), so a clone may be set from another thread.
///
/// ```
/// use synovia_time::history::{LoadHistory, SharedValue};
///
/// let force = SharedValue::new(10.0);
/// let in_model = force.clone(); // e.g. given to JointModel::traction
/// force.set(25.0);
/// assert_eq!(in_model.value(0.0), 25.0);
/// assert_eq!(in_model.value(7.0), 25.0); // independent of t
/// ```
#[derive(Clone, Default)]
pub struct SharedValue(Arc<AtomicU64>);

impl SharedValue {
    /// A shared value, initially `v`.
    pub fn new(v: Real) -> Self {
        Self(Arc::new(AtomicU64::new(v.to_bits())))
    }
    /// Stores `v` (seen by every clone).
    pub fn set(&self, v: Real) {
        self.0.store(v.to_bits(), AtomicOrdering::Relaxed);
    }
    /// The current value.
    pub fn get(&self) -> Real {
        Real::from_bits(self.0.load(AtomicOrdering::Relaxed))
    }
}

impl fmt::Debug for SharedValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple("SharedValue").field(&self.get()).finish()
    }
}

impl LoadHistory for SharedValue {
    fn value(&self, _t: Real) -> Real {
        self.get()
    }
}

/// A table `(t_k, h_k)`, `t_0 < t_1 < … < t_{m−1}`, interpolated linearly:
/// `h(t) = h_k + (h_{k+1} − h_k)(t − t_k)/(t_{k+1} − t_k)` for `t_k ≤ t ≤ t_{k+1}`, and
/// extrapolated by constants: `h(t) = h_0` for `t < t_0`, `h(t) = h_{m−1}` for `t > t_{m−1}`.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLinear {
    times: Vec<Real>,
    values: Vec<Real>,
}

impl PiecewiseLinear {
    /// A table of `(t, h)` points.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] when the table is empty, a time or value is not finite,
    /// or the times are not strictly increasing.
    pub fn new(points: &[(Real, Real)]) -> Result<Self, TimeError> {
        if points.is_empty() {
            return Err(TimeError::InvalidParameter("piecewise-linear history: empty table".into()));
        }
        for (k, &(t, v)) in points.iter().enumerate() {
            if !(t.is_finite() && v.is_finite()) {
                return Err(TimeError::InvalidParameter(format!(
                    "piecewise-linear history: point {k} ({t}, {v}) is not finite"
                )));
            }
            if k > 0 && t <= points[k - 1].0 {
                return Err(TimeError::InvalidParameter(format!(
                    "piecewise-linear history: times must increase strictly, but t_{k} = {t} ≤ t_{} = {}",
                    k - 1,
                    points[k - 1].0
                )));
            }
        }
        Ok(Self { times: points.iter().map(|p| p.0).collect(), values: points.iter().map(|p| p.1).collect() })
    }

    /// The table times `t_k`.
    pub fn times(&self) -> &[Real] {
        &self.times
    }
    /// The table values `h_k`.
    pub fn values(&self) -> &[Real] {
        &self.values
    }
}

impl LoadHistory for PiecewiseLinear {
    fn value(&self, t: Real) -> Real {
        let n = self.times.len();
        // `new` guarantees n ≥ 1
        if n == 0 || t.is_nan() {
            return Real::NAN;
        }
        if t <= self.times[0] {
            return self.values[0];
        }
        if t >= self.times[n - 1] {
            return self.values[n - 1];
        }
        // first k with t_k > t; 1 ≤ k ≤ n − 1 here
        let k = self.times.partition_point(|&tk| tk <= t);
        let (t0, t1) = (self.times[k - 1], self.times[k]);
        let (h0, h1) = (self.values[k - 1], self.values[k]);
        interpolate(t, (t0, h0), (t1, h1))
    }
}

/// `h0 + (h1 − h0) s` with `s = (t − t0) / (t1 − t0) ∈ [0, 1]`, finite for every finite
/// input with `t0 ≤ t ≤ t1`, `t0 < t1`: the fraction `s` is formed first (halved
/// operands when `t1 − t0` overflows) and `(1 − s) h0 + s h1` replaces the difference form
/// when `h1 − h0` overflows (points near ±1.8e308, found by `fuzz_table`).
fn interpolate(t: Real, (t0, h0): (Real, Real), (t1, h1): (Real, Real)) -> Real {
    let span = t1 - t0;
    let s = if span.is_finite() { (t - t0) / span } else { (0.5 * t - 0.5 * t0) / (0.5 * t1 - 0.5 * t0) };
    let s = s.clamp(0.0, 1.0);
    let rise = h1 - h0;
    if rise.is_finite() {
        h0 + rise * s
    } else {
        (1.0 - s) * h0 + s * h1
    }
}

/// A closure `t ↦ h(t)`.
#[derive(Clone)]
pub struct FnHistory {
    f: Arc<dyn Fn(Real) -> Real + Send + Sync>,
}

impl FnHistory {
    /// Wraps `f`.
    pub fn new(f: impl Fn(Real) -> Real + Send + Sync + 'static) -> Self {
        Self { f: Arc::new(f) }
    }
}

impl fmt::Debug for FnHistory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("FnHistory")
    }
}

impl LoadHistory for FnHistory {
    fn value(&self, t: Real) -> Real {
        (self.f)(t)
    }
}

/// The periodic continuation of `inner` on `[0, T)`: `h(t) = inner(t mod T)` with the
/// mathematical (non-negative) remainder, so `h(t + k T) = h(t)` for every integer `k`
/// (also for negative `t`).
#[derive(Debug, Clone, PartialEq)]
pub struct Periodic<H> {
    inner: H,
    period: Real,
}

impl<H: LoadHistory> Periodic<H> {
    /// Repeats `inner` with period `period`.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] unless `period` is finite and positive.
    pub fn new(inner: H, period: Real) -> Result<Self, TimeError> {
        if !(period.is_finite() && period > 0.0) {
            return Err(TimeError::InvalidParameter(format!(
                "periodic history: the period must be finite and > 0, got {period}"
            )));
        }
        Ok(Self { inner, period })
    }
    /// The wrapped history.
    pub fn inner(&self) -> &H {
        &self.inner
    }
    /// The period `T`.
    pub fn period(&self) -> Real {
        self.period
    }
}

impl<H: LoadHistory> LoadHistory for Periodic<H> {
    fn value(&self, t: Real) -> Real {
        let s = t.rem_euclid(self.period);
        // rem_euclid may round up to exactly T for tiny negative t
        self.inner.value(if s >= self.period { 0.0 } else { s })
    }
}

/// The vector field `(x, t) ↦ h(t) v` (a uniform load or displacement scaled by a history), in
/// the form [`Model::prescribe`](synovia_fem::Model::prescribe) and
/// [`Model::body_force`](synovia_fem::Model::body_force) take.
pub fn scaled<const D: usize>(
    history: impl LoadHistory + 'static,
    vector: Vector<D>,
) -> impl Fn(&Point<D>, Real) -> Vector<D> + Send + Sync + 'static {
    move |_x, t| vector * history.value(t)
}

/// The vector field `(x, t) ↦ h(t) f(x)`: a fixed spatial field scaled by a history.
pub fn scaled_field<const D: usize>(
    history: impl LoadHistory + 'static,
    field: impl Fn(&Point<D>) -> Vector<D> + Send + Sync + 'static,
) -> impl Fn(&Point<D>, Real) -> Vector<D> + Send + Sync + 'static {
    move |x, t| field(x) * history.value(t)
}

/// The traction `(x, n, t) ↦ h(t) P` of a uniform traction `P` scaled by a history, in the
/// form [`Model::traction`](synovia_fem::Model::traction) takes.
pub fn scaled_traction<const D: usize>(
    history: impl LoadHistory + 'static,
    traction: Vector<D>,
) -> impl Fn(&Point<D>, &Vector<D>, Real) -> Vector<D> + Send + Sync + 'static {
    move |_x, _n, t| traction * history.value(t)
}

/// A normal pressure `p(t)` on a boundary part: the traction `τ n = −p(t) n` (`n` the outward
/// normal; `p > 0` pushes into the body).
pub fn pressure<const D: usize>(
    history: impl LoadHistory + 'static,
) -> impl Fn(&Point<D>, &Vector<D>, Real) -> Vector<D> + Send + Sync + 'static {
    move |_x, n, t| -n * history.value(t)
}

/// A prescribed rigid motion of a boundary part: a rotation by the angle `θ(t)` about a centre
/// `c` (2D: about the point `c`; 3D: about the axis through `c` along the unit vector `k`)
/// followed by a translation `T(t)` (one history per component). A point `x` of the reference
/// configuration moves to `R(θ(t)) (x − c) + c + T(t)`, so its displacement is
///
/// ```text
/// u₂(x, t) = R(θ(t)) (x − c) + c + T(t) − x = (R(θ(t)) − I)(x − c) + T(t),
/// 2D:  R(θ) = [cos θ  −sin θ; sin θ  cos θ],
/// 3D:  R(θ) = I + sin θ [k]ₓ + (1 − cos θ) [k]ₓ²    (Rodrigues),
/// ```
///
/// evaluated with `1 − cos θ = 2 sin²(θ/2)` for accuracy at small angles. This is the exact
/// rigid map: distances between the moved points equal the reference distances for any `θ`.
/// Use it as
///
/// ```
/// use synovia_mesh::math::Point;
/// use synovia_time::history::{Constant, PiecewiseLinear, RigidMotion};
///
/// let angle = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, 0.01)])?;
/// let motion = RigidMotion::<2>::rotation(Point::<2>::new(0.0, 1.0), angle)
///     .with_translation_component(1, Constant(-0.02))?;
/// let u = motion.displacement(&Point::<2>::new(1.0, 1.0), 1.0);
/// assert!((u[1] - (0.01_f64.sin() - 0.02)).abs() < 1e-15);
/// // model.prescribe(body, "top", move |x, t| motion.displacement(x, t))?;
/// # Ok::<(), synovia_time::TimeError>(())
/// ```
///
/// **Small strain.** The model (docs/model.md §1) is linear (small-strain) elasticity. The prescribed
/// field is the exact rigid displacement, so a large `θ` simply gives large displacements, but
/// the linear strain of a rigid rotation is not zero: `e = sym(R − I) = (cos θ − 1) I` (in the
/// rotation plane), `O(θ²)`. Keep `θ` small (the strain error is `θ²/2`, about `1.5·10⁻⁴` at
/// 1°), or prescribe only the linearised motion (`R ≈ I + θ [k]ₓ`) if exact rigidity is not
/// wanted.
#[derive(Debug, Clone)]
pub struct RigidMotion<const D: usize> {
    centre: Point<D>,
    /// Unit rotation axis (3D only; `e_z` in 2D).
    axis: [Real; 3],
    angle: Option<Arc<dyn LoadHistory>>,
    translation: Vec<Option<Arc<dyn LoadHistory>>>,
}

impl<const D: usize> RigidMotion<D> {
    /// A pure translation `u₂(x, t) = T(t)` with one history per component.
    pub fn translation(components: [Arc<dyn LoadHistory>; D]) -> Self {
        Self {
            centre: Point::<D>::zeros(),
            axis: [0.0, 0.0, 1.0],
            angle: None,
            translation: components.into_iter().map(Some).collect(),
        }
    }

    /// The identity motion (no rotation, no translation); add parts with the `with_*` methods.
    pub fn identity() -> Self {
        Self { centre: Point::<D>::zeros(), axis: [0.0, 0.0, 1.0], angle: None, translation: vec![None; D] }
    }

    /// Sets the translation `T_k(t)` of component `k`.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] if `k ≥ D`.
    pub fn with_translation_component(
        mut self,
        k: usize,
        history: impl LoadHistory + 'static,
    ) -> Result<Self, TimeError> {
        if k >= D {
            return Err(TimeError::InvalidParameter(format!(
                "rigid motion: translation component {k} in {D}D"
            )));
        }
        self.translation.resize(D, None);
        self.translation[k] = Some(Arc::new(history));
        Ok(self)
    }

    /// Sets the whole translation `T(t)`, one history per component.
    #[must_use]
    pub fn with_translation(mut self, components: [Arc<dyn LoadHistory>; D]) -> Self {
        self.translation = components.into_iter().map(Some).collect();
        self
    }

    /// The centre `c` of the rotation.
    pub fn centre(&self) -> &Point<D> {
        &self.centre
    }

    /// The rotation angle `θ(t)` (0 without rotation).
    pub fn angle(&self, t: Real) -> Real {
        self.angle.as_ref().map_or(0.0, |h| h.value(t))
    }

    /// The translation `T(t)`.
    pub fn translation_at(&self, t: Real) -> Vector<D> {
        let mut v = Vector::<D>::zeros();
        for (k, h) in self.translation.iter().enumerate().take(D) {
            if let Some(h) = h {
                v[k] = h.value(t);
            }
        }
        v
    }

    /// `(R(θ) − I) v` with `1 − cos θ = 2 sin²(θ/2)`.
    fn rotate_minus_identity(&self, v: &Vector<D>, theta: Real) -> Vector<D> {
        let mut out = Vector::<D>::zeros();
        if theta == 0.0 {
            return out;
        }
        let (s, h) = (theta.sin(), (0.5 * theta).sin());
        let omc = 2.0 * h * h; // 1 − cos θ
        if D == 2 {
            out[0] = -omc * v[0] - s * v[1];
            out[1] = s * v[0] - omc * v[1];
        } else if D == 3 {
            let k = self.axis;
            // k × v and k × (k × v) = k (k·v) − v
            let kxv = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]];
            let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
            for i in 0..3 {
                out[i] = s * kxv[i] + omc * (k[i] * kv - v[i]);
            }
        }
        out
    }

    /// The displacement `u₂(x, t) = R(θ(t))(x − c) + c + T(t) − x`.
    pub fn displacement(&self, x: &Point<D>, t: Real) -> Vector<D> {
        let theta = self.angle(t);
        self.rotate_minus_identity(&(x - self.centre), theta) + self.translation_at(t)
    }

    /// The moved position `R(θ(t))(x − c) + c + T(t)`.
    pub fn position(&self, x: &Point<D>, t: Real) -> Point<D> {
        x + self.displacement(x, t)
    }
}

impl RigidMotion<2> {
    /// A rotation by `θ(t)` about the point `centre` (counter-clockwise for `θ > 0`).
    pub fn rotation(centre: Point<2>, angle: impl LoadHistory + 'static) -> Self {
        Self { centre, axis: [0.0, 0.0, 1.0], angle: Some(Arc::new(angle)), translation: vec![None; 2] }
    }
}

impl RigidMotion<3> {
    /// A rotation by `θ(t)` about the axis through `centre` along `axis` (right-handed;
    /// normalised here).
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] if `axis` is zero or not finite, or `centre` not finite.
    pub fn rotation(
        centre: Point<3>,
        axis: Vector<3>,
        angle: impl LoadHistory + 'static,
    ) -> Result<Self, TimeError> {
        let len = axis.norm();
        if !(len.is_finite() && len > 0.0) || centre.iter().any(|c| !c.is_finite()) {
            return Err(TimeError::InvalidParameter(format!(
                "rigid motion: the rotation axis must be finite and non-zero (got {axis:?}) and the centre finite"
            )));
        }
        Ok(Self {
            centre,
            axis: [axis[0] / len, axis[1] / len, axis[2] / len],
            angle: Some(Arc::new(angle)),
            translation: vec![None; 3],
        })
    }

    /// The unit rotation axis `k`.
    pub fn axis(&self) -> Vector<3> {
        Vector::<3>::new(self.axis[0], self.axis[1], self.axis[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_wraps_negative_times() {
        let p = Periodic::new(FnHistory::new(|t| t), 2.0).expect("period");
        assert!((p.value(-0.5) - 1.5).abs() < 1e-15);
        assert!((p.value(4.25) - 0.25).abs() < 1e-15);
    }

    #[test]
    fn piecewise_linear_stays_finite_at_the_ends_of_the_range() {
        // times and values near ±f64::MAX: the old form (h1 − h0)(t − t0)/(t1 − t0)
        // overflowed to ±inf or NaN on each of these
        let big = 1.0e308;
        let cases = [
            (vec![(0.0, 0.0), (0.005, -2.25), (big, 3000.0)], 1.25e305, -2.25, 3000.0),
            (vec![(-big, 1.0), (big, 2.0)], 0.0, 1.0, 2.0),
            (vec![(0.0, -big), (1.0, big)], 0.25, -big, big),
            (vec![(-big, -big), (big, big)], 0.5e308, -big, big),
        ];
        for (points, t, lo, hi) in cases {
            let h = PiecewiseLinear::new(&points).expect("finite points");
            let v = h.value(t);
            assert!(v.is_finite() && (lo..=hi).contains(&v), "{points:?} at {t}: {v}");
        }
        // exact midpoints where nothing overflows, and the old values at ordinary points
        assert!(PiecewiseLinear::new(&[]).is_err());
        let h = PiecewiseLinear::new(&[(-big, -big), (big, big)]).expect("points");
        assert_eq!(h.value(0.0), 0.0);
        let h = PiecewiseLinear::new(&[(0.0, 1.0), (2.0, 3.0), (4.0, -1.0)]).expect("points");
        assert_eq!(h.value(1.0), 2.0);
        assert_eq!(h.value(3.0), 1.0);
        assert_eq!(h.value(-1.0), 1.0);
        assert_eq!(h.value(5.0), -1.0);
    }
}
