//! A dynamic analysis of a nonlinear model from a scenario file
//! (`examples/scenarios/dynamic_drop2d_neo_hookean.toml`: a Kelvin–Voigt cylinder with a
//! neo-Hookean elastic part in finite strain dropped on a rigid floor with friction), run
//! through `JointModel::run_with` (docs/model.md (12.2)): every step is in contact equilibrium on
//! the deformed configuration, and at this moderate deformation the contact force follows the
//! linear file (`dynamic_drop2d.toml`) closely.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use synovia::builder::Analysis;
use synovia::fem::Kinematics;
use synovia_scenario::build::build;
use synovia_scenario::Scenario;

fn scenario(name: &str) -> Scenario {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios").join(name);
    Scenario::from_file(&path).expect("scenario")
}

#[test]
fn neo_hookean_drop_scenario_runs_through_the_nonlinear_dynamic_scheme() {
    let built = build::<2>(&scenario("dynamic_drop2d_neo_hookean.toml")).expect("build");
    assert!(built.joint.is_nonlinear());
    assert_eq!(built.joint.kinematics(), &[Kinematics::FiniteStrain]);
    assert!(matches!(built.analysis, Analysis::Dynamic { steps: 100, .. }));
    let nodes = built.joint.model().bodies()[0].mesh.nodes().to_vec();
    // every level on its deformed configuration: no node below the floor, KKT of the step
    let (mut lowest, mut kkt) = (f64::INFINITY, 0.0_f64);
    let nonlinear = built
        .joint
        .run_with(|view| {
            let u = &view.result.displacement[0];
            lowest = nodes.iter().zip(u).map(|(x, u)| x[1] + u[1]).fold(lowest, f64::min);
            if view.record.step > 0 {
                kkt = kkt.max(view.result.kkt.max());
            }
            Ok(())
        })
        .expect("nonlinear dynamic run");
    let linear =
        build::<2>(&scenario("dynamic_drop2d.toml")).expect("build").joint.run().expect("linear run");
    assert_eq!(nonlinear.records.len(), 101);
    let peak = |r: &synovia::builder::RunResult<2>| {
        r.records.iter().map(|s| s.pairs[0].normal_force).fold(0.0_f64, f64::max)
    };
    let (p_nl, p_lin) = (peak(&nonlinear), peak(&linear));
    let contact_steps = nonlinear.records.iter().filter(|s| s.pairs[0].normal_force > 0.0).count();
    let friction: f64 = nonlinear.records.iter().map(|s| s.friction_dissipation).sum();
    println!(
        "neo-Hookean drop: {contact_steps} contact steps, peak normal force {p_nl:.5e} N/mm (linear {p_lin:.5e}, ratio {:.4}), \
         friction work {friction:.3e}, lowest point {lowest:.2e} mm, max KKT {kkt:.2e}, {:.2} s",
        p_nl / p_lin,
        nonlinear.total_s
    );
    assert!(contact_steps > 20);
    assert!(lowest >= -1e-10, "penetration {lowest}");
    assert!(kkt <= 1e-8, "KKT {kkt}");
    assert!(friction > 0.0);
    assert!((p_nl / p_lin - 1.0).abs() < 0.1, "peak force ratio {}", p_nl / p_lin);
}
