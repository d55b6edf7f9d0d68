//! # knee2d with neo-Hookean cartilage: the active-set strategies of the Newton iteration
//!
//! The neo-Hookean `knee2d` cycle of `examples/knee2d_nonlinear.rs`
//! ([`synovia_models::knee2d::nonlinear_cycle_with`], state carried in space) run three times
//! over the same poses, with `ActiveSetStrategy::Nested` (each Newton iteration solves its contact
//! problem to convergence with PDAS), `ActiveSetStrategy::Combined` (one PDAS step per
//! Newton iteration) and `ActiveSetStrategy::Outer` (the sets fixed while Newton converges,
//! then updated). The Combined and Outer strategies are not available under load control inside the
//! Newton iteration, so all runs balance the ISO force by the secant iteration on the
//! approach around whole Newton solves (`control = false`). Prints one JSON line per strategy
//! (Newton iterations, factorisations, wall time, max KKT) and the largest relative difference
//! of the per-pose peak pressures, approaches and contact lengths from the Nested run.
//!
//! Run: `cargo run --release --example knee2d_active_sets [STEPS]` (default 8 uniform steps +
//! the 13 % peak).

use std::time::Instant;

use synovia::nonlinear::ActiveSetStrategy;
use synovia::pdas::Pdas;
use synovia_models::knee2d::{
    cycle_times, nonlinear_cycle_with, Carry, FemurFrame, Knee2d, KneeError, NonlinearKneeStep,
};

fn main() -> Result<(), KneeError> {
    let n: usize = std::env::args().nth(1).map(|s| s.parse()).transpose()?.unwrap_or(8);
    let knee = Knee2d::default();
    let times = cycle_times(n);
    let solver = Pdas::default();
    let linear = knee.run(&times, &solver, |_| Ok(()))?;
    let guesses: Vec<f64> = linear.iter().map(|s| s.approach).collect();
    let mut runs: Vec<Vec<NonlinearKneeStep>> = Vec::new();
    let strategies = [
        ("nested", ActiveSetStrategy::Nested),
        ("combined", ActiveSetStrategy::Combined),
        ("outer", ActiveSetStrategy::Outer),
    ];
    for (label, strategy) in strategies {
        let params = Knee2d::nonlinear_newton_params().with_active_sets(strategy);
        let t0 = Instant::now();
        let steps = nonlinear_cycle_with(
            &knee,
            &times,
            &guesses,
            &solver,
            params,
            Carry::InSpace,
            false,
            FemurFrame::Placed,
        )?;
        let wall = t0.elapsed().as_secs_f64();
        let newton: usize = steps.iter().map(|s| s.step.solver_iterations).sum();
        let solves: usize = steps.iter().map(|s| s.step.solves).sum();
        let fact: usize = steps.iter().map(|s| s.factorisations).sum();
        let kkt = steps.iter().map(|s| s.step.kkt).fold(0.0, f64::max);
        let peak = steps.iter().map(|s| s.step.peak_pressure).fold(0.0, f64::max);
        println!(
            "{{\"problem\":\"knee2d_active_sets\",\"strategy\":\"{label}\",\"poses\":{},\"newton_solves\":{solves},\"newton_iterations\":{newton},\"factorisations\":{fact},\"wall_s\":{wall:.3},\"max_kkt\":{kkt:.2e},\"peak_pressure_mpa\":{peak:.5}}}",
            steps.len()
        );
        runs.push(steps);
    }
    for (k, (label, _)) in strategies.iter().enumerate().skip(1) {
        let rel = |f: &dyn Fn(&NonlinearKneeStep) -> f64| {
            runs[0].iter().zip(&runs[k]).map(|(a, b)| ((f(b) - f(a)) / f(a)).abs()).fold(0.0, f64::max)
        };
        println!(
            "{{\"{label}_vs_nested\":{{\"peak_pressure\":{:.2e},\"approach\":{:.2e},\"contact_length\":{:.2e}}}}}",
            rel(&|s| s.step.peak_pressure),
            rel(&|s| s.step.approach),
            rel(&|s| s.step.contact_length)
        );
    }
    Ok(())
}
