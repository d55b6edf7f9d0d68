//! Contact verification (docs/model.md §9) and solver behaviour: Hertz 2D/3D, Cattaneo–Mindlin,
//! agreement of the solvers, mesh-independence of PDAS, KKT conditions of every solution, and
//! the error paths.

use std::sync::Arc;

use synovia::contact::StaticContact;
use synovia::contact_ops::operators::{ContactPair, FnObstacle, PlaneObstacle, SphereObstacle};
use synovia::contact_ops::{ContactError, ContactParams};
use synovia::prelude::*;
use synovia::solvers::{by_name, by_name_with, SOLVER_NAMES};
use synovia_models::hertz::{cattaneo_mindlin_2d, hertz2d, hertz2d_model, hertz3d, Hertz2d, Hertz3d};

#[test]
fn hertz_2d_cylinder_on_rigid_flat_matches_the_analytic_solution() {
    let solver = by_name("pdas").expect("solver");
    let run = hertz2d(&Hertz2d { levels: 12, ..Default::default() }, solver.as_ref()).expect("solve");
    println!("{}", run.json());
    assert!(2.0 * run.a_exact / run.h >= 40.0, "needs ≥ 40 contact nodes across the contact width");
    assert!(run.a_rel_err() < 0.02, "a: {} vs {}", run.a, run.a_exact);
    assert!(run.p0_rel_err() < 0.02, "p0: {} vs {}", run.p0, run.p0_exact);
    assert!(run.pressure_l2_err <= 0.03, "pressure L2 error {}", run.pressure_l2_err);
    assert!(run.kkt < 1e-8, "KKT residual {}", run.kkt);
}

#[test]
fn hertz_2d_two_cylinders_of_different_stiffness() {
    let solver = by_name("pdas").expect("solver");
    let run = hertz2d(&Hertz2d { levels: 12, e2: Some(3.0), ..Default::default() }, solver.as_ref())
        .expect("solve");
    println!("{}", run.json());
    assert!(2.0 * run.a_exact / run.h >= 40.0);
    assert!(run.a_rel_err() < 0.02 && run.p0_rel_err() < 0.02, "{run:?}");
    assert!(run.pressure_l2_err <= 0.03, "{run:?}");
    assert!(run.kkt < 1e-8);
}

#[test]
fn hertz_3d_hemisphere_on_rigid_flat() {
    let solver = by_name("pdas").expect("solver");
    let run = hertz3d(&Hertz3d::default(), solver.as_ref()).expect("solve");
    println!("{}", run.json());
    assert!(run.a_rel_err() < 0.05, "a: {} vs {}", run.a, run.a_exact);
    assert!(run.p0_rel_err() < 0.05, "p0: {} vs {}", run.p0, run.p0_exact);
    assert!(run.kkt < 1e-8);
}

#[test]
fn cattaneo_mindlin_partial_slip_at_half_the_friction_limit() {
    let solver = by_name("pdas").expect("solver");
    let p = Hertz2d { levels: 12, push: 0.02, ..Default::default() };
    let run = cattaneo_mindlin_2d(&p, 0.3, 0.5, solver.as_ref()).expect("solve");
    println!("{}", run.json());
    assert!((run.q_ratio - 0.5).abs() < 0.005, "Q/(μP) = {}", run.q_ratio);
    assert!(run.c_rel_err() < 0.05, "c: {} vs {}", run.c, run.c_exact);
    assert!(run.traction_l2_err < 0.05, "traction L2 error {}", run.traction_l2_err);
    assert!(run.coulomb_excess <= 1e-10 * run.p0_exact, "|q| exceeds μp by {}", run.coulomb_excess);
    assert!(run.kkt < 1e-8);
}

#[test]
fn pdas_iterations_barely_grow_under_refinement() {
    let solver = by_name("pdas").expect("solver");
    let its: Vec<usize> = [8, 10, 12, 14]
        .iter()
        .map(|&levels| {
            hertz2d(&Hertz2d { levels, ..Default::default() }, solver.as_ref()).expect("solve").iterations
        })
        .collect();
    println!("PDAS iterations (nested start) over 4 refinements: {its:?}");
    assert!(its[3] <= its[0] + 3, "{its:?}");
}

/// Frictionless and Tresca problems solved by all four solvers: the solutions agree to 1e-6
/// relative in `U`, `Λ_n`, `Λ_t`, and each satisfies the KKT conditions.
#[test]
fn the_solvers_agree_on_frictionless_and_tresca_problems() {
    let p = Hertz2d { levels: 8, e2: Some(1.0), push: 0.02, ..Default::default() };
    let (model, mut pairs) = hertz2d_model(&p).expect("model");
    pairs[0].friction = 0.3;
    let sc = StaticContact::new(&model, &pairs, Default::default()).expect("factorise");
    let tight = ContactParams::default().with_tolerance(1e-10).with_max_iterations(5000);
    // normal state and slip bounds from PDAS
    let pdas = by_name("pdas").expect("pdas");
    let normal = sc.solve(&model, 0.0, pdas.as_ref(), None, None, None).expect("normal");
    let gc = sc.geometry().slip_bounds_from_pressure(&normal.solution.lambda_n);
    for (case, slip, shift) in [("frictionless", None, 0.0), ("tresca", Some(gc.as_slice()), 0.004)] {
        let prev = slip.map(|_| normal.displacement.as_slice());
        let mut sols = Vec::new();
        for name in SOLVER_NAMES {
            let s = match *name {
                "au-pdas" => by_name_with(name, tight.with_rho_scale(0.2)),
                _ => by_name_with(name, tight),
            }
            .expect("solver");
            let res = sc
                .solve(&model, shift, s.as_ref(), slip, prev, None)
                .unwrap_or_else(|e| panic!("{case} {name}: {e}"));
            assert!(res.kkt.satisfied(1e-8), "{case} {name}: {:?}", res.kkt);
            sols.push((name, res));
        }
        let (_, reference) = &sols[0];
        if slip.is_some() {
            let stick = reference.solution.lambda_t.iter().filter(|l| l.abs() < 1.0 - 1e-6).count();
            assert!(
                stick > 0 && stick < reference.solution.lambda_t.len(),
                "{case}: need stick and slip cells"
            );
        }
        let rel = |a: &[f64], b: &[f64]| {
            let scale = a.iter().fold(0.0_f64, |m, x| m.max(x.abs())).max(1e-300);
            a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
        };
        for (name, res) in &sols[1..] {
            let du = rel(&reference.solution.u, &res.solution.u);
            let dn = rel(&reference.solution.lambda_n, &res.solution.lambda_n);
            let dt = if res.solution.lambda_t.is_empty() {
                0.0
            } else {
                rel(&reference.solution.lambda_t, &res.solution.lambda_t)
            };
            println!(
                "{case}: {name} vs pdas: U {du:.1e}, Λn {dn:.1e}, Λt {dt:.1e}, iterations {}",
                res.solution.report.iterations
            );
            assert!(
                du < 1e-6 && dn < 1e-6 && dt < 1e-6,
                "{case}: {name} differs from pdas: {du:e} {dn:e} {dt:e}"
            );
        }
    }
}

#[test]
fn non_convergence_returns_the_residual_history() {
    let p = Hertz2d { levels: 8, nested: false, ..Default::default() };
    let (model, pairs) = hertz2d_model(&p).expect("model");
    let mut sc = StaticContact::new(&model, &pairs, Default::default()).expect("factorise");
    sc.set_nested_iteration(None);
    let s = by_name_with("pdas", ContactParams::default().with_max_iterations(2)).expect("solver");
    match sc.solve(&model, 0.0, s.as_ref(), None, None, None) {
        Err(ContactError::NoConvergence { iterations, history, .. }) => {
            assert_eq!(iterations, 2);
            assert_eq!(history.len(), 2);
            assert!(history[1].normal > 0.0);
        }
        other => panic!("expected NoConvergence, got {other:?}"),
    }
}

/// A block whose whole boundary is prescribed is pushed into a rigid flat: no free unknown can
/// undo the penetration.
#[test]
fn infeasible_prescribed_penetration_is_an_error() {
    let mut mesh = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Clamped).expect("part");
    mesh.set_part_kind("bottom", BoundaryKind::Prescribed).expect("part");
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, _| x[1] < 1e-9).expect("contact");
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    model.prescribe(b, "bottom", |_, _| Vector::<2>::new(0.0, -0.1)).expect("prescribe");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
    let pairs = vec![ContactPair::rigid("block-flat", b, "contact", Arc::new(flat))];
    let sc = StaticContact::new(&model, &pairs, Default::default()).expect("factorise");
    for name in SOLVER_NAMES {
        let s = by_name(name).expect("solver");
        match sc.solve(&model, 0.0, s.as_ref(), None, None, None) {
            Err(ContactError::Infeasible(msg)) => assert!(!msg.is_empty()),
            other => panic!("{name}: expected Infeasible, got {other:?}"),
        }
    }
}

#[test]
fn unmatched_node_to_node_pairs_name_the_nodes() {
    let lower = rectangle(0.0, 1.0, -0.5, 0.0, 6, 3, Grading::Uniform, Grading::Uniform).expect("mesh");
    let upper = rectangle(0.0, 1.0, 0.0, 0.5, 5, 3, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut model = Model::<2>::new();
    let m = Arc::new(plane_strain(1.0, 0.3).expect("ok"));
    let u = model.add_body("upper", upper, m.clone()).expect("body");
    let l = model.add_body("lower", lower, m).expect("body");
    let pairs = vec![ContactPair::node_to_node("upper-lower", u, "bottom", l, "top")];
    match synovia::contact_ops::operators::ContactGeometry::new(&model, &pairs) {
        Err(ContactError::UnmatchedNodes { pair, count, nodes, .. }) => {
            assert_eq!(pair, "upper-lower");
            assert!(count > 0 && !nodes.is_empty());
        }
        other => panic!("expected UnmatchedNodes, got {other:?}"),
    }
}

/// A block pressed onto a rigid flat described three ways (plane, user-defined distance, a
/// huge sphere) gives the same contact force; and an obstacle facing away is rejected.
#[test]
fn rigid_obstacles_from_signed_distances() {
    let build = || {
        let mut mesh = rectangle(0.0, 1.0, 0.0, 0.5, 8, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
        mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("part");
        mesh.set_part_kind("bottom", BoundaryKind::Contact).expect("part");
        let mut model = Model::<2>::new();
        let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
        model.prescribe(b, "top", |_, _| Vector::<2>::new(0.0, -0.01)).expect("prescribe");
        (model, b)
    };
    let solver = by_name("pdas").expect("solver");
    let mut forces = Vec::new();
    let obstacles: Vec<Arc<dyn synovia::contact_ops::operators::SignedDistance<2>>> = vec![
        Arc::new(
            PlaneObstacle::new(Point::<2>::new(0.0, -0.001), Vector::<2>::new(0.0, 1.0)).expect("plane"),
        ),
        Arc::new(FnObstacle::new(|x: &Point<2>| (x[1] + 0.001, Vector::<2>::new(0.0, 1.0)))),
        Arc::new(SphereObstacle { center: Point::<2>::new(0.5, -1e6 - 0.001), radius: 1e6, cavity: false }),
    ];
    for obstacle in obstacles {
        let (model, b) = build();
        let pairs = vec![ContactPair::rigid("flat", b, "bottom", obstacle)];
        let sc = StaticContact::new(&model, &pairs, Default::default()).expect("factorise");
        let res = sc.solve(&model, 0.0, solver.as_ref(), None, None, None).expect("solve");
        assert!(res.kkt.satisfied(1e-8), "{:?}", res.kkt);
        forces.push(res.normal_force(sc.geometry(), 0..sc.geometry().len()));
    }
    assert!(forces[0] > 0.0);
    // the closure is the same plane: identical; the sphere sags by x²/2R ≈ 1e-7 over the block
    assert!((forces[1] - forces[0]).abs() < 1e-12 * forces[0], "{forces:?}");
    assert!((forces[2] - forces[0]).abs() < 1e-4 * forces[0], "{forces:?}");
    // a plane whose free side is below the body: its normal faces away from the contact part
    let (model, b) = build();
    let wrong = PlaneObstacle::new(Point::<2>::new(0.0, 1.0), Vector::<2>::new(0.0, -1.0)).expect("plane");
    let pairs = vec![ContactPair::rigid("wrong", b, "bottom", Arc::new(wrong))];
    assert!(matches!(
        StaticContact::new(&model, &pairs, Default::default()),
        Err(ContactError::InvalidPair { .. })
    ));
}

/// Two contact pairs at once: a block resting on two rigid steps of different heights; every
/// step carries load and the contact forces balance the reaction of the prescribed top.
#[test]
fn several_contact_pairs_in_one_model() {
    let mut mesh = rectangle(0.0, 2.0, 0.0, 0.5, 16, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
    mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("part");
    mesh.add_boundary_part("left_foot", BoundaryKind::Contact, |x, n| n[1] < -0.5 && x[0] < 0.6)
        .expect("part");
    mesh.add_boundary_part("right_foot", BoundaryKind::Contact, |x, n| n[1] < -0.5 && x[0] > 1.4)
        .expect("part");
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3).expect("ok"))).expect("body");
    model.prescribe(b, "top", |_, _| Vector::<2>::new(0.0, -0.01)).expect("prescribe");
    let low = PlaneObstacle::new(Point::<2>::new(0.0, -0.002), Vector::<2>::new(0.0, 1.0)).expect("plane");
    let high = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
    let pairs = vec![
        ContactPair::rigid("left", b, "left_foot", Arc::new(low)),
        ContactPair::rigid("right", b, "right_foot", Arc::new(high)),
    ];
    let sc = StaticContact::new(&model, &pairs, Default::default()).expect("factorise");
    let solver = by_name("pdas").expect("solver");
    let res = sc.solve(&model, 0.0, solver.as_ref(), None, None, None).expect("solve");
    assert!(res.kkt.satisfied(1e-8), "{:?}", res.kkt);
    let geo = sc.geometry();
    let fl = res.normal_force(geo, geo.pairs[0].1.clone());
    let fr = res.normal_force(geo, geo.pairs[1].1.clone());
    assert!(fl > 0.0 && fr > fl, "left {fl}, right {fr}");
}

/// 3D Tresca (block on a curved rigid foundation, stick and slip cells): all solvers agree.
#[test]
fn the_solvers_agree_in_3d_with_friction() {
    use synovia::contact_ops::testing::BlockOnFoundation;
    let owned = BlockOnFoundation {
        n: 6,
        push: 0.02,
        shift: 0.01,
        curvature: 0.5,
        slip_bound: Some(0.01),
        ..Default::default()
    }
    .build::<3>()
    .expect("problem");
    let problem = owned.problem();
    let tight = ContactParams::default().with_tolerance(1e-10).with_max_iterations(5000);
    let mut sols = Vec::new();
    for name in SOLVER_NAMES {
        let params = if *name == "au-pdas" { tight.with_rho_scale(0.2) } else { tight };
        let s = by_name_with(name, params).expect("solver");
        let sol = s
            .solve(&problem, &synovia::contact_ops::SolveContext::new())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let kkt = synovia::contact_ops::check_kkt(&problem, &sol.u, &sol.lambda_n, &sol.lambda_t);
        assert!(kkt.satisfied(1e-8), "{name}: {kkt:?}");
        sols.push(sol);
    }
    let stick =
        sols[0].lambda_t.chunks(2).filter(|l| (l[0] * l[0] + l[1] * l[1]).sqrt() < 1.0 - 1e-6).count();
    assert!(stick > 0 && stick < sols[0].lambda_t.len() / 2, "need stick and slip cells, stick = {stick}");
    let rel = |a: &[f64], b: &[f64]| {
        let scale = a.iter().fold(0.0_f64, |m, x| m.max(x.abs())).max(1e-300);
        a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
    };
    for (name, s) in SOLVER_NAMES.iter().zip(&sols).skip(1) {
        let (du, dn, dt) =
            (rel(&sols[0].u, &s.u), rel(&sols[0].lambda_n, &s.lambda_n), rel(&sols[0].lambda_t, &s.lambda_t));
        println!("3D tresca: {name} vs pdas: U {du:.1e}, Λn {dn:.1e}, Λt {dt:.1e}");
        assert!(du < 1e-6 && dn < 1e-6 && dt < 1e-6, "{name}: {du:e} {dn:e} {dt:e}");
    }
}

#[test]
fn contact_state_is_written_for_paraview_and_reads_back() {
    let p = Hertz2d { levels: 6, ..Default::default() };
    let (model, pairs) = hertz2d_model(&p).expect("model");
    let sc = StaticContact::new(&model, &pairs, Default::default()).expect("factorise");
    let solver = by_name("pdas").expect("solver");
    let res = sc.solve(&model, 0.0, solver.as_ref(), None, None, None).expect("solve");
    let dir = std::env::temp_dir().join(format!("synovia-contact-vtu-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("hertz.vtu");
    synovia::output::contact_vtu(&model, sc.geometry(), &res, synovia::io::Encoding::Ascii)
        .expect("writer")
        .write(&path)
        .expect("write");
    let data = synovia::io::read_vtu(&path).expect("read");
    let pressure = data.pieces[0].point_field("contact_pressure").expect("field");
    let mut n_active = 0;
    for (r, node) in sc.geometry().nodes.iter().enumerate() {
        assert_eq!(pressure.values[node.node.1], res.solution.lambda_n[r]);
        n_active += usize::from(res.solution.lambda_n[r] > 0.0);
    }
    let active = data.pieces[0].point_field("contact_active").expect("field");
    assert_eq!(active.values.iter().filter(|&&v| v == 1.0).count(), n_active);
    std::fs::remove_dir_all(&dir).ok();
}
