//! `friction_law` in quasi-static scenario files (docs/scenario.md): the exponential law
//! `F_c(v) = μ_k + (μ_s − μ_k) exp(−v / v_c)` on the Cattaneo–Mindlin pair of
//! `examples/scenarios/cattaneo_mindlin2d.toml` (two cylinders pressed, then sheared).
//!
//! * a law with `μ_s = μ_k = 0.3` gives the file's run with `friction = 0.3` (the same bounds);
//! * a decreasing law gives what the Rust API's `JointModel::friction_law` gives on the same
//!   model (bit for bit), and less tangential force than the constant `μ_s`;
//! * a static analysis with a law is refused with a message naming the key;
//! * (and a dynamic analysis with a rigid body is refused at the rigid body.)

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::sync::Arc;

use synovia::builder::RunResult;
use synovia::prelude::ExponentialFriction;
use synovia_scenario::build::build;
use synovia_scenario::scenario::Source;
use synovia_scenario::Scenario;

fn cattaneo_mindlin_text() -> (PathBuf, String) {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/cattaneo_mindlin2d.toml");
    let text = std::fs::read_to_string(&path).expect("scenario file");
    assert!(text.contains("friction = 0.3\n"));
    (path, text)
}

fn run(path: &PathBuf, text: String) -> RunResult<2> {
    let scenario = Scenario::parse(Source::new(path, text)).expect("parse");
    build::<2>(&scenario).expect("build").joint.run().expect("run")
}

fn tangential(r: &RunResult<2>) -> Vec<f64> {
    r.records.iter().map(|s| s.pairs[0].tangential_force).collect()
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().map(|v| v.abs()).fold(0.0, f64::max);
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale
}

#[test]
fn quasi_static_friction_law_from_a_scenario() {
    let (path, text) = cattaneo_mindlin_text();
    let constant = run(&path, text.clone());
    // μ_s = μ_k: the constant coefficient through the law
    let flat = run(
        &path,
        text.replace("friction = 0.3\n", "friction_law = { static = 0.3, kinetic = 0.3, speed = 1.0 }\n"),
    );
    let d_flat = max_rel(&tangential(&constant), &tangential(&flat));
    assert!(d_flat < 1e-13, "flat law vs friction = 0.3: {d_flat:e}");
    // a decreasing law: the scenario key equals the Rust API's call on the same model
    let law_text =
        text.replace("friction = 0.3\n", "friction_law = { static = 0.3, kinetic = 0.1, speed = 1e-3 }\n");
    let from_file = run(&path, law_text);
    let scenario = Scenario::parse(Source::new(&path, text.replace("friction = 0.3\n", ""))).expect("parse");
    let mut built = build::<2>(&scenario).expect("build");
    built
        .joint
        .friction_law(
            "upper-lower",
            Arc::new(ExponentialFriction {
                static_coefficient: 0.3,
                kinetic_coefficient: 0.1,
                characteristic_speed: 1e-3,
            }),
        )
        .expect("law");
    let from_api = built.joint.run().expect("run");
    assert_eq!(tangential(&from_file), tangential(&from_api));
    let (t_law, t_const) = (tangential(&from_file), tangential(&constant));
    let last = t_law.len() - 1;
    println!("tangential force at the last level: law {:.5e}, μ = 0.3 {:.5e}", t_law[last], t_const[last]);
    assert!(t_law[last].abs() < 0.9 * t_const[last].abs(), "the law did not act: {t_law:?} vs {t_const:?}");
    // a static analysis has no slip speed
    let static_text = text
        .replace("friction = 0.3\n", "friction_law = { static = 0.3, kinetic = 0.1, speed = 1e-3 }\n")
        .replace(
            "type = \"quasistatic\"\ntimes = { start = 0.0, end = 1.0, steps = 10 }",
            "type = \"static\"",
        );
    let scenario = Scenario::parse(Source::new(&path, static_text)).expect("parse");
    let err = match build::<2>(&scenario) {
        Ok(_) => panic!("a static analysis with a friction law was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("friction_law") && err.contains("quasi-static and dynamic"), "{err}");
}

/// A dynamic analysis with a force-controlled rigid body (`examples/scenarios/hertz3d_force.toml`
/// with its analysis made dynamic and densities given) is refused by the build, at the force of
/// the rigid body's coordinate (rigid bodies are massless and prescribed in dynamic analyses).
#[test]
fn force_controlled_rigid_body_in_a_dynamic_scenario_is_refused_at_its_force() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/hertz3d_force.toml");
    let text = std::fs::read_to_string(&path).expect("scenario file");
    assert!(text.contains("[analysis]\ntype = \"static\"\n"));
    let dynamic = text
        .replace("[analysis]\ntype = \"static\"\n", "[analysis]\ntype = \"dynamic\"\ndt = 0.01\nsteps = 3\n")
        .replace(
            "material = { type = \"isotropic\", E = 10.0, nu = 0.3 }",
            "material = { type = \"isotropic\", E = 10.0, nu = 0.3 }\ndensity = 1e-9",
        )
        .replace(
            "material = { type = \"isotropic\", E = 10000.0, nu = 0.3 }",
            "material = { type = \"isotropic\", E = 10000.0, nu = 0.3 }\ndensity = 1e-9",
        );
    let scenario = Scenario::parse(Source::new(&path, dynamic)).expect("parse");
    let err = match build::<3>(&scenario) {
        Ok(_) => panic!("a dynamic analysis with a force-controlled rigid body was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("rigid_body[0].") && err.contains(".force") && err.contains("dynamic analyses"),
        "{err}"
    );
}

/// `examples/scenarios/dynamic_roller2d.toml` (a rigid roller with all coordinates prescribed
/// in a dynamic analysis) builds and runs; the same file with a force on the roller's `ty`, or
/// with a part tied to the roller, is refused by the build at that key.
#[test]
fn prescribed_rigid_body_in_a_dynamic_scenario_runs_and_what_it_cannot_take_is_refused_at_the_key() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/dynamic_roller2d.toml");
    let text = std::fs::read_to_string(&path).expect("scenario file");
    let scenario = Scenario::parse(Source::new(&path, text.clone())).expect("parse");
    let built = build::<2>(&scenario).expect("build");
    let run = built.joint.run_with(|_| Ok(())).expect("run");
    let last = run.records.last().expect("records");
    assert_eq!(last.rigid[0].name, "roller");
    assert!((last.rigid[0].dofs[0] - 20.0).abs() < 1e-12 && last.pairs[0].normal_force > 0.0, "{last:?}");
    let ty = "ty = { value = -0.6, history = { table = [[0.0, 0.0], [0.003, 1.0], [0.01, 1.0]] } }";
    assert!(text.contains(ty));
    let forced = text.replace(ty, "ty = { force = -5.0 }");
    let err = match build::<2>(&Scenario::parse(Source::new(&path, forced)).expect("parse")) {
        Ok(_) => panic!("a force-controlled roller in a dynamic analysis was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("rigid_body[0].ty.force") && err.contains("dynamic analyses"), "{err}");
    let tied = format!(
        "{text}\n[[boundary]]\nbody = \"pad\"\npart = \"left\"\nkind = \"rigid_body\"\nrigid_body = \"roller\"\n"
    );
    let err = match build::<2>(&Scenario::parse(Source::new(&path, tied)).expect("parse")) {
        Ok(_) => panic!("a part tied to a rigid body in a dynamic analysis was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("boundary[1].kind") && err.contains("dynamic analyses"), "{err}");
}
