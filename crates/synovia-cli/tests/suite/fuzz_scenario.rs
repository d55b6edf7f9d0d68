//! Byte-level fuzzing of the scenario parser: the example scenarios in `examples/scenarios`
//! (the seed corpus), mutated by bit flips, insertions, deletions, duplications, splices of two
//! files, substitutions of numbers by huge / negative / NaN-like / mistyped values, and removal
//! of lines and `[sections]`, go through the full parse + validation + model build
//! ([`synovia_cli::run::check`], not the solve) and the error message formatting. Every input
//! must give `Ok` or a `ScenarioError`, never a panic.
//!
//! A few hundred cases by default (the CI smoke pass); more with
//! `SYNOVIA_FUZZ_CASES=100000 cargo test --release -p synovia-cli --test suite fuzz_scenario::`.
//! See `docs/fuzzing.md`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use proptest::prelude::*;
use synovia_cli::run::check;
use synovia_cli::{Scenario, Source};

#[path = "../../../../tests/support/mutate.rs"]
mod mutate;
use mutate::{caught, files_with_extension, fuzz_config, mutated, mutated_input};

/// The seed corpus: `examples/scenarios/*.toml`, with their paths (a `gmsh` mesh is resolved
/// relative to the scenario file, so the mutated text keeps its seed's path).
fn seeds() -> Vec<(PathBuf, Vec<u8>)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios");
    let out: Vec<(PathBuf, Vec<u8>)> = files_with_extension(&dir, "toml")
        .into_iter()
        .map(|p| {
            let b = std::fs::read(&p).expect("seed");
            (p, b)
        })
        .collect();
    assert!(out.len() >= 5, "seed corpus missing: {}", dir.display());
    out
}

/// Parse, validate and build; format the error. `Err(message)` on a panic.
fn exercise(path: &std::path::Path, bytes: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(bytes).into_owned();
    caught(|| {
        match Scenario::parse(Source::new(path, text)).and_then(|sc| check(&sc).map(|_| ())) {
            Ok(()) => {}
            Err(e) => {
                let _ = e.to_string();
                let _ = format!("{e:?}");
            }
        }
        Ok(())
    })
}

/// Size guards for fuzzing: the parser and validation are under test, not the mesh generators
/// at scale (with the default guards a mutation that asks for a mesh just under 2·10⁷ cells
/// builds it, and those rare builds made the run 50 inputs/s). Every seed builds under them.
fn fuzz_limits() {
    synovia_cli::build::set_limits(synovia_cli::build::Limits {
        max_cells: 5.0e5,
        max_refine_levels: 16,
        max_time_steps: 100_000,
    });
}

#[test]
fn seeds_build() {
    fuzz_limits();
    for (p, b) in seeds() {
        let sc = Scenario::from_file(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        check(&sc).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        exercise(&p, &b).unwrap();
    }
}

proptest! {
    #![proptest_config(fuzz_config(256))]

    #[test]
    fn mutated_scenarios_never_panic((seed, muts) in mutated(60)) {
        fuzz_limits();
        let seeds = seeds_cached();
        let path = &seeds[seed % seeds.len()].0;
        let corpus: Vec<Vec<u8>> = seeds.iter().map(|(_, b)| b.clone()).collect();
        let input = mutated_input(&corpus, seed, &muts, b"[");
        if let Ok(last) = std::env::var("SYNOVIA_FUZZ_LAST") {
            // The input about to run, for a case that ends the process (out of memory, abort).
            std::fs::write(last, &input).unwrap();
        }
        let r = exercise(path, &input);
        prop_assert!(r.is_ok(), "panic {:?} on input:\n{}", r, String::from_utf8_lossy(&input));
    }
}

fn seeds_cached() -> &'static [(PathBuf, Vec<u8>)] {
    static SEEDS: std::sync::OnceLock<Vec<(PathBuf, Vec<u8>)>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(seeds)
}

/// Found by this target (10⁵ run): `times = { start, end, steps = 2³² }` made the build
/// allocate 2³² + 1 time levels (34 GB) and abort. Now a size error.
#[test]
fn regression_huge_times_range_is_an_error() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/cattaneo_mindlin2d.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    for steps in ["4294967296", "18446744073709551615"] {
        let bad = text.replace("steps = 10 }", &format!("steps = {steps} }}"));
        assert_ne!(bad, text);
        let e = Scenario::parse(Source::new(&path, bad)).and_then(|sc| check(&sc).map(|_| ())).unwrap_err();
        assert!(e.to_string().contains("at most"), "{e}");
        assert_eq!(e.key, "analysis.times", "{e}");
    }
}

/// Found by this target in CI (a 256-case run killed by the OOM killer): a dynamic analysis
/// with `steps = 2³¹` made the build allocate a time level per step (7 GB and growing in
/// `check`). Now a size error, like `times`.
#[test]
fn regression_huge_dynamic_steps_is_an_error() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/dynamic_drop2d.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let current = text.lines().find(|l| l.starts_with("steps = ")).expect("the seed's `steps = …` line");
    for steps in ["2147483648", "18446744073709551615"] {
        let bad = text.replace(current, &format!("steps = {steps}"));
        assert_ne!(bad, text);
        let e = Scenario::parse(Source::new(&path, bad)).and_then(|sc| check(&sc).map(|_| ())).unwrap_err();
        assert!(e.to_string().contains("at most"), "{e}");
        assert_eq!(e.key, "analysis.steps", "{e}");
    }
}

/// Found by this target (a 60 000-case run, killed at 6 GB): `refine = { radius = 100000,
/// levels = 10 }` on the hemisphere refined every cell at every level, which the cell estimate
/// (taken from `n` alone) did not see. The refinement now stops with an error at the cell limit.
#[test]
fn regression_refinement_of_the_whole_mesh_stops_at_the_cell_limit() {
    fuzz_limits();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/hertz3d_force.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let bad = text.replace("radius = 2.5, levels = 10", "radius = 100000, levels = 10");
    assert_ne!(bad, text);
    let e = Scenario::parse(Source::new(&path, bad)).and_then(|sc| check(&sc).map(|_| ())).unwrap_err();
    assert!(e.to_string().contains("more than the limit 500000"), "{e}");
}
