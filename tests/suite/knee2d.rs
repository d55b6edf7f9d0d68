//! The sagittal knee model (`synovia_models::knee2d`) on a coarse mesh over the whole ISO 14243-1
//! gait cycle (41 poses): at every step the contact resultant balances the applied load within
//! 0.5 % and the contact solution satisfies the KKT conditions; the same for the total knee
//! replacement variant (`Knee2d::tkr_coarse`, 21 poses).

use synovia::prelude::LoadHistory;
use synovia_models::knee2d::{cycle_times, iso14243_axial_force, iso14243_flexion, Knee2d};

#[test]
fn iso_tables_have_the_standard_features() {
    let f = iso14243_axial_force().expect("force table");
    let th = iso14243_flexion().expect("flexion table");
    assert!((f.value(0.13) - 2600.0).abs() < 1e-9 && (f.value(0.50) - 2600.0).abs() < 1e-9);
    assert!((f.value(0.8) - 168.0).abs() < 1e-9);
    let max_flex = (0..=1000).map(|i| th.value(i as f64 / 1000.0)).fold(0.0, f64::max);
    assert!((max_flex.to_degrees() - 58.0).abs() < 1e-6, "max flexion {}", max_flex.to_degrees());
    assert!(th.value(0.0).abs() < 1e-12 && th.value(1.0).abs() < 1e-12);
}

#[test]
fn knee2d_coarse_cycle_balances_load_and_satisfies_kkt() {
    let knee = Knee2d::coarse();
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    // the whole cycle: 40 uniform poses plus the first load peak (13 %)
    let times = cycle_times(40);
    let mut kkt_checked = 0;
    let steps = knee
        .run(&times, solver.as_ref(), |pose| {
            assert!(pose.result.kkt.satisfied(1e-8), "t = {}: KKT {:?}", pose.step.time, pose.result.kkt);
            kkt_checked += 1;
            Ok(())
        })
        .expect("cycle");
    assert_eq!(kkt_checked, times.len());
    for s in &steps {
        assert!(s.balance_error <= 5e-3, "t = {}: load balance error {}", s.time, s.balance_error);
        assert!(
            s.contact_shear_per_mm.abs() <= 1e-2 * s.load_per_mm,
            "t = {}: shear {}",
            s.time,
            s.contact_shear_per_mm
        );
        assert!(s.peak_pressure > 0.5 && s.peak_pressure < 20.0, "t = {}: peak {}", s.time, s.peak_pressure);
    }
    // more load, more pressure: the 2600 N peaks above the 168 N swing
    let p =
        |t: f64| steps.iter().find(|s| (s.time - t).abs() < 1e-12).map(|s| s.peak_pressure).expect("step");
    assert!(p(0.13) > 3.0 * p(0.725) && p(0.5) > 3.0 * p(0.0));
}

#[test]
fn tkr2d_coarse_cycle_balances_load_and_satisfies_kkt() {
    let tkr = Knee2d::tkr_coarse();
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let times = cycle_times(20);
    let mut kkt_checked = 0;
    let steps = tkr
        .run(&times, solver.as_ref(), |pose| {
            assert!(pose.result.kkt.satisfied(1e-8), "t = {}: KKT {:?}", pose.step.time, pose.result.kkt);
            kkt_checked += 1;
            Ok(())
        })
        .expect("cycle");
    assert_eq!(kkt_checked, times.len());
    for s in &steps {
        assert!(s.balance_error <= 5e-3, "t = {}: load balance error {}", s.time, s.balance_error);
        // CoCr on UHMWPE: tens of MPa at the load peaks, several MPa in swing
        assert!(s.peak_pressure > 3.0 && s.peak_pressure < 60.0, "t = {}: peak {}", s.time, s.peak_pressure);
    }
    let peak = steps.iter().map(|s| s.peak_pressure).fold(0.0, f64::max);
    assert!(peak > 20.0 && peak < 50.0, "peak insert pressure {peak}");
}

/// The cycle's body-frame femur (one factorisation, rows `R(θ)ᵀ n`, prescribed motion rotated
/// into the femur frame) solves the same problem as the femur re-meshed in the pose
/// (`Knee2d::model`): at fixed approaches and poses up to the 58° swing maximum, the same
/// contact nodes, pressures and (rotated) displacements to rounding.
#[test]
fn body_frame_femur_equals_the_remeshed_pose() {
    use synovia::contact::StaticContact;
    use synovia::fem::ElasticParams;
    let knee = Knee2d::coarse();
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let mut cycle = knee.cycle().expect("cycle");
    let flexion = iso14243_flexion().expect("flexion");
    for (t, delta) in [(0.0, 0.3), (0.13, 0.6), (0.5, 0.5), (0.725, 0.2), (0.87, 0.25)] {
        let theta = flexion.value(t);
        // body frame: place the femur, solve at approach δ
        let pose = cycle.solve_pose(t, solver.as_ref(), Some(delta)).expect("pose");
        let (model_f, contact_f) = (pose.model, pose.contact);
        let framed = contact_f.solve(model_f, delta, solver.as_ref(), None, None, None).expect("framed");
        // reference: the femur re-meshed in the pose
        let (model_r, pairs_r) = knee.model(t).expect("posed model");
        let contact_r = StaticContact::new(&model_r, &pairs_r, ElasticParams::default()).expect("factorise");
        let reference =
            contact_r.solve(&model_r, delta, solver.as_ref(), None, None, None).expect("reference");
        let (gf, gr) = (contact_f.geometry(), contact_r.geometry());
        assert_eq!(gf.len(), gr.len(), "t = {t}: contact nodes");
        let pmax = reference.solution.lambda_n.iter().copied().fold(0.0, f64::max);
        assert!(pmax > 0.1, "t = {t}: no contact in the reference ({pmax})");
        for r in 0..gf.len() {
            assert_eq!(gf.nodes[r].node, gr.nodes[r].node);
            assert!((gf.nodes[r].gap - gr.nodes[r].gap).abs() <= 1e-10, "t = {t}: gap at {r}");
            let (a, b) = (framed.solution.lambda_n[r], reference.solution.lambda_n[r]);
            assert!((a - b).abs() <= 1e-7 * pmax, "t = {t}: Λ_n at {r}: {a} vs {b}");
        }
        assert!(framed.kkt.satisfied(1e-8), "t = {t}: {:?}", framed.kkt);
        // displacements: femur bodies rotated into space, tibia as is
        let umax = reference.displacement.iter().flatten().map(|u| u.norm()).fold(0.0, f64::max);
        for (b, (uf, ur)) in framed.displacement.iter().zip(&reference.displacement).enumerate() {
            let placement = gf.placement(synovia::fem::BodyId(b));
            if b < 2 {
                assert!((placement.rotation()[(1, 0)] - theta.sin()).abs() < 1e-14, "femur placed at θ");
            } else {
                assert!(placement.is_identity());
            }
            for (a, r) in uf.iter().zip(ur) {
                assert!((placement.to_global(a) - r).norm() <= 1e-7 * umax, "t = {t}: body {b}");
            }
        }
    }
}

/// The VTU of a pose writes the femur where it is placed (nodes `R(θ)(x − c) + c`) with its
/// displacements turned into space (`R(θ) u`), and the tibia as meshed.
#[test]
fn pose_output_writes_the_placed_femur() {
    let knee = Knee2d::coarse();
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let mut cycle = knee.cycle().expect("cycle");
    let t = 0.725; // swing: 57.8° of flexion
    let pose = cycle.solve_pose(t, solver.as_ref(), None).expect("pose");
    let dir = std::env::temp_dir().join(format!("synovia-knee-vtu-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("pose.vtu");
    synovia::output::contact_vtu(
        pose.model,
        pose.contact.geometry(),
        &pose.result,
        synovia::io::Encoding::Ascii,
    )
    .expect("writer")
    .write(&path)
    .expect("write");
    let data = synovia::io::read_vtu(&path).expect("read");
    let theta = iso14243_flexion().expect("flexion").value(t);
    assert!(theta.to_degrees() > 50.0);
    let c = knee.condyle_centre();
    let (s, co) = theta.sin_cos();
    for (b, body) in pose.model.bodies().iter().enumerate() {
        let piece = &data.pieces[b];
        let u = piece.point_field("displacement").expect("displacement");
        for (i, x) in body.mesh.nodes().iter().enumerate() {
            let (expected, ue) = if b < 2 {
                let d = x - c;
                let ul = pose.result.displacement[b][i];
                (
                    [c[0] + co * d[0] - s * d[1], c[1] + s * d[0] + co * d[1]],
                    [co * ul[0] - s * ul[1], s * ul[0] + co * ul[1]],
                )
            } else {
                ([x[0], x[1]], [pose.result.displacement[b][i][0], pose.result.displacement[b][i][1]])
            };
            let p = piece.points[i];
            assert!(
                (p[0] - expected[0]).abs() < 1e-9 && (p[1] - expected[1]).abs() < 1e-9,
                "body {b} node {i}"
            );
            let k = u.components;
            let (ux, uy) = (u.values[k * i], u.values[k * i + 1]);
            assert!((ux - ue[0]).abs() < 1e-12 && (uy - ue[1]).abs() < 1e-12, "body {b} node {i}: u");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Bad placements are typed errors: not a proper rotation, not one per body, tied bodies
/// placed apart.
#[test]
fn bad_body_placements_are_errors() {
    use synovia::contact_ops::operators::{BodyPlacement, ContactGeometry};
    use synovia::mesh::math::{Tensor, Vector};
    let zero = Vector::<2>::zeros();
    assert!(BodyPlacement::new(Tensor::<2>::new(1.0, 0.0, 0.0, -1.0), zero).is_err(), "reflection");
    assert!(BodyPlacement::new(Tensor::<2>::identity() * 1.01, zero).is_err(), "scaling");
    assert!(BodyPlacement::new(Tensor::<2>::identity(), Vector::<2>::new(f64::NAN, 0.0)).is_err());
    assert!(BodyPlacement::<2>::planar_rotation(Vector::<2>::zeros(), f64::INFINITY).is_err());
    let knee = Knee2d::coarse();
    let (model, pairs, femur) =
        knee.body_frame_model(synovia::prelude::SharedValue::new(0.0)).expect("model");
    let turned = BodyPlacement::planar_rotation(knee.condyle_centre(), 0.3).expect("rotation");
    let mut placements = vec![BodyPlacement::identity(); model.bodies().len()];
    assert!(ContactGeometry::new_placed(&model, &pairs, &placements[1..]).is_err(), "one per body");
    placements[femur[1].0] = turned; // cartilage turned, its tied bone not
    let err = ContactGeometry::new_placed(&model, &pairs, &placements).expect_err("tied apart");
    assert!(err.to_string().contains("tied"), "{err}");
    placements[femur[0].0] = turned;
    assert!(ContactGeometry::new_placed(&model, &pairs, &placements).is_ok());
}
