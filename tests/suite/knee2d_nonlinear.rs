//! The sagittal knee with neo-Hookean cartilage in finite strain (`nonlinear_cycle`,
//! docs/nonlinear.md) against the linear cycle on the coarse mesh, at a swing pose (168 N) and
//! at the first load peak (2600 N): the two peak pressures agree within 1 % at the light load
//! and differ by more than 1 % at the peak; every pose balances the load, satisfies the KKT
//! conditions and leaves (almost) no gap on its own deformed configuration.

use synovia_models::knee2d::{nonlinear_cycle, Knee2d};

#[test]
fn neo_hookean_knee_matches_linear_at_light_load_and_differs_at_the_peak() {
    let knee = Knee2d::coarse();
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    // swing (168 N, 43.5° flexion) and the first load peak (2600 N at 13 %)
    let times = [0.75, 0.13];
    let linear = knee.run(&times, solver.as_ref(), |_| Ok(())).expect("linear cycle");
    let guesses: Vec<f64> = linear.iter().map(|s| s.approach).collect();
    let nonlinear =
        nonlinear_cycle(&knee, &times, &guesses, solver.as_ref(), Knee2d::nonlinear_newton_params())
            .expect("neo-Hookean cycle");
    assert_eq!(nonlinear.len(), times.len());
    for h in &nonlinear {
        let s = &h.step;
        assert!(s.balance_error <= 1e-3, "t = {}: load balance error {}", s.time, s.balance_error);
        assert!(s.kkt <= 1e-8, "t = {}: KKT residual {}", s.time, s.kkt);
        // the gap evaluated on the deformed configuration of the solution
        assert!(
            h.mesh_size > 0.0 && h.gap_error <= 1e-3 * h.mesh_size,
            "t = {}: gap {} mm",
            s.time,
            h.gap_error
        );
        assert!(h.penetration <= 1e-3 * h.mesh_size, "t = {}: penetration {} mm", s.time, h.penetration);
    }
    let ratio = |i: usize| nonlinear[i].step.peak_pressure / linear[i].peak_pressure;
    println!("NH/linear peak pressure: {:.4} at 168 N, {:.4} at 2600 N", ratio(0), ratio(1));
    assert!((ratio(0) - 1.0).abs() <= 0.01, "light load: NH/linear peak ratio {}", ratio(0));
    assert!((ratio(1) - 1.0).abs() > 0.01, "peak load: NH/linear peak ratio {}", ratio(1));
    // the neo-Hookean layer stiffens in compression: a smaller approach at the peak load
    assert!(
        nonlinear[1].step.approach < 0.95 * linear[1].approach,
        "approach NH {} vs linear {}",
        nonlinear[1].step.approach,
        linear[1].approach
    );
}

/// `SpatialField` reproduces a linear field exactly inside the mesh and on its boundary circles
/// (P1 interpolation, extrapolation over the chords) and takes the nearest node's value beyond
/// the sector.
#[test]
fn spatial_field_interpolates_linear_fields_exactly() {
    use synovia::mesh::math::{Point, Vector};
    use synovia_models::knee2d::SpatialField;
    let centre = Point::<2>::new(0.0, 22.5);
    let mesh = synovia::mesh::generators::layered_arc_2d(centre, &[20.0, 22.5], (-2.5, -1.0), 40, &[3])
        .expect("arc")
        .pop()
        .expect("layer");
    let f = |x: &Point<2>| Vector::<2>::new(0.3 * x[0] - 0.1 * x[1] + 1.0, 0.2 * x[1] + 0.05 * x[0]);
    let values: Vec<Vector<2>> = mesh.nodes().iter().map(f).collect();
    let field = SpatialField::new(&mesh, &values, centre);
    // points inside the layer and on its circles (beyond the chords of the boundary:
    // extrapolated on the nearest cell, exact for a linear field)
    for k in 0..50 {
        let a = -2.45 + 1.4 * k as f64 / 49.0;
        let r = 20.0 + 2.5 * ((k * 7) % 11) as f64 / 10.0;
        let x = Point::<2>::new(centre[0] + r * a.cos(), centre[1] + r * a.sin());
        let v = field.value(&x);
        assert!((v - f(&x)).norm() < 1e-9, "at {x:?}: {v:?} vs {:?}", f(&x));
    }
    // outside the sector: the nearest node's value
    let far = Point::<2>::new(centre[0] + 21.0 * 0.5_f64.cos(), centre[1] + 21.0 * 0.5_f64.sin());
    let nearest =
        mesh.nodes().iter().min_by(|p, q| (*p - far).norm().total_cmp(&(*q - far).norm())).expect("node");
    assert!((field.value(&far) - f(nearest)).norm() < 1e-12);
}

/// The state carried between poses and the load control (`nonlinear_cycle_with`): keeping
/// the femur's field in space or rotating it with the femur are two starts of the same Newton
/// problem, and the secant iteration on the approach or the load control inside the Newton
/// iteration two ways to the same balanced pose, so all give the same poses (to the geometry
/// tolerance); the field kept in space is the better start, and the load control solves each
/// pose after the first in one Newton solve.
#[test]
fn carried_state_and_load_control_give_the_same_poses() {
    use synovia_models::knee2d::{nonlinear_cycle_with, Carry, FemurFrame, NonlinearKneeStep};
    let knee = Knee2d::coarse();
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let times = [0.1, 0.13, 0.16];
    let linear = knee.run(&times, solver.as_ref(), |_| Ok(())).expect("linear cycle");
    let guesses: Vec<f64> = linear.iter().map(|s| s.approach).collect();
    let run = |carry, control| {
        nonlinear_cycle_with(
            &knee,
            &times,
            &guesses,
            solver.as_ref(),
            Knee2d::nonlinear_newton_params(),
            carry,
            control,
            FemurFrame::Placed,
        )
        .expect("neo-Hookean cycle")
    };
    let space = run(Carry::InSpace, false);
    let rotate = run(Carry::Rotate, false);
    let controlled = run(Carry::InSpace, true);
    for other in [&rotate, &controlled] {
        for (a, b) in space.iter().zip(other.iter()) {
            let (pa, pb) = (a.step.peak_pressure, b.step.peak_pressure);
            assert!((pa - pb).abs() <= 1e-3 * pa, "t = {}: peak {pa} vs {pb}", a.step.time);
            assert!(b.step.balance_error <= 1e-3 && b.step.kkt <= 1e-8, "t = {}", b.step.time);
            assert!(b.gap_error <= 1e-3 * b.mesh_size, "t = {}: gap {}", b.step.time, b.gap_error);
        }
    }
    let newton = |r: &[NonlinearKneeStep]| -> usize { r[1..].iter().map(|h| h.step.solver_iterations).sum() };
    println!(
        "Newton iterations after the first pose: in space {}, rotated {}, load control {}",
        newton(&space),
        newton(&rotate),
        newton(&controlled)
    );
    assert!(newton(&space) <= newton(&rotate));
    // the first pose ramps with the secant iteration; every later one under load control, one solve
    assert!(!controlled[0].load_controlled && space.iter().all(|h| !h.load_controlled));
    assert!(controlled[1..].iter().all(|h| h.load_controlled && h.step.solves == 1));
    // every Newton iteration under load control takes at least one trial of the approach; the
    // poses without it none
    assert!(controlled[1..].iter().all(|h| h.load_control_trials >= h.step.solver_iterations));
    assert!(controlled[0].load_control_trials == 0 && space.iter().all(|h| h.load_control_trials == 0));
    assert!(newton(&controlled) < newton(&space));
}

/// The last geometry pass ends at the settled increment (`NewtonParams::settled_increment`,
/// `knee2d`: the geometry tolerance 1e-4): once a rebuild has moved the solution by at most
/// the geometry tolerance, a full step of at most that size ends the iteration instead of the
/// residual tolerance 1e-7. The poses are the same to the geometry's accuracy, balanced and
/// KKT, in fewer Newton iterations; a value outside (0, 1) is refused.
#[test]
fn the_settled_increment_ends_the_last_pass_at_the_geometry_accuracy() {
    use synovia_models::knee2d::{nonlinear_cycle_with, Carry, FemurFrame, NonlinearKneeStep};
    let knee = Knee2d::coarse();
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let times = [0.1, 0.13, 0.16, 0.7];
    let linear = knee.run(&times, solver.as_ref(), |_| Ok(())).expect("linear cycle");
    let guesses: Vec<f64> = linear.iter().map(|s| s.approach).collect();
    let params = Knee2d::nonlinear_newton_params();
    assert_eq!(params.settled_increment, Some(params.geometry_tolerance));
    let run = |p| {
        nonlinear_cycle_with(
            &knee,
            &times,
            &guesses,
            solver.as_ref(),
            p,
            Carry::InSpace,
            true,
            FemurFrame::Placed,
        )
    };
    let settled = run(params).expect("settled increment");
    let residual = run(params.with_settled_increment(None)).expect("residual tolerance only");
    for (a, b) in settled.iter().zip(&residual) {
        let (pa, pb) = (a.step.peak_pressure, b.step.peak_pressure);
        assert!((pa - pb).abs() <= 1e-4 * pb, "t = {}: peak {pa} vs {pb}", a.step.time);
        let (da, db) = (a.step.approach, b.step.approach);
        assert!((da - db).abs() <= 1e-4 * db, "t = {}: approach {da} vs {db}", a.step.time);
        assert!(a.step.balance_error <= 1e-3 && a.step.kkt <= 1e-8, "t = {}", a.step.time);
        assert!(a.gap_error <= 1e-3 * a.mesh_size, "t = {}: gap {}", a.step.time, a.gap_error);
    }
    let newton = |r: &[NonlinearKneeStep]| -> usize { r.iter().map(|h| h.step.solver_iterations).sum() };
    println!(
        "Newton iterations: settled increment {}, residual only {}",
        newton(&settled),
        newton(&residual)
    );
    assert!(newton(&settled) < newton(&residual));
    for bad in [0.0, 1.0, -1e-3, f64::NAN] {
        let p = params.with_settled_increment(Some(bad));
        assert!(
            matches!(p.check(), Err(synovia::nonlinear::NonlinearError::InvalidParameter(ref m)) if m.contains("settled")),
            "{bad}: {:?}",
            p.check()
        );
    }
}

/// The femur in its own frame, placed at each pose (`FemurFrame::Placed`: its meshes and the
/// tangent's factorisation kept, the contact geometry that of the placed deformed femur),
/// solves the poses of the femur whose meshes are rotated between poses
/// (`FemurFrame::MovedMesh`): the same peak pressures, approaches and contact lengths to
/// the geometry's accuracy, with either carry of the state, in fewer factorisations.
#[test]
fn the_placed_femur_solves_the_poses_of_the_moved_meshes() {
    use synovia_models::knee2d::{nonlinear_cycle_with, Carry, FemurFrame, NonlinearKneeStep};
    let knee = Knee2d::coarse();
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    // loading response, the first peak, and swing (flexion changing by 5–12° per pose)
    let times = [0.1, 0.13, 0.7, 0.75, 0.8];
    let linear = knee.run(&times, solver.as_ref(), |_| Ok(())).expect("linear cycle");
    let guesses: Vec<f64> = linear.iter().map(|s| s.approach).collect();
    let run = |carry, frame| {
        nonlinear_cycle_with(
            &knee,
            &times,
            &guesses,
            solver.as_ref(),
            Knee2d::nonlinear_newton_params(),
            carry,
            true,
            frame,
        )
        .expect("neo-Hookean cycle")
    };
    let factorisations = |r: &[NonlinearKneeStep]| -> usize { r.iter().map(|h| h.factorisations).sum() };
    for carry in [Carry::InSpace, Carry::Rotate] {
        let placed = run(carry, FemurFrame::Placed);
        let moved = run(carry, FemurFrame::MovedMesh);
        for (a, b) in placed.iter().zip(&moved) {
            let t = a.step.time;
            let close = |x: f64, y: f64| (x - y).abs() <= 1e-3 * y.abs();
            assert!(close(a.step.peak_pressure, b.step.peak_pressure), "t = {t}: peaks {a:?} vs {b:?}");
            assert!(close(a.step.approach, b.step.approach), "t = {t}: approaches");
            assert!((a.step.contact_length - b.step.contact_length).abs() <= a.mesh_size, "t = {t}: lengths");
            assert!(a.step.balance_error <= 1e-3 && a.step.kkt <= 1e-8, "t = {t}");
            assert!(a.gap_error <= 1e-3 * a.mesh_size && a.penetration <= 1e-3 * a.mesh_size, "t = {t}");
        }
        println!(
            "{carry:?}: factorisations placed {}, moved meshes {}",
            factorisations(&placed),
            factorisations(&moved)
        );
        assert!(factorisations(&placed) < factorisations(&moved), "{carry:?}");
    }
}
