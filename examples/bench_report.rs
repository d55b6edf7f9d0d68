//! # Contact and time-stepping benchmark report (issue 6)
//!
//! Prints one JSON line per case with `case`, `dofs`, `time_s`, `elastic_s` (one plain elastic
//! factorisation + solve of the same `A`, [`ElasticSolver::new`] + [`ElasticSolver::solve`], in
//! the same run; when one takes less than a second it is timed three times and the median is
//! used, `elastic_runs` in the JSON), `ratio = time_s / elastic_s` and `peak_rss_mb` (`VmHWM` of the case's own child
//! process: every case runs in this executable re-run as `--child CASE SCALE`). Cases:
//!
//! - `hertz2d_tresca`: two identical half-discs ([`hertz2d_model`], PDAS), a frictionless normal
//!   solve (`normal_s`), then a Tresca solve with `g_c = μ p` (μ = 0.3) and a small tangential
//!   shift of the top (`tresca_s`); `time_s = tresca_s` (the Tresca contact solve);
//! - `resolve_new_loads`: the same model and factorisation after the Tresca solve, re-solved with
//!   a new push (+5 %) and shift (× 1.5), warm-started from the previous solution;
//!   `time_s` = that re-solve;
//! - `hemisphere3d_friction`: the hemisphere of [`synovia_models::hertz::Hertz3d`] on a rigid flat with
//!   friction, normal then Tresca step as above; `time_s = tresca_s`;
//! - `knee2d_gait`: [`Knee2d`] (default mesh) over a quasi-static gait cycle of
//!   [`cycle_times`]`(steps)` poses ([`Knee2d::run`]: the femur in its body frame, one
//!   factorisation for the cycle); `time_s` = the whole cycle including that factorisation,
//!   `elastic_s` = one elastic factorisation + solve of the model (the stiffness is the same in
//!   every pose);
//! - `pose_resolve_3d`: the `tkr3d` knee replacement ([`Tkr3d`], 1 mm insert mesh, 42 063
//!   DOFs) re-solved for new poses of the rigid femoral component on one factorisation, as a
//!   navigation tool would: all six degrees of freedom prescribed (the superior–inferior
//!   translation at the values a force-controlled frictionless pass found, so each pose carries
//!   the ISO 14243-1 load), 100 poses over the cycle after a first one; frictionless
//!   (`JointSession::solve_static`, warm-started from the previous pose) and with μ = 0.04
//!   (`JointSession::step`, quasi-static levels); `time_s` = the frictionless poses,
//!   `time_per_pose_ms`, `friction_time_per_pose_ms`, `ratio` = time per pose / `elastic_s`,
//!   `max_force_error` (the contact force against the ISO load), `from_scratch_ratio` (set-up
//!   with the first pose, per elastic solve).
//! - `large_contact_surface` (issue 17, item 3): a 2 mm cartilage layer on a femoral head (one
//!   P1 cap of [`layered_cap_3d`], radii 23–25 mm, half-angle 80°, `n_surface` 71: 20 449
//!   candidate nodes on its outer sphere, 245 388 DOFs) on the rigid bone, pushed 0.032 mm into
//!   a rigid spherical socket (radial clearance 0.5 mm, touching at the pole), normal then
//!   Tresca step (shift 0.01 mm) as above; `time_s = tresca_s`, plus `setup_s`,
//!   `candidate_nodes`, `active_nodes` (positive pressure in the Tresca solution) and
//!   `elastic_peak_rss_mb` (the plain elastic factorisation + solve of the model in a child of
//!   its own) with `rss_over_elastic`. `scale` multiplies `n_surface` by `√scale`.
//!
//! Sizes at scale 1 (the defaults): 2D Hertz level 14 (169 120 DOFs), 3D hemisphere level 17
//! (≈ 270k DOFs, extrapolated: 79 686 at level 15, ≈ × 1.85 per level), 100 knee poses of the
//! default knee mesh (16 528 DOFs). `scale < 1` removes `round(log2(1 / scale))` refinement levels (2D, 3D) and
//! scales the number of knee steps.
//!
//! ```text
//! cargo run --release --example bench_report            # scale 1
//! cargo run --release --example bench_report 0.25       # quick run
//! cargo run --release --example bench_report 1 hertz2d_tresca resolve_new_loads
//! ```
//!
//! The contact cases also print `normal_active` (rows in contact after the normal solve),
//! `active_nodes` (contact nodes with a positive pressure in the final solution),
//! `trailing_dofs` (dofs in the dense trailing block of the factor) and the symbolic and
//! numeric times and size of the contact set-up's factorisation. The environment variables
//! `SYNOVIA_TRAILING_DOFS` and `SYNOVIA_SCREENED_DOFS` override
//! `InterfaceBlockParams::max_dofs` and `InterfaceBlockParams::screened_dofs` (to measure
//! the budgets of the trailing block).
//!
//! Results on the project's 2-core machine are in `docs/performance.md`.

use std::time::Instant;

use serde_json::{json, Value};
use synovia::contact::StaticContact;
use synovia::contact_ops::operators::ContactPair;
use synovia::mesh::generators::layered_cap_3d;
use synovia::prelude::*;
use synovia_models::hertz::{hertz2d_model, hertz3d_model, Hertz2d, Hertz3d};
use synovia_models::knee2d::{cycle_times, iso14243_axial_force, Knee2d};
use synovia_models::tkr3d::{Superior, Tkr3d};

mod bench_common;
use bench_common::{parse_args, peak_rss_bytes, spawn_case, Invocation, Res};

const CASES: [&str; 6] = [
    "hertz2d_tresca",
    "resolve_new_loads",
    "hemisphere3d_friction",
    "knee2d_gait",
    "pose_resolve_3d",
    "large_contact_surface",
];
/// The plain elastic solve of `large_contact_surface`'s model in a child of its own (for its
/// peak RSS); run by that case, not listed in [`CASES`].
const LARGE_ELASTIC: &str = "large_contact_surface_elastic";
const MU: Real = 0.3;

/// Refinement levels at `scale`: `base` minus `round(log2(1 / scale))`.
fn levels(base: usize, scale: f64) -> usize {
    let drop = (-scale.log2()).round().max(0.0) as usize;
    base.saturating_sub(drop).max(2)
}

/// One plain elastic factorisation + solve of `model`, in seconds: one run, or the median
/// of three when one run takes less than a second (timer noise on a shared machine).
fn elastic_time<const D: usize>(model: &Model<D>) -> Res<(f64, usize)> {
    let once = || -> Res<f64> {
        let t0 = Instant::now();
        let mut s = ElasticSolver::new(model, ElasticParams::default())?;
        s.solve(model, 0.0)?;
        Ok(t0.elapsed().as_secs_f64())
    };
    let first = once()?;
    if first >= 1.0 {
        return Ok((first, 1));
    }
    let mut runs = [first, once()?, once()?];
    runs.sort_by(f64::total_cmp);
    Ok((runs[1], 3))
}

fn hertz2d_params(scale: f64, push: Real) -> Hertz2d {
    Hertz2d { e2: Some(1.0), push, levels: levels(14, scale), ..Default::default() }
}

/// Normal then Tresca solve of a frictional pair; returns the JSON fields.
fn normal_tresca<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    shift: Real,
    resolve: Option<&Model<D>>,
) -> Res<Value> {
    let solver = synovia::solvers::by_name("pdas")?;
    let (elastic_s, elastic_runs) = elastic_time(model)?;
    let t_setup = Instant::now();
    let mut block = synovia::linalg::InterfaceBlockParams::default();
    // overrides for measuring the interface-block budgets
    let env = |name: &str| std::env::var(name).ok().and_then(|v| v.parse().ok());
    if let Some(k) = env("SYNOVIA_TRAILING_DOFS") {
        block = block.with_max_dofs(k);
    }
    if let Some(k) = env("SYNOVIA_SCREENED_DOFS") {
        block = block.with_screened_dofs(k);
    }
    let sc = StaticContact::with_interface_block(model, pairs, ElasticParams::default(), block)?;
    let setup_s = t_setup.elapsed().as_secs_f64();
    let geo = sc.geometry();
    let t0 = Instant::now();
    let normal = sc.solve(model, 0.0, solver.as_ref(), None, None, None)?;
    let normal_s = t0.elapsed().as_secs_f64();
    let gc = geo.slip_bounds_from_pressure(&normal.solution.lambda_n);
    let t1 = Instant::now();
    let tresca = sc.solve(model, shift, solver.as_ref(), Some(&gc), Some(&normal.displacement), None)?;
    let tresca_s = t1.elapsed().as_secs_f64();
    let dofs = sc.elastic().info().n_dofs;
    let mut v = json!({
        "dofs": dofs,
        "contact_nodes": geo.len(),
        "elastic_s": elastic_s,
        "elastic_runs": elastic_runs,
        "contact_setup_s": setup_s,
        "normal_s": normal_s,
        "tresca_s": tresca_s,
        "normal_iterations": normal.solution.report.iterations,
        "normal_active": normal.solution.report.active,
        "trailing_dofs": sc.elastic().cholesky().trailing().map_or(0, |b| b.dofs.len()),
        "contact_symbolic_s": sc.elastic().info().symbolic_s,
        "contact_numeric_s": sc.elastic().info().numeric_s,
        "contact_factor_nnz": sc.elastic().info().factor_nnz,
        "tresca_iterations": tresca.solution.report.iterations,
        // contact nodes with a positive pressure in the frictional solution
        "active_nodes": tresca.solution.lambda_n.iter().filter(|&&l| l > 0.0).count(),
        "kkt": tresca.kkt.max().max(normal.kkt.max()),
        // everything from the model: contact set-up (factorisation with the interface ordered
        // last, trailing block, geometry) + frictionless + Tresca solve, per elastic solve
        "from_scratch_ratio": (setup_s + normal_s + tresca_s) / elastic_s,
    });
    match resolve {
        None => v["time_s"] = json!(tresca_s),
        Some(new_model) => {
            let t2 = Instant::now();
            let res = sc.solve(
                new_model,
                1.5 * shift,
                solver.as_ref(),
                Some(&gc),
                Some(&normal.displacement),
                Some(&tresca.solution),
            )?;
            let resolve_s = t2.elapsed().as_secs_f64();
            v["time_s"] = json!(resolve_s);
            v["resolve_iterations"] = json!(res.solution.report.iterations);
            v["kkt"] = json!(res.kkt.max());
        }
    }
    Ok(v)
}

fn hertz2d_case(scale: f64, resolve: bool) -> Res<Value> {
    let p = hertz2d_params(scale, 0.02);
    let (model, mut pairs) = hertz2d_model(&p)?;
    pairs[0].friction = MU;
    let shift = 2e-4 * p.radius;
    let mut v = if resolve {
        // the same mesh (same dof map and `A`) with a 5 % larger push
        let (new_model, _) = hertz2d_model(&Hertz2d { push: 1.05 * p.push, ..p })?;
        normal_tresca(&model, &pairs, shift, Some(&new_model))?
    } else {
        normal_tresca(&model, &pairs, shift, None)?
    };
    v["levels"] = json!(p.levels);
    Ok(v)
}

fn hemisphere_case(scale: f64) -> Res<Value> {
    let p = Hertz3d { levels: levels(17, scale), ..Default::default() };
    // the time is the tangential displacement of the top
    let (model, mut pairs) = hertz3d_model(&p)?;
    pairs[0].friction = MU;
    let mut v = normal_tresca(&model, &pairs, 2e-4 * p.radius, None)?;
    v["levels"] = json!(p.levels);
    Ok(v)
}

/// The cartilage cap of `large_contact_surface` in its socket (see [`large_contact_case`]).
struct LargeCap {
    /// Inner (bone) and outer (cartilage surface) radius, mm.
    radii: [Real; 2],
    /// Half-angle of the cap (radians).
    half_angle: Real,
    /// Surface resolution of [`layered_cap_3d`]: `(2 n + 1)²` nodes per sphere.
    n_surface: usize,
    /// Radial cells through the cartilage.
    n_radial: usize,
    /// Radial clearance of the socket, mm.
    clearance: Real,
    /// Approach of the bone into the socket, mm.
    push: Real,
}

impl LargeCap {
    fn new(scale: f64) -> Self {
        Self {
            radii: [23.0, 25.0],
            half_angle: 80.0_f64.to_radians(),
            n_surface: ((71.0 * scale.sqrt()).round() as usize).max(4),
            n_radial: 4,
            clearance: 0.5,
            push: 0.032,
        }
    }

    /// The model: one cartilage body, its inner sphere moved by `(t, 0, −push)` with the
    /// (rigid) bone, its outer sphere the candidate surface against the rigid socket.
    fn model(&self) -> Res<(Model<3>, Vec<ContactPair<3>>)> {
        let mut layers = layered_cap_3d(
            Point::<3>::zeros(),
            &self.radii,
            self.half_angle,
            self.n_surface,
            &[self.n_radial],
        )?;
        let mut mesh = layers.pop().ok_or("no cartilage layer")?;
        mesh.set_part_kind("inner", BoundaryKind::Prescribed)?;
        mesh.set_part_kind("outer", BoundaryKind::Contact)?;
        let mut model = Model::<3>::new();
        let b = model.add_body("cartilage", mesh, std::sync::Arc::new(isotropic(10.0, 0.45)?))?;
        let push = self.push;
        model.prescribe(b, "inner", move |_, t| Vector::<3>::new(t, 0.0, -push))?;
        // the socket touches the cap's pole (centre raised by the clearance)
        let c = self.clearance;
        let socket = SphereObstacle::new(Point::<3>::new(0.0, 0.0, c), self.radii[1] + c, true)?;
        Ok((model, vec![ContactPair::rigid("cartilage-socket", b, "outer", std::sync::Arc::new(socket))]))
    }
}

/// `large_contact_surface`: a 2 mm cartilage layer on a femoral head (P1 cap of
/// [`layered_cap_3d`], radii 23–25 mm, half-angle 80°, its inner sphere carried by the rigid
/// bone) pushed into a rigid spherical socket (radial clearance 0.5 mm, touching at the pole)
/// by 0.032 mm, then shifted sideways by 0.01 mm: the whole outer sphere is the candidate
/// surface, a polar patch is in contact. Normal then Tresca solve (μ = 0.3) as the other
/// contact cases. The plain elastic solve of the same model also runs in a child of its own
/// ([`LARGE_ELASTIC`]) for its peak RSS.
fn large_contact_case(scale: f64) -> Res<Value> {
    // first, before this process holds anything large
    let plain = spawn_case(LARGE_ELASTIC, scale)?;
    let cap = LargeCap::new(scale);
    let (model, mut pairs) = cap.model()?;
    for pair in &mut pairs {
        pair.friction = MU;
    }
    let mut v = normal_tresca(&model, &pairs, 0.01, None)?;
    v["setup_s"] = v["contact_setup_s"].clone();
    v["candidate_nodes"] = v["contact_nodes"].clone();
    v["n_surface"] = json!(cap.n_surface);
    v["elastic_peak_rss_mb"] = plain["peak_rss_mb"].clone();
    v["elastic_child_s"] = plain["elastic_s"].clone();
    v["elastic_numeric_s"] = plain["numeric_s"].clone();
    v["elastic_factor_nnz"] = plain["factor_nnz"].clone();
    Ok(v)
}

/// The plain elastic factorisation + solve of `large_contact_surface`'s model, alone.
fn large_elastic_case(scale: f64) -> Res<Value> {
    let (model, _) = LargeCap::new(scale).model()?;
    let t0 = Instant::now();
    let mut s = ElasticSolver::new(&model, ElasticParams::default())?;
    s.solve(&model, 0.0)?;
    let elastic_s = t0.elapsed().as_secs_f64();
    let info = s.info();
    Ok(json!({
        "dofs": info.n_dofs,
        "time_s": elastic_s,
        "elastic_s": elastic_s,
        "symbolic_s": info.symbolic_s,
        "numeric_s": info.numeric_s,
        "factor_nnz": info.factor_nnz,
    }))
}

fn knee_case(scale: f64) -> Res<Value> {
    let steps = ((100.0 * scale).round() as usize).max(4);
    let knee = Knee2d::default();
    let times = cycle_times(steps);
    let (model, _) = knee.model(times[0])?;
    let (elastic_s, elastic_runs) = elastic_time(&model)?;
    let dofs = ElasticSolver::new(&model, ElasticParams::default())?.info().n_dofs;
    drop(model);
    let solver = synovia::solvers::by_name("pdas")?;
    let t0 = Instant::now();
    let out = knee.run(&times, solver.as_ref(), |_| Ok(()))?;
    let time_s = t0.elapsed().as_secs_f64();
    Ok(json!({
        "dofs": dofs,
        "steps": out.len(),
        "elastic_s": elastic_s,
        "elastic_runs": elastic_runs,
        "time_s": time_s,
        // the cycle is timed from the model (its one factorisation included)
        "from_scratch_ratio": time_s / elastic_s,
        "solves": out.iter().map(|s| s.solves).sum::<usize>(),
        "max_balance_error": out.iter().map(|s| s.balance_error).fold(0.0, Real::max),
        "max_kkt": out.iter().map(|s| s.kkt).fold(0.0, Real::max),
        "max_pose_s": out.iter().map(|s| s.seconds).fold(0.0, Real::max),
    }))
}

fn pose_resolve_case(scale: f64) -> Res<Value> {
    let poses = ((100.0 * scale).round() as usize).max(4);
    let times: Vec<Real> = (0..=poses).map(|i| i as Real / poses as Real).collect();
    // pass 1 (not timed): the superior–inferior translations that carry the ISO load
    let found = Tkr3d { friction: 0.0, ..Tkr3d::default() };
    let found_joint = found.joint_model()?;
    let mut session = found_joint.prepare()?;
    let mut si = Vec::with_capacity(times.len());
    for &t in &times {
        session.solve_static(t)?;
        let record = session.record().ok_or("no record")?;
        si.push((t, record.rigid.first().ok_or("no rigid body")?.dofs[1]));
    }
    drop(session);
    let si: std::sync::Arc<dyn synovia::time::history::LoadHistory> =
        std::sync::Arc::new(synovia::time::history::PiecewiseLinear::new(&si)?);
    let load = iso14243_axial_force()?;
    tracing::info!("pose_resolve_3d: prescribed poses");
    let mut out = json!({});
    for friction in [0.0, synovia_models::tkr3d::FRICTION] {
        let prescribed = Tkr3d { friction, superior: Superior::Prescribed(si.clone()), ..Tkr3d::default() };
        let joint = prescribed.joint_model()?;
        let t_setup = Instant::now();
        let mut session = joint.prepare()?;
        session.solve_static(times[0])?;
        let setup_s = t_setup.elapsed().as_secs_f64();
        let (mut force_error, mut kkt) = (0.0_f64, 0.0_f64);
        // `SYNOVIA_POSE_DUMP=<file>`: each pose's femur force, moment and strain energy (to
        // compare two builds' results; appended, one line per pose)
        let mut dump = match std::env::var_os("SYNOVIA_POSE_DUMP") {
            Some(path) => Some(std::fs::OpenOptions::new().create(true).append(true).open(path)?),
            None => None,
        };
        let t0 = Instant::now();
        for &t in &times[1..] {
            let report = if friction > 0.0 { session.step(t)? } else { session.solve_static(t)? };
            let record = session.record().ok_or("no record")?;
            if let Some(file) = dump.as_mut() {
                use std::io::Write;
                let r = record.rigid.first().ok_or("no rigid body")?;
                writeln!(
                    file,
                    "{friction} {t:.17e} {:?} {:?} {:.17e}",
                    r.force, r.moment, record.strain_energy
                )?;
            }
            let f = record.rigid.first().ok_or("no rigid body")?.force[1];
            force_error = force_error.max((f - load.value(t)).abs() / load.value(t));
            kkt = kkt.max(report.kkt);
        }
        let per_pose = t0.elapsed().as_secs_f64() / (times.len() - 1) as f64;
        let key = if friction > 0.0 { "friction_" } else { "" };
        out[format!("{key}time_per_pose_ms")] = json!(1e3 * per_pose);
        out[format!("{key}setup_s")] = json!(setup_s);
        out[format!("{key}max_force_error")] = json!(force_error);
        out[format!("{key}max_kkt")] = json!(kkt);
        if friction == 0.0 {
            out["time_s"] = json!(per_pose);
            out["dofs"] = json!(session.elastic_info().n_dofs);
            out["candidate_nodes"] = json!(session.geometry().len());
        }
    }
    let (elastic_s, elastic_runs) = elastic_time(found_joint.model())?;
    out["elastic_s"] = json!(elastic_s);
    out["elastic_runs"] = json!(elastic_runs);
    out["poses"] = json!(times.len() - 1);
    // from the model: factorisation, geometry and the first (cold) frictionless pose
    out["from_scratch_ratio"] = json!(out["setup_s"].as_f64().unwrap_or(f64::NAN) / elastic_s);
    Ok(out)
}

/// Child mode: run one case and print its JSON record on stdout (with `SYNOVIA_TRACE` set, the
/// library's debug spans with their times go to stderr).
fn child(case: &str, scale: f64) -> Res<()> {
    if std::env::var_os("SYNOVIA_TRACE").is_some() {
        tracing_subscriber::fmt()
            .with_max_level(tracing::Level::DEBUG)
            .with_span_events(tracing_subscriber::fmt::format::FmtSpan::CLOSE)
            .with_ansi(false)
            .with_writer(std::io::stderr)
            .init();
    }
    let mut v = match case {
        "hertz2d_tresca" => hertz2d_case(scale, false)?,
        "resolve_new_loads" => hertz2d_case(scale, true)?,
        "hemisphere3d_friction" => hemisphere_case(scale)?,
        "knee2d_gait" => knee_case(scale)?,
        "pose_resolve_3d" => pose_resolve_case(scale)?,
        "large_contact_surface" => large_contact_case(scale)?,
        LARGE_ELASTIC => large_elastic_case(scale)?,
        other => return Err(format!("unknown case `{other}` ({})", CASES.join(", ")).into()),
    };
    let (t, e) = (v["time_s"].as_f64().unwrap_or(f64::NAN), v["elastic_s"].as_f64().unwrap_or(f64::NAN));
    v["problem"] = json!("bench_report");
    v["case"] = json!(case);
    v["scale"] = json!(scale);
    v["ratio"] = json!(t / e);
    let peak_mb = peak_rss_bytes()? as f64 / 1.0e6;
    v["peak_rss_mb"] = json!(peak_mb);
    if let Some(elastic_mb) = v["elastic_peak_rss_mb"].as_f64() {
        // against the plain elastic solve of the same model in its own child
        v["rss_over_elastic"] = json!(peak_mb / elastic_mb);
    }
    println!("{v}");
    Ok(())
}

fn main() -> Res<()> {
    let (scale, cases) = match parse_args(&CASES)? {
        Invocation::Child { case, scale } => return child(&case, scale),
        Invocation::Parent { scale, cases } => (scale, cases),
    };
    for case in &cases {
        println!("{}", spawn_case(case, scale)?);
    }
    Ok(())
}
