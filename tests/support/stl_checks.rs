//! The checks of the STL fuzzers, shared by the proptest target (`fuzz_stl` of
//! `synovia-scenario`) and the libFuzzer target (`fuzz/fuzz_targets/stl.rs`): bytes go
//! through `parse_stl`, `TriangleSurface::scaled` (×1 and ×1000, metres to millimetres), the
//! three `SurfaceObstacle` constructors a scenario's `stl` shape uses (open patch, closed solid,
//! one level of Loop subdivision) and a concave fillet; every obstacle built must answer
//! closest-point and signed-distance queries around the surface with finite distances, closest
//! points and gradients of unit length. See `docs/fuzzing.md`.
//!
//! The including module brings `parse_stl`, `SurfaceObstacle`, `SignedDistance`, `Point` and
//! `TriangleSurface` into scope (the facade's paths in a test, the crates' in the fuzz
//! workspace).

use super::{parse_stl, Point, SignedDistance, SurfaceObstacle, TriangleSurface};

/// Query points around the surface: its vertices' bounding box, widened, on a 3 × 3 × 3 grid,
/// and a few far points.
pub fn query_points(surface: &TriangleSurface) -> Vec<Point<3>> {
    let (mut lo, mut hi) = (Point::<3>::repeat(f64::INFINITY), Point::<3>::repeat(f64::NEG_INFINITY));
    for v in surface.vertices() {
        lo = lo.inf(v);
        hi = hi.sup(v);
    }
    let span = (hi - lo).amax().max(1e-3);
    let mut points = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                let t = |a: usize, l: f64, h: f64| l - 0.25 * span + (h - l + 0.5 * span) * a as f64 / 2.0;
                points.push(Point::<3>::new(t(i, lo.x, hi.x), t(j, lo.y, hi.y), t(k, lo.z, hi.z)));
            }
        }
    }
    points.push(lo + (hi - lo) * 0.5 + Point::<3>::new(1e3 * span, 0.0, 0.0));
    points.push(Point::<3>::new(0.0, 0.0, 0.0));
    points
}

/// `Err` naming what is wrong with the answers of `obstacle` at `points`.
pub fn check_answers(obstacle: &SurfaceObstacle, points: &[Point<3>]) -> Result<(), String> {
    for x in points {
        let p = obstacle.closest_point(x);
        let ok = p.distance.is_finite()
            && p.point.iter().all(|v| v.is_finite())
            && (p.gradient.norm() - 1.0).abs() < 1e-6;
        if !ok {
            return Err(format!("closest point of {x:?}: {p:?}"));
        }
        let (d, g) = obstacle.distance_and_gradient(x);
        if !d.is_finite() || !g.iter().all(|v| v.is_finite()) {
            return Err(format!("signed distance of {x:?}: {d}, {g:?}"));
        }
    }
    Ok(())
}

/// Parse, scale, build the obstacles a scenario can build, query them; typed errors are
/// formatted and accepted. `Err(message)` on a non-finite answer (a panic propagates).
pub fn exercise_stl(bytes: &[u8]) -> Result<(), String> {
    let surface = match parse_stl(bytes) {
        Ok(s) => s,
        Err(e) => {
            let _ = e.to_string();
            return Ok(());
        }
    };
    for factor in [1.0, 1000.0] {
        let scaled = match surface.scaled(factor) {
            Ok(s) => s,
            Err(e) => {
                let _ = e.to_string();
                continue;
            }
        };
        let points = query_points(&scaled);
        let built = [
            SurfaceObstacle::new(scaled.clone()),
            SurfaceObstacle::solid(scaled.clone()),
            SurfaceObstacle::smoothed_solid(scaled.clone(), 1, 30f64.to_radians()),
        ];
        for obstacle in built {
            match obstacle {
                Ok(o) => {
                    check_answers(&o, &points)?;
                    match o.with_concave_fillet(0.1, f64::INFINITY) {
                        Ok(f) => check_answers(&f, &points)?,
                        Err(e) => {
                            let _ = e.to_string();
                        }
                    }
                }
                Err(e) => {
                    let _ = e.to_string();
                }
            }
        }
    }
    Ok(())
}
