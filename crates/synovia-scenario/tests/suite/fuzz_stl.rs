//! Byte-level fuzzing of STL surfaces the way a scenario's `stl` shape uses them: the seed
//! files in `tests/data/stl/` (binary and ASCII, closed and open, see the README there),
//! mutated by the engine of `tests/support/mutate.rs` (bit flips, insertions, deletions,
//! splices, numbers replaced by huge / NaN-like values, lines removed), go through
//! `synovia::io::parse_stl`, `TriangleSurface::scaled`, the three `SurfaceObstacle`
//! constructors (open, closed solid, one level of Loop subdivision), a concave fillet and
//! closest-point queries. Byte-level mutations of a binary file mostly break its length (a
//! typed error at once), so half the cases mutate the triangles of a binary seed instead,
//! keeping the file consistent ([`Structural`]: a coordinate replaced by a nasty single-precision
//! value or a random bit pattern, a corner moved onto another, a triangle flipped, removed or
//! repeated). Every input must give `Ok` or a typed error, never a panic; every
//! obstacle that is built must answer the queries with finite distances, gradients of unit
//! length and closest points (a NaN is a finding too).
//!
//! A few hundred cases by default (the CI smoke pass); more with
//! `SYNOVIA_FUZZ_CASES=100000 cargo test --release -p synovia-scenario --test suite fuzz_stl::`.
//! See `docs/fuzzing.md`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use proptest::prelude::*;
use synovia::contact_ops::operators::SignedDistance;
use synovia::contact_ops::SurfaceObstacle;
use synovia::io::parse_stl;
use synovia::mesh::{Point, TriangleSurface};

#[path = "../../../../tests/support/mutate.rs"]
mod mutate;
use mutate::{caught, files_with_extension, fuzz_config, mutated, mutated_input};
#[path = "../../../../tests/support/stl_checks.rs"]
mod stl_checks;

/// The seed corpus: `tests/data/stl/*.stl` of the workspace.
fn seeds() -> Vec<Vec<u8>> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/stl");
    let paths = files_with_extension(&dir, "stl");
    assert!(paths.len() >= 4, "seed corpus missing");
    paths.iter().map(|p| std::fs::read(p).expect("seed")).collect()
}

fn seeds_cached() -> &'static [Vec<u8>] {
    static SEEDS: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(seeds)
}

/// The shared checks, under [`caught`]: `Err(message)` on a panic or a non-finite answer.
fn exercise(bytes: &[u8]) -> Result<(), String> {
    caught(|| stl_checks::exercise_stl(bytes))
}

#[test]
fn seeds_build_obstacles() {
    for (i, b) in seeds_cached().iter().enumerate() {
        let s = synovia::io::parse_stl(b).unwrap_or_else(|e| panic!("seed {i}: {e}"));
        // every seed builds at least the open obstacle; the closed ones the solid too
        SurfaceObstacle::new(s.clone()).unwrap_or_else(|e| panic!("seed {i}: {e}"));
        if s.check_closed().is_ok() {
            SurfaceObstacle::solid(s).unwrap_or_else(|e| panic!("seed {i}: {e}"));
        }
        exercise(b).unwrap();
    }
}

/// A mutation of the triangles of a binary STL file that keeps the file well-formed.
#[derive(Debug, Clone)]
enum Structural {
    /// Coordinate `(triangle, corner, axis)` replaced by `NASTY_F32[value]`.
    Coordinate(usize, usize, usize, usize),
    /// Coordinate replaced by a random bit pattern.
    Bits(usize, usize, usize, u32),
    /// A corner moved onto another triangle's corner (degenerate or non-manifold surfaces).
    Weld(usize, usize, usize, usize),
    /// Two corners of a triangle swapped (one facet turned inside out).
    Flip(usize),
    /// A triangle removed (an open surface).
    Remove(usize),
    /// A triangle repeated (a non-manifold edge).
    Repeat(usize),
    /// Every coordinate scaled by a factor (units: millimetres read as metres and back).
    Scale(usize),
}

const NASTY_F32: &[f32] = &[
    0.0,
    -0.0,
    1.0,
    -1.0,
    1e-45,
    1e-38,
    1e-20,
    1e20,
    3.0e38,
    -3.0e38,
    f32::MAX,
    f32::MIN,
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    0.5,
    1e-7,
];
const SCALES: &[f32] = &[1e-3, 1e3, 1e-30, 1e30, 0.0, -1.0];

fn structural() -> impl Strategy<Value = Structural> {
    let i = any::<usize>();
    prop_oneof![
        (i, 0usize..3, 0usize..3, i).prop_map(|(t, c, a, v)| Structural::Coordinate(t, c, a, v)),
        (i, 0usize..3, 0usize..3, any::<u32>()).prop_map(|(t, c, a, v)| Structural::Bits(t, c, a, v)),
        (i, 0usize..3, i, 0usize..3).prop_map(|(t, c, u, d)| Structural::Weld(t, c, u, d)),
        i.prop_map(Structural::Flip),
        i.prop_map(Structural::Remove),
        i.prop_map(Structural::Repeat),
        i.prop_map(Structural::Scale),
    ]
}

/// The triangles of a binary STL file (`None` for an ASCII one) as 9 coordinates each.
fn binary_triangles(bytes: &[u8]) -> Option<Vec<[f32; 9]>> {
    if bytes.starts_with(b"solid") || bytes.len() < 84 {
        return None;
    }
    Some(
        bytes[84..]
            .chunks_exact(50)
            .map(|c| {
                std::array::from_fn(|k| {
                    f32::from_le_bytes(c[12 + 4 * k..16 + 4 * k].try_into().expect("4 bytes"))
                })
            })
            .collect(),
    )
}

/// A binary STL file of `triangles` (zero normals, as the reader ignores them).
fn binary_file(triangles: &[[f32; 9]]) -> Vec<u8> {
    let mut out = b"synovia structural fuzz".to_vec();
    out.resize(80, b' ');
    out.extend_from_slice(&u32::try_from(triangles.len()).expect("count").to_le_bytes());
    for t in triangles {
        out.extend_from_slice(&[0u8; 12]);
        t.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        out.extend_from_slice(&[0, 0]);
    }
    out
}

fn apply_structural(triangles: &mut Vec<[f32; 9]>, m: &Structural) {
    let n = triangles.len();
    if n == 0 {
        return;
    }
    match *m {
        Structural::Coordinate(t, c, a, v) => triangles[t % n][3 * c + a] = NASTY_F32[v % NASTY_F32.len()],
        Structural::Bits(t, c, a, bits) => triangles[t % n][3 * c + a] = f32::from_bits(bits),
        Structural::Weld(t, c, u, d) => {
            let from = triangles[u % n];
            triangles[t % n][3 * c..3 * c + 3].copy_from_slice(&from[3 * d..3 * d + 3]);
        }
        Structural::Flip(t) => {
            let tri = &mut triangles[t % n];
            for a in 0..3 {
                tri.swap(3 + a, 6 + a);
            }
        }
        Structural::Remove(t) => {
            triangles.remove(t % n);
        }
        Structural::Repeat(t) => {
            let tri = triangles[t % n];
            triangles.push(tri);
        }
        Structural::Scale(f) => {
            let f = SCALES[f % SCALES.len()];
            triangles.iter_mut().flatten().for_each(|v| *v *= f);
        }
    }
}

proptest! {
    #![proptest_config(fuzz_config(256))]

    #[test]
    fn mutated_stl_files_never_panic((seed, muts) in mutated(60)) {
        let input = mutated_input(seeds_cached(), seed, &muts, b"  facet");
        let r = exercise(&input);
        prop_assert!(r.is_ok(), "{:?} on input:\n{:?}", r, input);
    }

    #[test]
    fn mutated_triangles_never_panic(seed in 0usize..60, muts in proptest::collection::vec(structural(), 1..5)) {
        let seeds = seeds_cached();
        let binary: Vec<Vec<[f32; 9]>> = seeds.iter().filter_map(|s| binary_triangles(s)).collect();
        let mut triangles = binary[seed % binary.len()].clone();
        for m in &muts {
            apply_structural(&mut triangles, m);
        }
        let input = binary_file(&triangles);
        let r = exercise(&input);
        prop_assert!(r.is_ok(), "{:?} after {:?} on the triangles:\n{:?}", r, muts, triangles);
    }
}
