//! # 3D hip contact: femoral head in the acetabulum over the gait cycle
//!
//! A ball-in-socket model ([`synovia_models::hip3d`]): femoral head (bone `15–23 mm` + 2 mm cartilage)
//! in the acetabulum (2 mm cartilage + bone to 32 mm, 0.2 mm radial clearance), P1 tetrahedra,
//! cartilage E = 10 MPa, ν = 0.45, bone E = 800 MPa, ν = 0.3, frictionless node-to-facet
//! contact between the cartilage surfaces. The head's inner bone sphere is pushed into the
//! socket (`−z`) until the contact resultant equals the hip joint force of an approximate
//! Paul/Bergmann-type walking curve (`synovia_models::hip3d::HIP_FORCE`, 750 N body weight, peaks
//! 2.8 and 3 BW). See `docs/knee2d.md`.
//!
//! Every level checks the load balance (≤ 0.5 %) and the KKT conditions, prints the peak and
//! mean cartilage pressure and the contact area, and writes `OUT/hip3d.csv` and
//! `OUT/hip3d.pvd` (+ one `.vtu` per level). Ends with one JSON line.
//!
//! Run: `cargo run --release --example hip3d [OUT_DIR]` (default `out/hip3d`).

use std::fmt::Write as _;
use std::time::Instant;

use synovia::io::{Encoding, TimeSeriesWriter};
use synovia_models::hip3d::{Hip3d, BODY_WEIGHT_N};
use synovia_models::knee2d::KneeError;

fn main() -> Result<(), KneeError> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "out/hip3d".to_string());
    std::fs::create_dir_all(&out)?;
    let start = Instant::now();
    let hip = Hip3d::default();
    let solver = synovia::solvers::by_name("pdas")?;
    let model = hip.build()?;
    let dofs = model.contact.elastic().info().n_dofs;
    let setup_s = start.elapsed().as_secs_f64();
    println!(
        "hip3d: {dofs} dofs, {} contact nodes, model + factorisation {setup_s:.2} s",
        model.contact.geometry().len()
    );
    // load levels (cycle fractions): heel strike, loading, first peak, mid-stance, second peak,
    // push-off, toe-off, swing
    let times = [0.0, 0.05, 0.15, 0.30, 0.48, 0.55, 0.62, 0.80];
    let mut series = TimeSeriesWriter::new(&out, "hip3d", Encoding::Zlib)?;
    println!(
        "| level | cycle % | F (N) | F/BW | contact (N) | shear (N) | balance err | peak p (MPa) | mean p (MPa) | area (mm²) | active | δ (mm) | solves | KKT | s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut i = 0;
    let steps = hip.run(&model, &times, solver.as_ref(), |s, res| {
        println!(
            "| {i} | {:.0} | {:.0} | {:.2} | {:.1} | {:.2} | {:.1e} | {:.3} | {:.3} | {:.0} | {} | {:.4} | {} | {:.1e} | {:.2} |",
            100.0 * s.time,
            s.load_n,
            s.load_n / BODY_WEIGHT_N,
            s.contact_force_n,
            s.contact_shear_n,
            s.balance_error,
            s.peak_pressure,
            s.mean_pressure,
            s.contact_area,
            s.active_nodes,
            s.approach,
            s.solves,
            s.kkt,
            s.seconds
        );
        if s.balance_error > 5e-3 {
            return Err(format!("level {i}: load balance error {:.2e} > 0.5 %", s.balance_error).into());
        }
        if !res.kkt.satisfied(1e-8) {
            return Err(format!("level {i}: KKT violated: {:?}", res.kkt).into());
        }
        let vtu = synovia::output::contact_vtu(&model.model, model.contact.geometry(), res, Encoding::Zlib)?;
        series.write_step(s.time, &vtu)?;
        i += 1;
        Ok(())
    })?;

    let mut csv = String::from(
        "time [cycle],load [N],contact_force [N],contact_shear [N],balance_error [-],peak_pressure [MPa],mean_pressure [MPa],contact_area [mm^2],active_nodes [-],approach [mm],solves [-],kkt [-],seconds [s]\n",
    );
    for s in &steps {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.time,
            s.load_n,
            s.contact_force_n,
            s.contact_shear_n,
            s.balance_error,
            s.peak_pressure,
            s.mean_pressure,
            s.contact_area,
            s.active_nodes,
            s.approach,
            s.solves,
            s.kkt,
            s.seconds
        );
    }
    let csv_path = std::path::Path::new(&out).join("hip3d.csv");
    std::fs::write(&csv_path, csv)?;

    let max_err = steps.iter().map(|s| s.balance_error).fold(0.0, f64::max);
    let peak = steps.iter().max_by(|a, b| a.peak_pressure.total_cmp(&b.peak_pressure)).ok_or("no levels")?;
    let min_peak = steps.iter().map(|s| s.peak_pressure).fold(f64::INFINITY, f64::min);
    let max_kkt = steps.iter().map(|s| s.kkt).fold(0.0, f64::max);
    println!(
        "peak cartilage pressure {:.3} MPa at {:.0} % (F = {:.0} N, contact area {:.0} mm²); swing minimum {:.3} MPa",
        peak.peak_pressure,
        100.0 * peak.time,
        peak.load_n,
        peak.contact_area,
        min_peak
    );
    println!("wrote {} and {} ({} levels)", csv_path.display(), series.pvd_path().display(), steps.len());
    let total = start.elapsed().as_secs_f64();
    println!(
        "{{\"problem\":\"hip3d\",\"dofs\":{dofs},\"levels\":{},\"solves\":{},\"max_load_balance_error\":{max_err:.3e},\"max_peak_pressure_mpa\":{:.4},\"max_peak_load_n\":{:.1},\"max_contact_area_mm2\":{:.1},\"min_peak_pressure_mpa\":{min_peak:.4},\"max_kkt\":{max_kkt:.2e},\"total_s\":{total:.3}}}",
        steps.len(),
        steps.iter().map(|s| s.solves).sum::<usize>(),
        peak.peak_pressure,
        peak.load_n,
        steps.iter().map(|s| s.contact_area).fold(0.0, f64::max),
    );
    Ok(())
}
