//! # Total knee replacement (sagittal slice) over the ISO 14243-1 gait cycle
//!
//! The sagittal model of `synovia_models::knee2d` with the implant materials ([`Knee2d::tkr`]): a
//! 4 mm CoCr femoral component (E = 210 GPa, ν = 0.3, outer radius 24 mm) on the femoral bone
//! arc, on a 9 mm UHMWPE tibial insert (E = 700 MPa, ν = 0.46) on a metal tray block
//! (Ti-6Al-4V, E = 110 GPa, ν = 0.3); frictionless node-to-segment contact between the
//! component and the insert. Same ISO 14243-1 flexion and axial force (effective width 30 mm),
//! same per-pose secant on the vertical approach. See `docs/knee2d.md` ("tkr2d").
//!
//! Every step checks the load balance (≤ 0.5 %) and the KKT conditions, prints the peak insert
//! pressure, and writes `OUT/tkr2d.pvd` (+ one `.vtu` per step), `OUT/tkr2d.csv` and
//! `OUT/force_and_peak_pressure.svg`. Ends with one JSON line.
//!
//! Run: `cargo run --release --example tkr2d [OUT_DIR] [STEPS]` (defaults `out/tkr2d`, 40).

use std::time::Instant;

mod knee_common;
use knee_common::{csv_text, plot, run_cycle};
use synovia_models::knee2d::{hertz_estimate, Knee2d, KneeError};

fn main() -> Result<(), KneeError> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "out/tkr2d".to_string());
    let n: usize = std::env::args().nth(2).map(|s| s.parse()).transpose()?.unwrap_or(40);
    std::fs::create_dir_all(&out)?;
    let start = Instant::now();
    let tkr = Knee2d::tkr();
    let (steps, dofs, series) = run_cycle(&tkr, "tkr2d", &out, n)?;

    let csv = std::path::Path::new(&out).join("tkr2d.csv");
    std::fs::write(&csv, csv_text(&steps))?;
    let svg = std::path::Path::new(&out).join("force_and_peak_pressure.svg");
    plot(
        &svg,
        &steps,
        tkr.width,
        "tkr2d: CoCr on UHMWPE, ISO 14243-1 gait cycle",
        "peak insert pressure (right axis)",
    )?;

    let max_err = steps.iter().map(|s| s.balance_error).fold(0.0, f64::max);
    let peak = steps.iter().max_by(|a, b| a.peak_pressure.total_cmp(&b.peak_pressure)).ok_or("no steps")?;
    let min_peak = steps.iter().map(|s| s.peak_pressure).fold(f64::INFINITY, f64::min);
    let max_kkt = steps.iter().map(|s| s.kkt).fold(0.0, f64::max);
    // Hertz line contact, rigid CoCr cylinder on a UHMWPE half-space: E* = E / (1 − ν²), which
    // is `hertz_estimate` (two equal half-spaces) with the modulus 2E
    let (e_pe, nu_pe) = tkr.tibia_layer_material.ok_or("tkr has an insert material")?;
    let r = tkr.condyle_bone_radius + tkr.femur_cartilage;
    let (a_h, p0_h) = hertz_estimate(2600.0 / tkr.width, r, 2.0 * e_pe, nu_pe);
    let (a_s, p0_s) = hertz_estimate(168.0 / tkr.width, r, 2.0 * e_pe, nu_pe);
    println!(
        "peak insert pressure over the cycle {:.2} MPa at {:.1} % (flexion {:.1}°, F = {:.0} N); swing minimum {:.2} MPa",
        peak.peak_pressure,
        100.0 * peak.time,
        peak.flexion_deg,
        peak.load_n,
        min_peak
    );
    println!(
        "Hertz (rigid cylinder R = {r} mm on a UHMWPE half-space): 2600 N: a = {a_h:.2} mm, p0 = {p0_h:.2} MPa; 168 N: a = {a_s:.2} mm, p0 = {p0_s:.2} MPa"
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
        "{{\"problem\":\"tkr2d\",\"dofs\":{dofs},\"steps\":{},\"solves\":{},\"max_load_balance_error\":{max_err:.3e},\"max_peak_pressure_mpa\":{:.3},\"max_peak_time\":{:.4},\"min_peak_pressure_mpa\":{min_peak:.3},\"hertz_p0_2600n_mpa\":{p0_h:.3},\"max_kkt\":{max_kkt:.2e},\"width_mm\":{},\"total_s\":{total:.3}}}",
        steps.len(),
        steps.iter().map(|s| s.solves).sum::<usize>(),
        peak.peak_pressure,
        peak.time,
        tkr.width
    );
    Ok(())
}
