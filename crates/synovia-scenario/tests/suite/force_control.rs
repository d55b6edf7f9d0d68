//! `[force_control]` in scenario files (docs/scenario.md): the keys reach the model's
//! `ForceControlParams`; the coordinate solved inside the contact solve (the default) and the
//! search over trial solves (`bordered = false`) balance the same force at the same pose, the
//! first with fewer solves; bad values and a model without force-controlled coordinates are
//! refused at their key.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use synovia::rigid::ForceControlParams;
use synovia_scenario::build::build;
use synovia_scenario::scenario::Source;
use synovia_scenario::Scenario;

/// A rigid cylinder pressed by 4 N onto a clamped block (its vertical translation
/// force-controlled), with friction, two levels.
const INDENTER: &str = r#"
dimension = 2
title = "rigid indenter under force control"

[[body]]
name = "block"
mesh = { generator = "rectangle", x = [-1.0, 1.0], y = [0.0, 1.0], cells = [16, 8] }
material = { type = "isotropic", E = 1000.0, nu = 0.3 }

[[rigid_body]]
name = "indenter"
center = [0.1, 1.5]
shape = { type = "sphere", center = [0.1, 1.5], radius = 0.5 }
ty = { force = -4.0 }

[[boundary]]
body = "block"
part = "bottom"
kind = "clamped"

[[contact]]
name = "indent"
body = "block"
part = "top"
rigid_body = "indenter"
friction = 0.2

[solver]
name = "pdas"

[analysis]
type = "quasistatic"
times = [0.0, 1.0]
"#;

fn path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/force_control.toml")
}

fn scenario(path: &Path, text: &str) -> Scenario {
    Scenario::parse(Source::new(path, text.to_string())).expect("parse")
}

fn refusal(text: &str) -> String {
    match Scenario::parse(Source::new(path(), text.to_string())) {
        Err(e) => e.to_string(),
        Ok(s) => match build::<2>(&s) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted:\n{text}"),
        },
    }
}

#[test]
fn force_control_table_sets_the_parameters_and_both_iterations_agree() {
    let with = format!(
        "{INDENTER}\n[force_control]\ntolerance = 1e-11\nmax_solves = 80\ngeometry_tolerance = 1e-9\n\
         bordered = false\nfresh_jacobian = true\n"
    );
    let built = build::<2>(&scenario(&path(), &with)).expect("build");
    let expected = ForceControlParams {
        tolerance: 1e-11,
        max_solves: 80,
        geometry_tolerance: 1e-9,
        bordered: false,
        fresh_jacobian: true,
    };
    assert_eq!(built.joint.force_control_params(), expected);
    // the default (bordered) and the search, both to the geometry tolerance 1e-9
    let run = |table: &str| {
        let text = format!("{INDENTER}\n[force_control]\ngeometry_tolerance = 1e-9\n{table}");
        let r = build::<2>(&scenario(&path(), &text)).expect("build").joint.run().expect("run");
        r.records
            .iter()
            .map(|rec| {
                let rigid = &rec.rigid[0];
                assert!(rigid.balance_error <= 1e-10, "{rigid:?}");
                assert!((rec.pairs[0].force[1] + 4.0).abs() <= 1e-9 * 4.0, "{:?}", rec.pairs[0]);
                (rigid.dofs[1], rec.pairs[0].normal_force, rigid.solves)
            })
            .collect::<Vec<_>>()
    };
    let bordered = run("");
    let search = run("bordered = false\n");
    for ((yb, nb, _), (ys, ns, _)) in bordered.iter().zip(&search) {
        assert!((yb - ys).abs() <= 1e-9, "travel {yb} vs {ys}");
        assert!((nb - ns).abs() <= 1e-7 * ns.abs(), "normal force {nb} vs {ns}");
    }
    let solves = |v: &[(f64, f64, usize)]| v.iter().map(|x| x.2).sum::<usize>();
    println!("solves: bordered {}, search {}", solves(&bordered), solves(&search));
    assert!(solves(&bordered) < solves(&search));
}

#[test]
fn bad_force_control_values_are_refused_at_their_key() {
    for (line, key) in [
        ("tolerance = 0.0", "force_control.tolerance"),
        ("tolerance = 2.0", "force_control.tolerance"),
        ("max_solves = 0", "force_control.max_solves"),
        ("geometry_tolerance = -1e-6", "force_control.geometry_tolerance"),
    ] {
        let msg = refusal(&format!("{INDENTER}\n[force_control]\n{line}\n"));
        assert!(msg.contains(key), "`{line}`: {msg}");
    }
    let msg = refusal(&format!("{INDENTER}\n[force_control]\nsteps = 3\n"));
    assert!(msg.contains("steps"), "{msg}");
    // no force-controlled degree of freedom: the table has nothing to set
    let prescribed = INDENTER.replace("ty = { force = -4.0 }", "ty = { value = -0.01 }");
    let msg = refusal(&format!("{prescribed}\n[force_control]\nbordered = false\n"));
    assert!(msg.contains("force_control") && msg.contains("no rigid body"), "{msg}");
}
