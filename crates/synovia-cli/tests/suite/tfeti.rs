//! The solver `tfeti` from a scenario file (issue 19): `examples/scenarios/hertz2d_tfeti.toml`
//! run by TFETI and by the default direct solver (`pdas-fallback`) gives the same displacements
//! and contact forces to 1e-6 (relative, max norm), frictionless and with friction; what TFETI
//! does not treat is refused with an error naming it; keys of one kind of solver are refused
//! with the other.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use synovia_cli::compare::compare;
use synovia_cli::run;
use synovia_cli::{Scenario, Source};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-cli-tfeti").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The example scenario's text.
fn example() -> String {
    std::fs::read_to_string(workspace().join("examples/scenarios/hertz2d_tfeti.toml")).unwrap()
}

/// `text` with `from` replaced by `to` (which must occur).
fn replace(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` not in the scenario");
    text.replacen(from, to, 1)
}

/// `text` without its `[solver]` table (the default solver).
fn direct(text: &str) -> String {
    let start = text.find("[solver]").unwrap();
    let end = text.find("[analysis]").unwrap();
    format!("{}{}", &text[..start], &text[end..])
}

fn scenario(text: &str) -> Scenario {
    let file = workspace().join("examples/scenarios/hertz2d_tfeti.toml");
    Scenario::parse(Source::new(file, text.to_string())).unwrap()
}

fn run_into(text: &str, out: &Path) -> run::Summary {
    run::run(&scenario(text), Some(out), &mut |_| {}).unwrap().summary
}

#[test]
fn tfeti_equals_the_direct_solver_frictionless_and_with_friction() {
    for (case, friction) in [("frictionless", "0.0"), ("friction", "0.3")] {
        let text = replace(&example(), "friction = 0.3", &format!("friction = {friction}"));
        let dir = tmp(case);
        let feti = run_into(&text, &dir.join("tfeti"));
        let pdas = run_into(&direct(&text), &dir.join("direct"));
        assert_eq!(feti.solver, "tfeti");
        assert!(feti.steps.iter().all(|s| s.solver == "tfeti" && s.kkt < 1e-8), "{:?}", feti.steps);
        assert_eq!(pdas.solver, synovia::solvers::DEFAULT_SOLVER);
        assert_eq!(feti.steps.len(), 3);
        let force = feti.steps[2].pairs[0].normal_force;
        assert!(force > 0.0);
        let slipping = feti.steps[2].pairs[0].tangential_force;
        if friction == "0.0" {
            assert_eq!(slipping, 0.0);
        } else {
            assert!(slipping > 0.05 * force, "friction force {slipping} vs normal {force}");
        }
        let c = compare(&dir.join("direct"), &dir.join("tfeti")).unwrap();
        println!("{case}: {:?}", c.differences);
        assert_eq!((c.steps, c.files), (3, 3));
        for q in ["vtu:displacement", "pair:force", "pair:normal_force", "pair:tangential_force"] {
            let d = c.of(q).unwrap();
            assert!(d <= 1e-6, "{case}: {q} differs by {d:e}");
        }
        assert!(c.max() <= 1e-6, "{case}: {:?}", c.differences);
    }
}

#[test]
fn check_reports_the_tfeti_model() {
    let info = run::check(&scenario(&example())).unwrap();
    assert_eq!(info.solver, "tfeti");
    assert_eq!(info.steps, 3);
    assert!(info.dofs > 0 && info.contact_nodes[0].1 > 0);
}

/// The build error of `text`.
fn refused(text: &str) -> String {
    let sc = scenario(text);
    match synovia_cli::build::build::<2>(&sc) {
        Ok(_) => panic!("the scenario was accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn what_tfeti_does_not_treat_is_refused_by_name() {
    // a dynamic analysis
    let text = replace(
        &replace(
            &example(),
            "type = \"quasistatic\"\ntimes = { start = 0.0, end = 1.0, steps = 2 }",
            "type = \"dynamic\"\ndt = 0.01\nsteps = 2",
        ),
        "material = { type = \"isotropic\"",
        "density = 1e-9\nmaterial = { type = \"isotropic\"",
    );
    let e = refused(&text);
    assert!(
        e.contains("`solver.name`") && e.contains("the `tfeti` solver does not support dynamic analyses"),
        "{e}"
    );
    // a nonlinear material
    let text = replace(
        &example(),
        "type = \"isotropic\", E = 10.0, nu = 0.3, plane = \"strain\"",
        "type = \"neo_hookean\", E = 10.0, nu = 0.3",
    );
    let e = refused(&text);
    assert!(e.contains("the `tfeti` solver does not support nonlinear materials (body `cylinder`"), "{e}");
    // from the library: the same error type, also for a run without the scenario check
    let mut built = synovia_cli::build::build::<2>(&scenario(&example())).unwrap();
    built.joint.set_analysis(synovia::builder::Analysis::Dynamic { dt: 0.01, steps: 2 });
    let e = built.joint.run().unwrap_err();
    assert!(matches!(e, synovia::builder::JointError::Unsupported { .. }), "{e}");
    let e = built.joint.prepare().err().unwrap();
    assert!(matches!(e, synovia::builder::JointError::Unsupported { .. }), "{e}");
    assert!(e.to_string().contains("re-solve sessions"), "{e}");
}

#[test]
fn solver_keys_of_the_other_kind_are_refused() {
    let e = refused(&replace(&example(), "[solver]\nname = \"tfeti\"", "[solver]\nname = \"pdas\""));
    assert!(e.contains("solver.subdomains") && e.contains("keys of `tfeti`"), "{e}");
    let e = refused(&replace(&example(), "subdomains = 8", "subdomains = 8\nscreening_band = 0.5"));
    assert!(e.contains("solver.screening_band"), "{e}");
    let e = refused(&replace(&example(), "partitioner = \"metis\"", "partitioner = \"scotch\""));
    assert!(e.contains("solver.partitioner") && e.contains("`metis` or `bisection`"), "{e}");
    let e = refused(&replace(&example(), "preconditioner = \"dirichlet\"", "preconditioner = \"jacobi\""));
    assert!(e.contains("solver.preconditioner"), "{e}");
    let e = refused(&replace(&example(), "subdomains = 8", "subdomains = 0"));
    assert!(e.contains("solver.subdomains"), "{e}");
}

/// `coarse = "projector"` with the longer expansion steps (`examples/scenarios/
/// hertz2d_tfeti_projector.toml`) gives the direct solver's displacements and forces to 1e-6,
/// frictionless and with friction; unknown values are refused at their key.
#[test]
fn projector_and_longer_expansion_equal_the_direct_solver() {
    let projector =
        std::fs::read_to_string(workspace().join("examples/scenarios/hertz2d_tfeti_projector.toml")).unwrap();
    assert!(
        projector.contains("coarse = \"projector\"") && projector.contains("expansion = \"preconditioned\"")
    );
    for expansion in ["preconditioned", "projected_cg", "fixed"] {
        for (case, friction) in [("frictionless", "0.0"), ("friction", "0.3")] {
            let text = replace(&projector, "friction = 0.3", &format!("friction = {friction}"));
            let text =
                replace(&text, "expansion = \"preconditioned\"", &format!("expansion = \"{expansion}\""));
            let dir = tmp(&format!("projector-{expansion}-{case}"));
            let feti = run_into(&text, &dir.join("tfeti"));
            run_into(&direct(&text), &dir.join("direct"));
            assert!(feti.steps.iter().all(|s| s.solver == "tfeti" && s.kkt < 1e-8), "{:?}", feti.steps);
            let c = compare(&dir.join("direct"), &dir.join("tfeti")).unwrap();
            println!("projector, {expansion}, {case}: {:?}", c.differences);
            assert_eq!((c.steps, c.files), (3, 3));
            assert!(c.max() <= 1e-6, "{expansion}, {case}: {:?}", c.differences);
        }
    }
    for (key, from, to) in [
        ("solver.coarse", "coarse = \"projector\"", "coarse = \"schur\""),
        ("solver.expansion", "expansion = \"preconditioned\"", "expansion = \"long\""),
    ] {
        let e = refused(&replace(&projector, from, to));
        assert!(e.contains(key), "{e}");
    }
    let e = refused(&replace(&projector, "[solver]\nname = \"tfeti\"", "[solver]\nname = \"pdas\""));
    assert!(e.contains("keys of `tfeti`"), "{e}");
}
