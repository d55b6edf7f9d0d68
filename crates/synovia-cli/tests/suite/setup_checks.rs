//! Issue 15, round two: `synovia check` runs every check `run` does before solving (memory
//! estimate, coincident nodes, initial penetration, conflicting pairs, non-matching ties), with
//! the same messages; logs (`-q`, `-v`); messages printed once, without Rust internals.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("synovia-setup-tests").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn synovia(args: &[&std::ffi::OsStr], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_synovia"));
    cmd.args(args).env_remove("SYNOVIA_MEMORY_LIMIT_MB");
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("run synovia")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Writes `scenario` to `dir/name.toml`; runs `check` and `run` on it.
fn check_and_run(dir: &Path, name: &str, scenario: &str, env: &[(&str, &str)]) -> (Output, Output) {
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, scenario).unwrap();
    let out = dir.join(format!("out-{name}"));
    let check = synovia(&["check".as_ref(), file.as_os_str()], env);
    let run = synovia(&["run".as_ref(), file.as_os_str(), "--out".as_ref(), out.as_os_str()], env);
    (check, run)
}

/// Both fail, each prints `needle` exactly once on stderr, and the message lines agree.
fn both_refuse(check: &Output, run: &Output, needle: &str) -> String {
    let (ce, re) = (text(&check.stderr), text(&run.stderr));
    assert!(!check.status.success(), "check accepted it: {}", text(&check.stdout));
    assert!(!run.status.success(), "run accepted it: {}", text(&run.stdout));
    assert_eq!(ce.matches(needle).count(), 1, "check: {ce}");
    assert_eq!(re.matches(needle).count(), 1, "run: {re}");
    let line = |s: &str| s.lines().find(|l| l.contains(needle)).unwrap().to_string();
    assert_eq!(line(&ce), line(&re), "check and run give different messages");
    for bad in ["Vec(", "Some(", "[\"", "Point {"] {
        assert!(!ce.contains(bad), "Rust internals in: {ce}");
    }
    ce
}

const BLOCK: &str = r#"
dimension = 2
[[body]]
name = "block"
mesh = { generator = "rectangle", x = [0.0, 1.0], y = [0.0, 1.0], cells = [4, 4] }
material = { type = "isotropic", E = 1.0, nu = 0.3 }

[[boundary]]
body = "block"
part = "top"
kind = "prescribed"
value = [0.0, -0.01]

[[contact]]
name = "floor"
body = "block"
part = "bottom"
obstacle = { type = "plane", point = [0.0, FLOOR], normal = [0.0, 1.0] }
"#;

fn block(floor: f64, extra: &str) -> String {
    format!("{}{extra}\n[analysis]\ntype = \"static\"\n", BLOCK.replace("FLOOR", &format!("{floor:?}")))
}

#[test]
fn the_memory_estimate_refuses_a_factorisation_that_does_not_fit() {
    let dir = tmp("memory");
    // a limit from the scenario
    let (c, r) = check_and_run(&dir, "limit", &block(0.0, "[solver]\nmemory_limit_mb = 0.001\n"), &[]);
    let e = both_refuse(&c, &r, "the factorisation needs ≈");
    assert!(
        e.contains("2 KiB allowed by the memory limit") && e.contains("reduce the mesh size (40 DOFs now)"),
        "{e}"
    );
    assert_eq!(r.status.code(), Some(1));
    // from the environment
    let (c, r) = check_and_run(&dir, "env", &block(0.0, ""), &[("SYNOVIA_MEMORY_LIMIT_MB", "0.001")]);
    let e = both_refuse(&c, &r, "the factorisation needs ≈");
    assert!(e.contains("allowed by SYNOVIA_MEMORY_LIMIT_MB=0.001"), "{e}");
    // the same model fits without the limit, and check reports the estimate
    let (c, r) = check_and_run(&dir, "fits", &block(0.0, ""), &[]);
    assert!(c.status.success() && r.status.success(), "{}", text(&r.stderr));
    let out = text(&c.stdout);
    assert!(
        out.contains("40 dofs")
            && out.contains("factorisation: ≈")
            && out.contains("contact pair floor: 5 contact candidates"),
        "{out}"
    );
}

#[test]
fn the_linalg_memory_check_is_typed() {
    use synovia::linalg::{CholeskySolver, LinalgError, Ordering, SymmetricMatrix};
    let mut a = SymmetricMatrix::from_columns(3, vec![vec![0, 1], vec![1], vec![2]]).unwrap();
    a.add(0, 0, 4.0).unwrap();
    a.add(1, 1, 4.0).unwrap();
    a.add(2, 2, 4.0).unwrap();
    a.add(1, 0, 1.0).unwrap();
    let mut c = CholeskySolver::analyse(&a, &Ordering::Amd).unwrap();
    let est = c.memory_estimate();
    assert_eq!(est.factor_entries, c.info().factor_nnz);
    assert!(est.total_bytes() >= 8 * est.factor_entries as u64);
    c.set_memory_limit(Some(1));
    match c.factorize(&a) {
        Err(LinalgError::OutOfMemory { dofs: 3, .. }) => {}
        other => panic!("{other:?}"),
    }
    c.set_memory_limit(Some(1 << 30));
    c.factorize(&a).unwrap();
}

/// The example Gmsh block with node 80 written twice: one element uses the copy (tag 154).
fn block_msh_with_duplicate() -> String {
    let src = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/block2d.msh"),
    )
    .unwrap();
    let mut out = Vec::new();
    let mut section = "";
    let mut replaced = false;
    for line in src.lines() {
        match line {
            "$Nodes" | "$Elements" => section = line,
            "$EndNodes" => {
                out.push("154 13.75 5 0".to_string());
                section = "";
            }
            _ => {}
        }
        if section == "$Nodes" && line == "153" {
            out.push("154".into());
            continue;
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        if section == "$Elements" && !replaced && f.len() == 8 && f[1] == "2" && f[5..].contains(&"80") {
            let nodes: Vec<&str> = f[5..].iter().map(|&n| if n == "80" { "154" } else { n }).collect();
            out.push(format!("{} {}", f[..5].join(" "), nodes.join(" ")));
            replaced = true;
            continue;
        }
        out.push(line.to_string());
    }
    assert!(replaced);
    out.join("\n") + "\n"
}

#[test]
fn a_duplicated_gmsh_node_is_an_error_naming_the_nodes() {
    let dir = tmp("duplicate");
    std::fs::write(dir.join("dup.msh"), block_msh_with_duplicate()).unwrap();
    let scenario = r#"
dimension = 2
[[body]]
name = "block"
mesh = { gmsh = "dup.msh" }
material = { type = "isotropic", E = 5.0, nu = 0.4 }
[[boundary]]
body = "block"
part = "top"
kind = "prescribed"
value = [0.0, -0.05]
[[contact]]
name = "floor"
body = "block"
part = "bottom"
obstacle = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }
[analysis]
type = "static"
"#;
    let (c, r) = check_and_run(&dir, "dup", scenario, &[]);
    let e = both_refuse(&c, &r, "coincident nodes not shared by elements");
    assert!(e.contains("1 pair(s)") && e.contains("Gmsh nodes 80 and 154 at (13.750000, 5.000000)"), "{e}");
    assert!(e.contains("Coherence"), "{e}");
    assert_eq!(c.status.code(), Some(2));
    assert_eq!(r.status.code(), Some(2));
}

#[test]
fn initial_penetration_is_reported_and_refused_on_request() {
    let dir = tmp("penetration");
    // the floor 0.01 above the block's bottom: its 5 bottom nodes start inside
    let (c, r) = check_and_run(&dir, "warn", &block(0.01, ""), &[]);
    assert!(c.status.success() && r.status.success(), "{}", text(&r.stderr));
    let needle = "initial penetration in contact pair `floor`: 5 contact node(s) start inside their partner, up to 1.0000e-2 deep";
    assert_eq!(text(&c.stderr).matches(needle).count(), 1, "{}", text(&c.stderr));
    assert_eq!(text(&r.stderr).matches(needle).count(), 1, "{}", text(&r.stderr));
    let summary = std::fs::read_to_string(dir.join("out-warn/summary.json")).unwrap();
    assert!(summary.contains(needle), "{summary}");
    // touching exactly is not a penetration
    let (c, _) = check_and_run(&dir, "touch", &block(0.0, ""), &[]);
    assert!(!text(&c.stderr).contains("initial penetration"), "{}", text(&c.stderr));
    // refused on request
    let refuse = block(0.01, "")
        .replace("normal = [0.0, 1.0] }", "normal = [0.0, 1.0] }\nrefuse_initial_penetration = true");
    let (c, r) = check_and_run(&dir, "refuse", &refuse, &[]);
    let e = both_refuse(&c, &r, needle);
    assert!(e.contains("node 0 of body `block`") || e.contains("of body `block` at ("), "{e}");
}

#[test]
fn two_pairs_on_one_part_are_refused_naming_both() {
    let dir = tmp("two-pairs");
    let extra = r#"
[[contact]]
name = "floor2"
body = "block"
part = "bottom"
obstacle = { type = "plane", point = [0.0, -0.5], normal = [0.0, 1.0] }
"#;
    let (c, r) = check_and_run(&dir, "two", &block(0.0, extra), &[]);
    let e = both_refuse(
        &c,
        &r,
        "contact pairs `floor` and `floor2` both use the boundary part `bottom` of body `block`",
    );
    assert!(e.contains("contact[1].part"), "{e}");
}

#[test]
fn a_tie_with_non_matching_nodes_is_refused_by_check_and_run() {
    let dir = tmp("tie");
    let scenario = r#"
dimension = 2
[[body]]
name = "bone"
mesh = { generator = "rectangle", x = [0.0, 1.0], y = [0.0, 1.0], cells = [4, 2] }
material = { type = "isotropic", E = 10.0, nu = 0.3 }
[[body]]
name = "cartilage"
mesh = { generator = "rectangle", x = [0.0, 1.0], y = [1.0, 1.2], cells = [5, 1] }
material = { type = "isotropic", E = 1.0, nu = 0.3 }
[[boundary]]
body = "bone"
part = "bottom"
kind = "clamped"
[[boundary]]
body = "cartilage"
part = "top"
kind = "prescribed"
value = [0.0, -0.01]
[[tie]]
body_a = "bone"
part_a = "top"
body_b = "cartilage"
part_b = "bottom"
[analysis]
type = "static"
"#;
    let (c, r) = check_and_run(&dir, "tie", scenario, &[]);
    let e = both_refuse(&c, &r, "tie 0 (bonded interface `bone:top` – `cartilage:bottom`): the nodes of the two parts do not coincide");
    // bone nodes at x = 0.25, 0.5, 0.75 vs cartilage nodes at 0.2, 0.4, 0.6, 0.8: worst 0.1
    assert!(e.contains("largest distance to the nearest node of the other part is 1.0000e-1"), "{e}");
}

#[test]
fn quiet_prints_nothing_and_verbose_logs_steps() {
    let dir = tmp("logs");
    let file = dir.join("b.toml");
    std::fs::write(&file, block(0.0, "")).unwrap();
    let q = synovia(
        &["-q".as_ref(), "run".as_ref(), file.as_os_str(), "--out".as_ref(), dir.join("q").as_os_str()],
        &[],
    );
    assert!(q.status.success());
    assert_eq!((text(&q.stdout), text(&q.stderr)), (String::new(), String::new()));
    // -q also hides warnings (initial penetration) but not errors
    let pen = dir.join("p.toml");
    std::fs::write(&pen, block(0.01, "")).unwrap();
    let q = synovia(
        &["run".as_ref(), pen.as_os_str(), "-q".as_ref(), "--out".as_ref(), dir.join("p").as_os_str()],
        &[],
    );
    assert!(q.status.success());
    assert_eq!((text(&q.stdout), text(&q.stderr)), (String::new(), String::new()));
    let q = synovia(&["-q".as_ref(), "check".as_ref(), dir.join("missing.toml").as_os_str()], &[]);
    assert_eq!(q.status.code(), Some(2));
    assert!(text(&q.stderr).starts_with("error: "), "{}", text(&q.stderr));
    // -v: one debug line per step with iterations and KKT residual
    let v = synovia(
        &["run".as_ref(), "-v".as_ref(), file.as_os_str(), "--out".as_ref(), dir.join("v").as_os_str()],
        &[],
    );
    assert!(v.status.success());
    let log = text(&v.stderr);
    let line =
        log.lines().find(|l| l.starts_with("debug: step 1 of 1 done")).unwrap_or_else(|| panic!("{log}"));
    assert!(line.contains("iterations=") && line.contains("kkt=") && line.contains("step_s="), "{line}");
    // the closing report and summary.json carry the KKT residual and the solver that ran
    assert!(text(&v.stdout).contains("KKT residual"), "{}", text(&v.stdout));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("v/summary.json")).unwrap()).unwrap();
    let kkt = s["final_kkt"].as_f64().unwrap();
    assert!(kkt < 1e-8 && kkt == s["steps"][0]["kkt"].as_f64().unwrap(), "{s}");
    assert_eq!(s["steps"][0]["solver"].as_str(), Some("pdas"), "the default pdas-fallback ran PDAS: {s}");
    assert_eq!(s["solver"].as_str(), Some("pdas-fallback"));
}

#[test]
fn a_missing_top_level_key_is_named_by_itself() {
    let dir = tmp("missing-key");
    let no_analysis = BLOCK.replace("FLOOR", "0.0");
    let (c, _) = check_and_run(&dir, "a", &no_analysis, &[]);
    let e = text(&c.stderr);
    assert!(e.contains(": `analysis`: missing field `analysis`"), "{e}");
    let no_dim = block(0.0, "").replace("dimension = 2", "");
    let (c, _) = check_and_run(&dir, "d", &no_dim, &[]);
    let e = text(&c.stderr);
    assert!(e.contains(": `dimension`: missing field `dimension`"), "{e}");
}

/// A block held only by the floor: pulled up it cannot be balanced (an error printed once);
/// unloaded its position is undetermined (flagged per step).
#[test]
fn floating_bodies_unbalanced_once_and_undetermined_flagged() {
    let dir = tmp("floating");
    let body = r#"
dimension = 2
[[body]]
name = "block"
mesh = { generator = "rectangle", x = [0.0, 1.0], y = [0.0, 1.0], cells = [4, 4] }
material = { type = "isotropic", E = 1.0, nu = 0.3 }
[[boundary]]
body = "block"
part = "top"
kind = "pressure"
value = 0.01
history = HISTORY
[[contact]]
name = "floor"
body = "block"
part = "bottom"
obstacle = { type = "plane", point = [0.0, 0.0], normal = [0.0, 1.0] }
[analysis]
type = "quasistatic"
times = [0.0, 1.0]
"#;
    // pulled away (negative pressure): unbalanced
    let file = dir.join("pull.toml");
    std::fs::write(&file, body.replace("HISTORY", "-1.0")).unwrap();
    let r = synovia(&["run".as_ref(), file.as_os_str(), "--out".as_ref(), dir.join("pull").as_os_str()], &[]);
    assert_eq!(r.status.code(), Some(1));
    let e = text(&r.stderr);
    assert_eq!(e.matches("are held only by contact").count(), 1, "{e}");
    assert!(e.contains("bodies `block` are held only by contact"), "{e}");
    assert!(e.contains("an unbalanced net force of (") && e.contains(") N"), "the force in newtons: {e}");
    assert!(!e.contains("[\""), "{e}");
    // unloaded at t = 0, loaded at t = 1
    let file = dir.join("rest.toml");
    std::fs::write(&file, body.replace("HISTORY", "[[0.0, 0.0], [1.0, 1.0]]")).unwrap();
    let r = synovia(&["run".as_ref(), file.as_os_str(), "--out".as_ref(), dir.join("rest").as_os_str()], &[]);
    assert!(r.status.success(), "{}", text(&r.stderr));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("rest/summary.json")).unwrap()).unwrap();
    assert_eq!(s["steps"][0]["position_undetermined"].as_bool(), Some(true), "{s}");
    assert_eq!(s["steps"][1]["position_undetermined"].as_bool(), Some(false), "{s}");
    let e = text(&r.stderr);
    assert!(e.contains("warning: bodies `block` are held only by contact, and at 1 step(s) no contact force acts on them"), "{e}");
}
