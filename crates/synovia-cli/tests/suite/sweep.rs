//! Parameter studies (`[sweep]`): the cases run as scheduler-array tasks in separate
//! processes (`--task-index/--tasks` and Slurm's variables), `synovia gather` merges their
//! summaries, and every gathered row equals a plain single run of the same scenario with the
//! values written into it.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-cli-tests").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("tmp dir");
    dir
}

fn synovia() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_synovia"));
    for v in ["SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN"] {
        c.env_remove(v);
    }
    c
}

fn ok(o: &Output, what: &str) {
    assert!(
        o.status.success(),
        "{what}: {}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The 2D Hertz example (coarser), with E and the pushed displacement of the top as
/// placeholders.
fn base_text(e: &str, push: &str) -> String {
    let text = std::fs::read_to_string(workspace().join("examples/scenarios/hertz2d.toml")).expect("example");
    assert!(text.contains("levels = 8") && text.contains("E = 10.0") && text.contains("value = [0.0, -0.1]"));
    text.replace("levels = 8", "levels = 4")
        .replace("E = 10.0", &format!("E = {e}"))
        .replace("value = [0.0, -0.1]", &format!("value = {push}"))
}

const SWEEP: &str = r#"
[sweep]
mode = "product"
[sweep.values]
"body[0].material.E" = [5.0, 10.0]
"boundary[0].value" = [[0.0, -0.05], [0.0, -0.1]]
"#;

/// `(E, push)` of the four cases, in case order (the last key varies fastest).
const CASES: [(&str, &str); 4] =
    [("5.0", "[0.0, -0.05]"), ("5.0", "[0.0, -0.1]"), ("10.0", "[0.0, -0.05]"), ("10.0", "[0.0, -0.1]")];

fn read_csv(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    // the fields here hold no quotes; split respecting the quoted lists
    let split = |line: &str| -> Vec<String> {
        let mut out = Vec::new();
        let mut cur = String::new();
        let mut quoted = false;
        for ch in line.chars() {
            match ch {
                '"' => quoted = !quoted,
                ',' if !quoted => out.push(std::mem::take(&mut cur)),
                c => cur.push(c),
            }
        }
        out.push(cur);
        out
    };
    let mut lines = text.lines();
    let header = split(lines.next().expect("header"));
    (header, lines.map(split).collect())
}

fn col(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

#[test]
fn sweep_tasks_as_processes_gather_into_the_single_run_results() {
    let dir = tmp("sweep-tasks");
    let scenario = dir.join("study.toml");
    std::fs::write(&scenario, base_text("10.0", "[0.0, -0.1]") + SWEEP).expect("write");
    let study = dir.join("study");
    // task 0 of 2 by the flags, task 1 of 2 by Slurm's variables (an array --array=1-2),
    // concurrently as separate processes
    let t0 = synovia()
        .args(["run".as_ref(), scenario.as_os_str(), "--out".as_ref(), study.as_os_str()])
        .args(["--task-index", "0", "--tasks", "2"])
        .spawn()
        .expect("spawn task 0");
    let t1 = synovia()
        .args(["-q".as_ref(), "run".as_ref(), scenario.as_os_str(), "--out".as_ref(), study.as_os_str()])
        .env("SLURM_ARRAY_TASK_ID", "2")
        .env("SLURM_ARRAY_TASK_MIN", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .spawn()
        .expect("spawn task 1");
    ok(&t0.wait_with_output().expect("task 0"), "task 0");
    ok(&t1.wait_with_output().expect("task 1"), "task 1");
    for c in 0..4 {
        let s: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(study.join(format!("case-{c:04}/summary.json"))).expect("summary"),
        )
        .expect("json");
        assert_eq!(s["sweep"]["case"], c);
        assert_eq!(s["sweep"]["cases"], 4);
    }
    let table = dir.join("study.csv");
    let o = synovia()
        .args(["gather".as_ref(), study.as_os_str(), "--out".as_ref(), table.as_os_str()])
        .output()
        .expect("gather");
    ok(&o, "gather");
    let (header, rows) = read_csv(&std::fs::read_to_string(&table).expect("csv"));
    assert_eq!(rows.len(), 4, "{rows:?}");
    let (ce, cp) = (col(&header, "body[0].material.E"), col(&header, "boundary[0].value"));
    let fields = [
        "dofs",
        "cylinder-flat.normal_force",
        "cylinder-flat.contact_area",
        "cylinder-flat.peak_pressure",
        "contact_force",
    ];
    let mut forces = Vec::new();
    for (c, ((e, push), row)) in CASES.iter().zip(&rows).enumerate() {
        assert_eq!(row[col(&header, "case")], c.to_string());
        assert_eq!(row[ce].parse::<f64>().expect("E"), e.parse::<f64>().expect("E"));
        assert_eq!(row[cp].replace(' ', ""), push.replace(' ', ""));
        // the reference: a plain run of the scenario with the values written in
        let single = dir.join(format!("single{c}.toml"));
        std::fs::write(&single, base_text(e, push)).expect("write");
        let out = dir.join(format!("single{c}"));
        ok(
            &synovia()
                .args(["-q".as_ref(), "run".as_ref(), single.as_os_str(), "--out".as_ref(), out.as_os_str()])
                .output()
                .expect("single run"),
            "single run",
        );
        let o = synovia().args(["gather".as_ref(), out.as_os_str()]).output().expect("gather single");
        ok(&o, "gather single");
        let (h1, r1) = read_csv(&String::from_utf8_lossy(&o.stdout));
        assert_eq!(r1.len(), 1);
        for f in fields {
            let (a, b): (f64, f64) =
                (row[col(&header, f)].parse().expect("number"), r1[0][col(&h1, f)].parse().expect("number"));
            assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-300), "case {c} {f}: sweep {a} vs single {b}");
        }
        forces.push(row[col(&header, "cylinder-flat.normal_force")].parse::<f64>().expect("force"));
    }
    // linear elasticity: twice the modulus, twice the force at the same push
    assert!(forces[0] > 0.0 && forces[1] > forces[0]);
    assert!((forces[2] / forces[0] - 2.0).abs() < 1e-9, "{forces:?}");
    assert!((forces[3] / forces[1] - 2.0).abs() < 1e-9, "{forces:?}");
}

#[test]
fn gather_refuses_missing_and_incomplete_cases_and_bad_task_arguments() {
    let dir = tmp("sweep-missing");
    let scenario = dir.join("study.toml");
    std::fs::write(&scenario, base_text("10.0", "[0.0, -0.1]") + SWEEP).expect("write");
    let study = dir.join("study");
    let run = |args: &[&str]| -> Output {
        synovia()
            .args(["-q".as_ref(), "run".as_ref(), scenario.as_os_str(), "--out".as_ref(), study.as_os_str()])
            .args(args)
            .output()
            .expect("run")
    };
    // more tasks than cases, index out of range: refused before any solve
    let o = run(&["--task-index", "0", "--tasks", "5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("5 tasks for a sweep of 4 cases"), "{o:?}");
    let o = run(&["--task-index", "3", "--tasks", "3"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("out of range"), "{o:?}");
    // task 1 of 3 runs only case 1
    ok(&run(&["--task-index", "1", "--tasks", "3"]), "task 1 of 3");
    let names: Vec<String> = std::fs::read_dir(&study)
        .expect("study")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["case-0001".to_string()]);
    let gather = |extra: &[&str]| synovia().arg("gather").arg(&study).args(extra).output().expect("gather");
    let o = gather(&[]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("3 of 4 cases missing: 0, 2, 3"), "{err}");
    let o = gather(&["--allow-missing"]);
    ok(&o, "gather --allow-missing");
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 2);
    // all cases in one process (no task flags, no Slurm variables)
    ok(&run(&[]), "all cases");
    ok(&gather(&[]), "gather all");
    // a case whose run did not finish
    let manifest = study.join("case-0002/manifest.json");
    let text = std::fs::read_to_string(&manifest).expect("manifest");
    std::fs::write(&manifest, text.replace("\"complete\"", "\"running\"")).expect("write");
    let o = gather(&[]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("case-0002") && err.contains("did not complete"), "{err}");
    // a plain scenario refuses task flags
    let plain = dir.join("plain.toml");
    std::fs::write(&plain, base_text("10.0", "[0.0, -0.1]")).expect("write");
    let o = synovia()
        .args([
            "run".as_ref(),
            plain.as_os_str(),
            "--task-index".as_ref(),
            "0".as_ref(),
            "--tasks".as_ref(),
            "1".as_ref(),
        ])
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("[sweep]"), "{o:?}");
}
