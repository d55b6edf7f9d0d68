//! Units in the outputs and the unit-mistake check: every CSV column carries its unit,
//! `summary.json` names the units and reports the sides of a split pair, and a model whose
//! loads would strain a body by more than 100 % (a mesh in metres with loads in N and moduli in
//! MPa) is refused by `check` and `run` unless `[units] check = false`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use synovia_cli::run::{check, run};
use synovia_cli::{Scenario, ScenarioError, Source};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-cli-units").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::parse(Source::new("test.toml", text.to_string()))
}

/// `hertz2d.toml` with its pair split at `x = 0` (and `extra` appended).
fn hertz_split(extra: &str) -> String {
    let text = std::fs::read_to_string(workspace().join("examples/scenarios/hertz2d.toml")).unwrap();
    let from = "obstacle = { type = \"plane\", point = [0.0, 0.0], normal = [0.0, 1.0] }";
    assert!(text.contains(from));
    text.replace(
        from,
        &format!(
            "{from}\nsplit = {{ point = [0.0, 0.0], normal = [1.0, 0.0], positive = \"lateral\", negative = \"medial\" }}"
        ),
    ) + extra
}

#[test]
fn every_csv_column_has_a_unit_and_the_summary_has_the_sides() {
    let out = tmp("hertz");
    let sc = parse(&hertz_split("")).unwrap();
    let report = run(&sc, Some(&out), &mut |_| {}).unwrap();
    let csv = std::fs::read_to_string(out.join(&report.summary.files.csv)).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for col in &header {
        let (name, unit) = col.split_once(" [").unwrap_or_else(|| panic!("column `{col}` has no unit"));
        assert!(!name.is_empty() && unit.ends_with(']') && unit.len() > 1, "column `{col}`");
    }
    // 2D: forces per unit thickness, pressures in MPa; the sides' columns follow the pair's
    for expected in [
        "step [-]",
        "time [s]",
        "step_s [s]",
        "strain_energy [N*mm/mm]",
        "cylinder-flat_normal_force [N/mm]",
        "cylinder-flat_contact_area [mm^2/mm]",
        "cylinder-flat_peak_pressure [MPa]",
        "cylinder-flat_moment_z [N*mm/mm]",
        "cylinder-flat_centre_of_pressure_x [mm]",
        "cylinder-flat_lateral_normal_force [N/mm]",
        "cylinder-flat_medial_mean_pressure [MPa]",
    ] {
        assert!(header.contains(&expected), "no column `{expected}` in {header:?}");
    }
    let row: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(row.len(), header.len());
    let cell = |name: &str| -> f64 {
        row[header.iter().position(|c| c.starts_with(&format!("{name} ["))).unwrap()].parse().unwrap()
    };
    let total = cell("cylinder-flat_normal_force");
    let (lat, med) = (cell("cylinder-flat_lateral_normal_force"), cell("cylinder-flat_medial_normal_force"));
    assert!(total > 0.0 && (lat + med - total).abs() < 1e-12 * total, "{lat} + {med} vs {total}");
    // summary.json: the units, and the sides per pair per step
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let units = &json["units"];
    assert_eq!(units["length"], "mm");
    assert_eq!(units["force"], "N/mm");
    assert_eq!(units["pressure"], "MPa");
    let pair = &json["steps"][0]["pairs"][0];
    let sides = pair["sides"].as_array().unwrap();
    assert_eq!(sides.len(), 2);
    assert_eq!(sides[0]["name"], "lateral");
    assert_eq!(sides[1]["name"], "medial");
    let cop = sides[0]["centre_of_pressure"][0].as_f64().unwrap();
    assert!(cop > 0.0, "the lateral side's centre of pressure lies at x > 0: {cop}");
    // labels from [units]
    let out = tmp("hertz-m");
    let sc = parse(&hertz_split("\n[units]\nlength = \"m\"\nforce = \"N\"\ncheck = false\n")).unwrap();
    let report = run(&sc, Some(&out), &mut |_| {}).unwrap();
    let csv = std::fs::read_to_string(out.join(&report.summary.files.csv)).unwrap();
    assert!(csv.lines().next().unwrap().contains("cylinder-flat_peak_pressure [Pa]"), "{csv}");
}

#[test]
fn split_keys_are_checked() {
    let bad = hertz_split("").replace("normal = [1.0, 0.0], positive", "normal = [0.0, 0.0], positive");
    let e = check(&parse(&bad).unwrap()).unwrap_err();
    assert!(e.key.contains("split") && e.to_string().contains("normal is zero"), "{e}");
    let bad = hertz_split("")
        .replace("point = [0.0, 0.0], normal = [1.0, 0.0]", "point = [0.0], normal = [1.0, 0.0]");
    let e = check(&parse(&bad).unwrap()).unwrap_err();
    assert!(e.key.contains("split.point"), "{e}");
    let bad = hertz_split("").replace("negative = \"medial\"", "negative = \"lateral\"");
    assert!(check(&parse(&bad).unwrap()).is_err());
}

/// A tibial-insert-sized block of 1000 MPa loaded by 2000 N on its top (50 × 50 mm): fine in
/// millimetres, a unit mistake with the mesh in metres (0.05 m).
fn insert(size: f64, extra: &str) -> String {
    let p = 2000.0 / (size * size);
    format!(
        r#"
dimension = 3

[[body]]
name = "insert"
mesh = {{ generator = "box", lo = [0.0, 0.0, 0.0], hi = [{size}, {size}, {size}], cells = [2, 2, 2] }}
material = {{ type = "isotropic", E = 1000.0, nu = 0.45 }}

[[boundary]]
body = "insert"
part = "bottom"
kind = "clamped"

[[boundary]]
body = "insert"
part = "top"
kind = "pressure"
value = {p}

[analysis]
type = "static"
{extra}
"#
    )
}

#[test]
fn a_mesh_in_metres_with_newtons_and_megapascals_is_refused() {
    let info = check(&parse(&insert(50.0, "")).unwrap()).unwrap();
    assert!(info.warnings.is_empty(), "{:?}", info.warnings);
    let e = check(&parse(&insert(0.05, "")).unwrap()).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("strain body `insert`") && msg.contains("metres") && msg.contains("check = false"),
        "{msg}"
    );
    assert_eq!(e.key, "analysis", "{e}");
    // the run refuses it too, before writing anything
    let out = tmp("metres");
    let sc = parse(&insert(0.05, "")).unwrap();
    assert!(run(&sc, Some(&out), &mut |_| {}).is_err());
    // with [units]: the error points there; `check = false` lets it through (with a warning)
    let e = check(&parse(&insert(0.05, "[units]\nlength = \"mm\"\n")).unwrap()).unwrap_err();
    assert_eq!(e.key, "units", "{e}");
    let info = check(&parse(&insert(0.05, "[units]\ncheck = false\n")).unwrap()).unwrap();
    assert!(info.warnings.iter().any(|w| w.contains("check the units")), "{:?}", info.warnings);
    // prescribed displacements larger than the body
    let text = insert(50.0, "")
        .replace("kind = \"pressure\"\nvalue = 0.8", "kind = \"prescribed\"\nvalue = [0.0, 0.0, -100.0]");
    assert!(text.contains("-100.0"), "{text}");
    let e = check(&parse(&text).unwrap()).unwrap_err();
    assert!(e.to_string().contains("prescribed displacements"), "{e}");
}
