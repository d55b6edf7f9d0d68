//! Quasi-static time stepping (spec §7): path independence of frictionless contact, energy
//! balance of a frictional cycle, Cattaneo–Mindlin under a rising tangential load up to gross
//! sliding, the Coulomb fixed point, and the CSV/PVD output.

use std::path::PathBuf;
use std::sync::Arc;

use synovia_contact::operators::{ContactPair, PlaneObstacle};
use synovia_contact::{ContactParams, ContactSolver, StaticContact, StaticContactResult};
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
    Pdas::new(ContactParams { tolerance: 1e-12, max_iterations: 200, ..Default::default() })
}

/// The 2D Hertz set-up of `synovia::hertz::hertz2d_model`: the upper half-disc `"indenter"`
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
    model.prescribe(up, "top", move |_, t| Vector::<2>::new(shift.value(t), -push.value(t))).expect("prescribe");
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
/// state gives `Q/(μP) = target` (secant; the loading is monotone, so the quasi-static path
/// reaches the same state).
fn shift_for_ratio(levels: usize, push: Real, mu: Real, target: Real) -> Real {
    let (model, pairs) = half_discs(levels, Constant(push), FnHistory::new(|t| t), true, mu);
    let sc = StaticContact::new(&model, &pairs, ElasticParams::default()).expect("factorise");
    let solver = pdas();
    let normal = sc.solve(&model, 0.0, &solver, None, None, None).expect("normal");
    let geo = sc.geometry();
    let p = normal.normal_force(geo, 0..geo.len());
    let g = geo.slip_bounds_from_pressure(&normal.solution.lambda_n);
    let ratio = |s: Real| -> Real {
        let res = sc.solve(&model, s, &solver, Some(&g), Some(&normal.displacement), None).expect("tresca");
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
    println!("normal force per level: {force:.4e?}");
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
                assert!(max_abs(ub) == 0.0 && max_abs(lb) == 0.0 && max_abs(la) == 0.0, "unloaded state not zero");
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
    let (du, dl) = (rel_diff(&cold.solution.u, &states[12].0), rel_diff(&cold.solution.lambda_n, &states[12].1));
    println!("largest relative difference at equal loads {worst:.2e}; vs cold solve ΔU {du:.2e} ΔΛ_n {dl:.2e}");
    assert!(du < 1e-10 && dl < 1e-10);
    // strain energy is the same at equal loads and rises with the load
    assert!((records[4].strain_energy - records[12].strain_energy).abs() <= 1e-10 * records[4].strain_energy);
    assert!(records[4].strain_energy > records[2].strain_energy && records[2].strain_energy > 0.0);
}
