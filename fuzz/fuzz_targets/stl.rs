//! libFuzzer target for STL surfaces as a scenario's `stl` shape uses them: any bytes go
//! through `parse_stl`, `TriangleSurface::scaled` (×1000, metres to millimetres), the three
//! `SurfaceObstacle` constructors (open patch, closed solid, one level of Loop subdivision)
//! and a concave fillet; every obstacle built answers closest-point queries around the
//! surface. Any panic, abort, out-of-memory or time-out is a finding, and so is a
//! non-finite distance, gradient or closest point (see `docs/fuzzing.md`).
#![no_main]

mod alloc_guard;

use libfuzzer_sys::fuzz_target;
use synovia_contact::operators::SignedDistance;
use synovia_contact::SurfaceObstacle;
use synovia_mesh::{Point, TriangleSurface};

#[global_allocator]
static ALLOC: alloc_guard::Guard = alloc_guard::Guard;

fn query(obstacle: &SurfaceObstacle, surface: &TriangleSurface) {
    let (mut lo, mut hi) = (Point::<3>::repeat(f64::INFINITY), Point::<3>::repeat(f64::NEG_INFINITY));
    for v in surface.vertices() {
        lo = lo.inf(v);
        hi = hi.sup(v);
    }
    let span = (hi - lo).amax().max(1e-3);
    for k in 0..=8 {
        let s = k as f64 / 8.0;
        let x = lo + (hi - lo) * s + Point::<3>::new(0.3, -0.2, 0.1) * span * (s - 0.5);
        let p = obstacle.closest_point(&x);
        assert!(
            p.distance.is_finite()
                && p.point.iter().all(|v| v.is_finite())
                && (p.gradient.norm() - 1.0).abs() < 1e-6,
            "closest point of {x:?}: {p:?}"
        );
        let (d, g) = obstacle.distance_and_gradient(&x);
        assert!(d.is_finite() && g.iter().all(|v| v.is_finite()), "signed distance of {x:?}: {d}, {g:?}");
    }
}

fuzz_target!(|data: &[u8]| {
    let surface = match synovia_io::parse_stl(data) {
        Ok(s) => s,
        Err(e) => {
            let _ = e.to_string();
            return;
        }
    };
    let surface = match surface.scaled(1000.0) {
        Ok(s) => s,
        Err(e) => {
            let _ = e.to_string();
            return;
        }
    };
    for built in [
        SurfaceObstacle::new(surface.clone()),
        SurfaceObstacle::solid(surface.clone()),
        SurfaceObstacle::smoothed_solid(surface.clone(), 1, 30f64.to_radians()),
    ] {
        match built {
            Ok(o) => {
                query(&o, &surface);
                match o.with_concave_fillet(0.1, f64::INFINITY) {
                    Ok(f) => query(&f, &surface),
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
});
