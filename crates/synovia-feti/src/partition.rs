//! METIS partition of each body's cells into subdomains, split into facet-connected pieces.
//!
//! A subdomain whose cells hang together only at a node (2D) or an edge (3D) would have a
//! stiffness kernel larger than the rigid-body modes (a hinge). After METIS, every part is
//! therefore split into its components connected through facets (`D` shared nodes); the kernel
//! of the stiffness of such a component of non-degenerate P1 simplices is exactly the space of
//! rigid-body motions (docs/model.md §4).

use std::collections::HashMap;

use synovia_mesh::Mesh;

use crate::error::FetiError;

/// How the cells of a body are cut into parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Partitioner {
    /// METIS k-way on the dual graph (fewest cut facets; the parts can be far from convex —
    /// long arms — on structured meshes, see docs/scale-out.md).
    #[default]
    Metis,
    /// Recursive coordinate bisection of the cell centroids: the cells are split across the
    /// longest extent of their centroids in the proportion of the parts on either side
    /// (`⌊p/2⌋ : ⌈p/2⌉`), recursively. Compact parts of equal size (squares/cubes on a block).
    Bisection,
}

/// Recursive coordinate bisection of `cells` into `parts` parts numbered from `first`
/// ([`Partitioner::Bisection`]); ties in the coordinate are broken by the cell index.
fn bisect(centroids: &[[f64; 3]], cells: &mut [usize], parts: usize, first: usize, part: &mut [metis::Idx]) {
    if parts <= 1 || cells.len() <= 1 {
        for &c in cells.iter() {
            part[c] = metis::Idx::try_from(first).unwrap_or(metis::Idx::MAX);
        }
        return;
    }
    let mut axis = 0;
    let mut widest = f64::NEG_INFINITY;
    #[allow(clippy::needless_range_loop)]
    for k in 0..3 {
        let lo = cells.iter().map(|&c| centroids[c][k]).fold(f64::INFINITY, f64::min);
        let hi = cells.iter().map(|&c| centroids[c][k]).fold(f64::NEG_INFINITY, f64::max);
        if hi - lo > widest {
            widest = hi - lo;
            axis = k;
        }
    }
    cells.sort_by(|&a, &b| centroids[a][axis].total_cmp(&centroids[b][axis]).then(a.cmp(&b)));
    let left = parts / 2;
    let cut = (cells.len() * left + parts / 2) / parts;
    let (a, b) = cells.split_at_mut(cut.clamp(1, cells.len() - 1));
    bisect(centroids, a, left, first, part);
    bisect(centroids, b, parts - left, first + left, part);
}

/// The cell-to-cell adjacency through facets (the dual graph), in CSR form.
pub fn dual_graph<const D: usize>(mesh: &Mesh<D>) -> (Vec<usize>, Vec<usize>) {
    let nc = mesh.n_cells();
    let mut faces: HashMap<[usize; 3], usize> = HashMap::with_capacity(nc * (D + 1));
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); nc];
    for c in 0..nc {
        let cell = mesh.cell(c);
        for skip in 0..=D {
            let mut key = [usize::MAX; 3];
            let mut k = 0;
            for (a, &n) in cell.iter().enumerate() {
                if a != skip {
                    key[k] = n;
                    k += 1;
                }
            }
            key[..D].sort_unstable();
            match faces.remove(&key) {
                Some(other) => {
                    adj[c].push(other);
                    adj[other].push(c);
                }
                None => {
                    faces.insert(key, c);
                }
            }
        }
    }
    let mut xadj = Vec::with_capacity(nc + 1);
    let mut adjncy = Vec::new();
    xadj.push(0);
    for mut a in adj {
        a.sort_unstable();
        adjncy.extend(a);
        xadj.push(adjncy.len());
    }
    (xadj, adjncy)
}

/// Partitions the cells of `mesh` into `parts` parts — with METIS (`METIS_PartGraphKway` on the
/// dual graph, fixed seed) or by recursive coordinate bisection ([`Partitioner`]) — and splits
/// each part into facet-connected components. Returns the cell lists of the pieces (each
/// sorted, in order of their first cell).
pub fn partition_cells<const D: usize>(
    mesh: &Mesh<D>,
    parts: usize,
    body: &str,
    partitioner: Partitioner,
) -> Result<Vec<Vec<usize>>, FetiError> {
    let nc = mesh.n_cells();
    if parts == 0 {
        return Err(FetiError::InvalidParameter(format!("body `{body}`: 0 subdomains")));
    }
    let (xadj, adjncy) = dual_graph(mesh);
    let err = |message: String| FetiError::Partition { body: body.to_string(), parts, message };
    let mut part = vec![0 as metis::Idx; nc];
    if parts > 1 && nc > 0 && partitioner == Partitioner::Bisection {
        let centroids: Vec<[f64; 3]> = (0..nc)
            .map(|c| {
                let mut x = [0.0; 3];
                for &n in mesh.cell(c) {
                    for (k, xk) in x.iter_mut().enumerate().take(D) {
                        *xk += mesh.node(n)[k] / (D + 1) as f64;
                    }
                }
                x
            })
            .collect();
        let mut cells: Vec<usize> = (0..nc).collect();
        bisect(&centroids, &mut cells, parts.min(nc), 0, &mut part);
    } else if parts > 1 && nc > 0 {
        let to_idx = |v: usize| metis::Idx::try_from(v).map_err(|_| err("graph too large".into()));
        let x: Vec<metis::Idx> = xadj.iter().map(|&v| to_idx(v)).collect::<Result<_, _>>()?;
        let a: Vec<metis::Idx> = adjncy.iter().map(|&v| to_idx(v)).collect::<Result<_, _>>()?;
        let np = to_idx(parts.min(nc))?;
        // METIS's random-number state is process-wide: one call at a time (synovia_linalg::metis_lock)
        let _guard = synovia_linalg::metis_lock();
        metis::Graph::new(1, np, &x, &a)
            .map_err(|e| err(e.to_string()))?
            .set_option(metis::option::Seed(7))
            .part_kway(&mut part)
            .map_err(|e| err(e.to_string()))?;
    }
    // facet-connected components of every part
    let mut piece = vec![usize::MAX; nc];
    let mut pieces: Vec<Vec<usize>> = Vec::new();
    for start in 0..nc {
        if piece[start] != usize::MAX {
            continue;
        }
        let id = pieces.len();
        let mut cells = vec![start];
        piece[start] = id;
        let mut k = 0;
        while k < cells.len() {
            let c = cells[k];
            k += 1;
            for &o in &adjncy[xadj[c]..xadj[c + 1]] {
                if piece[o] == usize::MAX && part[o] == part[c] {
                    piece[o] = id;
                    cells.push(o);
                }
            }
        }
        cells.sort_unstable();
        pieces.push(cells);
    }
    Ok(pieces)
}
