//! `[newton]` (the Newton iteration of nonlinear models) and `fillet` of `stl` shapes in
//! scenario files (docs/scenario.md):
//!
//! * `[newton]` reaches the model's `NewtonParams` key by key; modified Newton with Aitken's
//!   relaxation solves the neo-Hookean Hertz scenario to the default iteration's answer;
//! * bad values are refused at their key, and `[newton]` in a linear model is refused;
//! * `fillet` rounds the concave edge of an STL groove as `SurfaceObstacle::with_concave_fillet`
//!   does: the scenario's run equals the Rust API's on the same model, and differs from the
//!   faceted groove's.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use synovia::builder::{Analysis, JointModel, RunResult};
use synovia::contact_ops::SurfaceObstacle;
use synovia::mesh::generators::{box_mesh, Grading};
use synovia::mesh::math::{Point, Vector};
use synovia::mesh::TriangleSurface;
use synovia::nonlinear::NewtonParams;
use synovia::prelude::isotropic;
use synovia::time::history::Constant;
use synovia_scenario::build::build;
use synovia_scenario::scenario::Source;
use synovia_scenario::Scenario;

fn hertz_neo_hookean() -> (PathBuf, String) {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/hertz2d_neo_hookean.toml");
    let text = std::fs::read_to_string(&path).expect("scenario file");
    assert!(!text.contains("[newton]"));
    (path, text)
}

fn scenario(path: &Path, text: &str) -> Scenario {
    Scenario::parse(Source::new(path, text.to_string())).expect("parse")
}

/// The error of building `text` (a scenario expected to be refused).
fn refusal<const D: usize>(path: &Path, text: &str) -> String {
    match Scenario::parse(Source::new(path, text.to_string())) {
        Err(e) => e.to_string(),
        Ok(s) => match build::<D>(&s) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted:\n{text}"),
        },
    }
}

fn normal_forces<const D: usize>(r: &RunResult<D>) -> Vec<f64> {
    r.records.iter().map(|s| s.pairs[0].normal_force).collect()
}

#[test]
fn newton_table_sets_the_parameters_and_solves_the_same_problem() {
    let (path, text) = hertz_neo_hookean();
    let with = format!(
        "{text}\n[newton]\ntolerance = 1e-11\nmax_iterations = 40\nline_search = true\nmax_cutbacks = 5\n\
         tangent_reuse = 0.5\ngeometry = \"converged\"\ngeometry_tolerance = 1e-9\nmax_geometry_passes = 25\n\
         geometry_relaxation = 0.6\ngeometry_aitken = true\ngeometry_pass_tolerance = 1e-3\nsettled_increment = 1e-9\nactive_sets = \"nested\"\n"
    );
    let built = build::<2>(&scenario(&path, &with)).expect("build");
    let expected = NewtonParams::default()
        .with_tolerance(1e-11)
        .with_max_iterations(40)
        .with_line_search(true)
        .with_max_cutbacks(5)
        .with_tangent_reuse(Some(0.5))
        .with_geometry_tolerance(1e-9)
        .with_max_geometry_passes(25)
        .with_geometry_relaxation(0.6)
        .with_geometry_aitken(true)
        .with_geometry_pass_tolerance(Some(1e-3))
        .with_settled_increment(Some(1e-9));
    assert_eq!(built.joint.newton_parameters(), expected);
    // the default iteration and modified Newton with Aitken's relaxation: the same answer
    let a = build::<2>(&scenario(&path, &text)).expect("build").joint.run().expect("run");
    let b = built.joint.run().expect("run");
    let (fa, fb) = (normal_forces(&a), normal_forces(&b));
    assert_eq!(fa.len(), fb.len());
    let scale = fa.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    for (x, y) in fa.iter().zip(&fb) {
        assert!((x - y).abs() <= 1e-6 * scale, "normal force {x} vs {y}");
    }
}

#[test]
fn bad_newton_values_are_refused_at_their_key() {
    let (path, text) = hertz_neo_hookean();
    for (line, key) in [
        ("tangent_reuse = 1.0", "newton.tangent_reuse"),
        ("tangent_reuse = 0.0", "newton.tangent_reuse"),
        ("geometry_relaxation = 1.5", "newton.geometry_relaxation"),
        ("tolerance = -1e-8", "newton.tolerance"),
        ("max_iterations = 0", "newton.max_iterations"),
        ("geometry = \"always\"", "newton.geometry"),
        ("active_sets = \"inner\"", "newton.active_sets"),
        ("geometry_pass_tolerance = 0.0", "newton.geometry_pass_tolerance"),
        ("settled_increment = 0.0", "newton.settled_increment"),
        ("settled_increment = 1.5", "settled increment"),
    ] {
        let msg = refusal::<2>(&path, &format!("{text}\n[newton]\n{line}\n"));
        assert!(msg.contains(key), "`{line}`: {msg}");
    }
    let msg = refusal::<2>(&path, &format!("{text}\n[newton]\nrelaxation = 0.5\n"));
    assert!(msg.contains("relaxation"), "unknown key: {msg}");
    // a linear model has no Newton iteration
    let linear = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/hertz2d.toml");
    let linear_text = std::fs::read_to_string(&linear).expect("scenario file");
    let msg = refusal::<2>(&linear, &format!("{linear_text}\n[newton]\ntangent_reuse = 0.5\n"));
    assert!(msg.contains("newton") && msg.contains("linear"), "{msg}");
}

/// The open groove `z = 1 − 0.05 x` (x ≥ 0), `z = 1 + 0.1 x` (x < 0) over `[-2, 2]²`, normals
/// down (the free space below): its crease `x = 0` is a concave edge seen from below.
fn groove() -> TriangleSurface {
    let v = |x: f64, y: f64| Point::<3>::new(x, y, if x >= 0.0 { 1.0 - 0.05 * x } else { 1.0 + 0.1 * x });
    let vertices = vec![v(-2.0, -2.0), v(0.0, -2.0), v(2.0, -2.0), v(-2.0, 2.0), v(0.0, 2.0), v(2.0, 2.0)];
    let triangles = vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
    let surface = TriangleSurface::new(vertices, triangles).unwrap();
    if surface.normal(0)[2] > 0.0 {
        surface.flipped()
    } else {
        surface
    }
}

/// A linear block under the groove, its top 0.01 below the crease (a row of nodes under the
/// crease line, within the fillet's reach), its bottom pushed up by 0.3 (static, small strain:
/// a test of the shape, not of the material), with the groove as given.
fn groove_scenario(stl: &str, shape_keys: &str) -> String {
    format!(
        r#"dimension = 3
[[body]]
name = "block"
mesh = {{ generator = "box", lo = [-0.1, -0.1, 0.0], hi = [0.1, 0.1, 0.99], cells = [8, 4, 4] }}
material = {{ type = "isotropic", E = 10.0, nu = 0.3 }}

[[boundary]]
body = "block"
part = "bottom"
kind = "prescribed"
value = [0.0, 0.0, 0.3]

[[contact]]
name = "block-groove"
body = "block"
part = "top"
obstacle = {{ type = "stl", file = "{stl}", solid = false{shape_keys} }}

[analysis]
type = "static"
"#
    )
}

#[test]
fn stl_fillet_rounds_the_concave_edge_as_the_rust_api() {
    let dir = std::env::temp_dir().join(format!("synovia_fillet_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let stl = dir.join("groove.stl");
    synovia::io::write_stl(&stl, &groove()).unwrap();
    let path = dir.join("groove.toml");
    let run = |keys: &str| -> RunResult<3> {
        let text = groove_scenario("groove.stl", keys);
        build::<3>(&scenario(&path, &text)).expect("build").joint.run().expect("run")
    };
    let filleted = run(", fillet = 0.05, fillet_max_offset = 0.01");
    let faceted = run("");
    // the Rust API's model with the same fillet
    let mesh = box_mesh([-0.1, -0.1, 0.0], [0.1, 0.1, 0.99], [8, 4, 4], [Grading::Uniform; 3]).unwrap();
    let mut joint = JointModel::<3>::new();
    joint.add_body("block", mesh, isotropic(10.0, 0.3).unwrap()).unwrap();
    joint.prescribe("block", "bottom", Vector::<3>::new(0.0, 0.0, 0.3), Constant(1.0)).unwrap();
    let shape = SurfaceObstacle::new(synovia::io::read_stl(&stl).unwrap())
        .unwrap()
        .with_concave_fillet(0.05, 0.01)
        .unwrap();
    assert_eq!(shape.filleted_edges(), 1);
    joint.contact_rigid("block-groove", "block", "top", shape, 0.0).unwrap();
    joint.set_analysis(Analysis::Static { time: 0.0 });
    let api = joint.run().expect("run");
    let (fs, fa, ff) = (normal_forces(&filleted), normal_forces(&api), normal_forces(&faceted));
    println!("normal force: scenario with fillet {fs:?}, Rust API {fa:?}, faceted {ff:?}");
    assert!(fs[0] > 0.0);
    assert!((fs[0] - fa[0]).abs() <= 1e-12 * fa[0], "scenario {} vs Rust API {}", fs[0], fa[0]);
    assert!((fs[0] - ff[0]).abs() > 1e-6 * ff[0], "the fillet changed nothing: {} vs {}", fs[0], ff[0]);
    // `fillet_max_offset` without `fillet`, a negative radius
    let msg = refusal::<3>(&path, &groove_scenario("groove.stl", ", fillet_max_offset = 0.01"));
    assert!(msg.contains("fillet_max_offset"), "{msg}");
    let msg = refusal::<3>(&path, &groove_scenario("groove.stl", ", fillet = -0.1"));
    assert!(msg.contains("fillet"), "{msg}");
    std::fs::remove_dir_all(&dir).ok();
}
