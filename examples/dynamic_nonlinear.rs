//! # A neo-Hookean cylinder hitting a rigid floor (dynamic, nonlinear elastic part)
//!
//! The semi-implicit Kelvin–Voigt scheme of docs/model.md (12.2) with a compressible
//! neo-Hookean elastic part in total Lagrangian finite strain: every time step is one nonlinear
//! contact problem solved by Newton's method (the contact semismooth Newton inside, the contact
//! geometry on the deformed configuration), cut back into half steps on failure.
//!
//! A plane-strain cylinder (radius R = 10 mm, neo-Hookean with the small-strain constants
//! E = 10 MPa, ν = 0.3, density 1100 kg/m³, viscosity `C⁽¹⁾ = τ_v C⁽⁰⁾` of those constants with
//! τ_v = 0.05 ms, no Dirichlet data) touches the rigid floor y = 0 at its lowest point and moves
//! at (0.5, −10) m/s under gravity, with friction μ = 0.3 against the floor. The same run with
//! the linear material (small strain) gives the comparison: at this impact speed the cylinder
//! is compressed by up to ≈ 17 % under the contact (largest principal Green–Lagrange strain 0.15,
//! smallest `det F` 0.84).
//!
//! Printed: one JSON line `{"problem":"dynamic_nonlinear",...}` with the steps, Newton
//! iterations (mean, max per step), cut-backs, the peak contact force and pressure of both laws,
//! the largest compression (smallest `det F`) and Green–Lagrange strain, the largest
//! penetration of a contact node below the floor and the largest KKT residual over the steps,
//! the energy at the end relative to the start for both laws, the viscous and friction
//! dissipation, and the wall times.
//!
//! Run: `cargo run --release --example dynamic_nonlinear [STEPS]` (default 250 steps of 4 µs).

use std::sync::Arc;
use std::time::Instant;

use serde_json::json;
use synovia::contact_ops::operators::{ContactPair, PlaneObstacle};
use synovia::fem::nonlinear::cell_stresses;
use synovia::fem::Kinematics;
use synovia::material::neo_hookean;
use synovia::mesh::generators::disc;
use synovia::nonlinear::NewtonParams;
use synovia::pdas::Pdas;
use synovia::prelude::*;
use synovia::time::dynamic::{DynamicBody, DynamicParams, DynamicStepper};
use synovia::time::nonlinear_dynamic::NonlinearDynamicStepper;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let steps: usize = match std::env::args().nth(1) {
        Some(s) => s.parse()?,
        None => 250,
    };
    // mm, N, MPa, s, tonne
    let (radius, e, nu, rho, tau_v, g) = (10.0, 10.0, 0.3, 1.1e-9, 5e-5, 9810.0);
    let (v0, dt) = (Vector::<2>::new(500.0, -10000.0), 4e-6);
    let mut mesh = disc(Point::<2>::new(0.0, radius), radius, 16)?;
    mesh.add_boundary_part("contact", BoundaryKind::Contact, move |x, n| x[1] < 0.5 * radius && n[1] < 0.0)?;
    let contact_nodes = mesh.boundary_part("contact").map(|p| p.nodes()).unwrap_or_default();
    let nodes = mesh.nodes().to_vec();
    let viscous = plane_strain(tau_v * e, nu)?.stiffness().clone();
    let body = DynamicBody { density: rho, damping: 0.0, viscous: Some(viscous) };
    let build = |material: Arc<dyn Material<2>>| -> Result<(Model<2>, Vec<ContactPair<2>>), Box<dyn std::error::Error>> {
        let mut model = Model::<2>::new();
        let b = model.add_body("cylinder", mesh.clone(), material)?;
        model.body_force(b, move |_, _| Vector::<2>::new(0.0, -rho * g))?;
        let floor = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::y())?;
        Ok((model, vec![ContactPair::rigid("floor", b, "contact", Arc::new(floor)).with_friction(0.3)]))
    };
    let solver = Pdas::new(ContactParams::default().with_tolerance(1e-12));
    let velocity = vec![vec![v0; nodes.len()]];
    let penetration =
        |u: &[Vector<2>]| contact_nodes.iter().map(|&i| -(nodes[i][1] + u[i][1])).fold(0.0, f64::max);

    // the neo-Hookean run
    let (model, pairs) = build(Arc::new(neo_hookean(e, nu)?))?;
    let t0 = Instant::now();
    let mut st = NonlinearDynamicStepper::new(
        &model,
        std::slice::from_ref(&body),
        &pairs,
        &[Kinematics::FiniteStrain],
        DynamicParams::new(dt),
        NewtonParams::default().with_tolerance(1e-10),
    )?;
    st.set_initial_state(&model, None, Some(&velocity))?;
    let e0 = st.energy();
    let (mut newton, mut newton_max, mut cutbacks, mut kkt, mut pen, mut visc, mut fric) =
        (0usize, 0usize, 0usize, 0.0_f64, 0.0_f64, 0.0, 0.0);
    let (mut peak_force, mut peak_pressure, mut min_det, mut max_strain, mut contact_steps) =
        (0.0_f64, 0.0_f64, f64::INFINITY, 0.0_f64, 0usize);
    for _ in 0..steps {
        let rec = st.step(&model, &solver)?;
        let report = st.last_report();
        newton += report.newton_iterations;
        newton_max = newton_max.max(report.newton_iterations);
        cutbacks += report.cutbacks;
        visc += rec.viscous_dissipation;
        fric += rec.friction_dissipation;
        pen = pen.max(penetration(&st.displacement()[0]));
        if rec.pairs[0].normal_force > 0.0 {
            contact_steps += 1;
            kkt = kkt.max(st.last_contact().map_or(0.0, |c| c.kkt.max()));
        }
        peak_force = peak_force.max(rec.pairs[0].normal_force);
        peak_pressure = peak_pressure.max(rec.pairs[0].peak_pressure);
        for (strain, _, det) in &cell_stresses(&model, &[Kinematics::FiniteStrain], st.displacement())?[0] {
            min_det = min_det.min(*det);
            // principal values of the Green–Lagrange strain (Voigt with engineering shear)
            let (a, b, c) = (strain[0], strain[1], 0.5 * strain[2]);
            let r = (0.25 * (a - b) * (a - b) + c * c).sqrt();
            max_strain = max_strain.max((0.5 * (a + b)).abs() + r);
        }
    }
    let nl_s = t0.elapsed().as_secs_f64();
    let nl_energy = st.energy() / e0;

    // the linear run (small strain) on the same mesh
    let (lin_model, lin_pairs) = build(Arc::new(plane_strain(e, nu)?))?;
    let t1 = Instant::now();
    let mut lin = DynamicStepper::new(&lin_model, &[body], &lin_pairs, DynamicParams::new(dt))?;
    lin.set_initial_state(&lin_model, None, Some(&velocity))?;
    let le0 = lin.energy();
    let (mut lin_force, mut lin_pressure, mut lin_pen) = (0.0_f64, 0.0_f64, 0.0_f64);
    for _ in 0..steps {
        let rec = lin.step(&lin_model, &solver)?;
        lin_force = lin_force.max(rec.pairs[0].normal_force);
        lin_pressure = lin_pressure.max(rec.pairs[0].peak_pressure);
        lin_pen = lin_pen.max(penetration(&lin.displacement()[0]));
    }
    let lin_s = t1.elapsed().as_secs_f64();

    let line = json!({
        "problem": "dynamic_nonlinear",
        "law": "neo-Hookean (finite strain) + linear Kelvin-Voigt viscosity",
        "dofs": st.dofs().n_dofs(),
        "steps": steps,
        "dt_s": dt,
        "contact_steps": contact_steps,
        "newton_iterations_mean": newton as f64 / steps as f64,
        "newton_iterations_max": newton_max,
        "cutbacks": cutbacks,
        "peak_force_n_per_mm": peak_force,
        "peak_force_linear_n_per_mm": lin_force,
        "peak_pressure_mpa": peak_pressure,
        "peak_pressure_linear_mpa": lin_pressure,
        "min_det_f": min_det,
        "max_green_lagrange_strain": max_strain,
        "max_penetration_mm": pen,
        "max_penetration_linear_mm": lin_pen,
        "max_kkt": kkt,
        "energy_end_over_start": nl_energy,
        "energy_end_over_start_linear": lin.energy() / le0,
        "viscous_dissipation_over_e0": visc / e0,
        "friction_dissipation_over_e0": fric / e0,
        "time_s": nl_s,
        "time_linear_s": lin_s,
    });
    println!("{line}");
    Ok(())
}
