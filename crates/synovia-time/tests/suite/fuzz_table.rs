//! Byte-level fuzzing of the history tables (kinematics and load files of a scenario's
//! `[[table]]`): the seeds — the gait kinematics `.sto` of `data/tka-grand-challenge-dm/` and
//! the CSV files in `tests/data/tables/` (comma, semicolon and tab delimited) — mutated by the
//! engine of `tests/support/mutate.rs`, go through `Table::parse_storage` and
//! `Table::parse_csv`, then `require` (the six kinematics columns), `column` and `history`
//! with unit factors (metres to millimetres, percent to cycles, a reversed time), and the
//! histories are evaluated over the table's time range. Every input must give `Ok` or a
//! `TableError`, never a panic, and every history built must give finite values.
//!
//! A few hundred cases by default (the CI smoke pass); more with
//! `SYNOVIA_FUZZ_CASES=100000 cargo test --release -p synovia-time --test suite fuzz_table::`.
//! See `docs/fuzzing.md`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use proptest::prelude::*;
use synovia_time::history::LoadHistory;
use synovia_time::table::Table;

#[path = "../../../../tests/support/mutate.rs"]
mod mutate;
use mutate::{caught, files_with_extension, fuzz_config, mutated, mutated_input};
#[path = "../../../../tests/support/table_checks.rs"]
mod table_checks;

/// The seed corpus: the gait kinematics `.sto` and `tests/data/tables/*.csv`.
fn seeds() -> Vec<Vec<u8>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut paths = files_with_extension(&root.join("tests/data/tables"), "csv");
    paths.push(root.join("data/tka-grand-challenge-dm/fluoroscopic_gait_kinematics.sto"));
    assert!(paths.len() >= 4, "seed corpus missing");
    paths.iter().map(|p| std::fs::read(p).expect("seed")).collect()
}

fn seeds_cached() -> &'static [Vec<u8>] {
    static SEEDS: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(seeds)
}

/// The shared checks, under [`caught`]: `Err(message)` on a panic or a non-finite value.
fn exercise(bytes: &[u8]) -> Result<(), String> {
    caught(|| table_checks::exercise_table(bytes))
}

#[test]
fn seeds_parse() {
    for (i, b) in seeds_cached().iter().enumerate() {
        let text = String::from_utf8_lossy(b);
        let table = Table::parse_storage(&text, "seed.sto")
            .or_else(|_| Table::parse_csv(&text, "seed.csv"))
            .unwrap_or_else(|e| panic!("seed {i}: {e}"));
        assert!(table.rows() >= 3, "seed {i}");
        exercise(b).unwrap();
    }
}

proptest! {
    #![proptest_config(fuzz_config(512))]

    #[test]
    fn mutated_tables_never_panic((seed, muts) in mutated(60)) {
        let input = mutated_input(seeds_cached(), seed, &muts, b"endheader");
        let r = exercise(&input);
        prop_assert!(r.is_ok(), "{:?} on input:\n{}", r, String::from_utf8_lossy(&input));
    }
}
