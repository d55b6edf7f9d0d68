//! # The sagittal knee with hyperelastic cartilage: linear vs neo-Hookean over the gait cycle
//!
//! The `knee2d` model ([`synovia_models::knee2d`], docs/knee2d.md) run twice over the same
//! poses of the ISO 14243-1 cycle, in one process: with linear (small-strain) cartilage (the
//! `knee2d` cycle: femur in its body frame, one factorisation), and with compressible
//! neo-Hookean cartilage in total Lagrangian finite strain (same small-strain constants,
//! E = 10 MPa, ν = 0.45; bone linear), the contact geometry rebuilt on the deformed
//! configuration ([`synovia_models::knee2d::nonlinear_cycle`]: one model, the state carried
//! from pose to pose). Each pose is load-controlled to the ISO force: the linear one by the
//! secant iteration on the femur's approach, the neo-Hookean one (after the first pose) by
//! choosing the approach inside each Newton iteration. Prints per pose the peak
//! cartilage pressure, contact length and approach of both runs, the Newton work and the gap
//! left on the deformed configuration, then the cost of each run (the linear one timed as the
//! fastest of three runs, the neo-Hookean one of two, which must agree to the last bit) and
//! their ratio, also in the JSON line (docs/nonlinear.md).
//!
//! Run: `cargo run --release --example knee2d_nonlinear [STEPS] [--moved-mesh]` (default 40
//! uniform steps + the 13 % peak = 41 poses, the poses of the `knee2d` example). The femur is
//! placed at each pose in its own frame (`FemurFrame::Placed`, the tangent's factorisation
//! kept); `--moved-mesh` rotates its meshes between poses instead (`FemurFrame::MovedMesh`,
//! the way before 2026-11-29), for comparison.

use std::time::Instant;

mod process_cpu;
use process_cpu::process_cpu_s;

use synovia::pdas::Pdas;
use synovia_models::knee2d::{cycle_times, nonlinear_cycle_with, Carry, FemurFrame, Knee2d, KneeError};

fn main() -> Result<(), KneeError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frame =
        if args.iter().any(|a| a == "--moved-mesh") { FemurFrame::MovedMesh } else { FemurFrame::Placed };
    let frame_name = match frame {
        FemurFrame::Placed => "placed",
        FemurFrame::MovedMesh => "moved_mesh",
    };
    let n: usize = match args.iter().find(|a| !a.starts_with("--")) {
        Some(a) => a.parse().map_err(|e| format!("STEPS `{a}`: {e}"))?,
        None => 40,
    };
    if let Some(bad) = args.iter().find(|a| a.starts_with("--") && *a != "--moved-mesh") {
        return Err(format!("unknown option `{bad}` (usage: knee2d_nonlinear [STEPS] [--moved-mesh])").into());
    }
    let knee = Knee2d::default();
    let times = cycle_times(n);
    let solver = Pdas::default();
    // ## Step 1: the linear cycle (one factorisation, femur in its body frame), timed as the
    // fastest of three runs (the machine is shared: a single short run is easily slowed down,
    // which would flatter the ratio)
    let mut linear_s = f64::INFINITY;
    let mut linear = Vec::new();
    let c0 = process_cpu_s();
    for _ in 0..3 {
        let t0 = Instant::now();
        linear = knee.run(&times, &solver, |_| Ok(()))?;
        linear_s = linear_s.min(t0.elapsed().as_secs_f64());
    }
    // CPU time of the process (all threads) per linear cycle: the mean of the three runs
    let linear_cpu_s = (process_cpu_s() - c0) / 3.0;
    // ## Step 2: neo-Hookean cartilage, finite strain, deformed contact geometry; each pose
    // starts from the linear approach. Timed like the linear cycle, as the fastest of its runs
    // (two: a run takes seconds), CPU time the mean; the two runs must give the same figures
    // to the last bit (the cycle is deterministic)
    let guesses: Vec<f64> = linear.iter().map(|s| s.approach).collect();
    let mut nonlinear_s = f64::INFINITY;
    let mut runs = Vec::new();
    let c1 = process_cpu_s();
    for _ in 0..2 {
        let t1 = Instant::now();
        let params = Knee2d::nonlinear_newton_params();
        runs.push(nonlinear_cycle_with(
            &knee,
            &times,
            &guesses,
            &solver,
            params,
            Carry::InSpace,
            true,
            frame,
        )?);
        nonlinear_s = nonlinear_s.min(t1.elapsed().as_secs_f64());
    }
    let nonlinear_cpu_s = (process_cpu_s() - c1) / 2.0;
    let figures = |r: &[synovia_models::knee2d::NonlinearKneeStep]| -> Vec<u64> {
        r.iter()
            .flat_map(|h| {
                [h.step.peak_pressure, h.step.approach, h.step.contact_force_per_mm].map(f64::to_bits)
            })
            .collect()
    };
    if figures(&runs[0]) != figures(&runs[1]) {
        return Err("the two neo-Hookean runs differ: the cycle is not deterministic".into());
    }
    let nonlinear = runs.swap_remove(0);
    // ## Step 3: the comparison
    println!(
        "{:>6} {:>8} {:>9} {:>9} {:>7} {:>8} {:>8} {:>8} {:>8} {:>6} {:>5} {:>9} {:>7}",
        "t",
        "F (N)",
        "p lin",
        "p NH",
        "NH/lin",
        "len lin",
        "len NH",
        "d lin",
        "d NH",
        "Newton",
        "fact",
        "gap/h",
        "KKT NH"
    );
    let mut max_ratio: f64 = 0.0;
    let mut min_ratio = f64::INFINITY;
    for (l, h) in linear.iter().zip(&nonlinear) {
        let s = &h.step;
        let ratio = s.peak_pressure / l.peak_pressure;
        max_ratio = max_ratio.max(ratio);
        min_ratio = min_ratio.min(ratio);
        println!(
            "{:>6.3} {:>8.1} {:>9.4} {:>9.4} {:>7.4} {:>8.3} {:>8.3} {:>8.4} {:>8.4} {:>6} {:>5} {:>9.2e} {:>7.1e}",
            l.time,
            l.load_n,
            l.peak_pressure,
            s.peak_pressure,
            ratio,
            l.contact_length,
            s.contact_length,
            l.approach,
            s.approach,
            s.solver_iterations,
            h.factorisations,
            h.gap_error / h.mesh_size,
            s.kkt
        );
    }
    let peak = |v: &mut dyn Iterator<Item = f64>| v.fold(0.0, f64::max);
    let balance = peak(&mut linear.iter().chain(nonlinear.iter().map(|h| &h.step)).map(|s| s.balance_error));
    let kkt = peak(&mut linear.iter().chain(nonlinear.iter().map(|h| &h.step)).map(|s| s.kkt));
    let gap = peak(&mut nonlinear.iter().map(|h| h.gap_error / h.mesh_size));
    let penetration = peak(&mut nonlinear.iter().map(|h| h.penetration));
    let h = nonlinear.iter().map(|h| h.mesh_size).fold(f64::INFINITY, f64::min);
    let newton: usize = nonlinear.iter().map(|h| h.step.solver_iterations).sum();
    let factorisations: usize = nonlinear.iter().map(|h| h.factorisations).sum();
    let solves: usize = nonlinear.iter().map(|h| h.step.solves).sum();
    let controlled = nonlinear.iter().filter(|h| h.load_controlled).count();
    let trials: usize = nonlinear.iter().map(|h| h.load_control_trials).sum();
    let cost_ratio = nonlinear_s / linear_s;
    let cpu_ratio = nonlinear_cpu_s / linear_cpu_s;
    println!(
        "linear {linear_s:.3} s (fastest of 3), neo-Hookean {nonlinear_s:.2} s (fastest of 2, the same figures to the last bit; {cost_ratio:.1}x); CPU time {linear_cpu_s:.3} s (mean of 3) and {nonlinear_cpu_s:.2} s (mean of 2; {cpu_ratio:.1}x): {solves} Newton solves ({controlled} poses under load control inside the Newton iteration), {newton} Newton iterations, {factorisations} factorisations, {trials} load-control trials"
    );
    println!(
        "{{\"problem\":\"knee2d_nonlinear\",\"femur_frame\":\"{frame_name}\",\"poses\":{},\"peak_pressure_linear_mpa\":{:.4},\"peak_pressure_neo_hookean_mpa\":{:.4},\"min_peak_ratio\":{min_ratio:.4},\"max_peak_ratio\":{max_ratio:.4},\"max_balance_error\":{balance:.3e},\"max_kkt\":{kkt:.3e},\"max_gap_error_per_h\":{gap:.3e},\"h_mm\":{h:.4},\"max_penetration_mm\":{penetration:.3e},\"newton_solves\":{solves},\"load_controlled_poses\":{controlled},\"newton_iterations\":{newton},\"factorisations\":{factorisations},\"load_control_trials\":{trials},\"linear_s\":{linear_s:.3},\"nonlinear_s\":{nonlinear_s:.3},\"cost_ratio\":{cost_ratio:.2},\"linear_cpu_s\":{linear_cpu_s:.3},\"nonlinear_cpu_s\":{nonlinear_cpu_s:.3},\"cpu_ratio\":{cpu_ratio:.2}}}",
        times.len(),
        peak(&mut linear.iter().map(|s| s.peak_pressure)),
        peak(&mut nonlinear.iter().map(|h| h.step.peak_pressure)),
    );
    Ok(())
}
