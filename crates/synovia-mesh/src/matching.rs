//! Pairing of nodes at equal positions, for bonded (tied) interfaces and node-to-node contact.
//!
//! Two bodies meshed with matching interface nodes (docs/model.md §5, the conforming case) have, on their
//! common boundary, pairs of nodes at the same position. [`match_nodes`] finds those pairs with a
//! hash grid in `O(n)` expected time.

use std::collections::HashMap;

use crate::math::{Point, Real};

/// Result of [`match_nodes`] when some nodes have no partner.
#[derive(Debug, Clone, PartialEq)]
pub struct UnmatchedNodes {
    /// Indices (into the first list) without a partner within the tolerance.
    pub first: Vec<usize>,
    /// Indices (into the second list) without a partner within the tolerance.
    pub second: Vec<usize>,
}

/// Pairs every point of `first` with the point of `second` at the same position, within the
/// absolute distance `tol`.
///
/// Returns the pairs `(i, j)` (`first[i] ≈ second[j]`) sorted by `i`, or the unmatched indices of
/// both lists. Each point is used at most once; if several candidates are within `tol`, the
/// closest is taken. `tol` must be positive and smaller than half the smallest distance between
/// distinct nodes of one list for the result to be unambiguous.
pub fn match_nodes<const D: usize>(
    first: &[Point<D>],
    second: &[Point<D>],
    tol: Real,
) -> Result<Vec<(usize, usize)>, UnmatchedNodes> {
    let cell = if tol > 0.0 && tol.is_finite() { 2.0 * tol } else { Real::MIN_POSITIVE };
    let key = |p: &Point<D>| -> [i64; 3] {
        let mut k = [0i64; 3];
        for (d, kd) in k.iter_mut().enumerate().take(D) {
            *kd = (p[d] / cell).floor() as i64;
        }
        k
    };
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::with_capacity(second.len());
    for (j, p) in second.iter().enumerate() {
        grid.entry(key(p)).or_default().push(j);
    }
    let mut used = vec![false; second.len()];
    let mut pairs = Vec::with_capacity(first.len());
    let mut unmatched_first = Vec::new();
    let offsets: Vec<[i64; 3]> = neighbour_offsets(D);
    for (i, p) in first.iter().enumerate() {
        let k = key(p);
        let mut best: Option<(usize, Real)> = None;
        for o in &offsets {
            let kk = [k[0] + o[0], k[1] + o[1], k[2] + o[2]];
            if let Some(cands) = grid.get(&kk) {
                for &j in cands {
                    if used[j] {
                        continue;
                    }
                    let dist = (second[j] - p).norm();
                    if dist <= tol && best.is_none_or(|(_, bd)| dist < bd) {
                        best = Some((j, dist));
                    }
                }
            }
        }
        match best {
            Some((j, _)) => {
                used[j] = true;
                pairs.push((i, j));
            }
            None => unmatched_first.push(i),
        }
    }
    let unmatched_second: Vec<usize> = (0..second.len()).filter(|&j| !used[j]).collect();
    if unmatched_first.is_empty() && unmatched_second.is_empty() {
        Ok(pairs)
    } else {
        Err(UnmatchedNodes { first: unmatched_first, second: unmatched_second })
    }
}

fn neighbour_offsets(d: usize) -> Vec<[i64; 3]> {
    let r = |k: usize| if k < d { -1..=1 } else { 0..=0 };
    let mut out = Vec::new();
    for a in r(0) {
        for b in r(1) {
            for c in r(2) {
                out.push([a, b, c]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_permuted_points_and_reports_strays() {
        let a: Vec<Point<2>> = (0..10).map(|i| Point::<2>::new(i as f64 * 0.1, 1.0)).collect();
        let mut b: Vec<Point<2>> = a.iter().rev().map(|p| p + Point::<2>::new(1e-9, 0.0)).collect();
        let pairs = match_nodes(&a, &b, 1e-6).expect("all match");
        for (i, j) in pairs {
            assert!((a[i] - b[j]).norm() < 1e-6);
            assert_eq!(j, 9 - i);
        }
        b[3][1] += 0.5;
        let err = match_nodes(&a, &b, 1e-6).expect_err("one stray");
        assert_eq!(err.first, vec![6]);
        assert_eq!(err.second, vec![3]);
    }
}
