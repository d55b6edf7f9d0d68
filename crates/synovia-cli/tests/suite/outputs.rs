//! The output folder of `synovia run` never mixes runs: re-runs replace the files of earlier
//! runs, an interrupted run leaves a consistent folder (`"interrupted": true`), and a folder
//! with files synovia did not write is refused without `--force` (and those files are kept).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-cli-outputs").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `cattaneo_mindlin2d.toml` with `steps` quasi-static steps (`steps + 1` records), written as
/// `dir/mix.toml` (scenario name `mix`).
fn scenario(dir: &Path, steps: usize) -> PathBuf {
    let text =
        std::fs::read_to_string(workspace().join("examples/scenarios/cattaneo_mindlin2d.toml")).unwrap();
    let from = "times = { start = 0.0, end = 1.0, steps = 10 }";
    assert!(text.contains(from));
    let file = dir.join("mix.toml");
    std::fs::write(
        &file,
        text.replace(from, &format!("times = {{ start = 0.0, end = 1.0, steps = {steps} }}")),
    )
    .unwrap();
    file
}

fn run(file: &Path, out: &Path, extra: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_synovia"));
    cmd.arg("run").arg(file).arg("--out").arg(out).arg("--quiet").args(extra);
    cmd.env_remove("SYNOVIA_STOP_AFTER_STEPS");
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("run synovia")
}

fn listing(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let n = e.file_name().to_string_lossy().into_owned();
            if e.file_type().unwrap().is_dir() {
                format!("{n}/")
            } else {
                n
            }
        })
        .collect()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Checks that `out` holds exactly the manifest's files (plus `foreign`), with the sizes it
/// gives, that the PVD lists exactly the `.vtu` files present, and that summary, CSV and PVD
/// agree on the steps. Returns (manifest, summary).
fn consistent(out: &Path, foreign: &[&str]) -> (serde_json::Value, serde_json::Value) {
    let manifest = json(&out.join("manifest.json"));
    let files = manifest["files"].as_array().unwrap();
    let mut expected: BTreeSet<String> =
        files.iter().map(|f| f["file"].as_str().unwrap().to_string()).collect();
    assert_eq!(expected.len(), files.len(), "duplicate manifest entries: {manifest}");
    for f in files {
        let len = std::fs::metadata(out.join(f["file"].as_str().unwrap())).unwrap().len();
        assert_eq!(f["bytes"].as_u64().unwrap(), len, "{}", f["file"]);
    }
    expected.insert("manifest.json".into());
    expected.extend(foreign.iter().map(|s| s.to_string()));
    assert_eq!(listing(out), expected, "directory listing vs manifest");
    assert!(
        expected.contains("summary.json") && expected.contains("mix.csv") && expected.contains("mix.pvd")
    );

    let summary = json(&out.join("summary.json"));
    let steps = summary["steps"].as_array().unwrap();
    // the PVD references exactly the .vtu files present, in step order
    let series = synovia::io::read_pvd(out.join("mix.pvd")).unwrap();
    let in_pvd: Vec<String> =
        series.iter().map(|e| e.file.file_name().unwrap().to_string_lossy().into_owned()).collect();
    let on_disk: Vec<String> = listing(out).into_iter().filter(|f| f.ends_with(".vtu")).collect();
    assert_eq!(in_pvd, on_disk, "PVD vs .vtu files");
    let in_summary: Vec<String> =
        steps.iter().filter_map(|s| s["vtu"].as_str().map(str::to_string)).collect();
    assert_eq!(in_summary, on_disk, "summary vs .vtu files");
    assert_eq!(summary["files"]["vtu"].as_u64().unwrap() as usize, on_disk.len());
    for e in &series {
        assert!(e.file.exists(), "{}", e.file.display());
    }
    let csv = std::fs::read_to_string(out.join("mix.csv")).unwrap();
    assert_eq!(csv.lines().count(), steps.len() + 1, "CSV rows");
    for (i, s) in steps.iter().enumerate() {
        assert_eq!(s["step"].as_u64().unwrap() as usize, i);
    }
    (manifest, summary)
}

#[test]
fn a_shorter_rerun_leaves_only_its_own_files() {
    let dir = tmp("rerun");
    let out = dir.join("out");
    let o = run(&scenario(&dir, 4), &out, &[], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (m, s) = consistent(&out, &[]);
    assert_eq!(m["status"], "complete");
    assert_eq!(s["steps"].as_array().unwrap().len(), 5);
    assert_eq!(s["interrupted"], false);
    assert_eq!(listing(&out).iter().filter(|f| f.ends_with(".vtu")).count(), 5);

    // 2 records into the same folder: the 5-step files are gone
    let o = run(&scenario(&dir, 1), &out, &[], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (m, s) = consistent(&out, &[]);
    assert_eq!(m["status"], "complete");
    assert_eq!(s["steps"].as_array().unwrap().len(), 2);
    assert_eq!(s["steps_planned"], 2);
    let vtus: Vec<String> = listing(&out).into_iter().filter(|f| f.ends_with(".vtu")).collect();
    assert_eq!(vtus, ["mix_0000.vtu", "mix_0001.vtu"]);

    // outputs of the scenario's name that no manifest explains (an older synovia, a crash)
    // are stale too
    std::fs::remove_file(out.join("manifest.json")).unwrap();
    std::fs::write(out.join("mix_0007.vtu"), "old").unwrap();
    std::fs::write(out.join("mix.csv.tmp"), "half").unwrap();
    let o = run(&scenario(&dir, 1), &out, &[], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    consistent(&out, &[]);
}

#[test]
fn an_interrupted_run_leaves_a_consistent_folder() {
    let dir = tmp("interrupted");
    let out = dir.join("out");
    // older, longer results in the folder
    let o = run(&scenario(&dir, 6), &out, &[], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    consistent(&out, &[]);
    // SYNOVIA_STOP_AFTER_STEPS raises the interrupt flag (as Ctrl-C does) after 2 steps
    let o = run(&scenario(&dir, 10), &out, &[], &[("SYNOVIA_STOP_AFTER_STEPS", "2")]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted after 2 of 11 steps"), "{err}");
    let (m, s) = consistent(&out, &[]);
    assert_eq!(m["status"], "interrupted");
    assert_eq!(s["interrupted"], true);
    assert_eq!(s["steps_planned"], 11);
    let steps = s["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 2);
    assert!((steps[1]["time"].as_f64().unwrap() - 0.1).abs() < 1e-12, "{}", steps[1]["time"]);
    assert!(s["dofs"].as_u64().unwrap() > 0 && s["contact_nodes"].as_u64().unwrap() > 0);
    assert_eq!(s["solver"], "pdas");
    let vtus: Vec<String> = listing(&out).into_iter().filter(|f| f.ends_with(".vtu")).collect();
    assert_eq!(vtus, ["mix_0000.vtu", "mix_0001.vtu"]);
}

#[cfg(unix)]
#[test]
fn sigint_stops_after_the_current_step() {
    let dir = tmp("sigint");
    let out = dir.join("out");
    let file = scenario(&dir, 200);
    let mut child = Command::new(env!("CARGO_BIN_EXE_synovia"))
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .env_remove("SYNOVIA_STOP_AFTER_STEPS")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // wait for the first step's file (no timing assertion: at most ~10 min of polling)
    let mut seen = false;
    for _ in 0..60_000 {
        if out.join("mix_0000.vtu").exists() || child.try_wait().unwrap().is_some() {
            seen = out.join("mix_0000.vtu").exists();
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(seen, "the first step was never written");
    let kill = Command::new("kill").arg("-INT").arg(child.id().to_string()).status().unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    let (m, s) = consistent(&out, &[]);
    match o.status.code() {
        // the usual case: stopped after the step in progress
        Some(130) => {
            assert_eq!(m["status"], "interrupted", "{err}");
            assert_eq!(s["interrupted"], true);
            assert!(s["steps"].as_array().unwrap().len() < 201);
        }
        // the run had already finished all its steps when the signal came
        Some(0) => assert_eq!(s["steps"].as_array().unwrap().len(), 201),
        c => panic!("exit {c:?}: {err}"),
    }
}

#[test]
fn foreign_files_refuse_the_run_unless_forced_and_are_kept() {
    let dir = tmp("foreign");
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("keep")).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let file = scenario(&dir, 1);
    let o = run(&file, &out, &[], &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("notes.txt") && err.contains("keep/") && err.contains("--force"), "{err}");
    assert_eq!(err.matches("error:").count(), 1, "{err}");
    assert_eq!(listing(&out), BTreeSet::from(["keep/".to_string(), "notes.txt".to_string()]));

    let o = run(&file, &out, &["--force"], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    consistent(&out, &["keep/", "notes.txt"]);
    assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
    // a re-run still needs --force (the foreign files are there) and replaces only its own
    let o = run(&file, &out, &[], &[]);
    assert_eq!(o.status.code(), Some(2));
    consistent(&out, &["keep/", "notes.txt"]);
    let o = run(&scenario(&dir, 2), &out, &["--force"], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (_, s) = consistent(&out, &["keep/", "notes.txt"]);
    assert_eq!(s["steps"].as_array().unwrap().len(), 3);
    assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
}

#[test]
fn library_interrupt_flag_and_refusal() {
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;
    use synovia_cli::run::{run_with_options, RunError, RunOptions};
    let dir = tmp("library");
    let out = dir.join("out");
    let sc = synovia_cli::Scenario::from_file(scenario(&dir, 3)).unwrap();
    // a flag raised before the run stops it after its first step
    let options =
        RunOptions { force: false, interrupt: Some(Arc::new(AtomicBool::new(true))), ..Default::default() };
    let mut seen = Vec::new();
    let report = run_with_options(&sc, Some(&out), &options, &mut |p| seen.push(p)).unwrap();
    assert!(report.summary.interrupted);
    assert_eq!((report.summary.steps.len(), report.summary.steps_planned), (1, 4));
    assert_eq!(seen.len(), 2, "{seen:?}");
    let (m, _) = consistent(&out, &[]);
    assert_eq!(m["status"], "interrupted");
    // a foreign file: refused (not a solve failure), accepted with force
    std::fs::write(out.join("report.pdf"), "x").unwrap();
    let err = run_with_options(&sc, Some(&out), &RunOptions::default(), &mut |_| {}).unwrap_err();
    assert!(matches!(&err, RunError::Refused(m) if m.contains("report.pdf")), "{err}");
    let forced = RunOptions { force: true, interrupt: None, ..Default::default() };
    let report = run_with_options(&sc, Some(&out), &forced, &mut |_| {}).unwrap();
    assert!(!report.summary.interrupted && report.summary.steps.len() == 4);
    consistent(&out, &["report.pdf"]);
}
