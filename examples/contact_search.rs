//! # Cost of the contact search (node-to-segment / node-to-facet pairing)
//!
//! Builds the R*-tree of `synovia_contact::search::FacetSearch` over a wavy master surface of
//! `n` facets (2D: a polyline of `n` segments; 3D: a triangulated square, `n = 2 k²`
//! triangles) and projects one slave point per facet (at a small, varying offset, as the slave
//! nodes of a contact surface of the same resolution, in mesh order), with the default search radius (nearest
//! facet + one facet size) and with a fixed search distance. Prints build and query times and
//! the time per facet, which stays about constant when the search is near-linear
//! (`O(n log n)`).
//!
//! Run: `cargo run --release --example contact_search [max_facets]` (default 1 000 000).

use std::time::Instant;

use synovia::contact_ops::search::FacetSearch;
use synovia::prelude::*;

/// Deterministic pseudo-random number in [0, 1).
fn hash(i: usize) -> f64 {
    let mut x = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 53) as f64
}

fn surface(x: f64, y: f64) -> f64 {
    0.05 * (6.0 * x).sin() * (4.0 * y).cos()
}

struct Row {
    dim: usize,
    facets: usize,
    build_s: f64,
    query_s: f64,
    query_fixed_s: f64,
    found: usize,
}

fn run_2d(n: usize) -> Row {
    let h = 1.0 / n as f64;
    // master: the top of a body below, facets oriented so that the normal points up (+y)
    let pos: Vec<Point<2>> =
        (0..=n).map(|i| Point::<2>::new(i as f64 * h, surface(i as f64 * h, 0.0))).collect();
    let facets: Vec<Vec<usize>> = (0..n).map(|i| vec![i + 1, i]).collect();
    let slaves: Vec<Point<2>> = (0..n)
        .map(|i| {
            let x = (i as f64 + hash(i)) * h;
            Point::<2>::new(x, surface(x, 0.0) + h * (hash(i + n) - 0.3))
        })
        .collect();
    measure(2, &pos, &facets, &slaves, Vector::<2>::new(0.0, -1.0), 2.0 * h)
}

fn run_3d(k: usize) -> Row {
    let h = 1.0 / k as f64;
    let id = |i: usize, j: usize| i * (k + 1) + j;
    let mut pos = Vec::with_capacity((k + 1) * (k + 1));
    for i in 0..=k {
        for j in 0..=k {
            let (x, y) = (i as f64 * h, j as f64 * h);
            pos.push(Point::<3>::new(x, y, surface(x, y)));
        }
    }
    let mut facets = Vec::with_capacity(2 * k * k);
    for i in 0..k {
        for j in 0..k {
            // counter-clockwise seen from +z: outward normal +z
            facets.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            facets.push(vec![id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let n = facets.len();
    let slaves: Vec<Point<3>> = (0..n)
        .map(|s| {
            // two points per grid cell, in mesh order (as the nodes of a slave mesh)
            let (i, j) = ((s / 2) / k, (s / 2) % k);
            let (x, y) = ((i as f64 + hash(3 * s)) * h, (j as f64 + hash(3 * s + 1)) * h);
            Point::<3>::new(x, y, surface(x, y) + h * (hash(3 * s + 2) - 0.3))
        })
        .collect();
    measure(3, &pos, &facets, &slaves, Vector::<3>::new(0.0, 0.0, -1.0), 2.0 * h)
}

fn measure<const D: usize>(
    dim: usize,
    pos: &[Point<D>],
    facets: &[Vec<usize>],
    slaves: &[Point<D>],
    slave_normal: Vector<D>,
    distance: f64,
) -> Row {
    let t0 = Instant::now();
    let search = FacetSearch::new(pos, facets);
    let build_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let mut found = 0;
    for x in slaves {
        if search.project(x, Some(&slave_normal), None).is_some() {
            found += 1;
        }
    }
    let query_s = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    for x in slaves {
        std::hint::black_box(search.project(x, Some(&slave_normal), Some(distance)));
    }
    let query_fixed_s = t2.elapsed().as_secs_f64();
    Row { dim, facets: facets.len(), build_s, query_s, query_fixed_s, found }
}

fn main() {
    let max: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let mut rows = Vec::new();
    let mut n = 1000;
    while n <= max {
        rows.push(run_2d(n));
        n *= 10;
    }
    let mut n = 1000;
    while n <= max {
        let k = ((n / 2) as f64).sqrt().round() as usize;
        rows.push(run_3d(k));
        n *= 10;
    }
    println!(
        "| D | facets (= slave points) | build tree (s) | project, default radius (s) | project, fixed distance 2h (s) | µs per slave point | paired |"
    );
    println!("|---|---|---|---|---|---|---|");
    for r in &rows {
        println!(
            "| {} | {} | {:.4} | {:.4} | {:.4} | {:.2} | {:.1} % |",
            r.dim,
            r.facets,
            r.build_s,
            r.query_s,
            r.query_fixed_s,
            1e6 * (r.build_s + r.query_s) / r.facets as f64,
            100.0 * r.found as f64 / r.facets as f64
        );
    }
}
