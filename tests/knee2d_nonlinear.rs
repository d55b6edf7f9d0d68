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
