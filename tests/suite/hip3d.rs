//! The 3D hip model (`synovia_models::hip3d`) on a coarse mesh at two load levels (swing and the
//! second force peak): the contact resultant balances the hip force within 0.5 %, the contact
//! solution satisfies the KKT conditions, and the pressures are in the physiological range.

use synovia::prelude::LoadHistory;
use synovia_models::hip3d::{hip_force, Hip3d, BODY_WEIGHT_N};

#[test]
fn hip_force_table_is_double_peaked() {
    let f = hip_force().expect("force table");
    let peak1 = f.value(0.15) / BODY_WEIGHT_N;
    let peak2 = f.value(0.48) / BODY_WEIGHT_N;
    assert!(peak1 > 2.5 && peak2 > 2.5 && peak1 <= 3.0 && peak2 <= 3.0, "{peak1} {peak2}");
    assert!(f.value(0.30) < f.value(0.15) && f.value(0.30) < f.value(0.48));
    assert!(f.value(0.8) < 0.5 * BODY_WEIGHT_N);
}

#[test]
fn hip3d_coarse_levels_balance_load_and_satisfy_kkt() {
    let hip = Hip3d::coarse();
    let model = hip.build().expect("model");
    let solver = synovia::solvers::by_name("pdas").expect("solver");
    let mut kkt_checked = 0;
    let steps = hip
        .run(&model, &[0.8, 0.48], solver.as_ref(), |s, res| {
            assert!(res.kkt.satisfied(1e-8), "t = {}: KKT {:?}", s.time, res.kkt);
            kkt_checked += 1;
            Ok(())
        })
        .expect("levels");
    assert_eq!(kkt_checked, 2);
    for s in &steps {
        eprintln!("{s:?}");
        assert!(s.balance_error <= 5e-3, "t = {}: load balance error {}", s.time, s.balance_error);
        // transverse resultant: a discretisation effect of the tetrahedral split (≈ 0.3 % on the
        // default mesh, a few % on this coarse one)
        assert!(s.contact_shear_n <= 0.1 * s.load_n, "t = {}: shear {}", s.time, s.contact_shear_n);
        assert!(s.peak_pressure > 0.2 && s.peak_pressure < 15.0, "t = {}: peak {}", s.time, s.peak_pressure);
        assert!(s.approach > hip.socket_radii[0] - hip.head_radii[2], "t = {}: δ {}", s.time, s.approach);
    }
    // more load: more pressure and a larger contact area
    assert!(steps[1].peak_pressure > 1.5 * steps[0].peak_pressure);
    assert!(steps[1].contact_area > steps[0].contact_area);
}
