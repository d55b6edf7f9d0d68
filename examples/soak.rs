//! # Soak: does memory stay flat over thousands of re-solves?
//!
//! A navigation tool re-solves one prepared model at 10–60 Hz for hours. This example builds a
//! frictional 3D model of ≈ 40 000 DOFs — an elastic block `[−½, ½]² × [0, ½]` (tetrahedra,
//! `E = 1 kPa`-scale units as in the tests, ν = 0.3) whose bottom rests on a rigid sphere of
//! radius 2 with Coulomb friction μ = 0.3 and whose top is moved by a periodic prescribed
//! displacement (press `δ(t) = δ₀ (1 + ½ sin ωt)` and a sideways shift `s(t) = s₀ cos ωt`, so
//! the contact zone breathes and the stick/slip zones move every step) — prepares it once
//! ([`JointModel::prepare`]) and runs `STEPS` quasi-static levels ([`JointSession::step`],
//! warm-started, friction state carried) with the load period spanning 37 steps.
//!
//! It samples the resident set size (`VmRSS` of `/proc/self/status`, Linux) after the first
//! step, after step 1 000 and at the end, and checks every step's KKT residual. The pass
//! criterion of issue 15 is a growth of at most 5 MB between step 1 000 and step 10 000.
//!
//! Run with `cargo run --release --example soak -- STEPS` (default 2 000). Ends with one JSON
//! line: `steps`, `dofs`, `rss_start_mb`, `rss_1000_mb`, `rss_end_mb`, `growth_mb` (end − step
//! 1 000, or end − start for shorter runs), `ms_per_step`, `max_kkt`.

use std::time::Instant;

use synovia::prelude::*;

/// Resident set size of this process in MiB (`None` where `/proc` is not available).
fn rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Steps per load period (not a divisor of 1 000, so the sampled states differ).
const PERIOD_STEPS: f64 = 37.0;
/// Mean press depth and shift amplitude of the top face.
const DEPTH: Real = 0.01;
const SHIFT: Real = 0.004;

fn build(n: usize) -> Result<JointModel<3>, Box<dyn std::error::Error>> {
    let mesh = box_mesh(
        [-0.5, -0.5, 0.0],
        [0.5, 0.5, 0.5],
        [n, n, n / 2],
        [Grading::Uniform, Grading::Uniform, Grading::Uniform],
    )?;
    let mut joint = JointModel::<3>::new();
    let block = joint.add_body("block", mesh, isotropic(1.0e3, 0.3)?)?;
    let omega = 2.0 * std::f64::consts::PI / PERIOD_STEPS;
    joint.prescribe_field(block, "top", ComponentMask::ALL, move |_x, t| {
        let press = DEPTH * (1.0 + 0.5 * (omega * t).sin());
        let shift = SHIFT * (omega * t).cos();
        Vector::<3>::new(shift, 0.0, -press)
    })?;
    let sphere = SphereObstacle::new(Point::<3>::new(0.0, 0.0, -2.0), 2.0, false)?;
    joint.contact_rigid("sphere", block, "bottom", sphere, 0.3)?;
    Ok(joint)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let steps: usize = match std::env::args().nth(1) {
        Some(s) => s.parse().map_err(|e| format!("STEPS must be a whole number, got {s:?}: {e}"))?,
        None => 2000,
    };
    if steps == 0 {
        return Err("STEPS must be at least 1".into());
    }
    let joint = build(30)?;
    let mut session = joint.prepare()?;
    let dofs = session.elastic_info().n_dofs;

    let mut rss_start = None;
    let mut rss_1000 = None;
    let mut max_kkt: Real = 0.0;
    let started = Instant::now();
    let mut timed_from = started;
    for step in 1..=steps {
        let report = session.step(step as Real)?;
        max_kkt = max_kkt.max(report.kkt);
        if step == 1 {
            rss_start = rss_mb();
            timed_from = Instant::now();
        }
        if step == 1000 {
            rss_1000 = rss_mb();
        }
        if step % 500 == 0 {
            eprintln!(
                "step {step:>6}: rss {:.1} MB, {} iterations, kkt {:.1e}",
                rss_mb().unwrap_or(f64::NAN),
                report.iterations,
                report.kkt
            );
        }
    }
    let per_step_ms = if steps > 1 {
        timed_from.elapsed().as_secs_f64() * 1e3 / (steps - 1) as f64
    } else {
        started.elapsed().as_secs_f64() * 1e3
    };
    let rss_end = rss_mb();
    let growth = match (rss_1000.or(rss_start), rss_end) {
        (Some(a), Some(b)) => Some(b - a),
        _ => None,
    };
    let num = |x: Option<f64>| x.map_or("null".to_string(), |v| format!("{v:.2}"));
    println!(
        "{{\"example\":\"soak\",\"steps\":{steps},\"dofs\":{dofs},\"rss_start_mb\":{},\"rss_1000_mb\":{},\"rss_end_mb\":{},\"growth_mb\":{},\"ms_per_step\":{per_step_ms:.3},\"max_kkt\":{max_kkt:.3e}}}",
        num(rss_start),
        num(rss_1000),
        num(rss_end),
        num(growth)
    );
    Ok(())
}
