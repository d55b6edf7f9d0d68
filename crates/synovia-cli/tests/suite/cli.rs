//! `synovia run` on every example scenario, and on broken scenarios.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scenarios_dir() -> PathBuf {
    workspace().join("examples/scenarios")
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-cli-tests").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn synovia(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_synovia")).args(args).output().expect("run synovia")
}

fn run(scenario: &Path, out: &Path) -> Output {
    synovia(&["run".as_ref(), scenario.as_os_str(), "--out".as_ref(), out.as_os_str()])
}

/// Number of steps the scenario's `[analysis]` asks for.
fn expected_steps(text: &str) -> usize {
    let doc: toml::Value = toml::from_str(text).unwrap();
    let a = &doc["analysis"];
    match a["type"].as_str().unwrap() {
        "static" => 1,
        "quasistatic" => match &a["times"] {
            toml::Value::Array(t) => t.len(),
            t => t["steps"].as_integer().unwrap() as usize + 1,
        },
        "dynamic" => a["steps"].as_integer().unwrap() as usize + 1,
        other => panic!("unknown analysis {other}"),
    }
}

#[test]
fn every_example_scenario_runs() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenarios_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 3, "{files:?}");
    for file in files {
        let stem = file.file_stem().unwrap().to_string_lossy().into_owned();
        let out = tmp(&format!("example-{stem}"));
        let o = run(&file, &out);
        assert!(o.status.success(), "{}: {}", file.display(), String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(&file).unwrap();
        let n = expected_steps(&text);
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
        let steps = summary["steps"].as_array().unwrap();
        assert_eq!(steps.len(), n, "{stem}");
        assert!(summary["dofs"].as_u64().unwrap() > 0);
        assert!(summary["total_s"].as_f64().unwrap() >= 0.0);
        assert_eq!(summary["name"], stem.as_str());
        let dynamic = text.contains("type = \"dynamic\"");
        let mut peak: f64 = 0.0;
        for (i, s) in steps.iter().enumerate() {
            assert_eq!(s["step"].as_u64().unwrap() as usize, i);
            assert!(s["time"].is_number() && s["iterations"].is_u64() && s["step_s"].is_number());
            let pairs = s["pairs"].as_array().unwrap();
            assert!(!pairs.is_empty(), "{stem}: step {i} has no contact pair");
            for p in pairs {
                for k in ["normal_force", "contact_area", "peak_pressure"] {
                    assert!(p[k].as_f64().unwrap() >= 0.0, "{stem} step {i}: {k}");
                }
            }
            let f = s["contact_force"].as_f64().unwrap();
            peak = peak.max(f);
            // static and quasi-static loads keep the bodies in contact at every step; a dynamic
            // impact starts and ends without contact
            if !dynamic {
                assert!(f > 0.0, "{stem}: step {i} has contact force {f}");
                assert!(pairs[0]["peak_pressure"].as_f64().unwrap() > 0.0);
            }
        }
        assert!(peak > 0.0, "{stem}: no contact at any step");
        let csv = std::fs::read_to_string(out.join(format!("{stem}.csv"))).unwrap();
        assert_eq!(csv.lines().count(), n + 1, "{stem}: CSV rows");
        assert!(csv.starts_with("step [-],time [s],iterations [-]"), "{stem}: CSV header with units");
        let pvd = out.join(format!("{stem}.pvd"));
        let series = synovia::io::read_pvd(&pvd).unwrap();
        assert_eq!(series.len(), summary["files"]["vtu"].as_u64().unwrap() as usize);
        assert!(!series.is_empty());
        for e in &series {
            assert!(e.file.exists(), "{}", e.file.display());
        }
        let last = synovia::io::read_vtu(&series[series.len() - 1].file).unwrap();
        assert_eq!(last.pieces.len(), summary["bodies"].as_array().unwrap().len());
        let names: Vec<&str> = last.pieces[0].point_data.iter().map(|f| f.name.as_str()).collect();
        assert!(names.contains(&"displacement") && names.contains(&"contact_pressure"), "{names:?}");
        // the stress and strain tensors of every body (`[output] stress`, default true)
        for piece in &last.pieces {
            for name in ["stress", "strain"] {
                let f = piece.cell_field(name).unwrap_or_else(|| panic!("{stem}: no {name}"));
                assert_eq!(f.components, 6, "{stem}: {name}");
            }
            assert_eq!(piece.cell_field("principal_stress").map(|f| f.components), Some(3), "{stem}");
        }
    }
}

/// `[output] stress = false`: the files carry the displacement and the contact state only.
#[test]
fn stress_fields_can_be_left_out() {
    let text = std::fs::read_to_string(scenarios_dir().join("hertz2d.toml")).unwrap();
    assert!(!text.contains("[output]"), "hertz2d.toml has its own [output]");
    let dir = tmp("no-stress");
    let file = dir.join("hertz2d.toml");
    std::fs::write(&file, format!("{text}\n[output]\nstress = false\n")).unwrap();
    let o = run(&file, &dir.join("out"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let series = synovia::io::read_pvd(dir.join("out").join("hertz2d.pvd")).unwrap();
    let last = synovia::io::read_vtu(&series[series.len() - 1].file).unwrap();
    for piece in &last.pieces {
        assert!(piece.cell_field("stress").is_none() && piece.point_field("von_mises_nodal").is_none());
        assert!(piece.point_field("contact_pressure").is_some());
    }
}

/// `hertz2d.toml` with `from` replaced by `to` (which must occur), written to a temp file.
fn broken(name: &str, from: &str, to: &str) -> (PathBuf, PathBuf) {
    let text = std::fs::read_to_string(scenarios_dir().join("hertz2d.toml")).unwrap();
    assert!(text.contains(from), "{from}");
    let dir = tmp(&format!("broken-{name}"));
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text.replacen(from, to, 1)).unwrap();
    (file, dir.join("out"))
}

/// Runs a broken scenario: non-zero exit, nothing on stdout, the message on stderr with the
/// key and `file:line:column`.
fn rejects(name: &str, from: &str, to: &str, key: &str, line_col: &str, words: &str) {
    let (file, out) = broken(name, from, to);
    let o = run(&file, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{name} was accepted");
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    assert!(err.contains(&format!("`{key}`")), "{name}: no key `{key}` in: {err}");
    assert!(err.contains(&format!("{name}.toml:{line_col}:")), "{name}: no position {line_col} in: {err}");
    assert!(err.contains(words), "{name}: `{words}` not in: {err}");
    assert!(!out.join("summary.json").exists());
}

#[test]
fn broken_scenarios_are_rejected_with_key_and_position() {
    // line 16 is `material = { type = "isotropic", E = 10.0, ... }`
    rejects(
        "unknown_key",
        "material = {",
        "materal = {",
        "body[0].materal",
        "16:1",
        "unknown field `materal`",
    );
    rejects("wrong_type", "E = 10.0", "E = \"ten\"", "body[0].material.E", "16:38", "invalid type");
    rejects(
        "unknown_part",
        "part = \"top\"",
        "part = \"topp\"",
        "boundary[0].part",
        "27:8",
        "no part `topp`",
    );
    rejects(
        "unknown_body",
        "body = \"cylinder\"",
        "body = \"cylindre\"",
        "boundary[0].body",
        "26:8",
        "no body",
    );
    rejects(
        "missing_value",
        "value = [0.0, -0.1]",
        "history = [[0.0, 0.0], [1.0, 1.0]]",
        "boundary[0]",
        "25:1",
        "missing `value`",
    );
    rejects(
        "history_not_increasing",
        "value = [0.0, -0.1]",
        "value = [0.0, -0.1]\nhistory = [[0.0, 0.0], [0.0, 1.0]]",
        "boundary[0].history[1]",
        "30:24",
        "increase strictly",
    );
    rejects(
        "history_short_row",
        "value = [0.0, -0.1]",
        "value = [0.0, -0.1]\nhistory = [[0.0, 0.0], [1.0]]",
        "boundary[0].history[1]",
        "30:24",
        "[t, v]",
    );
    rejects(
        "history_string",
        "value = [0.0, -0.1]",
        "value = [0.0, -0.1]\nhistory = \"ramp\"",
        "boundary[0].history",
        "30:11",
        "invalid type",
    );
    rejects(
        "history_bad_period",
        "value = [0.0, -0.1]",
        "value = [0.0, -0.1]\nhistory = { table = [[0.0, 0.0], [1.0, 1.0]], period = -1.0 }",
        "boundary[0].history.period",
        "30:56",
        "> 0",
    );
    rejects(
        "vector_length",
        "value = [0.0, -0.1]",
        "value = [0.0, -0.1, 0.0]",
        "boundary[0].value",
        "29:9",
        "2D vector",
    );
    rejects(
        "bad_solver",
        "name = \"pdas\"",
        "name = \"newton\"",
        "solver.name",
        "38:8",
        "unknown contact solver",
    );
    rejects("syntax", "dimension = 2", "dimension = 2\nfoo = [1, 2", "foo[2]", "12:1", "comma");
    rejects(
        "no_analysis",
        "[analysis]\ntype = \"static\"",
        "",
        "analysis",
        "1:1",
        "missing field `analysis`",
    );
}

#[test]
fn gmsh_part_of_kind_prescribed_needs_data() {
    // `prescribed_top` is of kind Prescribed by the Gmsh naming convention: without a
    // `[[boundary]]` for it the model is incomplete
    let dir = tmp("gmsh-prescribed");
    let msh = std::fs::read_to_string(scenarios_dir().join("block2d.msh")).unwrap();
    std::fs::write(dir.join("block2d.msh"), msh.replace("\"top\"", "\"prescribed_top\"")).unwrap();
    let text = std::fs::read_to_string(scenarios_dir().join("gmsh_block2d.toml")).unwrap();
    let file = dir.join("gmsh_prescribed.toml");
    let cut = text.find("[[boundary]]").unwrap();
    let end = text.find("[[contact]]").unwrap();
    std::fs::write(&file, format!("{}{}", &text[..cut], &text[end..])).unwrap();
    let o = run(&file, &dir.join("out"));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("`body[0].mesh`") && err.contains("prescribed_top"), "{err}");
    assert!(err.contains("missing boundary data"), "{err}");
    // a missing group and a missing file name the `gmsh` key
    std::fs::write(
        &file,
        text.replace("{ gmsh = \"block2d.msh\" }", "{ gmsh = \"block2d.msh\", group = \"femur\" }"),
    )
    .unwrap();
    let o = run(&file, &dir.join("out"));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("`body[0].mesh.group`") && err.contains("femur"), "{err}");
    std::fs::write(&file, text.replace("block2d.msh", "nothere.msh")).unwrap();
    let o = run(&file, &dir.join("out"));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("`body[0].mesh.gmsh`") && err.contains("nothere.msh"),
        "{err}"
    );
}

#[test]
fn check_builds_without_solving_and_missing_files_fail() {
    let o = synovia(&["check".as_ref(), scenarios_dir().join("cattaneo_mindlin2d.toml").as_os_str()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("body upper") && text.contains("contact pair upper-lower"), "{text}");
    let o = synovia(&["run".as_ref(), "no/such/scenario.toml".as_ref()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read"));
}

/// `hertz3d_force.toml`: the rigid plate's force control balances the contact resultant to
/// 1e-9, and Hertz's `a` (from the contact area) and `p₀` (the peak pressure) come out within
/// 3 % for two elastic bodies.
#[test]
fn force_controlled_hertz_matches_hertz() {
    let out = tmp("hertz3d-force");
    let o = run(&scenarios_dir().join("hertz3d_force.toml"), &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let step = &summary["steps"][0];
    let pair = &step["pairs"][0];
    let plate = &step["rigid_bodies"][0];
    let load = 2.0;
    let fz = pair["force"][2].as_f64().unwrap();
    // the contact force on the sphere pushes it up with the plate's load
    assert!((fz - load).abs() <= 1e-9 * load, "resultant {fz}");
    assert!(plate["balance_error"].as_f64().unwrap() <= 1e-9);
    assert!((plate["reaction"][2].as_f64().unwrap() - load).abs() <= 1e-9 * load);
    assert!(plate["dofs"][2].as_f64().unwrap() < 0.0, "the plate moved down");
    // Hertz, two elastic bodies (E = 10 and 10 000 MPa, ν = 0.3, R = 10 mm)
    let (e1, e2, nu, r) = (10.0_f64, 1.0e4_f64, 0.3_f64, 10.0_f64);
    let e_star = 1.0 / ((1.0 - nu * nu) / e1 + (1.0 - nu * nu) / e2);
    let a = (3.0 * load * r / (4.0 * e_star)).cbrt();
    let p0 = 3.0 * load / (2.0 * std::f64::consts::PI * a * a);
    let a_fe = (pair["contact_area"].as_f64().unwrap() / std::f64::consts::PI).sqrt();
    let p0_fe = pair["peak_pressure"].as_f64().unwrap();
    assert!((a_fe / a - 1.0).abs() < 0.03, "a = {a_fe} vs Hertz {a}");
    assert!((p0_fe / p0 - 1.0).abs() < 0.03, "p0 = {p0_fe} vs Hertz {p0}");
}

/// `tkr3d_stance.toml`: an STL rigid body posed from a kinematics table, force-controlled,
/// split medial/lateral; the axial force is balanced at every pose.
#[test]
fn knee_replacement_scenario_balances_the_axial_force() {
    let out = tmp("tkr3d-stance");
    let o = run(&scenarios_dir().join("tkr3d_stance.toml"), &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    for step in summary["steps"].as_array().unwrap() {
        let femur = &step["rigid_bodies"][0];
        let applied = femur["applied"][1].as_f64().unwrap();
        assert!(applied < -100.0, "the ISO axial force pushes the femur down: {applied}");
        assert!(femur["balance_error"].as_f64().unwrap() <= 1e-9);
        assert!((femur["reaction"][1].as_f64().unwrap() + applied).abs() <= 1e-6 * applied.abs());
        let pair = &step["pairs"][0];
        let sides = pair["sides"].as_array().unwrap();
        assert_eq!(sides.len(), 2);
        let sum: f64 = sides.iter().map(|s| s["normal_force"].as_f64().unwrap()).sum();
        assert!((sum - pair["normal_force"].as_f64().unwrap()).abs() <= 1e-9 * sum.max(1.0));
        assert!(step["kkt"].as_f64().unwrap() <= 1e-8);
    }
}
