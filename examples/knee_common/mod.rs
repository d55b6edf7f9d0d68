//! Helpers shared by the `knee2d` and `tkr2d` examples: the checked run over the gait cycle,
//! the per-pose CSV and the SVG plot of force and peak pressure over the cycle.

use std::fmt::Write as _;

use plotters::prelude::*;
use synovia::io::{Encoding, TimeSeriesWriter};
use synovia_models::knee2d::{cycle_times, Knee2d, KneeError, KneeStep};

/// Runs `model` over `n` poses of the ISO cycle with PDAS: prints one table row per pose, checks
/// the load balance (≤ 0.5 %) and the KKT conditions at every pose, and writes the contact state
/// of each pose to the PVD series `OUT/NAME.pvd`. Returns the steps, the unknowns of the last
/// pose and the series writer.
pub fn run_cycle(
    model: &Knee2d,
    name: &str,
    out: &str,
    n: usize,
) -> Result<(Vec<KneeStep>, usize, TimeSeriesWriter), KneeError> {
    let solver = synovia::solvers::by_name("pdas")?;
    let times = cycle_times(n);
    let mut series = TimeSeriesWriter::new(out, name, Encoding::Zlib)?;
    let mut dofs = 0;
    println!(
        "| step | cycle % | flexion ° | F (N) | P (N/mm) | contact (N/mm) | balance err | peak p (MPa) | contact length (mm) | δ (mm) | solves | KKT | s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut i = 0;
    let steps = model.run(&times, solver.as_ref(), |pose| {
        let s = &pose.step;
        dofs = pose.contact.elastic().info().n_dofs;
        println!(
            "| {i} | {:.1} | {:.1} | {:.0} | {:.2} | {:.4} | {:.1e} | {:.3} | {:.2} | {:.5} | {} | {:.1e} | {:.2} |",
            100.0 * s.time,
            s.flexion_deg,
            s.load_n,
            s.load_per_mm,
            s.contact_force_per_mm,
            s.balance_error,
            s.peak_pressure,
            s.contact_length,
            s.approach,
            s.solves,
            s.kkt,
            s.seconds
        );
        if s.balance_error > 5e-3 {
            return Err(format!("step {i}: load balance error {:.2e} > 0.5 %", s.balance_error).into());
        }
        if !pose.result.kkt.satisfied(1e-8) {
            return Err(format!("step {i}: KKT violated: {:?}", pose.result.kkt).into());
        }
        let vtu = synovia::output::contact_state_vtu(pose.model, pose.contact.geometry(), &pose.result, Encoding::Zlib)?;
        series.write_step(s.time, &vtu)?;
        i += 1;
        Ok(())
    })?;
    Ok((steps, dofs, series))
}

/// The per-pose CSV table.
pub fn csv_text(steps: &[KneeStep]) -> String {
    let mut s = String::from(
        "time [cycle],flexion [deg],load [N],load [N/mm],contact_force [N/mm],contact_shear [N/mm],balance_error [-],peak_pressure [MPa],peak_x [mm],contact_length [mm],approach [mm],solves [-],solver_iterations [-],kkt [-],seconds [s]\n",
    );
    for r in steps {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.time,
            r.flexion_deg,
            r.load_n,
            r.load_per_mm,
            r.contact_force_per_mm,
            r.contact_shear_per_mm,
            r.balance_error,
            r.peak_pressure,
            r.peak_x,
            r.contact_length,
            r.approach,
            r.solves,
            r.solver_iterations,
            r.kkt,
            r.seconds
        );
    }
    s
}

/// Applied and computed contact force (N, i.e. per-mm values × width) and peak pressure (MPa,
/// right axis) over the cycle.
pub fn plot(
    path: &std::path::Path,
    steps: &[KneeStep],
    width: f64,
    title: &str,
    pressure_label: &str,
) -> Result<(), KneeError> {
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let f_max = steps.iter().map(|s| s.load_n).fold(0.0, f64::max) * 1.1;
    let p_max = steps.iter().map(|s| s.peak_pressure).fold(0.0, f64::max) * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .right_y_label_area_size(60)
        .build_cartesian_2d(0.0..100.0, 0.0..f_max)
        .map_err(|e| e.to_string())?
        .set_secondary_coord(0.0..100.0, 0.0..p_max);
    chart
        .configure_mesh()
        .x_desc("gait cycle (%)")
        .y_desc("axial force (N)")
        .draw()
        .map_err(|e| e.to_string())?;
    chart
        .configure_secondary_axes()
        .y_desc("peak contact pressure (MPa)")
        .draw()
        .map_err(|e| e.to_string())?;
    let table = synovia_models::knee2d::ISO14243_AXIAL_FORCE;
    chart
        .draw_series(LineSeries::new(table.iter().copied(), &BLUE))
        .map_err(|e| e.to_string())?
        .label("ISO 14243-1 axial force (applied)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
    chart
        .draw_series(
            steps
                .iter()
                .map(|s| Circle::new((100.0 * s.time, s.contact_force_per_mm * width), 3, BLACK.filled())),
        )
        .map_err(|e| e.to_string())?
        .label("computed contact force × width")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
    chart
        .draw_secondary_series(LineSeries::new(steps.iter().map(|s| (100.0 * s.time, s.peak_pressure)), &RED))
        .map_err(|e| e.to_string())?
        .label(pressure_label)
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())?;
    Ok(())
}
