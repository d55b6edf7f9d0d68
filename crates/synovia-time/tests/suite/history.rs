//! Load histories and rigid motions.

use std::sync::Arc;

use synovia_mesh::math::{Point, Vector};
use synovia_time::history::{
    pressure, scaled, scaled_field, Constant, FnHistory, LoadHistory, Periodic, PiecewiseLinear, RigidMotion,
};
use synovia_time::TimeError;

#[test]
fn piecewise_linear_interpolates_and_extrapolates_by_constants() {
    let h = PiecewiseLinear::new(&[(0.0, 1.0), (1.0, 3.0), (3.0, -1.0)]).expect("table");
    let cases =
        [(-5.0, 1.0), (0.0, 1.0), (0.25, 1.5), (1.0, 3.0), (2.0, 1.0), (2.5, 0.0), (3.0, -1.0), (10.0, -1.0)];
    for (t, v) in cases {
        assert!((h.value(t) - v).abs() < 1e-15, "h({t}) = {} ≠ {v}", h.value(t));
    }
    // a single point is a constant
    let c = PiecewiseLinear::new(&[(2.0, 7.0)]).expect("one point");
    assert_eq!(c.value(-1.0), 7.0);
    assert_eq!(c.value(9.0), 7.0);
    assert_eq!(h.times(), &[0.0, 1.0, 3.0]);
    assert_eq!(h.values(), &[1.0, 3.0, -1.0]);
}

#[test]
fn invalid_histories_are_errors() {
    let bad: [&[(f64, f64)]; 4] =
        [&[], &[(0.0, 1.0), (0.0, 2.0)], &[(0.0, 1.0), (1.0, 2.0), (0.5, 0.0)], &[(0.0, f64::NAN)]];
    for table in bad {
        assert!(
            matches!(PiecewiseLinear::new(table), Err(TimeError::InvalidParameter(_))),
            "{table:?} accepted"
        );
    }
    assert!(matches!(PiecewiseLinear::new(&[(f64::INFINITY, 1.0)]), Err(TimeError::InvalidParameter(_))));
    for period in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(Periodic::new(Constant(1.0), period), Err(TimeError::InvalidParameter(_))));
    }
    let id = RigidMotion::<2>::identity();
    assert!(matches!(id.with_translation_component(2, Constant(1.0)), Err(TimeError::InvalidParameter(_))));
    assert!(RigidMotion::<3>::rotation(Point::<3>::zeros(), Vector::<3>::zeros(), Constant(0.1)).is_err());
}

#[test]
fn periodic_history_wraps_around() {
    // a triangle wave 0 → 1 → 0 on [0, 2), repeated
    let tri = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)]).expect("table");
    let p = Periodic::new(tri, 2.0).expect("periodic");
    for t in [0.0, 0.3, 0.9, 1.0, 1.7] {
        for k in [-3.0, -1.0, 1.0, 2.0, 10.0] {
            let (a, b) = (p.value(t), p.value(t + 2.0 * k));
            assert!((a - b).abs() < 1e-12, "h({t}) = {a}, h({t} + {k}·2) = {b}");
        }
    }
    assert!((p.value(2.5) - 0.5).abs() < 1e-15);
    assert!((p.value(3.5) - 0.5).abs() < 1e-15);
    assert!((p.value(-0.25) - 0.25).abs() < 1e-15);
    assert_eq!(p.period(), 2.0);
    // through trait objects
    let shared: Arc<dyn LoadHistory> = Arc::new(FnHistory::new(|t| t * t));
    let q = Periodic::new(shared, 1.0).expect("periodic");
    assert!((q.value(2.5) - 0.25).abs() < 1e-15);
}

#[test]
fn scaled_fields_follow_the_history() {
    let h = FnHistory::new(|t| 2.0 * t);
    let f = scaled(h.clone(), Vector::<2>::new(1.0, -3.0));
    assert_eq!(f(&Point::<2>::new(5.0, 5.0), 0.5), Vector::<2>::new(1.0, -3.0));
    let g = scaled_field(h, |x: &Point<2>| Vector::<2>::new(x[1], 0.0));
    assert_eq!(g(&Point::<2>::new(0.0, 4.0), 1.0), Vector::<2>::new(8.0, 0.0));
    let p = pressure::<3>(Constant(2.0));
    assert_eq!(
        p(&Point::<3>::zeros(), &Vector::<3>::new(0.0, 0.0, 1.0), 0.0),
        Vector::<3>::new(0.0, 0.0, -2.0)
    );
}

fn max_distance_error<const D: usize>(motion: &RigidMotion<D>, points: &[Point<D>], t: f64) -> f64 {
    let moved: Vec<Point<D>> = points.iter().map(|x| motion.position(x, t)).collect();
    let mut err: f64 = 0.0;
    for i in 0..points.len() {
        for j in 0..i {
            let d0 = (points[i] - points[j]).norm();
            let d1 = (moved[i] - moved[j]).norm();
            err = err.max((d1 - d0).abs() / d0);
        }
    }
    err
}

#[test]
fn rigid_motion_2d_preserves_distances_and_moves_the_centre_by_the_translation() {
    let angle = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, 1.2)]).expect("angle"); // large angle
    let c = Point::<2>::new(0.3, -0.7);
    let motion = RigidMotion::<2>::rotation(c, angle).with_translation([
        Arc::new(Constant(0.5)) as Arc<dyn LoadHistory>,
        Arc::new(FnHistory::new(|t| -t)),
    ]);
    let points: Vec<Point<2>> = (0..12)
        .map(|k| Point::<2>::new((k as f64 * 0.7).sin() * 2.0, (k as f64 * 1.3).cos() - k as f64 * 0.1))
        .collect();
    for t in [0.0, 0.3, 1.0, 4.0] {
        let err = max_distance_error(&motion, &points, t);
        assert!(err < 1e-14, "t = {t}: distance error {err:e}");
        // the centre only translates
        let uc = motion.displacement(&c, t);
        assert!((uc - Vector::<2>::new(0.5, -t)).norm() < 1e-15);
    }
    // a quarter turn about the origin maps (1, 0) to (0, 1)
    let quarter = RigidMotion::<2>::rotation(Point::<2>::zeros(), Constant(std::f64::consts::FRAC_PI_2));
    let u = quarter.displacement(&Point::<2>::new(1.0, 0.0), 0.0);
    assert!((u - Vector::<2>::new(-1.0, 1.0)).norm() < 1e-15, "{u:?}");
    // small angles: the displacement is θ × (x − c) to first order, accurately
    let tiny = RigidMotion::<2>::rotation(Point::<2>::zeros(), Constant(1e-9));
    let u = tiny.displacement(&Point::<2>::new(1.0, 0.0), 0.0);
    assert!((u[1] - 1e-9).abs() < 1e-24 && (u[0] + 0.5e-18).abs() < 1e-30, "{u:?}");
}

#[test]
fn rigid_motion_3d_preserves_distances_and_fixes_the_axis() {
    let c = Point::<3>::new(0.1, 0.2, -0.3);
    let axis = Vector::<3>::new(1.0, 2.0, 2.0); // normalised inside
    let motion = RigidMotion::<3>::rotation(c, axis, FnHistory::new(|t| 2.0 * t))
        .expect("rotation")
        .with_translation_component(2, Constant(-0.25))
        .expect("component");
    assert!((motion.axis().norm() - 1.0).abs() < 1e-15);
    let points: Vec<Point<3>> = (0..10)
        .map(|k| {
            let s = k as f64;
            Point::<3>::new((0.9 * s).sin(), (1.7 * s).cos(), 0.2 * s - 1.0)
        })
        .collect();
    for t in [0.0, 0.1, 0.8, 3.0] {
        let err = max_distance_error(&motion, &points, t);
        assert!(err < 1e-14, "t = {t}: distance error {err:e}");
        // points on the axis only translate
        let on_axis = c + motion.axis() * 1.7;
        let u = motion.displacement(&on_axis, t);
        assert!((u - Vector::<3>::new(0.0, 0.0, -0.25)).norm() < 1e-14, "t = {t}: {u:?}");
    }
    // right-handed: a quarter turn about z maps x to y
    let q = RigidMotion::<3>::rotation(
        Point::<3>::zeros(),
        Vector::<3>::z(),
        Constant(std::f64::consts::FRAC_PI_2),
    )
    .expect("rotation");
    let x = q.position(&Point::<3>::new(1.0, 0.0, 0.0), 0.0);
    assert!((x - Point::<3>::new(0.0, 1.0, 0.0)).norm() < 1e-15, "{x:?}");
    // a pure translation
    let tr = RigidMotion::<3>::translation([
        Arc::new(Constant(1.0)),
        Arc::new(Constant(2.0)),
        Arc::new(FnHistory::new(|t| t)),
    ]);
    assert_eq!(tr.displacement(&Point::<3>::new(9.0, 9.0, 9.0), 3.0), Vector::<3>::new(1.0, 2.0, 3.0));
}
