//! Byte-level fuzzing of the Gmsh reader: the fixtures in `tests/data/*.msh` and
//! `examples/scenarios/block2d.msh` (the seed corpus: MSH 2.2 and 4.1, ASCII and binary),
//! mutated by bit flips, insertions, deletions, duplications, splices of two files,
//! substitutions of numbers by huge / negative / NaN-like values, and removal of lines and
//! `$Sections`, go through [`parse_msh`], `physical_groups` and `bodies::<2>()` /
//! `bodies::<3>()`. Every input must give `Ok` or an `IoError`, never a panic.
//!
//! A few hundred cases by default (the CI smoke pass); more with
//! `SYNOVIA_FUZZ_CASES=100000 cargo test --release -p synovia-io --test suite fuzz_gmsh::`.
//! See `docs/fuzzing.md`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use proptest::prelude::*;
use synovia_io::parse_msh;

#[path = "../../../../tests/support/mutate.rs"]
mod mutate;
use mutate::{caught, files_with_extension, fuzz_config, mutated, mutated_input};

/// The seed corpus: `tests/data/*.msh` and `examples/scenarios/block2d.msh`.
fn seeds() -> Vec<Vec<u8>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut paths = files_with_extension(&root.join("tests/data"), "msh");
    paths.push(root.join("../../examples/scenarios/block2d.msh"));
    assert!(paths.len() >= 5, "seed corpus missing");
    paths.iter().map(|p| std::fs::read(p).expect("seed")).collect()
}

fn seeds_cached() -> &'static [Vec<u8>] {
    static SEEDS: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(seeds)
}

/// Parse and build the bodies in 2D and 3D; format the errors. `Err(message)` on a panic.
fn exercise(bytes: &[u8]) -> Result<(), String> {
    caught(|| {
        match parse_msh(bytes) {
            Ok(m) => {
                let _ = m.physical_groups();
                for r in [m.bodies::<2>().map(|_| ()), m.bodies::<3>().map(|_| ())] {
                    if let Err(e) = r {
                        let _ = e.to_string();
                    }
                }
            }
            Err(e) => {
                let _ = e.to_string();
            }
        }
        Ok(())
    })
}

#[test]
fn seeds_parse() {
    for (i, b) in seeds_cached().iter().enumerate() {
        let m = parse_msh(b).unwrap_or_else(|e| panic!("seed {i}: {e}"));
        assert!(m.bodies::<2>().is_ok() || m.bodies::<3>().is_ok(), "seed {i}");
        exercise(b).unwrap();
    }
}

proptest! {
    #![proptest_config(fuzz_config(512))]

    #[test]
    fn mutated_msh_files_never_panic((seed, muts) in mutated(60)) {
        let input = mutated_input(seeds_cached(), seed, &muts, b"$");
        let r = exercise(&input);
        prop_assert!(r.is_ok(), "panic {:?} on input:\n{:?}", r, String::from_utf8_lossy(&input));
    }
}
