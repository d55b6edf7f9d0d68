//! Smoothed STL obstacles in scenario files (`subdivide`, `crease_angle_deg`; docs/scenario.md):
//! a block pressed onto a coarse tessellated ball (an icosahedron split twice) smoothed by the
//! scenario's keys gets the contact force of the same ball subdivided beforehand by the library
//! and read from a (single-precision) file to 1e-5, not the faceted ball's; zero levels give the
//! faceted ball's exactly; the keys are checked.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use synovia::mesh::TriangleSurface;
use synovia::prelude::*;
use synovia_cli::run::{check, run};
use synovia_cli::{Scenario, ScenarioError, Source};

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-cli-stl").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::parse(Source::new("test.toml", text.to_string()))
}

/// A unit block (clamped bottom, E = 100) whose top is pressed 0.1 into a ball of radius 2
/// above it: `obstacle` is the ball's table.
fn pressed_block(obstacle: &str) -> String {
    format!(
        r#"
dimension = 3

[[body]]
name = "block"
mesh = {{ generator = "box", lo = [0.0, 0.0, 0.0], hi = [1.0, 1.0, 1.0], cells = [8, 8, 4] }}
material = {{ type = "isotropic", E = 100.0, nu = 0.3 }}

[[boundary]]
body = "block"
part = "bottom"
kind = "clamped"

[[contact]]
name = "ball"
body = "block"
part = "top"
obstacle = {obstacle}

[analysis]
type = "static"
"#
    )
}

fn contact_force(text: &str, name: &str) -> f64 {
    let out = tmp(name);
    let report = run(&parse(text).unwrap(), Some(&out), &mut |_| {}).unwrap();
    report.summary.steps[0].pairs[0].normal_force
}

#[test]
fn subdivide_smooths_the_stl_as_the_library_does_and_its_keys_are_checked() {
    let dir = tmp("files");
    // (off the block's symmetry planes: a node inside the ball on a plane of symmetry is as
    // far from two mirror-image facets, and which one the closest-point search returns — and so
    // the node's normal, tilted by ±1.5–2.7° — depends on the facets' numbering, which the file
    // written and read back changes; centred, the forces differed by 2e-4)
    let centre = Point::<3>::new(0.5137, 0.4871, 2.93);
    let ball = TriangleSurface::icosphere(centre, 2.0, 2).unwrap();
    let file = dir.join("ball.stl");
    synovia::io::write_stl(&file, &ball).unwrap();
    let smoothed_file = dir.join("ball_smoothed.stl");
    // (the control points as the file holds them: single precision)
    let read = synovia::io::read_stl(&file).unwrap();
    synovia::io::write_stl(&smoothed_file, &read.loop_subdivided(2, 40f64.to_radians()).unwrap()).unwrap();
    let stl = |f: &Path, extra: &str| format!("{{ type = \"stl\", file = \"{}\"{extra} }}", f.display());
    let faceted = contact_force(&pressed_block(&stl(&file, "")), "faceted");
    let smooth =
        contact_force(&pressed_block(&stl(&file, ", subdivide = 2, crease_angle_deg = 40.0")), "smooth");
    let library = contact_force(&pressed_block(&stl(&smoothed_file, "")), "library");
    eprintln!(
        "contact force: faceted {faceted:.9}, smoothed {smooth:.9}, smoothed by the library {library:.9}"
    );
    assert!(faceted > 0.0 && smooth > 0.0);
    // (measured: 6.2e-7 apart, 5.3e-7 with the ball 1e-3 lower: the single-precision file's
    // rounding of the smoothed points, ≈ 1e-7 of the coordinates)
    assert!((smooth - library).abs() < 1e-5 * library, "{smooth} vs {library}");
    // zero levels: the faceted ball, bit for bit (two runs of the same model in one process;
    // they differed in the last bits while other tests ran beside them until every call into
    // METIS held `synovia_linalg::metis_lock`: docs/reliability.md)
    let zero = contact_force(&pressed_block(&stl(&file, ", subdivide = 0")), "zero");
    assert_eq!(zero.to_bits(), faceted.to_bits(), "{zero} vs {faceted}");
    assert!((smooth - faceted).abs() > 1e-2 * faceted, "{smooth} vs {faceted}");

    // the keys are checked
    let bad = [
        (stl(&file, ", subdivide = 5"), "at most 4"),
        (stl(&file, ", subdivide = -1"), "0 to 4"),
        (stl(&file, ", crease_angle_deg = 30.0"), "needs `subdivide`"),
        (stl(&file, ", subdivide = 1, crease_angle_deg = 200.0"), "crease angle"),
    ];
    for (obstacle, why) in bad {
        let e = check(&parse(&pressed_block(&obstacle)).unwrap()).unwrap_err();
        assert!(e.to_string().contains(why), "{obstacle}: {e}");
    }
    // not for other shapes
    let e =
        parse(&pressed_block("{ type = \"sphere\", center = [0.5, 0.5, 2.9], radius = 2.0, subdivide = 1 }"))
            .and_then(|s| check(&s).map(|_| ()));
    assert!(e.is_err());
}
