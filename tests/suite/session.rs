//! The re-solve API for navigation ([`JointModel::prepare`], [`JointSession`]): re-solves with
//! new loads equal fresh runs, never refactorise, and are warm-started; a sequence of session
//! steps is the quasi-static run.

use synovia::prelude::*;
use synovia::time::history::FnHistory;
use synovia::time::quasistatic::QuasiStaticParams;

/// The navigation inputs: depth and sideways shift of the tool (the block's top), and a
/// pressure on the block's left side.
#[derive(Clone)]
struct Inputs {
    depth: SharedValue,
    shift: SharedValue,
    side: SharedValue,
}

impl Inputs {
    fn new(depth: Real, shift: Real, side: Real) -> Self {
        Self { depth: SharedValue::new(depth), shift: SharedValue::new(shift), side: SharedValue::new(side) }
    }
    fn set(&self, depth: Real, shift: Real, side: Real) {
        self.depth.set(depth);
        self.shift.set(shift);
        self.side.set(side);
    }
}

/// A block `[−1, 1] × [0, 0.5]` pressed onto a rigid disc of radius 2 below it; the top is
/// moved by `(shift, −depth)` (times `ramp(t)`), the left side loaded by the pressure `side`.
fn block_on_disc(
    depth: impl LoadHistory + 'static,
    shift: impl LoadHistory + 'static,
    side: impl LoadHistory + 'static,
    ramp: impl LoadHistory + 'static,
    mu: Real,
    params: QuasiStaticParams,
) -> JointModel<2> {
    block_on_disc_n(32, depth, shift, side, ramp, mu, params)
}

/// [`block_on_disc`] with `n × n/4` cell pairs.
fn block_on_disc_n(
    n: usize,
    depth: impl LoadHistory + 'static,
    shift: impl LoadHistory + 'static,
    side: impl LoadHistory + 'static,
    ramp: impl LoadHistory + 'static,
    mu: Real,
    params: QuasiStaticParams,
) -> JointModel<2> {
    let mesh = rectangle(-1.0, 1.0, 0.0, 0.5, n, n / 4, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let b = joint.add_body("block", mesh, plane_strain(1.0e3, 0.3).expect("material")).expect("body");
    joint
        .prescribe_field(b, "top", ComponentMask::ALL, move |_x, t| {
            Vector::<2>::new(shift.value(t), -depth.value(t)) * ramp.value(t)
        })
        .expect("top");
    joint.pressure(b, "left", 1.0, side).expect("left");
    let disc = SphereObstacle::new(Point::<2>::new(0.0, -2.0), 2.0, false).expect("disc");
    joint.contact_rigid("disc", b, "bottom", disc, mu).expect("contact");
    joint.quasistatic_params(params);
    joint
}

fn max_abs(v: impl IntoIterator<Item = Real>) -> Real {
    v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn flat(u: &[Vec<Vector<2>>]) -> Vec<Real> {
    u.iter().flatten().flat_map(|v| [v[0], v[1]]).collect()
}

fn rel_diff(a: &[Real], b: &[Real]) -> Real {
    assert_eq!(a.len(), b.len());
    let scale = max_abs(a.iter().copied()).max(max_abs(b.iter().copied())).max(1e-300);
    max_abs(a.iter().zip(b).map(|(x, y)| x - y)) / scale
}

#[test]
fn resolve_with_new_loads_equals_a_fresh_run_static() {
    let frames = [(0.01, 0.0, 0.0), (0.02, 0.001, 0.5), (0.015, -0.002, 2.0), (0.03, 0.0, 0.0)];
    for (mu, initial_friction) in [(0.0, false), (0.3, true)] {
        let params = QuasiStaticParams::default().with_initial_friction(initial_friction);
        let inputs = Inputs::new(frames[0].0, frames[0].1, frames[0].2);
        let joint = block_on_disc(
            inputs.depth.clone(),
            inputs.shift.clone(),
            inputs.side.clone(),
            Constant(1.0),
            mu,
            params,
        );
        let mut session = joint.prepare().expect("prepare");
        let info = session.elastic_info();
        assert_eq!(session.factorizations(), 1);
        for (i, &(depth, shift, side)) in frames.iter().enumerate() {
            inputs.set(depth, shift, side);
            let report = session.solve_static(0.0).expect("re-solve");
            assert_eq!(report.warm_started, i > 0);
            assert_eq!(report.step, 0);
            let res = session.result().expect("result");
            assert!(res.kkt.satisfied(1e-8), "frame {i}: {:?}", res.kkt);
            // a fresh model with these loads as constants, solved from scratch
            let fresh_joint =
                block_on_disc(Constant(depth), Constant(shift), Constant(side), Constant(1.0), mu, params);
            let fresh = fresh_joint.run_static(0.0).expect("fresh");
            let fresh_res = fresh.contact.as_ref().expect("contact");
            let du = rel_diff(&flat(&res.displacement), &flat(&fresh.displacement));
            let dl = rel_diff(&res.solution.lambda_n, &fresh_res.solution.lambda_n);
            let dt = rel_diff(&res.solution.lambda_t, &fresh_res.solution.lambda_t);
            let rec = session.record().expect("record");
            let (f, g) = (&rec.pairs[0], &fresh.records[0].pairs[0]);
            let df = (f.normal_force - g.normal_force).abs() / g.normal_force.abs();
            let dq = (f.tangential_force - g.tangential_force).abs() / g.normal_force.abs();
            println!(
                "mu {mu} frame {i}: warm {} its {} ({:.2e} s) | fresh its {} ({:.2e} s solve, {:.2e} s total) | rel diff u {du:.1e} λn {dl:.1e} λt {dt:.1e} P {df:.1e} Q {dq:.1e}",
                report.warm_started,
                report.iterations,
                report.seconds,
                fresh.records[0].iterations,
                fresh.records[0].step_s,
                fresh.total_s,
            );
            assert!(du <= 1e-10 && dl <= 1e-10 && dt <= 1e-10 && df <= 1e-10 && dq <= 1e-10, "frame {i}");
            assert!(f.normal_force > 0.0);
            // warm start: not more iterations than the cold start of the fresh run
            assert!(report.iterations <= fresh.records[0].iterations, "frame {i}");
        }
        // no refactorisation: the factorisation's figures (incl. its timings) are unchanged
        assert_eq!(session.elastic_info(), info);
        assert_eq!(session.factorizations(), 1);
        // a cold re-solve after reset gives the same solution
        let warm_u = flat(session.displacement().expect("u"));
        session.reset();
        assert!(session.result().is_none());
        let cold = session.solve_static(0.0).expect("cold");
        assert!(!cold.warm_started);
        assert!(rel_diff(&warm_u, &flat(session.displacement().expect("u"))) <= 1e-10);
    }
}

#[test]
fn warm_resolve_needs_fewer_iterations_than_a_cold_one() {
    let inputs = Inputs::new(0.01, 0.0, 0.0);
    let joint = block_on_disc_n(
        256,
        inputs.depth.clone(),
        inputs.shift.clone(),
        inputs.side.clone(),
        Constant(1.0),
        0.0,
        QuasiStaticParams::default(),
    );
    let mut session = joint.prepare().expect("prepare");
    session.solve_static(0.0).expect("first");
    let (mut warm_its, mut cold_its) = (0, 0);
    let (mut warm_s, mut cold_s) = (0.0, 0.0);
    // small changes from frame to frame, as in navigation
    for k in 1..=10 {
        let depth = 0.01 + 0.0005 * k as Real;
        inputs.set(depth, 0.0, 0.0);
        let warm = session.solve_static(0.0).expect("warm");
        assert!(warm.warm_started);
        let u = flat(session.displacement().expect("u"));
        session.reset();
        let cold = session.solve_static(0.0).expect("cold");
        assert!(!cold.warm_started);
        assert!(rel_diff(&u, &flat(session.displacement().expect("u"))) <= 1e-10);
        assert!(
            warm.iterations <= cold.iterations,
            "frame {k}: warm {} cold {}",
            warm.iterations,
            cold.iterations
        );
        warm_its += warm.iterations;
        cold_its += cold.iterations;
        warm_s += warm.seconds;
        cold_s += cold.seconds;
    }
    let fresh = joint.run_static(0.0).expect("fresh");
    println!(
        "{} dofs, 10 frames: warm {warm_its} iterations ({:.2e} s/frame), cold {cold_its} iterations ({:.2e} s/frame); fresh run_static {:.2e} s (set-up {:.2e} s); session set-up {:.2e} s",
        session.elastic_info().n_dofs,
        warm_s / 10.0,
        cold_s / 10.0,
        fresh.total_s,
        fresh.setup_s,
        session.setup_s()
    );
    assert!(warm_its < cold_its, "warm {warm_its} cold {cold_its}");
}

#[test]
fn session_steps_are_the_quasistatic_run() {
    // push down, then shear with friction: the friction state goes from step to step
    let down = PiecewiseLinear::new(&[(0.0, 0.0), (1.0, 1.0)]).expect("down");
    let times = [0.5, 1.0, 1.5, 2.0, 2.5];
    let joint = block_on_disc(
        Constant(0.02),
        PiecewiseLinear::new(&[(1.0, 0.0), (2.0, 0.05), (3.0, 0.0)]).expect("shift"),
        Constant(0.0),
        down,
        0.3,
        QuasiStaticParams::default(),
    );
    let run = joint.run_quasistatic(&times).expect("run");
    let mut session = joint.prepare().expect("prepare");
    for (i, &t) in times.iter().enumerate() {
        let report = session.step(t).expect("step");
        assert_eq!(report.step, i);
        assert_eq!(report.warm_started, i > 0);
        let rec = session.record().expect("record");
        let expected = &run.records[i];
        assert_eq!(StepRecord { step_s: 0.0, ..rec.clone() }, StepRecord { step_s: 0.0, ..expected.clone() });
    }
    assert!(run.records.iter().any(|r| r.friction_dissipation > 0.0));
    let last = run.contact.as_ref().expect("contact");
    let res = session.result().expect("result");
    assert_eq!(res.displacement, last.displacement);
    assert_eq!(res.solution.lambda_t, last.solution.lambda_t);
    // time must increase; the failed step keeps the state
    assert!(session.step(2.5).is_err());
    assert_eq!(session.report().map(|r| r.step), Some(times.len() - 1));
    session.step(3.0).expect("next");
}

#[test]
fn elastic_session_without_contact() {
    let load = SharedValue::new(0.01);
    let mesh = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let b = joint.add_body("b", mesh, plane_strain(1.0, 0.3).expect("material")).expect("body");
    joint.clamp(b, "bottom").expect("clamp").pressure(b, "top", 1.0, load.clone()).expect("load");
    let mut session = joint.prepare().expect("prepare");
    session.solve_static(0.0).expect("solve");
    let u1 = flat(session.displacement().expect("u"));
    load.set(0.02);
    let r = session.solve_static(0.0).expect("solve");
    assert!(!r.warm_started && r.iterations == 0);
    let u2 = flat(session.displacement().expect("u"));
    let doubled: Vec<Real> = u1.iter().map(|x| 2.0 * x).collect();
    assert!(rel_diff(&u2, &doubled) < 1e-12);
    assert_eq!(session.step(1.0).expect("step").step, 1);
    assert!(session.step(0.5).is_err());
}

/// A navigation loop keeps memory flat: under a periodic motion with friction (the slip
/// bounds `g_c`, which scale the friction rows, change at every step) the solve caches reach
/// their size in the first period and do not grow over the next ones (issue 15: before the
/// row solves were keyed by direction, every step added the solves of its rescaled friction
/// rows until the budget).
#[test]
fn periodic_frictional_loop_keeps_the_caches_flat() {
    let period = 11.0;
    let w = 2.0 * std::f64::consts::PI / period;
    let depth = FnHistory::new(move |t| 0.02 * (1.0 + 0.5 * (w * t).sin()));
    let shift = FnHistory::new(move |t| 0.01 * (w * t).cos());
    let joint = block_on_disc(depth, shift, Constant(0.0), Constant(1.0), 0.3, QuasiStaticParams::default());
    let mut session = joint.prepare().expect("prepare");
    let mut after_first_period = 0;
    let mut bounds_changed = 0;
    let mut last_tangential = None;
    for step in 1..=(3 * period as usize) {
        let report = session.step(step as Real).expect("step");
        assert!(report.kkt < 1e-8, "step {step}: KKT {:.2e}", report.kkt);
        let tangential = session.record().map(|r| r.pairs[0].tangential_force);
        if last_tangential.is_some() && tangential != last_tangential {
            bounds_changed += 1;
        }
        last_tangential = tangential;
        if step == period as usize {
            after_first_period = session.cache_bytes();
        }
    }
    assert!(bounds_changed > 20, "the friction state must change from step to step ({bounds_changed})");
    assert!(after_first_period > 0, "the contact solves keep row solves and columns");
    assert_eq!(session.cache_bytes(), after_first_period, "the caches grew after the first period");
}
