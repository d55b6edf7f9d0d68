//! Coincident (unmerged) nodes of a mesh: an unmerged seam between two Gmsh surfaces or
//! volumes, or a node written twice, leaves two nodes at one position that no element shares:
//! the mesh is cut there (a crack), which silently changes the result, or makes the stiffness
//! singular.
//!
//! [`coincident_nodes`] finds them in `O(n)` expected time (a hash of the nodes' grid cells of
//! the size of the tolerance, each node compared with the nodes of its `3^D` neighbour cells).

use std::collections::HashMap;

use synovia_mesh::Mesh;

/// Relative tolerance of [`coincident_nodes`]: two nodes closer than this times the mesh's
/// smallest edge are coincident.
pub const COINCIDENT_TOLERANCE: f64 = 1e-6;

/// The coincident nodes of a mesh ([`coincident_nodes`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CoincidentNodes {
    /// Pairs `(i, j)`, `i < j`, of coincident nodes that both belong to cells: the mesh is
    /// cut there.
    pub in_cells: Vec<(usize, usize)>,
    /// Pairs `(i, j)` of coincident nodes of which at least one belongs to no cell (harmless
    /// for the solve; a [`Mesh`] built by `Mesh::new` has no such nodes, one built otherwise
    /// may).
    pub unused: Vec<(usize, usize)>,
    /// The absolute tolerance used.
    pub tolerance: f64,
}

impl CoincidentNodes {
    /// `true` if no coincident nodes were found.
    pub fn is_empty(&self) -> bool {
        self.in_cells.is_empty() && self.unused.is_empty()
    }
}

/// The pairs of nodes of `mesh` closer than [`COINCIDENT_TOLERANCE`] × its smallest edge,
/// split by whether both belong to cells. Pairs are sorted; each pair once.
pub fn coincident_nodes<const D: usize>(mesh: &Mesh<D>) -> CoincidentNodes {
    let h = mesh.min_edge_length();
    let tolerance = if h.is_finite() && h > 0.0 { COINCIDENT_TOLERANCE * h } else { 0.0 };
    let mut out = CoincidentNodes { tolerance, ..Default::default() };
    let nodes = mesh.nodes();
    if nodes.len() < 2 {
        return out;
    }
    let mut used = vec![false; nodes.len()];
    for &i in mesh.cells_flat() {
        if let Some(u) = used.get_mut(i) {
            *u = true;
        }
    }
    // grid cells of size `cell` (exact duplicates only when the tolerance is 0)
    let cell = if tolerance > 0.0 { tolerance } else { f64::MIN_POSITIVE };
    let key = |x: &synovia_mesh::math::Point<D>| -> [i64; D] {
        let mut k = [0i64; D];
        for (a, ka) in k.iter_mut().enumerate() {
            // saturating float → int conversion: far-away nodes share the extreme cells, which
            // only costs comparisons
            *ka = (x[a] / cell).floor() as i64;
        }
        k
    };
    let mut grid: HashMap<[i64; D], Vec<usize>> = HashMap::with_capacity(nodes.len());
    for (i, x) in nodes.iter().enumerate() {
        grid.entry(key(x)).or_default().push(i);
    }
    let mut pairs = Vec::new();
    let n_neighbours = 3usize.pow(D as u32);
    for (i, x) in nodes.iter().enumerate() {
        let k = key(x);
        for m in 0..n_neighbours {
            let mut nk = k;
            let mut r = m;
            for c in nk.iter_mut() {
                *c = c.saturating_add((r % 3) as i64 - 1);
                r /= 3;
            }
            if let Some(list) = grid.get(&nk) {
                for &j in list {
                    if j > i && (nodes[j] - x).norm() <= tolerance {
                        pairs.push((i, j));
                    }
                }
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    for (i, j) in pairs {
        if used[i] && used[j] {
            out.in_cells.push((i, j));
        } else {
            out.unused.push((i, j));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use synovia_mesh::math::Point;

    #[test]
    fn finds_a_seam() {
        // two triangles sharing the edge (1, 2) by position only: nodes 1 ≡ 3, 2 ≡ 4 (a mesh
        // cannot hold nodes of no cell: `Mesh::new` refuses them)
        let nodes = vec![
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(0.0, 1.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(0.0, 1.0),
            Point::<2>::new(1.0, 1.0),
        ];
        let mesh = Mesh::<2>::new(nodes, vec![0, 1, 2, 3, 5, 4]).unwrap();
        let c = coincident_nodes(&mesh);
        assert_eq!(c.in_cells, vec![(1, 3), (2, 4)]);
        assert!(c.unused.is_empty());
        // a regular grid has none
        let grid = synovia_mesh::generators::rectangle(
            0.0,
            1.0,
            0.0,
            1.0,
            20,
            20,
            synovia_mesh::generators::Grading::Uniform,
            synovia_mesh::generators::Grading::Uniform,
        )
        .unwrap();
        assert!(coincident_nodes(&grid).is_empty());
    }
}
