//! # A user-defined friction law: a cartilage plug dragged over glass (quasi-static, docs/model.md §3, §7)
//!
//! **Problem.** A plane-strain cartilage plug `[0, 10] × [0, 4]` mm (E = 1 MPa, ν = 0.3) is
//! pressed onto a rigid glass plate `y = 0` by its top, prescribed to `u₂(t) = (v t, −δ)` with
//! `δ = 0.04` mm, and dragged at `v = 1` mm/s; time levels every `Δt = 0.5` s. The friction law
//! is defined here, outside the crates, by implementing the public trait
//! [`FrictionLaw`]: a Stribeck curve of a lubricated contact,
//!
//! ```text
//! F_c(v) = μ_min + (μ_s − μ_min) exp(−(v / v_s)²) + η v
//! ```
//!
//! (start-up coefficient `μ_s = 0.3`, fluid-film minimum `μ_min = 0.02`, Stribeck speed
//! `v_s = 2` mm/s, hydrodynamic slope `η = 5` s/m), and handed to the analysis with
//! [`JointModel::friction_law`]; nothing else changes.
//!
//! **Equations.** Each level `t_i` is the contact problem of docs/model.md §5 with Coulomb
//! friction `g_c = F_c(|[u'_t]|) |λ_n|` (Coulomb fixed point per level, docs/model.md §3),
//! `|[u'_t]|` the slip rate of the level, `(‖[u_t](t_i) − [u_t](t_{i−1})‖) / Δt`.
//!
//! **Expected result.** Once the plug slides steadily (after a short transient that decays
//! geometrically from level to level), every contact node slips at the drag speed `v` and carries
//! the traction `F_c(v) λ_n`, so the friction force is exactly `T = F_c(v) N` with `N` the normal
//! force: `T/N = F_c(1 mm/s) = 0.02 + 0.28 e^{−1/4} + 0.005 ≈ 0.2431`, between the start-up
//! value 0.3 and the lubricated minimum. The run checks `|T/N − F_c(v)| ≤ 1e-8`, the slip rates
//! `|v_r − v| ≤ 1e-8 v` and the KKT residual of the last level `≤ 1e-8`, and prints one JSON line.
//!
//! Run: `cargo run --release --example custom_friction_law`.

use serde_json::json;
use std::sync::Arc;
use synovia::contact_ops::slip_speeds;
use synovia::prelude::*;
use synovia::time::quasistatic::QuasiStaticParams;

/// Stribeck curve of a lubricated contact (see the header).
#[derive(Debug, Clone, Copy)]
struct Stribeck {
    /// Start-up (static) coefficient `μ_s`.
    static_coefficient: f64,
    /// Fluid-film minimum `μ_min`.
    minimum: f64,
    /// Stribeck speed `v_s` (m/s).
    stribeck_speed: f64,
    /// Hydrodynamic slope `η` (s/m).
    viscous_slope: f64,
}

impl FrictionLaw for Stribeck {
    fn coefficient(&self, slip_speed: f64) -> f64 {
        let v = slip_speed.abs();
        let r = v / self.stribeck_speed;
        self.minimum + (self.static_coefficient - self.minimum) * (-r * r).exp() + self.viscous_slope * v
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (width, height) = (0.010, 0.004);
    let (e, nu) = (1.0e6, 0.3);
    let (v, delta, dt, levels) = (1.0e-3, 4.0e-5, 0.5, 20);
    let law = Stribeck { static_coefficient: 0.3, minimum: 0.02, stribeck_speed: 2.0e-3, viscous_slope: 5.0 };
    let expected = law.coefficient(v);

    let mut joint = JointModel::<2>::new();
    let mesh = rectangle(0.0, width, 0.0, height, 20, 8, Grading::Uniform, Grading::Uniform)?;
    let plug = joint.add_body("plug", mesh, plane_strain(e, nu)?)?;
    joint.prescribe_field(plug, "top", ComponentMask::ALL, move |_, t| Vector::<2>::new(v * t, -delta))?;
    let glass = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0))?;
    joint.contact_rigid("glass", plug, "bottom", glass, 0.0)?;
    joint.friction_law("glass", Arc::new(law))?;
    joint.quasistatic_params(
        QuasiStaticParams::default().with_coulomb_fixed_point(true).with_fixed_point_tolerance(1e-13),
    );
    joint.contact_params(ContactParams::default().with_tolerance(1e-13).with_max_iterations(200));

    let times: Vec<Real> = (0..levels).map(|i| i as Real * dt).collect();
    let mut previous: Option<Vec<Vec<Vector<2>>>> = None;
    let mut slip_rate_error = 0.0_f64;
    let run = joint.run_quasistatic_with(&times, |view| {
        let p = &view.record.pairs[0];
        if let Some(prev) = &previous {
            let rates = slip_speeds(view.geometry, &view.result.displacement, prev, dt);
            if view.record.step + 1 == levels {
                for (rate, l) in rates.iter().zip(&view.result.solution.lambda_n) {
                    if *l > 0.0 {
                        slip_rate_error = slip_rate_error.max((rate - v).abs() / v);
                    }
                }
            }
        }
        if view.record.step % 4 == 0 || view.record.step + 1 == levels {
            println!(
                "t = {:4.1} s  N = {:.6e} N/m  T = {:.6e} N/m  T/N = {:.10}  slip length {:.2e} m",
                view.record.time,
                p.normal_force,
                p.tangential_force,
                p.tangential_force / p.normal_force.max(f64::MIN_POSITIVE),
                p.slip_area
            );
        }
        previous = Some(view.result.displacement.clone());
        Ok(())
    })?;
    let last = run.records.last().ok_or("no levels")?;
    let pair = &last.pairs[0];
    let ratio = pair.tangential_force / pair.normal_force;
    let reference_error = (ratio - expected).abs();
    let kkt = run.contact.as_ref().ok_or("no contact result")?.kkt.max();
    println!(
        "steady sliding: T/N = {ratio:.12}, F_c(v) = {expected:.12}, error {reference_error:.2e}, \
         slip-rate error {slip_rate_error:.2e}, KKT {kkt:.2e}"
    );
    println!(
        "{}",
        json!({
            "problem": "custom_friction_law",
            "drag_speed": v,
            "normal_force": pair.normal_force,
            "friction_force": pair.tangential_force,
            "friction_ratio": ratio,
            "expected_coefficient": expected,
            "reference_error": reference_error,
            "slip_rate_error": slip_rate_error,
            "kkt_residual": kkt,
            "levels": levels,
        })
    );
    if !(reference_error <= 1e-8 && slip_rate_error <= 1e-8 && kkt <= 1e-8) {
        return Err(format!(
            "checks failed: |T/N − F_c(v)| = {reference_error:e}, slip rate {slip_rate_error:e}, KKT {kkt:e}"
        )
        .into());
    }
    Ok(())
}
