//! # A viscoelastic cylinder dropped on a rigid floor with friction (dynamic, docs/model.md §7)
//!
//! A plane-strain Kelvin–Voigt cylinder (radius R = 50 mm, E = 5 MPa, ν = 0.3, ρ = 1100 kg/m³,
//! viscosity `C⁽¹⁾ = τ_v C⁽⁰⁾` with τ_v = 0.05 ms) starts 5 mm above a rigid floor with the
//! velocity (0.5, −1) m/s under gravity. It has **no Dirichlet data** (a free body: the mass
//! matrix keeps `A = M_ρ + Δt² A⁽⁰⁾ + Δt A⁽¹⁾` positive definite). Its lower arc is the
//! contact part; friction follows the slip-rate-dependent law
//! `F_c(v) = μ_k + (μ_s − μ_k) exp(−v/v_c)` (μ_s = 0.5, μ_k = 0.3, v_c = 0.05 m/s) with the
//! slip bound `g_c = F_c |λ_n|` frozen from the previous level (docs/model.md §3, §7). Each step is one
//! contact problem of docs/model.md §5 solved by PDAS with the factorisation of `A` computed once.
//!
//! Printed every 20 steps: time, height of the centre of mass, its velocity, the normal and
//! friction contact forces (per metre of thickness), kinetic and strain energy and the friction
//! work so far. At the end: the largest penetration, the momentum balance (change of momentum
//! vs. contact + gravity impulse), and the cost of one step relative to one plain elastic
//! factorisation + solve of the same mesh: an `ElasticSolver` of the same cylinder with its top
//! quarter clamped, timed as ordering + symbolic analysis + numeric factorisation + one load
//! case (`ratio`), and as its whole construction + solve including dof map and assembly
//! (`ratio_total`). The CSV of all steps goes to `OUT_DIR/dynamic_drop.csv` and the run ends
//! with one JSON line `{"problem":"dynamic_drop",...}`.
//!
//! Run: `cargo run --release --example dynamic_drop [OUT_DIR]` (default `out/dynamic_drop`).

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use serde_json::json;
use synovia::contact_ops::operators::{ContactPair, PlaneObstacle};
use synovia::contact_ops::ExponentialFriction;
use synovia::fem::{ElasticParams, ElasticSolver};
use synovia::mesh::generators::disc;
use synovia::pdas::Pdas;
use synovia::prelude::*;
use synovia::time::dynamic::{DynamicBody, DynamicParams, DynamicStepper};
use synovia::time::results::{write_csv_with_units, StepRecord, Units};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "out/dynamic_drop".to_string());
    std::fs::create_dir_all(&out)?;

    // ## Step 1: the cylinder, its material and the floor
    let (radius, gap, n) = (0.05, 0.005, 16);
    let (e, nu, rho, tau_v) = (5.0e6, 0.3, 1100.0, 5.0e-5);
    let (g, v0) = (9.81, Vector::<2>::new(0.5, -1.0));
    let centre = Point::<2>::new(0.0, radius + gap);
    let mut mesh = disc(centre, radius, n)?;
    mesh.add_boundary_part("contact", BoundaryKind::Contact, move |x, nrm| {
        x[1] < centre[1] - 0.5 * radius && nrm[1] < 0.0
    })?;
    let c0 = plane_strain(e, nu)?;
    let c1 = plane_strain(tau_v * e, nu)?;
    let material = KelvinVoigt::from_linear(c0, c1, rho, 0.0)?;
    let body = DynamicBody::from_kelvin_voigt(&material)?;
    let mut model = Model::<2>::new();
    let cyl = model.add_body("cylinder", mesh.clone(), Arc::new(material))?;
    model.body_force(cyl, move |_, _| Vector::<2>::new(0.0, -rho * g))?;
    let floor = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0))?;
    let pairs = vec![ContactPair::rigid("floor", cyl, "contact", Arc::new(floor))];

    // ## Step 2: the stepper (A assembled and factorised once)
    let dt = 1.0e-4;
    let steps = 400;
    let mut stepper = DynamicStepper::new(&model, &[body], &pairs, DynamicParams::new(dt))?;
    stepper.set_friction_law(
        "floor",
        Arc::new(ExponentialFriction {
            static_coefficient: 0.5,
            kinetic_coefficient: 0.3,
            characteristic_speed: 0.05,
        }),
    )?;
    let nodes = mesh.n_nodes();
    stepper.set_initial_state(&model, None, Some(&[vec![v0; nodes]]))?;
    let info = stepper.info();
    println!(
        "cylinder R = {radius} m, {} cells, {} dofs; A: {} entries, factor {} entries, symbolic {:.2} ms, numeric {:.2} ms",
        mesh.n_cells(),
        info.n_dofs,
        info.matrix_nnz,
        info.factor_nnz,
        1e3 * info.symbolic_s,
        1e3 * info.numeric_s
    );

    // ## Step 3: time stepping
    let solver = Pdas::default();
    let total_mass: Real = stepper.nodal_masses().iter().flatten().sum();
    let gravity = Vector::<2>::new(0.0, -total_mass * g);
    let p0 = stepper.momentum();
    let contact_nodes: Vec<usize> = mesh.boundary_part("contact")?.nodes();
    let mut records: Vec<StepRecord> = vec![stepper.initial_record()];
    let mut impulse = Vector::<2>::zeros();
    let mut max_pen: Real = 0.0;
    let mut max_up: Real = Real::NEG_INFINITY;
    let mut touched = false;
    println!(
        "\n{:>5} {:>8} {:>10} {:>9} {:>9} {:>10} {:>10} {:>11} {:>11} {:>11} {:>4}",
        "step",
        "t [ms]",
        "h_cm [mm]",
        "v_x",
        "v_y",
        "N [N/m]",
        "T [N/m]",
        "E_kin [J/m]",
        "E_str [J/m]",
        "W_fric",
        "it"
    );
    let print = |r: &StepRecord, st: &DynamicStepper<2>, model: &Model<2>| {
        let (nf, tf) = r.pairs.first().map_or((0.0, 0.0), |p| (p.normal_force, p.tangential_force));
        let v = st.momentum() / total_mass;
        println!(
            "{:>5} {:>8.3} {:>10.4} {:>9.4} {:>9.4} {:>10.1} {:>10.1} {:>11.4e} {:>11.4e} {:>11.4e} {:>4}",
            r.step,
            1e3 * r.time,
            1e3 * st.centre_of_mass(model)[1],
            v[0],
            v[1],
            nf,
            tf,
            r.kinetic_energy,
            r.strain_energy,
            r.cumulative_friction_dissipation,
            r.iterations
        );
    };
    print(&records[0], &stepper, &model);
    // ParaView series (every 20th step): displacement, contact pressure, friction traction
    let mut series =
        synovia::time::quasistatic::QuasiStaticOutput::new(&out, "dynamic_drop", stepper.geometry())?;
    for _ in 0..steps {
        let rec = stepper.step(&model, &solver)?;
        let f = Vector::<2>::new(rec.pairs[0].force[0], rec.pairs[0].force[1]);
        impulse += (f + gravity) * dt;
        let u = &stepper.displacement()[0];
        for &i in &contact_nodes {
            max_pen = max_pen.max(-(mesh.node(i)[1] + u[i][1]) / radius);
        }
        if rec.pairs[0].normal_force > 0.0 {
            touched = true;
        }
        if touched {
            max_up = max_up.max(stepper.momentum()[1] / total_mass);
        }
        if rec.step % 20 == 0 {
            print(&rec, &stepper, &model);
            if let Some(state) = stepper.last_contact() {
                series.write_step(&model, &rec, state)?;
            }
        }
        records.push(rec);
    }
    let mismatch = (stepper.momentum() - p0 - impulse).norm() / (total_mass * v0.norm());
    let csv = Path::new(&out).join("dynamic_drop.csv");
    // SI units, 2D: forces per metre of thickness
    let si = Units { length: "m".into(), force: "N".into(), time: "s".into() };
    write_csv_with_units(&csv, &records, &si, 2)?;
    println!("ParaView series: {}", series.pvd_path().display());

    // ## Step 4: cost of a step vs. a plain elastic factorisation + solve of the same mesh
    let mut clamped = mesh.clone();
    clamped.add_boundary_part("clamp", BoundaryKind::Clamped, move |x, _| x[1] > centre[1] + 0.7 * radius)?;
    let mut elastic_model = Model::<2>::new();
    let eb = elastic_model.add_body("cylinder", clamped, Arc::new(plane_strain(e, nu)?))?;
    elastic_model.body_force(eb, move |_, _| Vector::<2>::new(0.0, -rho * g))?;
    let (mut factor_solve_s, mut total_s) = (Real::INFINITY, Real::INFINITY);
    for _ in 0..5 {
        let t0 = Instant::now();
        let mut es = ElasticSolver::new(&elastic_model, ElasticParams::default())?;
        es.solve(&elastic_model, 0.0)?;
        total_s = total_s.min(t0.elapsed().as_secs_f64());
        let i = es.info();
        factor_solve_s = factor_solve_s.min(i.symbolic_s + i.numeric_s + i.solve_s);
    }
    let step_times: Vec<Real> = records[1..].iter().map(|r| r.step_s).collect();
    let mean_step = step_times.iter().sum::<Real>() / step_times.len() as Real;
    let contact_times: Vec<Real> =
        records[1..].iter().filter(|r| r.pairs[0].normal_force > 0.0).map(|r| r.step_s).collect();
    let mean_contact = if contact_times.is_empty() {
        0.0
    } else {
        contact_times.iter().sum::<Real>() / contact_times.len() as Real
    };
    let ratio = mean_step / factor_solve_s;
    let ratio_contact = mean_contact / factor_solve_s;
    let ratio_total = mean_step / total_s;
    let last = records.last().map(|r| r.cumulative_friction_dissipation).unwrap_or(0.0);
    println!("\nlargest penetration / R = {max_pen:.2e}");
    println!("momentum change − (contact + gravity impulse) = {mismatch:.2e} × m |v0|");
    println!("rebound: largest upward centre-of-mass speed after touching the floor {max_up:.4} m/s (impact {:.1} m/s)", -v0[1]);
    println!("friction work {last:.4e} J/m; CSV: {}", csv.display());
    println!(
        "one dynamic time step / one elastic factorisation + solve = {ratio:.2} (mean step {:.3} ms, {:.3} ms in contact \
         steps → {ratio_contact:.2}; elastic symbolic + numeric + solve {:.3} ms; whole ElasticSolver::new + solve {:.3} ms → {ratio_total:.2})",
        1e3 * mean_step,
        1e3 * mean_contact,
        1e3 * factor_solve_s,
        1e3 * total_s
    );
    println!(
        "{}",
        json!({
            "problem": "dynamic_drop",
            "dofs": info.n_dofs,
            "cells": mesh.n_cells(),
            "dt": dt,
            "steps": steps,
            "contact_steps": contact_times.len(),
            "max_penetration_rel": max_pen,
            "momentum_mismatch_rel": mismatch,
            "rebound_speed": max_up,
            "friction_work": last,
            "step_mean_s": mean_step,
            "step_contact_mean_s": mean_contact,
            "elastic_factor_solve_s": factor_solve_s,
            "elastic_total_s": total_s,
            "ratio": ratio,
            "ratio_contact_steps": ratio_contact,
            "ratio_total": ratio_total,
            "setup_numeric_s": info.numeric_s,
        })
    );
    Ok(())
}
