//! The sagittal knee model (`synovia::knee2d`) on a coarse mesh over the whole ISO 14243-1
//! gait cycle (41 poses): at every step the contact resultant balances the applied load within
//! 0.5 % and the contact solution satisfies the KKT conditions; the same for the total knee
//! replacement variant (`Knee2d::tkr_coarse`, 21 poses).

use synovia::knee2d::{cycle_times, iso14243_axial_force, iso14243_flexion, Knee2d};
use synovia::prelude::LoadHistory;

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
