//! Quasi-static time stepping (docs/model.md §7): path independence of frictionless contact, energy
//! balance of a frictional cycle, Cattaneo–Mindlin under a rising tangential load up to gross
//! sliding, the Coulomb fixed point, and the CSV/PVD output.

use std::path::PathBuf;
use std::sync::Arc;

use synovia_contact::operators::{ContactPair, PlaneObstacle};
use synovia_contact::{ContactParams, StaticContact, StaticContactResult};
use synovia_fem::{ElasticParams, Model};
use synovia_material::plane_strain;
use synovia_mesh::generators::half_disc_refined;
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::BoundaryKind;
use synovia_pdas::Pdas;
use synovia_time::history::{Constant, FnHistory, LoadHistory, PiecewiseLinear};
use synovia_time::quasistatic::{QuasiStaticOutput, QuasiStaticParams, QuasiStaticStepper};
use synovia_time::results::StepRecord;
use synovia_time::TimeError;

const R: Real = 1.0;
const E: Real = 1.0;
const NU: Real = 0.3;

fn pdas() -> Pdas {
    Pdas::new(ContactParams::default().with_tolerance(1e-12).with_max_iterations(200))
}

/// The 2D Hertz set-up of `synovia_models::hertz::hertz2d_model`: the upper half-disc `"indenter"`
/// (centre `(0, R)`, flat top prescribed to `(shift(t), −push(t))`, contact part its arc below
/// `y < 0.3 R`) on either a rigid flat `y = 0` or the mirrored half-disc `"base"` (clamped at
/// its flat side), refined `levels` times toward the contact point.
fn half_discs(
    levels: usize,
    push: impl LoadHistory + 'static,
    shift: impl LoadHistory + 'static,
    second_body: bool,
    mu: Real,
) -> (Model<2>, Vec<ContactPair<2>>) {
    let centre = Point::<2>::new(0.0, R);
    let mut upper = half_disc_refined(centre, R, 8, Point::<2>::zeros(), 0.16 * R, levels).expect("mesh");
    upper.set_part_kind("top", BoundaryKind::Prescribed).expect("top");
    let mut model = Model::<2>::new();
    let mut pairs = Vec::new();
    let lower = if second_body {
        let mut lower = upper.reflected(1, 0.0).expect("reflect");
        lower.set_part_kind("top", BoundaryKind::Clamped).expect("clamp");
        lower
            .add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[1] > -0.3 * R && n[1] > 0.0)
            .expect("contact part");
        Some(lower)
    } else {
        None
    };
    upper
        .add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[1] < 0.3 * R && n[1] < 0.0)
        .expect("contact part");
    let material = Arc::new(plane_strain(E, NU).expect("material"));
    let up = model.add_body("indenter", upper, material.clone()).expect("body");
    model
        .prescribe(up, "top", move |_, t| Vector::<2>::new(shift.value(t), -push.value(t)))
        .expect("prescribe");
    match lower {
        Some(lower) => {
            let lo = model.add_body("base", lower, material).expect("body");
            pairs.push(
                ContactPair::node_to_node("indenter-base", up, "contact", lo, "contact")
                    .with_fixed_normal(Vector::<2>::new(0.0, -1.0))
                    .with_friction(mu),
            );
        }
        None => {
            let flat = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0)).expect("flat");
            pairs.push(ContactPair::rigid("indenter-flat", up, "contact", Arc::new(flat)).with_friction(mu));
        }
    }
    (model, pairs)
}

fn check_kkt<const D: usize>(rec: &StepRecord, res: &StaticContactResult<D>) -> Result<(), TimeError> {
    assert!(res.kkt.satisfied(1e-8), "step {} (t = {}): KKT {:?}", rec.step, rec.time, res.kkt);
    Ok(())
}

fn max_abs(v: &[Real]) -> Real {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn rel_diff(a: &[Real], b: &[Real]) -> Real {
    let scale = max_abs(a).max(max_abs(b)).max(1e-300);
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

/// `Q / (μ P)` of a record with one pair.
fn q_ratio(rec: &StepRecord, mu: Real) -> Real {
    rec.pairs[0].tangential_force / (mu * rec.pairs[0].normal_force)
}

/// Tangential shift of the top for which a single Tresca step from the frictionless normal
/// state gives `Q/(μP) = target` (secant on the shift; the loading is monotone, so the
/// quasi-static path reaches the same state). `model` must prescribe the top's shift as the
/// time and a constant push.
fn shift_for_ratio(sc: &StaticContact<2>, model: &Model<2>, mu: Real, target: Real) -> Real {
    let solver = pdas();
    let normal = sc.solve(model, 0.0, &solver, None, None, None).expect("normal");
    let geo = sc.geometry();
    let p = normal.normal_force(geo, 0..geo.len());
    let g = geo.slip_bounds_from_pressure(&normal.solution.lambda_n);
    let ratio = |s: Real| -> Real {
        let res = sc.solve(model, s, &solver, Some(&g), Some(&normal.displacement), None).expect("tresca");
        let q: Real = res
            .cell_node
            .iter()
            .zip(&res.slip_bound)
            .zip(&res.solution.lambda_t)
            .map(|((&r, g), l)| g * geo.nodes[r].weight * l)
            .sum();
        q.abs() / (mu * p)
    };
    let (mut s0, mut q0) = (1e-4, ratio(1e-4));
    let mut s1 = s0 * target / q0;
    let mut q1 = ratio(s1);
    for _ in 0..20 {
        if (q1 - target).abs() < 2e-3 * target {
            break;
        }
        let s2 = s1 + (target - q1) * (s1 - s0) / (q1 - q0);
        (s0, q0) = (s1, q1);
        s1 = s2;
        q1 = ratio(s1);
    }
    s1
}

/// Frictionless Hertz contact loaded, unloaded and reloaded (push 0 → δ → 0 → δ): the state
/// `(U, Λ_n)` depends only on the current load, not on the path or the warm start.
#[test]
fn frictionless_hertz_load_unload_reload_is_path_independent() {
    let delta = 0.01;
    let push = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, delta), (2.0, 0.0), (3.0, delta)]).expect("history");
    let (model, pairs) = half_discs(9, push, Constant(0.0), false, 0.0);
    let mut stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), QuasiStaticParams::default())
            .expect("stepper");
    let times: Vec<Real> = (0..=12).map(|i| 0.25 * i as Real).collect();
    let mut states: Vec<(Vec<Real>, Vec<Real>)> = Vec::new();
    let solver = pdas();
    let records = stepper
        .run(&model, &times, &solver, |rec, res| {
            check_kkt(rec, res)?;
            assert!(res.cell_node.is_empty(), "frictionless: no friction cells");
            states.push((res.solution.u.clone(), res.solution.lambda_n.clone()));
            Ok(())
        })
        .expect("run");
    assert_eq!(records.len(), times.len());
    // the load path: forces rise, fall to zero, rise again
    let force: Vec<Real> = records.iter().map(|r| r.pairs[0].normal_force).collect();
    println!("normal force per level: {force:?}");
    assert!(force[4] > force[2] && force[2] > force[1] && force[1] > 0.0, "{force:?}");
    assert!(force[0] == 0.0 && force[8] == 0.0);
    assert_eq!(records.iter().map(|r| r.friction_dissipation).sum::<Real>(), 0.0);
    // equal loads: levels (1,7,9), (2,6,10), (3,5,11), (4,12), (0,8)
    let mut worst: Real = 0.0;
    for group in [[1, 7, 9].as_slice(), &[2, 6, 10], &[3, 5, 11], &[4, 12], &[0, 8]] {
        for &j in &group[1..] {
            let (ua, la) = &states[group[0]];
            let (ub, lb) = &states[j];
            if max_abs(ua) == 0.0 {
                assert!(
                    max_abs(ub) == 0.0 && max_abs(lb) == 0.0 && max_abs(la) == 0.0,
                    "unloaded state not zero"
                );
                continue;
            }
            let (du, dl) = (rel_diff(ua, ub), rel_diff(la, lb));
            worst = worst.max(du).max(dl);
            assert!(du < 1e-10 && dl < 1e-10, "levels {} and {j}: ΔU {du:e}, ΔΛ_n {dl:e}", group[0]);
        }
    }
    // and the same as a cold static solve at full load
    let sc = stepper.contact();
    let cold = sc.solve(&model, 3.0, &solver, None, None, None).expect("cold solve");
    let (du, dl) =
        (rel_diff(&cold.solution.u, &states[12].0), rel_diff(&cold.solution.lambda_n, &states[12].1));
    println!(
        "largest relative difference at equal loads {worst:.2e}; vs cold solve ΔU {du:.2e} ΔΛ_n {dl:.2e}"
    );
    assert!(du < 1e-10 && dl < 1e-10);
    // strain energy is the same at equal loads and rises with the load
    assert!((records[4].strain_energy - records[12].strain_energy).abs() <= 1e-10 * records[4].strain_energy);
    assert!(records[4].strain_energy > records[2].strain_energy && records[2].strain_energy > 0.0);
}

/// Stick half-width: midpoint between the outermost sticking cell and the innermost slipping
/// cell beyond it (0 without sticking cells).
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

/// Quasi-static Cattaneo–Mindlin: two identical half-discs pressed together, then sheared by a
/// rising tangential displacement of the top. At every partial-slip level the stick zone is
/// `|x| ≤ c = a sqrt(1 − Q/(μP))`; gross sliding starts at `Q = μP`, after which `Q` stays
/// at `μP`, the whole contact slips and the upper body slides rigidly (`D_i = μ P Δs`).
#[test]
fn cattaneo_mindlin_under_rising_tangential_load_up_to_gross_sliding() {
    let (mu, push, levels) = (0.3, 0.02, 12);
    // the time is the tangential shift of the top
    let (model, pairs) = half_discs(levels, Constant(push), FnHistory::new(|t| t), true, mu);
    let mut stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), QuasiStaticParams::default())
            .expect("stepper");
    let s09 = shift_for_ratio(stepper.contact(), &model, mu, 0.9);
    let fractions = [0.1, 0.25, 0.4, 0.55, 0.7, 0.85, 1.0, 1.1, 1.2, 1.5, 2.0];
    let mut times = vec![0.0];
    times.extend(fractions.iter().map(|f| f * s09));
    let solver = pdas();
    let t0 = std::time::Instant::now();
    let mut results = Vec::new();
    let records = stepper
        .run(&model, &times, &solver, |rec, res| {
            check_kkt(rec, res)?;
            results.push(res.clone());
            Ok(())
        })
        .expect("run");
    let run_s = t0.elapsed().as_secs_f64();
    let widths: Vec<Real> = results.iter().map(|res| stick_half_width(&stepper, res)).collect();
    let p = records[0].pairs[0].normal_force;
    let e_star = E / (2.0 * (1.0 - NU * NU));
    let a = (4.0 * p * (R / 2.0) / (std::f64::consts::PI * e_star)).sqrt();
    println!("P = {p:.5e}, a = {a:.5e}, run {run_s:.2} s");
    println!(
        "{:>4} {:>10} {:>8} {:>10} {:>10} {:>9} {:>10} {:>10} {:>5} {:>7}",
        "step", "shift", "Q/μP", "c", "c_exact", "c err", "stick", "D_i/μPΔs", "its", "step s"
    );
    let mut checked = 0;
    let mut gross: Option<usize> = None;
    for (i, (rec, &c)) in records.iter().zip(&widths).enumerate() {
        let q = q_ratio(rec, mu);
        let ce = a * (1.0 - q.min(1.0)).sqrt();
        let err = if ce > 0.0 { (c - ce).abs() / ce } else { Real::NAN };
        let ds = if i > 0 { rec.time - records[i - 1].time } else { Real::NAN };
        println!(
            "{:>4} {:>10.3e} {:>8.5} {:>10.4e} {:>10.4e} {:>9.2e} {:>10.3e} {:>10.6} {:>5} {:>7.3}",
            rec.step,
            rec.time,
            q,
            c,
            ce,
            err,
            rec.pairs[0].stick_area,
            rec.friction_dissipation / (mu * p * ds),
            rec.iterations,
            rec.step_s
        );
        // the normal problem decouples (identical bodies): P does not change
        assert!((rec.pairs[0].normal_force - p).abs() < 1e-10 * p, "step {i}: P changed");
        if i > 0 && gross.is_none() {
            if rec.pairs[0].stick_area > 0.0 {
                assert!(q < 1.0 && q > q_ratio(&records[i - 1], mu), "step {i}: Q must grow below μP");
                if q > 0.05 && q <= 0.92 {
                    assert!(err < 0.05, "step {i}: c = {c:.5e} vs {ce:.5e} at Q/μP = {q:.4}");
                    checked += 1;
                }
            } else {
                gross = Some(i);
            }
        }
    }
    assert!(checked >= 5, "only {checked} partial-slip levels with 0.05 < Q/μP ≤ 0.92");
    let g = gross.expect("gross sliding reached");
    let q_gross = q_ratio(&records[g], mu);
    println!(
        "gross sliding from step {g} (shift {:.4e}): Q/μP = {q_gross:.6} (last partial-slip level Q/μP = {:.4})",
        records[g].time,
        q_ratio(&records[g - 1], mu)
    );
    assert!((q_gross - 1.0).abs() < 0.02, "gross sliding at Q/μP = {q_gross}");
    assert!(q_ratio(&records[g - 1], mu) > 0.9);
    for (i, rec) in records.iter().enumerate().skip(g) {
        let pr = &rec.pairs[0];
        assert!(
            pr.stick_area == 0.0 && (pr.slip_area - pr.contact_area).abs() < 1e-12,
            "step {i}: not all slipping"
        );
        assert!((q_ratio(rec, mu) - q_gross).abs() < 1e-8, "step {i}: Q keeps changing after gross sliding");
        if i > g {
            // rigid sliding of the whole contact: D_i = μ P Δs
            let ds = rec.time - records[i - 1].time;
            let ratio = rec.friction_dissipation / (mu * p * ds);
            assert!((ratio - 1.0).abs() < 1e-6, "step {i}: D_i / (μPΔs) = {ratio}");
        }
    }
}

/// A closed tangential loading cycle `s: 0 → +s_max → −s_max → 0` at constant push between two
/// identical half-discs (partial slip, `|Q| ≈ 0.8 μP` at the turning points) dissipates energy,
/// and the friction dissipation summed from the contact variables balances the external work
/// of the prescribed top computed independently from the reaction forces:
/// `W = Σ_i ½ (R_i + R_{i−1}) · Δu₂ = D + E(t_end) − E(t_0)` within 1 % (trapezoidal rule), and
/// the exact discrete identity of the implicit levels
/// `Σ_i (R_i · Δu₂,i − E(ΔU_i)) = D + E(t_end) − E(t_0)` to round-off. The reaction on the top
/// is the negative of the contact resultant on the upper body (its equilibrium).
#[test]
fn closed_tangential_cycle_dissipates_the_external_work() {
    let (mu, push, levels) = (0.3, 0.02, 9);
    let s_max = {
        let (model, pairs) = half_discs(levels, Constant(push), FnHistory::new(|t| t), true, mu);
        let sc = StaticContact::new(&model, &pairs, ElasticParams::default()).expect("factorise");
        shift_for_ratio(&sc, &model, mu, 0.8)
    };
    let shift =
        PiecewiseLinear::new(&[(0.0, 0.0), (1.0, s_max), (3.0, -s_max), (4.0, 0.0)]).expect("history");
    let shift_at = shift.clone();
    let (model, pairs) = half_discs(levels, Constant(push), shift, true, mu);
    let mut stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), QuasiStaticParams::default())
            .expect("stepper");
    let per_unit = 10;
    let times: Vec<Real> = (0..=4 * per_unit).map(|i| i as Real / per_unit as Real).collect();
    let mut prev: Option<Vec<Vec<Vector<2>>>> = None;
    let mut increment_energy = Vec::new();
    let solver = pdas();
    let records = stepper
        .run(&model, &times, &solver, |rec, res| {
            check_kkt(rec, res)?;
            let e = match &prev {
                Some(p) => {
                    let du: Vec<Vec<Vector<2>>> = res
                        .displacement
                        .iter()
                        .zip(p)
                        .map(|(a, b)| a.iter().zip(b).map(|(x, y)| x - y).collect())
                        .collect();
                    synovia_fem::post::body_fields(&model, &du)?.iter().map(|f| f.strain_energy).sum()
                }
                None => 0.0,
            };
            increment_energy.push(e);
            prev = Some(res.displacement.clone());
            Ok(())
        })
        .expect("run");
    let mut trapezoid = 0.0;
    let mut implicit = 0.0;
    for i in 1..records.len() {
        // reaction of the top on the upper body = −(contact resultant on it)
        let (r0, r1) = (-records[i - 1].pairs[0].force[0], -records[i].pairs[0].force[0]);
        let ds = shift_at.value(records[i].time) - shift_at.value(records[i - 1].time);
        trapezoid += 0.5 * (r0 + r1) * ds;
        implicit += r1 * ds - increment_energy[i];
    }
    let last = records.last().expect("records");
    let dissipation = last.cumulative_friction_dissipation;
    let sum: Real = records.iter().map(|r| r.friction_dissipation).sum();
    let stored = last.strain_energy - records[0].strain_energy;
    let q_peak = records.iter().map(|r| q_ratio(r, mu)).fold(0.0, Real::max);
    let residual_q = last.pairs[0].force[0] / (mu * last.pairs[0].normal_force);
    println!(
        "s_max = {s_max:.4e}, max Q/μP = {q_peak:.4}, residual Q/μP at s = 0: {residual_q:.4}\n\
         dissipation D = {dissipation:.6e}, ΔE = {stored:.3e}, work (trapezoid) W = {trapezoid:.6e}, \
         (W − ΔE)/D − 1 = {:.3e}; implicit identity (Σ R_i Δs − E(ΔU) − ΔE)/D − 1 = {:.3e}",
        (trapezoid - stored) / dissipation - 1.0,
        (implicit - stored) / dissipation - 1.0
    );
    assert!((q_peak - 0.8).abs() < 0.02, "max Q/μP = {q_peak}");
    assert!(dissipation > 0.0 && (sum - dissipation).abs() <= 1e-12 * dissipation);
    assert!(records.iter().all(|r| r.friction_dissipation >= 0.0));
    assert!(
        ((trapezoid - stored) - dissipation).abs() < 0.01 * dissipation,
        "work {trapezoid:e} − ΔE {stored:e} vs dissipation {dissipation:e}"
    );
    assert!(((implicit - stored) - dissipation).abs() < 1e-6 * dissipation, "discrete energy identity");
}

/// Pushing a half-disc further onto a rigid flat while shearing it changes the pressure during
/// every step: the Coulomb fixed point converges, its slip bounds are consistent with its own
/// pressures (`g_c = μ |Λ_n|` on the whole contact zone), and it differs slightly from frozen
/// Tresca; with one allowed solve and a tight tolerance it reports `FixedPoint`.
#[test]
fn coulomb_fixed_point_converges_and_differs_slightly_from_frozen_tresca() {
    let (mu, delta, levels) = (0.3, 0.01, 8);
    let push = FnHistory::new(move |t| delta * (0.5 + 0.5 * t));
    let shift = FnHistory::new(|t| 1.5e-3 * t);
    let (model, pairs) = half_discs(levels, push, shift, false, mu);
    let times = [0.0, 0.25, 0.5, 0.75, 1.0];
    let solver = pdas();
    let run = |params: QuasiStaticParams| -> Result<(Vec<StepRecord>, StaticContactResult<2>), TimeError> {
        let mut stepper = QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), params)?;
        let records = stepper.run(&model, &times, &solver, check_kkt)?;
        let last = stepper.last_result().cloned().expect("last result");
        // Coulomb consistency of the final state: g_c against μ |Λ_n| of the same solution
        let geo = stepper.geometry();
        let ln = &last.solution.lambda_n;
        let scale = mu * max_abs(ln);
        let mismatch = last
            .cell_node
            .iter()
            .zip(&last.slip_bound)
            .map(|(&r, g)| (g - mu * ln[r].abs()).abs())
            .fold(0.0, Real::max);
        let uncovered = (0..geo.len()).filter(|r| ln[*r] > 0.0 && !last.cell_node.contains(r)).count();
        println!(
            "coulomb {}: Q/μP = {:.4}, P = {:.5e}, max |g_c − μΛ_n| / μ max Λ_n = {:.2e}, contact nodes without friction cell: {uncovered}, iterations {:?}",
            params.coulomb_fixed_point,
            q_ratio(&records[4], mu),
            records[4].pairs[0].normal_force,
            mismatch / scale,
            records.iter().map(|r| r.iterations).collect::<Vec<_>>()
        );
        if params.coulomb_fixed_point {
            assert!(mismatch <= 1e-8 * scale && uncovered == 0, "Coulomb state inconsistent");
        } else {
            assert!(mismatch > 1e-3 * scale, "frozen Tresca should lag the pressure");
        }
        Ok((records, last))
    };
    let (tresca, tresca_last) = run(QuasiStaticParams::default()).expect("frozen Tresca");
    let coulomb_params = QuasiStaticParams::default().with_coulomb_fixed_point(true);
    let (coulomb, coulomb_last) = run(coulomb_params).expect("Coulomb fixed point");
    let dl = rel_diff(&tresca_last.solution.lambda_n, &coulomb_last.solution.lambda_n);
    let (qt, qc) = (tresca[4].pairs[0].tangential_force, coulomb[4].pairs[0].tangential_force);
    let dq = (qt - qc).abs() / qc;
    println!("frozen Tresca vs Coulomb: ΔΛ_n = {dl:.3e} (rel. max), ΔQ/Q = {dq:.3e}");
    assert!(dl > 1e-8 && dl < 0.05, "ΔΛ_n = {dl}");
    assert!(dq > 1e-6 && dq < 0.1, "ΔQ/Q = {dq}");
    // one solve per level is not enough for a tight tolerance
    let strict = QuasiStaticParams::default()
        .with_coulomb_fixed_point(true)
        .with_max_fixed_point(1)
        .with_fixed_point_tolerance(1e-12);
    match run(strict) {
        Err(TimeError::FixedPoint { step, iterations, change }) => {
            println!("max_fixed_point = 1: FixedPoint at step {step}, change {change:.2e}");
            assert_eq!((step, iterations), (1, 1));
            assert!(change > 1e-12);
        }
        other => panic!("expected a FixedPoint error, got {:?}", other.map(|r| r.0.len())),
    }
}

fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("synovia_time_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The CSV has one row per level with the documented header; the PVD lists one data set per
/// level with its time, and the `.vtu` files carry the displacement and contact pressure.
#[test]
fn csv_and_pvd_series_are_written_and_read_back() {
    let mu = 0.3;
    let (model, pairs) =
        half_discs(6, Constant(0.02), PiecewiseLinear::new(&[(0.0, 0.0), (1.0, 4e-3)]).expect("h"), true, mu);
    let mut stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), QuasiStaticParams::default())
            .expect("stepper");
    let dir = scratch_dir("output");
    let mut out = QuasiStaticOutput::new(&dir, "cycle", stepper.geometry()).expect("output");
    let times = [0.0, 0.25, 0.5, 1.0];
    let solver = pdas();
    let records = stepper
        .run(&model, &times, &solver, |rec, res| {
            check_kkt(rec, res)?;
            out.write_step(&model, rec, res).map(|_| ())
        })
        .expect("run");
    let csv = out.write_csv(&records).expect("csv");
    let text = std::fs::read_to_string(&csv).expect("read csv");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), times.len() + 1);
    let header: Vec<&str> = lines[0].split(',').collect();
    // every header cell is `name [unit]`; the names without units:
    assert!(header.iter().all(|c| c.ends_with(']') && c.contains(" [")), "{header:?}");
    assert!(lines[0].contains("indenter-base_peak_pressure [MPa]"), "{}", lines[0]);
    let header: Vec<&str> = header.iter().map(|c| c.split(" [").next().unwrap_or(c)).collect();
    for col in [
        "step",
        "time",
        "strain_energy",
        "friction_dissipation",
        "cumulative_friction_dissipation",
        "indenter-base_normal_force",
        "indenter-base_tangential_force",
        "indenter-base_stick_area",
    ] {
        assert!(header.contains(&col), "missing column {col}: {header:?}");
    }
    for (line, rec) in lines[1..].iter().zip(&records) {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len());
        let time: Real = cells[1].parse().expect("time");
        assert_eq!(time, rec.time);
        let nf: Real = cells[header.iter().position(|c| *c == "indenter-base_normal_force").expect("col")]
            .parse()
            .expect("number");
        assert_eq!(nf, rec.pairs[0].normal_force);
    }
    assert_eq!(out.n_steps(), times.len());
    let entries = synovia_io::read_pvd(out.pvd_path()).expect("pvd");
    assert_eq!(entries.len(), times.len());
    for (e, t) in entries.iter().zip(&times) {
        assert_eq!(e.time, *t);
    }
    let last = synovia_io::read_vtu(&entries[3].file).expect("vtu");
    assert_eq!(last.pieces.len(), 2);
    let pressure = last.pieces[0].point_field("contact_pressure").expect("pressure field");
    let peak = pressure.values.iter().fold(0.0, |m: Real, v| m.max(*v));
    assert!((peak - records[3].pairs[0].peak_pressure).abs() <= 1e-12 * peak && peak > 0.0);
    let lower = last.pieces[1].point_field("contact_pressure").expect("pressure on base");
    assert!((lower.values.iter().fold(0.0, |m: Real, v| m.max(*v)) - peak).abs() <= 1e-12 * peak);
    for name in ["displacement", "friction_traction", "stick", "von_mises_nodal"] {
        assert!(last.pieces[0].point_field(name).is_some(), "missing {name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad time levels, parameters and a foreign model are errors, not panics.
#[test]
fn invalid_inputs_are_reported() {
    let (model, pairs) = half_discs(4, Constant(0.01), Constant(0.0), false, 0.2);
    let bad = QuasiStaticParams::default().with_max_fixed_point(0);
    assert!(matches!(
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), bad),
        Err(TimeError::InvalidParameter(_))
    ));
    let bad = QuasiStaticParams::default().with_fixed_point_tolerance(f64::NAN);
    assert!(matches!(
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), bad),
        Err(TimeError::InvalidParameter(_))
    ));
    let mut stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), QuasiStaticParams::default())
            .expect("stepper");
    let solver = pdas();
    for times in [&[][..], &[0.0, 0.0], &[0.0, 1.0, 0.5], &[f64::NAN]] {
        let r = stepper.run(&model, times, &solver, |_, _| Ok(()));
        assert!(matches!(r, Err(TimeError::InvalidParameter(_))), "{times:?}");
    }
    let (other, _) = half_discs(5, Constant(0.01), Constant(0.0), false, 0.2);
    let r = stepper.run(&other, &[0.0, 1.0], &solver, |_, _| Ok(()));
    assert!(matches!(r, Err(TimeError::InvalidParameter(_))));
    // the observer's error stops the run
    let mut calls = 0;
    let r = stepper.run(&model, &[0.0, 1.0, 2.0], &solver, |_, _| {
        calls += 1;
        Err(TimeError::InvalidParameter("stop".into()))
    });
    assert!(matches!(r, Err(TimeError::InvalidParameter(m)) if m == "stop"));
    assert_eq!(calls, 1);
}

/// The slip origin options: on a monotone path the report's total-displacement form and the
/// incremental form agree; around a closed cycle the total form is path independent (it
/// returns to the initial state, no residual friction force), the incremental form keeps a
/// residual tangential force (hysteresis). With `initial_friction` step 0 is a Tresca (here
/// Coulomb) solve whose slip is measured from the reference state.
#[test]
fn slip_origin_and_initial_friction_options() {
    let (mu, push, s) = (0.3, 0.02, 6e-3);
    let shift = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, s), (3.0, -s), (4.0, 0.0)]).expect("history");
    let (model, pairs) = half_discs(7, Constant(push), shift, true, mu);
    let times = [0.0, 0.5, 1.0, 2.0, 3.0, 4.0];
    let solver = pdas();
    let run = |incremental_slip: bool| -> (Vec<StepRecord>, Vec<Vec<Real>>) {
        let params = QuasiStaticParams::default().with_incremental_slip(incremental_slip);
        let mut stepper =
            QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), params).expect("stepper");
        let mut us = Vec::new();
        let records = stepper
            .run(&model, &times, &solver, |rec, res| {
                check_kkt(rec, res)?;
                us.push(res.solution.u.clone());
                Ok(())
            })
            .expect("run");
        (records, us)
    };
    let (inc, u_inc) = run(true);
    let (tot, u_tot) = run(false);
    for i in 0..3 {
        let d = rel_diff(&u_inc[i], &u_tot[i]);
        assert!(d < 1e-8, "monotone level {i}: incremental vs total differ by {d:e}");
    }
    let residual = |r: &StepRecord| r.pairs[0].tangential_force / (mu * r.pairs[0].normal_force);
    let (q_inc, q_tot) = (residual(&inc[5]), residual(&tot[5]));
    let back = rel_diff(&u_tot[0], &u_tot[5]);
    println!("after the cycle: Q/μP incremental {q_inc:.3e}, total {q_tot:.3e}; total-form state vs initial {back:.2e}");
    assert!(q_inc > 1e-3, "incremental slip keeps a residual friction force");
    assert!(q_tot < 1e-8 && back < 1e-8, "total-displacement slip is path independent");
    assert!(inc[5].cumulative_friction_dissipation > 0.0);

    // initial friction on a rigid flat: the Poisson expansion of the indenter slips at the edges
    let (model, pairs) = half_discs(7, Constant(0.01), Constant(0.0), false, mu);
    let params = QuasiStaticParams::default().with_initial_friction(true).with_coulomb_fixed_point(true);
    let mut stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), params).expect("stepper");
    let mut cells = Vec::new();
    let records = stepper
        .run(&model, &[0.0, 1.0], &solver, |rec, res| {
            check_kkt(rec, res)?;
            cells.push(res.cell_node.len());
            Ok(())
        })
        .expect("run");
    println!(
        "initial friction: cells {cells:?}, dissipation {:.3e}, {:.3e}",
        records[0].friction_dissipation, records[1].friction_dissipation
    );
    assert!(cells[0] > 0 && records[0].friction_dissipation > 0.0);
    assert!(records[0].pairs[0].stick_area > 0.0 && records[0].pairs[0].slip_area > 0.0);
    // with the Coulomb fixed point step 0 is an equilibrium of the next level at the same load:
    // nothing slips any more (without it, the lagged g_c of step 0 lets the edges slip a bit)
    assert!(records[1].friction_dissipation < 1e-6 * records[0].friction_dissipation);
}

/// Records without the wall time (`step_s`), for bit-exact comparisons.
fn timeless(rec: &StepRecord) -> StepRecord {
    StepRecord { step_s: 0.0, ..rec.clone() }
}

/// Same step, same active and stick/slip sets (areas, iterations), forces and energies equal to
/// `tol` relative.
fn assert_records_close(a: &StepRecord, b: &StepRecord, tol: Real) {
    // relative to `scale` (the pair's force for its components, which may be rounding zeros)
    let close_to = |x: Real, y: Real, scale: Real, what: &str| {
        assert!((x - y).abs() <= tol * scale.max(1e-300), "{what}: {x} vs {y}");
    };
    let close = |x: Real, y: Real, what: &str| close_to(x, y, x.abs().max(y.abs()), what);
    assert_eq!((a.step, a.time, a.iterations, a.pairs.len()), (b.step, b.time, b.iterations, b.pairs.len()));
    for (p, q) in a.pairs.iter().zip(&b.pairs) {
        assert_eq!(
            (&p.name, p.contact_area, p.stick_area, p.slip_area),
            (&q.name, q.contact_area, q.stick_area, q.slip_area)
        );
        let scale = p.force.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for k in 0..3 {
            close_to(p.force[k], q.force[k], scale, "force");
        }
        close(p.normal_force, q.normal_force, "normal force");
        close_to(p.tangential_force, q.tangential_force, scale, "tangential force");
        close(p.peak_pressure, q.peak_pressure, "peak pressure");
    }
    close(a.strain_energy, b.strain_energy, "strain energy");
    close_to(a.friction_dissipation, b.friction_dissipation, a.strain_energy.abs(), "friction dissipation");
}

fn assert_same_result(a: &StaticContactResult<2>, b: &StaticContactResult<2>) {
    assert_eq!(a.displacement, b.displacement);
    assert_eq!(a.solution.u, b.solution.u);
    assert_eq!(a.solution.lambda_n, b.solution.lambda_n);
    assert_eq!(a.solution.lambda_t, b.solution.lambda_t);
    assert_eq!(a.cell_node, b.cell_node);
    assert_eq!(a.slip_bound, b.slip_bound);
}

#[test]
fn stepping_one_level_at_a_time_is_bit_identical_to_run() {
    // push, then shear into partial slip and back: friction state carried from level to level
    let push = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, 0.02)]).expect("push");
    let shift = PiecewiseLinear::new(&[(1.0, 0.0), (2.0, 0.004), (3.0, -0.002)]).expect("shift");
    let (model, pairs) = half_discs(1, push, shift, true, 0.3);
    let times = [0.5, 1.0, 1.5, 2.0, 2.5, 3.0];
    for params in [
        QuasiStaticParams::default(),
        QuasiStaticParams::default().with_coulomb_fixed_point(true).with_initial_friction(true),
        QuasiStaticParams::default().with_incremental_slip(false),
    ] {
        let solver = pdas();
        let mut runner =
            QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), params).expect("new");
        let mut run_results = Vec::new();
        let records = runner
            .run(&model, &times, &solver, |_, res| {
                run_results.push(res.clone());
                Ok(())
            })
            .expect("run");
        let mut stepper =
            QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), params).expect("new");
        for (i, &t) in times.iter().enumerate() {
            assert_eq!(stepper.next_step(), i);
            let (rec, res) = stepper.step(&model, t, &solver).expect("step");
            assert_eq!(timeless(&rec), timeless(&records[i]), "{params:?} level {i}");
            assert_same_result(res, &run_results[i]);
            assert_eq!(stepper.last_time(), Some(t));
        }
        assert!(records.iter().skip(2).any(|r| r.friction_dissipation > 0.0), "{params:?}: no slip");
        // time must increase; a failed step keeps the sequence
        assert!(matches!(stepper.step(&model, 3.0, &solver), Err(TimeError::InvalidParameter(_))));
        assert!(stepper.step(&model, Real::NAN, &solver).is_err());
        assert_eq!(stepper.next_step(), times.len());
        // restart: step 0 again, cold or warm, equal to the first level of the run up to
        // rounding (its A⁻¹F now comes from the recycled load subspace of the later levels)
        let (rec, _) = stepper.restart(&model, times[0], &solver, false).expect("restart");
        assert_records_close(&rec, &records[0], 1e-12);
        assert_eq!(stepper.next_step(), 1);
        stepper.reset();
        assert!(stepper.last_result().is_none() && stepper.next_step() == 0);
    }
}

#[test]
fn warm_restart_matches_a_cold_static_solve() {
    let depth = synovia_time::history::SharedValue::new(0.01);
    let (model, pairs) = half_discs(1, depth.clone(), Constant(0.0), false, 0.0);
    let solver = pdas();
    let mut stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), QuasiStaticParams::default())
            .expect("new");
    assert!(!stepper.has_warm_start());
    stepper.restart(&model, 0.0, &solver, true).expect("first");
    assert!(stepper.has_warm_start());
    depth.set(0.015);
    let (warm_rec, warm) = stepper.restart(&model, 0.0, &solver, true).expect("warm");
    let warm = warm.clone();
    let mut cold_stepper =
        QuasiStaticStepper::new(&model, &pairs, ElasticParams::default(), QuasiStaticParams::default())
            .expect("new");
    let (cold_rec, cold) = cold_stepper.step(&model, 0.0, &solver).expect("cold");
    let du: Vec<Real> = warm.solution.u.iter().zip(&cold.solution.u).map(|(a, b)| a - b).collect();
    assert!(max_abs(&du) <= 1e-10 * max_abs(&cold.solution.u), "{}", max_abs(&du));
    assert!(rel_diff(&warm.solution.lambda_n, &cold.solution.lambda_n) <= 1e-10);
    assert!(warm.kkt.max() < 1e-8, "{:?}", warm.kkt);
    assert!(warm_rec.iterations <= cold_rec.iterations, "{} > {}", warm_rec.iterations, cold_rec.iterations);
}
