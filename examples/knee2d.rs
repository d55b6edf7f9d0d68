//! # Sagittal tibiofemoral contact over the ISO 14243-1 gait cycle
//!
//! A plane-strain sagittal slice of one knee compartment ([`synovia_models::knee2d`]): a femoral
//! condyle (bone arc, subchondral radius 20 mm, with a 2.5 mm cartilage layer) on a tibial
//! plateau (bone block with a 2.5 mm cartilage layer), cartilage E = 10 MPa, ν = 0.45, bone
//! E = 800 MPa, ν = 0.3; frictionless node-to-segment contact between the two (non-matching)
//! cartilage surfaces. The femur is flexed by the ISO 14243-1:2009 flexion angle (rotation about
//! the condyle centre) and pushed down until the contact resultant equals the ISO axial force
//! divided by an effective condyle width of 30 mm. Both ISO curves are approximations digitised
//! from the standard (`synovia_models::knee2d::ISO14243_*`). See `docs/knee2d.md`.
//!
//! Every step checks the load balance (contact resultant vs applied load, ≤ 0.5 %) and the KKT
//! conditions of the contact solution, prints the peak cartilage pressure, and writes
//! `OUT/knee2d.pvd` (+ one `.vtu` per step), `OUT/knee2d.csv` and
//! `OUT/force_and_peak_pressure.svg`. Ends with one JSON line.
//!
//! Run: `cargo run --release --example knee2d [OUT_DIR] [STEPS] [--cartilage linear|neo-hookean]`
//! (defaults `out/knee2d`, 40, `linear`). With `--cartilage neo-hookean` both cartilage layers
//! are compressible neo-Hookean in finite strain (same E, ν), the contact geometry is rebuilt on
//! the deformed configuration (`synovia_models::knee2d::nonlinear_cycle`, docs/nonlinear.md;
//! each pose starts from the approach of the linear cycle, run first), and the example writes
//! `knee2d.csv` and the plot but no `.vtu` files.

use std::time::Instant;

mod knee_common;
use knee_common::{csv_text, plot, run_cycle};
use synovia_models::knee2d::{cycle_times, hertz_estimate, nonlinear_cycle, Knee2d, KneeError};

fn main() -> Result<(), KneeError> {
    let mut positional = Vec::new();
    let mut neo_hookean = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--cartilage" {
            neo_hookean = match args.next().as_deref() {
                Some("linear") => false,
                Some("neo-hookean") => true,
                other => {
                    return Err(format!("--cartilage takes `linear` or `neo-hookean`, got {other:?}").into())
                }
            };
        } else {
            positional.push(a);
        }
    }
    let out = positional.first().cloned().unwrap_or_else(|| "out/knee2d".to_string());
    let n: usize = positional.get(1).map(|s| s.parse()).transpose()?.unwrap_or(40);
    std::fs::create_dir_all(&out)?;
    let start = Instant::now();
    let knee = Knee2d::default();
    if neo_hookean {
        return run_neo_hookean(&knee, &out, n, start);
    }
    let (steps, dofs, series) = run_cycle(&knee, "knee2d", &out, n)?;

    let csv = std::path::Path::new(&out).join("knee2d.csv");
    std::fs::write(&csv, csv_text(&steps))?;
    let svg = std::path::Path::new(&out).join("force_and_peak_pressure.svg");
    plot(&svg, &steps, knee.width, "knee2d: ISO 14243-1 gait cycle", "peak cartilage pressure (right axis)")?;

    let max_err = steps.iter().map(|s| s.balance_error).fold(0.0, f64::max);
    let peak = steps.iter().max_by(|a, b| a.peak_pressure.total_cmp(&b.peak_pressure)).ok_or("no steps")?;
    let min_peak = steps.iter().map(|s| s.peak_pressure).fold(f64::INFINITY, f64::min);
    let max_kkt = steps.iter().map(|s| s.kkt).fold(0.0, f64::max);
    let (a_h, p0_h) = hertz_estimate(
        2600.0 / knee.width,
        knee.condyle_bone_radius + knee.femur_cartilage,
        knee.cartilage.0,
        knee.cartilage.1,
    );
    println!(
        "peak cartilage pressure over the cycle {:.3} MPa at {:.1} % (flexion {:.1}°, F = {:.0} N); swing minimum {:.3} MPa",
        peak.peak_pressure,
        100.0 * peak.time,
        peak.flexion_deg,
        peak.load_n,
        min_peak
    );
    println!(
        "half-space Hertz estimate at 2600 N (both cartilages, no bone): a = {a_h:.2} mm, p0 = {p0_h:.3} MPa"
    );
    println!(
        "wrote {}, {} ({} steps) and {}",
        csv.display(),
        series.pvd_path().display(),
        steps.len(),
        svg.display()
    );
    println!("open the .pvd in ParaView: colour by contact_pressure, Warp By Vector on displacement, play the time steps");
    let total = start.elapsed().as_secs_f64();
    println!(
        "{{\"problem\":\"knee2d\",\"dofs\":{dofs},\"steps\":{},\"solves\":{},\"max_load_balance_error\":{max_err:.3e},\"max_peak_pressure_mpa\":{:.4},\"max_peak_time\":{:.4},\"min_peak_pressure_mpa\":{min_peak:.4},\"max_kkt\":{max_kkt:.2e},\"width_mm\":{},\"total_s\":{total:.3}}}",
        steps.len(),
        steps.iter().map(|s| s.solves).sum::<usize>(),
        peak.peak_pressure,
        peak.time,
        knee.width
    );
    Ok(())
}

/// The cycle with neo-Hookean cartilage: per pose the table row, then `knee2d.csv`, the plot
/// and one JSON line.
fn run_neo_hookean(knee: &Knee2d, out: &str, n: usize, start: Instant) -> Result<(), KneeError> {
    let solver = synovia::solvers::by_name("pdas")?;
    let times = cycle_times(n);
    // the linear cycle (0.3 s) gives each pose's starting approach
    let guesses: Vec<f64> =
        knee.run(&times, solver.as_ref(), |_| Ok(()))?.iter().map(|s| s.approach).collect();
    let nonlinear =
        nonlinear_cycle(knee, &times, &guesses, solver.as_ref(), Knee2d::nonlinear_newton_params())?;
    println!("| cycle % | flexion ° | F (N) | peak p (MPa) | contact length (mm) | δ (mm) | solves | Newton | gap / h | KKT | s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for h in &nonlinear {
        let s = &h.step;
        println!(
            "| {:.1} | {:.1} | {:.0} | {:.3} | {:.2} | {:.5} | {} | {} | {:.1e} | {:.1e} | {:.2} |",
            100.0 * s.time,
            s.flexion_deg,
            s.load_n,
            s.peak_pressure,
            s.contact_length,
            s.approach,
            s.solves,
            s.solver_iterations,
            h.gap_error / h.mesh_size,
            s.kkt,
            s.seconds
        );
        if s.balance_error > 5e-3 {
            return Err(format!("t = {}: load balance error {:.2e} > 0.5 %", s.time, s.balance_error).into());
        }
        if s.kkt > 1e-8 {
            return Err(format!("t = {}: KKT residual {:.2e}", s.time, s.kkt).into());
        }
    }
    let steps: Vec<_> = nonlinear.iter().map(|h| h.step.clone()).collect();
    let csv = std::path::Path::new(out).join("knee2d.csv");
    std::fs::write(&csv, csv_text(&steps))?;
    let svg = std::path::Path::new(out).join("force_and_peak_pressure.svg");
    plot(
        &svg,
        &steps,
        knee.width,
        "knee2d, neo-Hookean cartilage: ISO 14243-1 gait cycle",
        "peak cartilage pressure (right axis)",
    )?;
    let peak = steps.iter().max_by(|a, b| a.peak_pressure.total_cmp(&b.peak_pressure)).ok_or("no steps")?;
    let max_err = steps.iter().map(|s| s.balance_error).fold(0.0, f64::max);
    let max_kkt = steps.iter().map(|s| s.kkt).fold(0.0, f64::max);
    let gap = nonlinear.iter().map(|h| h.gap_error / h.mesh_size).fold(0.0, f64::max);
    println!("wrote {} and {} ({} steps)", csv.display(), svg.display(), steps.len());
    println!(
        "{{\"problem\":\"knee2d\",\"cartilage\":\"neo-hookean\",\"steps\":{},\"solves\":{},\"newton_iterations\":{},\"max_load_balance_error\":{max_err:.3e},\"max_peak_pressure_mpa\":{:.4},\"max_peak_time\":{:.4},\"max_gap_error_per_h\":{gap:.2e},\"max_kkt\":{max_kkt:.2e},\"width_mm\":{},\"total_s\":{:.3}}}",
        steps.len(),
        steps.iter().map(|s| s.solves).sum::<usize>(),
        steps.iter().map(|s| s.solver_iterations).sum::<usize>(),
        peak.peak_pressure,
        peak.time,
        knee.width,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
