//! The scenario format through the library: every kind of mesh, material, condition and
//! obstacle builds; errors carry key and position; no input panics.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use synovia_cli::run::{check, run};
use synovia_cli::{Scenario, ScenarioError, Source};

fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::parse(Source::new("test.toml", text.to_string()))
}

fn checked(text: &str) -> Result<synovia_cli::run::ModelInfo, ScenarioError> {
    check(&parse(text)?)
}

const FEATURES_2D: &str = r#"
dimension = 2

[[body]]
name = "bone"
mesh = { generator = "layered_arc", center = [0.0, 30.0], radii = [20.0, 28.0, 30.0], angles_deg = [240.0, 300.0], n_angle = 12, n_radial = [3, 2], layer = 0 }
material = { type = "anisotropic", C = [[2000.0, 800.0, 0.0], [800.0, 2000.0, 0.0], [0.0, 0.0, 600.0]] }
density = 2.0e-9
body_force = { value = [0.0, -1.0e-5], history = 1.0 }

[[body]]
name = "cartilage"
mesh = { generator = "layered_arc", center = [0.0, 30.0], radii = [20.0, 28.0, 30.0], angles_deg = [240.0, 300.0], n_angle = 12, n_radial = [3, 2], layer = 1 }
[body.material]
type = "kelvin_voigt"
density = 1.1e-9
damping = 0.0
elastic = { type = "isotropic", E = 10.0, nu = 0.45, plane = "stress" }
viscous = { type = "anisotropic", C = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.005]] }

[[body]]
name = "block"
mesh = { generator = "rectangle", x = [0.0, 4.0], y = [40.0, 42.0], cells = [4, 2], grading = [{ type = "geometric", ratio = 1.1 }, { type = "toward_low", ratio = 1.2 }], translate = [1.0, 0.0] }
material = { type = "transversely_isotropic", E_p = 15.0, nu_p = 0.3, E_a = 8.0, nu_ap = 0.1, G_a = 3.0, axis = [1.0, 1.0], plane = "stress" }

[[body.part]]
name = "corner"
from = "top"
x = [4.0, inf]
within = { center = [5.0, 42.0], radius = 3.0 }

[[boundary]]
body = "bone"
part = "inner"
kind = "rigid_motion"
translation = [0.0, 0.1]
history = { table = [[0.0, 0.0], [1.0, 1.0]], period = 2.0 }
rotation_deg = 1.0
center = [0.0, 30.0]
rotation_history = [[0.0, 0.0], [1.0, 1.0]]

[[boundary]]
body = "bone"
part = "side_start"
kind = "symmetry"

[[boundary]]
body = "cartilage"
part = "side_end"
kind = "pressure"
value = 0.1
history = [[0.0, 0.0], [1.0, 1.0]]

[[boundary]]
body = "block"
part = "left"
kind = "clamped"

[[boundary]]
body = "block"
part = "corner"
kind = "traction"
value = [0.0, 0.5]

[[boundary]]
body = "block"
part = "bottom"
kind = "traction_free"

[[tie]]
body_a = "bone"
part_a = "outer"
body_b = "cartilage"
part_b = "inner"

[[contact]]
body = "cartilage"
part = "outer"
obstacle = { type = "sphere", center = [0.0, 30.0], radius = 31.0, cavity = true }
friction = 0.1

[solver]
name = "au-pdas"
tolerance = 1e-9
max_iterations = 50
rho_scale = 2.0
nested_iteration = 0
screening_band = 0.25
ordering = "amd"
load_degree = 3

[analysis]
type = "quasistatic"
times = [0.0, 0.5, 1.0]
incremental_slip = false
initial_friction = true
coulomb_fixed_point = true
max_fixed_point = 20
fixed_point_tolerance = 1e-6

[output]
dir = "out/features"
vtu_every = 0
encoding = "ascii"
"#;

#[test]
fn every_2d_feature_builds() {
    let info = checked(FEATURES_2D).unwrap();
    assert_eq!(info.dimension, 2);
    assert_eq!(info.bodies.len(), 3);
    assert_eq!(info.pairs, vec!["cartilage:outer".to_string()]);
    assert_eq!((info.analysis.as_str(), info.steps), ("quasistatic", 3));
    let sc = parse(FEATURES_2D).unwrap();
    let built = synovia_cli::build::build::<2>(&sc).unwrap();
    assert_eq!(built.output.vtu_every, 0);
    assert_eq!(built.joint.solver_name(), "au-pdas");
}

const FEATURES_3D: &str = r#"
dimension = 3

[[body]]
name = "head"
mesh = { generator = "layered_cap", center = [0.0, 0.0, 0.0], radii = [20.0, 22.0], half_angle_deg = 50.0, n_surface = 3, n_radial = [2] }
material = { type = "transversely_isotropic", E_p = 15.0, nu_p = 0.3, E_a = 8.0, nu_ap = 0.1, G_a = 3.0, axis = [0.0, 0.0, 1.0] }

[[body]]
name = "block"
mesh = { generator = "box", lo = [30.0, 0.0, 0.0], hi = [32.0, 2.0, 2.0], cells = [2, 2, 2] }
material = { type = "isotropic", E = 100.0, nu = 0.3 }

[[body]]
name = "ball"
mesh = { generator = "ball", center = [50.0, 0.0, 0.0], radius = 2.0, n = 2 }
material = { type = "anisotropic", C = [[3.0, 1.0, 1.0, 0.0, 0.0, 0.0], [1.0, 3.0, 1.0, 0.0, 0.0, 0.0], [1.0, 1.0, 3.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]] }

[[body]]
name = "cap"
mesh = { generator = "hemisphere", center = [0.0, 60.0, 10.0], radius = 10.0, n = 2, reflect = { axis = "z", at = 5.0 } }
material = { type = "isotropic", E = 10.0, nu = 0.3 }

[[boundary]]
body = "head"
part = "inner"
kind = "rigid_motion"
rotation_deg = 2.0
center = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]

[[boundary]]
body = "block"
part = "bottom"
kind = "prescribed"
components = ["z"]
value = [0.0, 0.0, 0.01]

[[boundary]]
body = "block"
part = "left"
kind = "symmetry"

[[boundary]]
body = "block"
part = "front"
kind = "symmetry"

[[boundary]]
body = "ball"
part = "boundary"
kind = "clamped"

[[boundary]]
body = "cap"
part = "top"
kind = "clamped"

[[contact]]
name = "head-socket"
body = "head"
part = "outer"
obstacle = { type = "sphere", center = [0.0, 0.0, 0.0], radius = 22.5, cavity = true }

[[contact]]
name = "block-rod"
body = "block"
part = "top"
obstacle = { type = "cylinder", point = [0.0, 0.0, 3.0], axis = [1.0, 0.0, 0.0], radius = 1.0 }

[analysis]
type = "static"
time = 1.0
"#;

#[test]
fn every_3d_feature_builds() {
    let info = checked(FEATURES_3D).unwrap();
    assert_eq!(info.dimension, 3);
    assert_eq!(info.bodies.len(), 4);
    assert_eq!(info.pairs.len(), 2);
}

#[test]
fn a_small_dynamic_scenario_runs_through_the_library() {
    let text = r#"
dimension = 2
[[body]]
name = "b"
mesh = { generator = "rectangle", x = [0.0, 1.0], y = [0.0, 1.0], cells = [2, 2] }
material = { type = "isotropic", E = 1.0, nu = 0.3 }
density = 1.0
initial_velocity = [0.0, -0.1]
[[contact]]
body = "b"
part = "bottom"
obstacle = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }
[analysis]
type = "dynamic"
dt = 0.01
steps = 3
mass = "lumped"
"#;
    let sc = parse(text).unwrap();
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-cli-tests/lib-dynamic");
    let mut seen = Vec::new();
    let report = run(&sc, Some(&out), &mut |p| seen.push(p)).unwrap();
    assert_eq!(report.summary.steps.len(), 4);
    assert_eq!(seen.len(), 5); // start + 4 steps
    assert!(report.summary.steps.iter().skip(1).any(|s| s.contact_force > 0.0));
    assert!(out.join("summary.json").exists());
}

fn error_of(text: &str) -> ScenarioError {
    checked(text).expect_err("accepted")
}

/// The error of `text` is about `key`, at the first occurrence of `at` (after the line that
/// contains `after`, if given), and its message contains `words`.
fn assert_error(text: &str, key: &str, at: &str, words: &str) {
    let offset = text.find(at).unwrap_or_else(|| panic!("`{at}` not in the text"));
    let line = text[..offset].matches('\n').count() + 1;
    let column = text[..offset].rsplit('\n').next().unwrap_or("").chars().count() + 1;
    let e = error_of(text);
    assert_eq!((e.key.as_str(), e.line, e.column), (key, line, column), "{e}");
    assert!(e.message.contains(words), "{e}");
    let shown = e.to_string();
    assert!(shown.starts_with(&format!("test.toml:{line}:{column}: `{key}`: ")), "{shown}");
}

const SMALL: &str = r#"dimension = 2
[[body]]
name = "b"
mesh = { generator = "rectangle", x = [0.0, 1.0], y = [0.0, 1.0], cells = [2, 2] }
material = { type = "isotropic", E = 1.0, nu = 0.3 }
[[boundary]]
body = "b"
part = "top"
kind = "prescribed"
value = [0.0, -0.01]
[[contact]]
body = "b"
part = "bottom"
obstacle = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }
[analysis]
type = "static"
"#;

#[test]
fn semantic_errors_name_key_and_position() {
    assert!(checked(SMALL).is_ok());
    let with = |from: &str, to: &str| {
        assert!(SMALL.contains(from), "{from}");
        SMALL.replacen(from, to, 1)
    };
    assert_error(
        &with("type = \"static\"\n", "type = \"static\"\n[solver]\nscreening_band = -0.5\n"),
        "solver.screening_band",
        "-0.5",
        "screening band",
    );
    assert_error(
        &with("cells = [2, 2] }", "cells = [2, 2], radius = 1.0 }"),
        "body[0].mesh.radius",
        "1.0 }",
        "does not apply",
    );
    assert_error(
        &with("\"rectangle\"", "\"square\""),
        "body[0].mesh.generator",
        "\"square\"",
        "unknown generator",
    );
    assert_error(&with("\"rectangle\"", "\"box\""), "body[0].mesh.generator", "\"box\"", "3D meshes");
    assert_error(&with("x = [0.0, 1.0]", "x = [1.0, 0.0]"), "body[0].mesh.x", "[1.0, 0.0]", "lo ≤ hi");
    assert_error(
        &with("cells = [2, 2]", "cells = [2]"),
        "body[0].mesh.cells",
        "[2]",
        "2 positive cell counts",
    );
    assert_error(&with("nu = 0.3", "nu = 0.5"), "body[0].material", "{ type = \"isotropic\"", "");
    assert_error(
        &with("E = 1.0, nu = 0.3", "nu = 0.3"),
        "body[0].material",
        "{ type = \"isotropic\"",
        "missing `E`",
    );
    assert_error(
        &with("\"prescribed\"", "\"fixed\""),
        "boundary[0].kind",
        "\"fixed\"",
        "unknown boundary kind",
    );
    assert_error(
        &with("\"prescribed\"", "\"clamped\""),
        "boundary[0].value",
        "[0.0, -0.01]",
        "does not apply",
    );
    assert_error(
        &with("value = [0.0, -0.01]", "value = 1.0"),
        "boundary[0].value",
        "1.0\n[[contact",
        "2D vector",
    );
    assert_error(
        &with("value = [0.0, -0.01]", "value = [0.0, -0.01]\ncomponents = [\"w\"]"),
        "boundary[0].components[0]",
        "\"w\"",
        "component",
    );
    assert_error(
        &with("part = \"bottom\"", "part = \"side\""),
        "contact[0].part",
        "\"side\"",
        "no part `side`",
    );
    assert_error(&with("\"plane\"", "\"cone\""), "contact[0].obstacle.type", "\"cone\"", "unknown obstacle");
    assert_error(
        &with("normal = [0.0, 1.0] }", "normal = [0.0, 0.0] }"),
        "contact[0].obstacle.normal",
        "[0.0, 0.0] }",
        "zero",
    );
    assert_error(
        &with("type = \"static\"", "type = \"static\"\ndt = 0.1"),
        "analysis.dt",
        "0.1\n",
        "does not apply",
    );
    assert_error(
        &with("type = \"static\"", "type = \"quasistatic\""),
        "analysis",
        "[analysis]",
        "missing `times`",
    );
    assert_error(
        &with("type = \"static\"", "type = \"quasistatic\"\ntimes = [0.0, 1.0, 0.5]"),
        "analysis.times",
        "[0.0, 1.0, 0.5]",
        "increase strictly",
    );
    assert_error(
        &with("type = \"static\"", "type = \"dynamic\"\ndt = 0.1\nsteps = 2"),
        "body[0]",
        "\"b\"",
        "density",
    );
    assert_error(&with("dimension = 2", "dimension = 4"), "dimension", "4", "2 or 3");
    assert_error(&with("dimension = 2", "dimension = 2\nname = \"a/b\""), "name", "\"a/b\"", "file name");
    assert_error(&with("cells = [2, 2]", "cells = [100000, 100000]"), "body[0].mesh", "{ generator", "limit");
    let reset = format!("{SMALL}[[boundary]]\nbody = \"b\"\npart = \"top\"\nkind = \"traction_free\"\n");
    let e = error_of(&reset);
    assert_eq!((e.key.as_str(), e.line), ("boundary[1].kind", 20), "{e}");
    assert!(e.message.contains("already has a condition"), "{e}");
    // a part given two kinds
    let twice = format!("{SMALL}[[boundary]]\nbody = \"b\"\npart = \"top\"\nkind = \"clamped\"\n");
    let e = error_of(&twice);
    assert_eq!((e.key.as_str(), e.line, e.column), ("boundary[1].kind", 20, 8), "{e}");
    assert!(e.message.contains("already of kind Prescribed"), "{e}");
}

#[test]
fn no_prefix_of_a_scenario_panics() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/hertz2d.toml"),
    )
    .unwrap();
    let mut accepted = 0;
    for (i, _) in text.char_indices().step_by(7) {
        if let Ok(sc) = parse(&text[..i]) {
            if check(&sc).is_ok() {
                accepted += 1;
            }
        }
    }
    // only prefixes that end after `type = "static"` are complete scenarios
    assert!(accepted <= 1, "{accepted}");
    assert!(checked(&text).is_ok());
}

#[test]
fn the_documented_example_is_the_example_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let doc = std::fs::read_to_string(root.join("docs/scenario.md")).unwrap();
    let example = std::fs::read_to_string(root.join("examples/scenarios/tibial_plateau2d.toml")).unwrap();
    assert!(doc.contains(&format!("```toml\n{example}```")), "docs/scenario.md is out of date");
}

/// Body-body pairs on non-matching meshes: the `discretisation` key and its errors.
#[test]
fn contact_discretisation_key() {
    let two = |extra: &str| {
        format!(
            r#"dimension = 2
[[body]]
name = "upper"
mesh = {{ generator = "rectangle", x = [0.0, 1.0], y = [0.0, 0.5], cells = [5, 2] }}
material = {{ type = "isotropic", E = 1.0, nu = 0.3 }}
[[body]]
name = "lower"
mesh = {{ generator = "rectangle", x = [0.0, 1.0], y = [-0.5, 0.0], cells = [3, 2] }}
material = {{ type = "isotropic", E = 1.0, nu = 0.3 }}
[[boundary]]
body = "upper"
part = "top"
kind = "prescribed"
value = [0.0, -0.01]
[[boundary]]
body = "lower"
part = "bottom"
kind = "clamped"
[[contact]]
body = "upper"
part = "bottom"
partner = {{ body = "lower", part = "top" }}
{extra}
[analysis]
type = "static"
"#
        )
    };
    // non-matching meshes (5 vs 3 cells): both non-matching discretisations build
    for kind in ["node_to_segment", "mortar"] {
        checked(&two(&format!("discretisation = \"{kind}\""))).unwrap_or_else(|e| panic!("{kind}: {e}"));
    }
    let text = two("discretisation = \"node_to_surface\"");
    assert_error(&text, "contact[0].discretisation", "\"node_to_surface\"", "unknown contact discretisation");
    let text = two("discretisation = \"mortar\"\nnormal = [0.0, 1.0]");
    assert_error(&text, "contact[0].normal", "[0.0, 1.0]\n", "node-to-node pairs only");
    let text = two("search_distance = 0.1");
    assert_error(&text, "contact[0].search_distance", "0.1\n", "`node_to_segment` and `mortar` pairs only");
    let text = two("discretisation = \"mortar\"\nsearch_distance = -1.0");
    assert!(error_of(&text).key.contains("search_distance"), "{}", error_of(&text));
}

/// Keys that take one name among a few (`plane`, `kinematics`, `analysis.mass`,
/// `output.encoding`): a wrong name is refused at its key with the list of the names taken.
#[test]
fn keyword_keys_list_their_names() {
    let with = |from: &str, to: &str| {
        assert!(SMALL.contains(from), "{from}");
        SMALL.replacen(from, to, 1)
    };
    assert_error(
        &with("nu = 0.3 }", "nu = 0.3, plane = \"strian\" }"),
        "body[0].material.plane",
        "\"strian\"",
        "`plane` is `strain` or `stress`, got `strian`",
    );
    assert!(checked(&with("nu = 0.3 }", "nu = 0.3, plane = \"stress\" }")).is_ok());
    assert_error(
        &with("nu = 0.3 }\n", "nu = 0.3 }\nkinematics = \"large\"\n"),
        "body[0].kinematics",
        "\"large\"",
        "`kinematics` is `small` or `finite`, got `large`",
    );
    assert_error(
        &with("type = \"static\"\n", "type = \"dynamic\"\ndt = 0.1\nsteps = 2\nmass = \"diagonal\"\n"),
        "analysis.mass",
        "\"diagonal\"",
        "mass is `consistent` or `lumped`, got `diagonal`",
    );
    assert_error(
        &format!("{SMALL}[output]\nencoding = \"hdf5\"\n"),
        "output.encoding",
        "\"hdf5\"",
        "encoding is `zlib`, `binary`, `base64` or `ascii`, got `hdf5`",
    );
    assert!(checked(&format!("{SMALL}[output]\nencoding = \"base64\"\n")).is_ok());
}
