//! Rigid obstacles defined by triangle surfaces (STL): the signed distance of a tessellated
//! sphere converges to the sphere's, and a block pressed onto it reproduces the analytic
//! sphere obstacle's contact force within the tessellation error, measured at two
//! tessellations (issue 16).

use synovia::contact_ops::obstacle::SignedDistance;
use synovia::contact_ops::SurfaceObstacle;
use synovia::mesh::TriangleSurface;
use synovia::prelude::*;

const R: Real = 2.0;

/// Deterministic points in the box `[-3, 3]³` around the origin (a simple LCG).
fn points(n: usize) -> Vec<Point<3>> {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 6.0 - 3.0
    };
    (0..n).map(|_| Point::<3>::new(next(), next(), next())).collect()
}

/// `|φ_h − φ| ≤ s_h` with the sagitta `s_h = R − √(R² − ρ²)` of a face whose circumradius is
/// `ρ ≤ L/√3` (`L`: the longest edge, the faces are acute): the faces lie between the sphere
/// and the sphere shrunk by `s_h`.
#[test]
fn tessellated_sphere_distance_converges_with_the_right_sign() {
    let centre = Point::<3>::new(0.3, -0.2, 0.1);
    let exact = SphereObstacle::new(centre, R, false).expect("sphere");
    let mut last = Real::INFINITY;
    for k in [3, 4, 5] {
        let surface = TriangleSurface::icosphere(centre, R, k).expect("icosphere");
        let longest = (0..surface.len())
            .flat_map(|t| {
                let c = surface.corners(t);
                [(c[0] - c[1]).norm(), (c[1] - c[2]).norm(), (c[2] - c[0]).norm()]
            })
            .fold(0.0, Real::max);
        let rho = longest / 3.0_f64.sqrt();
        let sagitta = R - (R * R - rho * rho).sqrt();
        let obstacle = SurfaceObstacle::solid(surface).expect("closed");
        let mut worst: Real = 0.0;
        for x in points(2000) {
            let (phi, phi_exact) = (obstacle.distance(&x), exact.distance(&x));
            let err = (phi - phi_exact).abs();
            assert!(err <= sagitta * (1.0 + 1e-9) + 1e-12, "k = {k}, x = {x:?}: φ {phi} vs {phi_exact}");
            if phi_exact.abs() > sagitta {
                assert_eq!(phi.signum(), phi_exact.signum(), "sign at {x:?}");
            }
            if phi_exact.abs() > 0.2 {
                let g = obstacle.gradient(&x);
                assert!((g - exact.gradient(&x)).norm() < 0.2, "gradient at {x:?}");
                assert!((g.norm() - 1.0).abs() < 1e-12);
            }
            worst = worst.max(err);
        }
        assert!(worst < last / 3.0, "k = {k}: error {worst} after {last}");
        last = worst;
    }
}

/// A pose moves the surface; the tree is not rebuilt.
#[test]
fn posed_surface_equals_the_moved_surface() {
    let surface = TriangleSurface::icosphere(Point::<3>::zeros(), 1.0, 3).expect("icosphere");
    let rotation = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
    let shift = Vector::<3>::new(0.5, -1.0, 2.0);
    let posed = SurfaceObstacle::solid(surface.clone()).expect("solid").with_pose(rotation, shift);
    let moved = SurfaceObstacle::solid(surface.transformed(&rotation, &shift)).expect("solid");
    for x in points(300) {
        let (a, b) = (posed.closest_point(&x), moved.closest_point(&x));
        assert!((a.distance - b.distance).abs() < 1e-12, "{x:?}");
        assert!((a.gradient - b.gradient).norm() < 1e-9, "{x:?}");
        assert!((a.point - b.point).norm() < 1e-12);
    }
}

#[test]
fn open_or_inconsistent_surfaces_are_refused_where_a_solid_is_needed() {
    let s = TriangleSurface::icosphere(Point::<3>::zeros(), 1.0, 2).expect("icosphere");
    let mut tris = s.triangles().to_vec();
    tris.truncate(tris.len() - 2);
    let open = TriangleSurface::new(s.vertices().to_vec(), tris).expect("open");
    let err = SurfaceObstacle::solid(open.clone()).expect_err("open");
    assert!(err.to_string().contains("open"), "{err}");
    SurfaceObstacle::new(open).expect("an open patch is a valid obstacle surface");
    let err = SurfaceObstacle::solid(s.flipped()).expect_err("inward");
    assert!(err.to_string().contains("inward"), "{err}");
    // two overlapping closed spheres in one surface: closed and consistent, but it crosses
    // itself, so it bounds no solid
    let other = s.transformed(&nalgebra::Rotation3::identity(), &Vector::<3>::new(0.5, 0.0, 0.0));
    let mut vertices = s.vertices().to_vec();
    let shift = vertices.len();
    vertices.extend_from_slice(other.vertices());
    let mut tris = s.triangles().to_vec();
    tris.extend(other.triangles().iter().map(|t| [t[0] + shift, t[1] + shift, t[2] + shift]));
    let crossing = TriangleSurface::new(vertices, tris).expect("two spheres");
    let err = SurfaceObstacle::solid(crossing).expect_err("self-intersecting");
    assert!(err.to_string().contains("cross") || err.to_string().contains("intersect"), "{err}");
}

/// Normal force of a block `[−½, ½]² × [0, ½]` (E = 1000, ν = 0.3) whose top is pushed down
/// by 0.02 onto a rigid ball of radius 2 below it.
fn block_force(obstacle: impl SignedDistance<3> + 'static) -> Real {
    let mesh =
        box_mesh([-0.5, -0.5, 0.0], [0.5, 0.5, 0.5], [12, 12, 6], [Grading::Uniform; 3]).expect("mesh");
    let mut joint = JointModel::<3>::new();
    let block = joint.add_body("block", mesh, isotropic(1.0e3, 0.3).expect("material")).expect("body");
    joint.prescribe(block, "top", Vector::<3>::new(0.0, 0.0, -1.0), Constant(0.02)).expect("top");
    joint.contact_rigid("ball", block, "bottom", obstacle, 0.0).expect("pair");
    let mut session = joint.prepare().expect("prepare");
    let report = session.solve_static(0.0).expect("solve");
    assert!(report.kkt < 1e-8, "KKT {}", report.kkt);
    session.record().expect("record").pairs[0].normal_force
}

#[test]
fn tessellated_ball_reproduces_the_analytic_ball_within_the_tessellation_error() {
    let centre = Point::<3>::new(0.0, 0.0, -R);
    let exact = block_force(SphereObstacle::new(centre, R, false).expect("sphere"));
    assert!(exact > 0.0);
    let mut errors = Vec::new();
    for k in [4, 6] {
        let surface = TriangleSurface::icosphere(centre, R, k).expect("icosphere");
        let force = block_force(SurfaceObstacle::solid(surface).expect("solid"));
        errors.push(((force - exact) / exact).abs());
    }
    eprintln!(
        "block on a tessellated ball: force {exact:.6e} (analytic), relative errors k = 4, 6: {errors:?}"
    );
    // the faces lie up to the sagitta (k = 4: 2.4e-3, k = 6: 1.5e-4) below the sphere
    assert!(errors[1] < errors[0] / 4.0, "errors {errors:?}");
    assert!(errors[1] < 0.02, "errors {errors:?}");
}

/// A smoothed solid (Loop subdivision of a coarse tessellation): within `δ` of its control
/// surface, with normals nearer the sphere's, and its bounded query (`distance_and_gradient_within`, used beyond a
/// pair's search distance) is exact up to `reach` — inside the solid too — and a lower bound
/// above `reach` beyond it.
#[test]
fn smoothed_solid_turns_with_the_sphere_and_its_bounded_query_is_exact_within_reach() {
    let centre = Point::<3>::new(0.3, -0.2, 0.1);
    let sphere = SphereObstacle::new(centre, R, false).expect("sphere");
    let control = TriangleSurface::icosphere(centre, R, 2).expect("icosphere");
    let coarse = SurfaceObstacle::solid(control.clone()).expect("control solid");
    let smooth = SurfaceObstacle::smoothed_solid(control, 2, 0.5).expect("smoothed");
    assert_eq!(smooth.surface().len(), 320 * 16);
    let delta = smooth.smoothing_bound().expect("bound");
    assert!(delta > 0.0 && delta < 0.5, "δ = {delta}");
    // the smoothed surface stays within δ of the control surface, and its normals (the
    // gradient near the surface) turn with the sphere's instead of jumping at facet edges
    let pts = points(400);
    let (mut turn_coarse, mut turn_smooth): (Real, Real) = (0.0, 0.0);
    for x in &pts {
        let (dc, ds) = (coarse.distance(x), smooth.distance(x));
        assert!((dc - ds).abs() <= delta, "{dc} vs {ds}");
        if sphere.distance(x).abs() < 0.3 {
            let exact = sphere.gradient(x);
            turn_coarse = turn_coarse.max(coarse.gradient(x).angle(&exact));
            turn_smooth = turn_smooth.max(smooth.gradient(x).angle(&exact));
        }
    }
    assert!(turn_smooth < 0.5 * turn_coarse, "normal error: smoothed {turn_smooth} vs control {turn_coarse}");
    // bounded queries against the exact one, near, far and deep inside (reach 0.2 < R)
    for reach in [0.2, 1.0] {
        let (mut exact, mut bounded) = (0, 0);
        for x in pts.iter().chain([centre].iter()) {
            let (d, g) = smooth.distance_and_gradient(x);
            let (db, gb) = smooth.distance_and_gradient_within(x, reach);
            assert!((gb.norm() - 1.0).abs() < 1e-12);
            if d <= reach {
                assert_eq!((d, g), (db, gb), "within reach {reach} at {x:?}");
                exact += 1;
            } else {
                assert!(db > reach && db <= d, "{db} not in ({reach}, {d}]");
                bounded += usize::from(db < d);
            }
        }
        assert!(exact > 50 && bounded > 50, "reach {reach}: {exact} exact, {bounded} bounded");
    }
    // a posed smoothed solid answers in the world frame
    let rotation = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::y_axis(), 0.4);
    let shift = Vector::<3>::new(1.0, 0.5, -0.2);
    let posed = smooth.clone().with_pose(rotation, shift);
    for x in pts.iter().take(50) {
        let moved = rotation * x + shift;
        let (a, b) =
            (smooth.distance_and_gradient_within(x, 0.2), posed.distance_and_gradient_within(&moved, 0.2));
        assert!((a.0 - b.0).abs() < 1e-12 && (rotation * a.1 - b.1).norm() < 1e-12);
    }
}
