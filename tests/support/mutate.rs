//! The byte-level mutation engine shared by the fuzz targets
//! `crates/synovia-io/tests/suite/fuzz_gmsh.rs`, `crates/synovia-cli/tests/suite/fuzz_scenario.rs`,
//! `crates/synovia-scenario/tests/suite/fuzz_stl.rs` and `crates/synovia-time/tests/suite/fuzz_table.rs`
//! (included there with `#[path]`; see `docs/fuzzing.md`). Not a test target itself: cargo only
//! builds the `.rs` files directly under `tests/`.

use proptest::prelude::*;

/// Runs `f`, a panic turned into `Err` with its message (the fuzz targets' check that an
/// input gives `Ok` or a typed error, never a panic).
pub fn caught(f: impl FnOnce() -> Result<(), String>) -> Result<(), String> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(p) => Err(p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| (*s).to_string()))
            .unwrap_or_else(|| "panic".to_string())),
    }
}

/// The files of `dir` whose extension is `ext`, sorted (a seed corpus).
pub fn files_with_extension(dir: &std::path::Path, ext: &str) -> Vec<std::path::PathBuf> {
    let mut paths: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    paths.sort();
    paths
}

/// The proptest configuration of the fuzz targets: [`fuzz_cases`]`(default)` cases, failing
/// inputs printed (shrunk) rather than persisted.
pub fn fuzz_config(default: u32) -> ProptestConfig {
    ProptestConfig { cases: fuzz_cases(default), failure_persistence: None, ..ProptestConfig::default() }
}

/// Seed `seed` (modulo the number of seeds) with `mutations` applied in order ([`apply`]).
pub fn mutated_input(
    seeds: &[Vec<u8>],
    seed: usize,
    mutations: &[Mutation],
    section_start: &[u8],
) -> Vec<u8> {
    let mut input = seeds[seed % seeds.len()].clone();
    for m in mutations {
        apply(&mut input, m, seeds, section_start);
    }
    input
}

/// Number of cases: `SYNOVIA_FUZZ_CASES`, default `default`.
pub fn fuzz_cases(default: u32) -> u32 {
    std::env::var("SYNOVIA_FUZZ_CASES").ok().and_then(|s| s.trim().parse().ok()).unwrap_or(default)
}

/// Values substituted for numbers (and other values) at the token level.
pub const NASTY: &[&str] = &[
    "0", "-0.0", "-1", "1e308", "-1e308", "1e400", "1e-320", "nan", "-nan", "inf", "-inf",
    "18446744073709551616", "9223372036854775807", "-9223372036854775808", "4294967296",
    "2147483648", "999999999", "100000", "3", "1.5", "\"x\"", "[]", "[1.0]", "[[]]", "{}", "true",
    "", "-", "1e", "0x10", "9999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999",
    "1e+1e+1", "--1", "1..2", "١",
];

/// One mutation; positions and choices are taken modulo the current length.
#[derive(Debug, Clone)]
pub enum Mutation {
    /// Flip one bit.
    Flip(usize, u8),
    /// Insert bytes.
    Insert(usize, Vec<u8>),
    /// Delete a range.
    Delete(usize, usize),
    /// Replace the tail from `at` by the tail of another seed from `from`.
    Splice(usize, usize, usize),
    /// Replace the `n`-th number token by a nasty value.
    Number(usize, usize),
    /// Duplicate a range (repeated sections, keys, numbers).
    Duplicate(usize, usize),
    /// Remove the `n`-th section (from a line starting with `[` / `$` to the next one).
    RemoveSection(usize),
    /// Remove the `n`-th line.
    RemoveLine(usize),
}

pub fn mutation() -> impl Strategy<Value = Mutation> {
    let pos = any::<usize>();
    prop_oneof![
        (pos, 0u8..8).prop_map(|(p, b)| Mutation::Flip(p, b)),
        (
            pos,
            prop_oneof![
                proptest::collection::vec(any::<u8>(), 1..4),
                proptest::sample::select(vec![
                    b"0".to_vec(),
                    b"9".to_vec(),
                    b"-".to_vec(),
                    b"\n".to_vec(),
                    b" ".to_vec(),
                    b"[".to_vec(),
                    b"]".to_vec(),
                    b"=".to_vec(),
                    b"\"".to_vec(),
                    b",".to_vec(),
                    b"$".to_vec(),
                    b"e99".to_vec(),
                    b"\xff\xff\xff\xff".to_vec(),
                    b"\0\0\0\0".to_vec(),
                ]),
            ]
        )
            .prop_map(|(p, b)| Mutation::Insert(p, b)),
        (pos, 1usize..64).prop_map(|(p, n)| Mutation::Delete(p, n)),
        (any::<usize>(), pos, pos).prop_map(|(s, a, b)| Mutation::Splice(s, a, b)),
        (pos, any::<usize>()).prop_map(|(n, v)| Mutation::Number(n, v)),
        (pos, 1usize..64).prop_map(|(p, n)| Mutation::Duplicate(p, n)),
        pos.prop_map(Mutation::RemoveSection),
        pos.prop_map(Mutation::RemoveLine),
    ]
}

/// Byte ranges of number-like tokens: a digit (optionally after `-`/`+`/`.`) and the run of
/// `[0-9a-zA-Z.+-_]` around it.
pub fn number_tokens(b: &[u8]) -> Vec<(usize, usize)> {
    let tok = |c: u8| c.is_ascii_alphanumeric() || b".+-_".contains(&c);
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if tok(b[i]) && (i == 0 || !tok(b[i - 1])) {
            let mut j = i;
            while j < b.len() && tok(b[j]) {
                j += 1;
            }
            let first = b[i..j].iter().find(|c| !b"+-.".contains(c));
            if first.is_some_and(u8::is_ascii_digit) {
                out.push((i, j));
            }
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// Byte offsets of line starts.
pub fn line_starts(b: &[u8]) -> Vec<usize> {
    std::iter::once(0)
        .chain(b.iter().enumerate().filter(|(_, &c)| c == b'\n').map(|(i, _)| i + 1))
        .filter(|&i| i < b.len())
        .collect()
}

pub fn apply(input: &mut Vec<u8>, m: &Mutation, seeds: &[Vec<u8>], section_start: &[u8]) {
    let len = input.len();
    let at = |p: usize| if len == 0 { 0 } else { p % (len + 1) };
    match m {
        Mutation::Flip(p, bit) => {
            if len > 0 {
                input[p % len] ^= 1 << bit;
            }
        }
        Mutation::Insert(p, bytes) => {
            let p = at(*p);
            input.splice(p..p, bytes.iter().copied());
        }
        Mutation::Delete(p, n) => {
            let p = at(*p);
            let e = (p + n).min(len);
            input.drain(p..e);
        }
        Mutation::Splice(s, a, b) => {
            let other = &seeds[s % seeds.len()];
            let a = at(*a);
            let b = if other.is_empty() { 0 } else { b % (other.len() + 1) };
            input.truncate(a);
            input.extend_from_slice(&other[b..]);
        }
        Mutation::Number(n, v) => {
            let toks = number_tokens(input);
            if !toks.is_empty() {
                let (s, e) = toks[n % toks.len()];
                input.splice(s..e, NASTY[v % NASTY.len()].bytes());
            }
        }
        Mutation::Duplicate(p, n) => {
            let p = at(*p);
            let e = (p + n).min(len);
            let copy = input[p..e].to_vec();
            input.splice(e..e, copy);
        }
        Mutation::RemoveSection(n) => {
            let starts = line_starts(input);
            let sections: Vec<usize> =
                starts.iter().copied().filter(|&s| input[s..].starts_with(section_start)).collect();
            if !sections.is_empty() {
                let i = n % sections.len();
                let s = sections[i];
                let e = sections.get(i + 1).copied().unwrap_or(len);
                input.drain(s..e);
            }
        }
        Mutation::RemoveLine(n) => {
            let starts = line_starts(input);
            if !starts.is_empty() {
                let i = n % starts.len();
                let e = starts.get(i + 1).copied().unwrap_or(len);
                input.drain(starts[i]..e);
            }
        }
    }
}

/// A seed and 1–6 mutations of it.
pub fn mutated(n_seeds: usize) -> impl Strategy<Value = (usize, Vec<Mutation>)> {
    (0..n_seeds, proptest::collection::vec(mutation(), 1..7))
}
