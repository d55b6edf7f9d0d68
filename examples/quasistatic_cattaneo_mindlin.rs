//! # Quasi-static Cattaneo–Mindlin: rising tangential load up to gross sliding
//!
//! Two identical cylinders (plane strain, `R = 1`, `E = 1`, `ν = 0.3`, Dundurs `β = 0`) are
//! pressed together by a push of the upper one's top (step 0, frictionless), then sheared by a
//! tangential displacement `s(t) = t` of that top that rises level by level (docs/model.md §7). Each
//! level solves the Tresca problem with `g_c = μ |λ_n|` of the previous level and slip measured
//! from the previous level (docs/model.md §3), warm-started from it, with one factorisation of `A` for
//! the whole run.
//!
//! While `Q < μP` the centre sticks over `|x| ≤ c = a sqrt(1 − Q/(μP))`,
//! `a = sqrt(4 P R*/(π E*))`, `R* = R/2`, `E* = E/(2(1 − ν²))` (docs/model.md §9); at `Q = μP` the
//! whole contact slips (gross sliding) and `Q` stops growing. The example prints, per level,
//! `Q/(μP)`, the measured stick half-width `c`, `c_exact` and the error, then one JSON line,
//! and writes `out/quasistatic_cm/cm.csv` and the ParaView series `out/quasistatic_cm/cm.pvd`.
//!
//! Run: `cargo run --release --example quasistatic_cattaneo_mindlin [pdas|au-pdas|uzawa-mprgp|dual-mprgp]`

use std::time::Instant;

use synovia::contact::{StaticContact, StaticContactResult};
use synovia::contact_ops::ContactSolver;
use synovia::fem::{ElasticParams, Model};
use synovia::mesh::math::Real;
use synovia::time::quasistatic::{QuasiStaticOutput, QuasiStaticParams, QuasiStaticStepper};
use synovia::time::results::StepRecord;
use synovia_models::hertz::{hertz2d_model, Hertz2d};

/// Shift of the top for which one Tresca step from the frictionless normal state gives
/// `Q/(μP) = target` (secant); the loading is monotone, so the quasi-static path reaches the
/// same state.
fn shift_for_ratio(
    sc: &StaticContact<2>,
    model: &Model<2>,
    solver: &dyn ContactSolver,
    mu: Real,
    target: Real,
) -> Result<Real, Box<dyn std::error::Error>> {
    let normal = sc.solve(model, 0.0, solver, None, None, None)?;
    let geo = sc.geometry();
    let p = normal.normal_force(geo, 0..geo.len());
    let g = geo.slip_bounds_from_pressure(&normal.solution.lambda_n);
    let ratio = |s: Real| -> Result<Real, Box<dyn std::error::Error>> {
        let res = sc.solve(model, s, solver, Some(&g), Some(&normal.displacement), None)?;
        let q: Real = res
            .cell_node
            .iter()
            .zip(&res.slip_bound)
            .zip(&res.solution.lambda_t)
            .map(|((&r, g), l)| g * geo.nodes[r].weight * l)
            .sum();
        Ok(q.abs() / (mu * p))
    };
    let (mut s0, mut q0) = (1e-4, ratio(1e-4)?);
    let mut s1 = s0 * target / q0;
    let mut q1 = ratio(s1)?;
    for _ in 0..20 {
        if (q1 - target).abs() < 2e-3 * target {
            break;
        }
        let s2 = s1 + (target - q1) * (s1 - s0) / (q1 - q0);
        (s0, q0) = (s1, q1);
        s1 = s2;
        q1 = ratio(s1)?;
    }
    Ok(s1)
}

/// Midpoint between the outermost sticking cell and the innermost slipping cell beyond it.
fn stick_half_width(stepper: &QuasiStaticStepper<2>, res: &StaticContactResult<2>) -> Real {
    let geo = stepper.geometry();
    let x = |r: usize| geo.nodes[r].position[0].abs();
    let cells =
        || res.cell_node.iter().copied().zip(res.solution.lambda_t.iter().map(|l| l.abs() < 1.0 - 1e-6));
    let Some(stick_max) = cells().filter(|c| c.1).map(|c| x(c.0)).reduce(Real::max) else {
        return 0.0;
    };
    let slip_min =
        cells().filter(|c| !c.1 && x(c.0) > stick_max).map(|c| x(c.0)).fold(Real::INFINITY, Real::min);
    if slip_min.is_finite() {
        0.5 * (stick_max + slip_min)
    } else {
        stick_max
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "pdas".to_string());
    let solver = synovia::solvers::by_name(&name)?;
    let mu = 0.3;
    let p = Hertz2d { levels: 12, push: 0.02, e2: Some(1.0), ..Default::default() };
    // the prescribed top displacement is (t, −push): the time is the tangential shift
    let (model, mut pairs) = hertz2d_model(&p)?;
    pairs[0].friction = mu;
    let t_setup = Instant::now();
    let mut stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), QuasiStaticParams::default())?;
    let setup_s = t_setup.elapsed().as_secs_f64();
    let s09 = shift_for_ratio(stepper.contact(), &model, solver.as_ref(), mu, 0.9)?;
    let fractions = [0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0, 1.05, 1.1, 1.2, 1.5, 2.0];
    let mut times = vec![0.0];
    times.extend(fractions.iter().map(|f| f * s09));

    let mut out = QuasiStaticOutput::new("out/quasistatic_cm", "cm", stepper.geometry())?;
    let mut results: Vec<StaticContactResult<2>> = Vec::new();
    let mut kkt: Real = 0.0;
    let t_run = Instant::now();
    let records: Vec<StepRecord> = stepper.run(&model, &times, solver.as_ref(), |rec, res| {
        kkt = kkt.max(res.kkt.max());
        results.push(res.clone());
        out.write_step(&model, rec, res).map(|_| ())
    })?;
    let run_s = t_run.elapsed().as_secs_f64();
    let csv = out.write_csv(&records)?;

    let force = records[0].pairs[0].normal_force;
    let e_star = p.e1 / (2.0 * (1.0 - p.nu1 * p.nu1));
    let a = (4.0 * force * (p.radius / 2.0) / (std::f64::consts::PI * e_star)).sqrt();
    println!(
        "P = {force:.5e}, a = {a:.5e}, dofs = {}, contact nodes = {}, solver {}",
        stepper.contact().elastic().info().n_dofs,
        stepper.geometry().len(),
        solver.name()
    );
    println!(
        "{:>4} {:>10} {:>8} {:>10} {:>10} {:>9} {:>10} {:>11} {:>5} {:>7}",
        "step", "shift", "Q/μP", "c", "c_exact", "c err", "stick", "D_i", "iter", "step s"
    );
    let mut levels_json = Vec::new();
    let mut max_err: Real = 0.0;
    let mut gross: Option<(usize, Real)> = None;
    for (rec, res) in records.iter().zip(&results) {
        let q = rec.pairs[0].tangential_force / (mu * rec.pairs[0].normal_force);
        let c = stick_half_width(&stepper, res);
        let c_exact = a * (1.0 - q.min(1.0)).sqrt();
        let partial = rec.step > 0 && rec.pairs[0].stick_area > 0.0;
        let err = if partial { (c - c_exact).abs() / c_exact } else { Real::NAN };
        if partial && q <= 0.92 {
            max_err = max_err.max(err);
        }
        if rec.step > 0 && !partial && gross.is_none() {
            gross = Some((rec.step, q));
        }
        println!(
            "{:>4} {:>10.3e} {:>8.5} {:>10.4e} {:>10.4e} {:>9.2e} {:>10.3e} {:>11.4e} {:>5} {:>7.3}",
            rec.step,
            rec.time,
            q,
            c,
            c_exact,
            err,
            rec.pairs[0].stick_area,
            rec.friction_dissipation,
            rec.iterations,
            rec.step_s
        );
        if partial {
            levels_json.push(format!(
                "{{\"q_ratio\":{q:.5},\"c\":{c:.6e},\"c_exact\":{c_exact:.6e},\"c_rel_err\":{err:.3e}}}"
            ));
        }
    }
    let (gross_step, gross_q) = gross.unwrap_or((0, Real::NAN));
    println!(
        "gross sliding from step {gross_step}: Q/(μP) = {gross_q:.6}; max c error for Q/(μP) ≤ 0.92: {max_err:.2e}; \
         total friction dissipation {:.4e}",
        records.last().map_or(0.0, |r| r.cumulative_friction_dissipation)
    );
    println!("wrote {} and {}", csv.display(), out.pvd_path().display());
    println!(
        "{{\"problem\":\"quasistatic_cattaneo_mindlin\",\"solver\":\"{}\",\"level\":{},\"dofs\":{},\"contact_nodes\":{},\"mu\":{mu},\"force\":{force:.6e},\"a\":{a:.6e},\"steps\":{},\"partial_slip_levels\":[{}],\"max_c_rel_err\":{max_err:.3e},\"gross_sliding_step\":{gross_step},\"gross_sliding_q_ratio\":{gross_q:.6},\"total_dissipation\":{:.6e},\"setup_s\":{setup_s:.3},\"run_s\":{run_s:.3},\"kkt\":{kkt:.2e}}}",
        solver.name(),
        p.levels,
        stepper.contact().elastic().info().n_dofs,
        stepper.geometry().len(),
        records.len(),
        levels_json.join(","),
        records.last().map_or(0.0, |r| r.cumulative_friction_dissipation)
    );
    if !(max_err < 0.05 && (gross_q - 1.0).abs() < 0.02 && kkt < 1e-8) {
        return Err(
            format!("verification failed: max c error {max_err}, gross Q/μP {gross_q}, KKT {kkt}").into()
        );
    }
    Ok(())
}
