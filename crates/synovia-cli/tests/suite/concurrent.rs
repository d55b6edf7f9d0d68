//! Scenario runs on several threads at once give the results of the run alone, bit for bit:
//! a navigation tool with worker threads, or a batch of studies in one process, must not see
//! its figures depend on the threads' timing (docs/reliability.md, "Fixed: last-bit
//! differences between two runs in one process": two METIS calls at once raced on METIS's
//! process-wide random-number state until every call held `synovia_linalg::metis_lock`;
//! without the lock this test failed in 4 of 4 runs, with it it passed 3 of 3).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use serde_json::Value;
use synovia_cli::run::run;
use synovia_cli::{Scenario, Source};

/// Scenarios of every path whose set-up or solve could depend on threads: 3D with METIS
/// (`block3d`, below, large enough for two orderings to overlap in time, and `hertz3d`),
/// friction (`cattaneo_mindlin2d`), a neo-Hookean body (`hertz2d_neo_hookean`), TFETI
/// subdomains partitioned by METIS (`hertz2d_tfeti`), a dynamic rolling contact
/// (`dynamic_roller2d`), and the knee replacement's stance (`tkr3d_stance`: an STL femur
/// queried on two threads with bounded queries, its kept far answers shared between them, and
/// a force-controlled coordinate).
const SCENARIOS: [&str; 7] = [
    "block3d",
    "hertz3d",
    "cattaneo_mindlin2d",
    "hertz2d_neo_hookean",
    "hertz2d_tfeti",
    "dynamic_roller2d",
    "tkr3d_stance",
];

/// A block of 24 × 24 × 12 cells (≈ 23 000 unknowns, METIS ordering) pressed onto a sphere.
const BLOCK3D: &str = r#"
dimension = 3

[[body]]
name = "block"
mesh = { generator = "box", lo = [0.0, 0.0, 0.0], hi = [1.0, 1.0, 0.5], cells = [24, 24, 12] }
material = { type = "isotropic", E = 100.0, nu = 0.3 }

[[boundary]]
body = "block"
part = "bottom"
kind = "clamped"

[[contact]]
name = "ball"
body = "block"
part = "top"
obstacle = { type = "sphere", center = [0.5137, 0.4871, 2.43], radius = 2.0 }

[analysis]
type = "static"
"#;

/// The scenario's file and text.
fn scenario(stem: &str) -> (PathBuf, String) {
    if stem == "block3d" {
        return (PathBuf::from("block3d.toml"), BLOCK3D.to_string());
    }
    let file =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios").join(format!("{stem}.toml"));
    let text = std::fs::read_to_string(&file).unwrap();
    (file, text)
}

/// The summary's steps and final KKT residuals without run times and file names.
fn figures(stem: &str, out: &str) -> Value {
    let (file, text) = scenario(stem);
    let scenario = Scenario::parse(Source::new(file.to_string_lossy().into_owned(), text)).unwrap();
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-cli-concurrent").join(out);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let report = run(&scenario, Some(&dir), &mut |_| {}).unwrap();
    let mut summary = serde_json::to_value(&report.summary).unwrap();
    fn strip(v: &mut Value) {
        match v {
            Value::Object(m) => {
                m.retain(|k, _| !k.ends_with("_s") && k != "vtu" && k != "files");
                m.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut summary);
    serde_json::json!({ "steps": summary["steps"], "final_kkt": summary["final_kkt"], "dofs": summary["dofs"] })
}

#[test]
fn runs_on_three_threads_at_once_equal_the_runs_alone() {
    let alone: Vec<Value> = SCENARIOS.iter().map(|s| figures(s, &format!("alone-{s}"))).collect();
    // each thread runs every scenario, starting at a different one, so that different
    // scenarios' set-ups (orderings, partitions) overlap
    let together: Vec<Vec<(usize, Value)>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..3)
            .map(|t| {
                scope.spawn(move || {
                    // then the small 3D model 20 more times: its set-up is mostly the METIS
                    // ordering, so the threads' orderings overlap often
                    (0..SCENARIOS.len() + 20)
                        .map(|i| {
                            let k = if i < SCENARIOS.len() { (i + 2 * t) % SCENARIOS.len() } else { 1 };
                            (k, figures(SCENARIOS[k], &format!("thread{t}-{i}-{}", SCENARIOS[k])))
                        })
                        .collect()
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (t, runs) in together.iter().enumerate() {
        for (k, v) in runs {
            assert!(v["steps"].as_array().is_some_and(|s| !s.is_empty()), "{}: no steps", SCENARIOS[*k]);
            // serde_json writes the shortest representation that reads back to the same
            // f64: equal values are equal bits
            assert!(
                *v == alone[*k],
                "{} on thread {t} differs from the run alone:\n{}\n{}",
                SCENARIOS[*k],
                v,
                alone[*k]
            );
        }
    }
}
