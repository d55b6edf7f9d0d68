//! Conforming local refinement by longest-edge bisection, in 2D (triangles) and 3D (tetrahedra).
//!
//! One refinement level ([`refine_marked`]) works on the edges of the input mesh:
//!
//! 1. every edge gets the strict total order key `(squared length, min node id, max node id)`;
//!    the larger key is the "longer" edge, so ties between equally long edges are broken the same
//!    way by every cell;
//! 2. the longest edge of every marked cell is marked, and then, until nothing changes, every
//!    cell with a marked edge gets its longest edge marked too (the closure that keeps the
//!    refinement a longest-edge one and bounds the shape degradation);
//! 3. every marked edge gets one midpoint node; on boundary edges the midpoint is placed by a
//!    [`BoundaryProjection`] (e.g. [`SphereProjection`] keeps a circle or a sphere curved);
//! 4. every cell is bisected recursively: of its marked edges whose two end nodes are old nodes,
//!    the one with the largest key is split first, then each child continues with its own
//!    remaining marked old edges. The subdivision of a shared face depends only on the marked
//!    edges of that face and on the global key order, so neighbours agree and the refined mesh is
//!    conforming (no hanging nodes);
//! 5. the boundary parts are carried over: every new boundary facet inherits the parts of the old
//!    boundary facet it lies in.
//!
//! Bisection replaces one end node of the split edge by the midpoint in each child, which keeps
//! every child positively oriented; a boundary projection that would invert or flatten a cell is
//! reported as the [`MeshError`] of [`Mesh::new`].

use std::cmp::Ordering;
use std::collections::{HashMap, HashSet};

use crate::error::MeshError;
use crate::math::{is_supported_dim, Point, Real};
use crate::mesh::Mesh;

/// How the midpoint of a *boundary* edge is placed when that edge is bisected (interior edges are
/// always split at their plain midpoint).
///
/// Use it to keep curved boundaries curved: with [`SphereProjection`] the new nodes of a refined
/// disc or ball lie on the circle or sphere instead of on the chords.
pub trait BoundaryProjection<const D: usize> {
    /// Position of the new node that splits the boundary edge `(a, b)`.
    fn midpoint(&self, a: &Point<D>, b: &Point<D>) -> Point<D>;
}

/// The plain midpoint `(a + b) / 2`: the boundary stays the polygon / polyhedron it is.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StraightMidpoint;

impl<const D: usize> BoundaryProjection<D> for StraightMidpoint {
    fn midpoint(&self, a: &Point<D>, b: &Point<D>) -> Point<D> {
        (a + b) * 0.5
    }
}

/// Places the midpoint of a boundary edge on the circle (2D) or sphere (3D)
/// `|x − center| = radius` when **both** end points lie on it (within the relative tolerance
/// [`SphereProjection::REL_TOL`]); otherwise (and for an edge whose midpoint is the center) it is
/// the plain midpoint.
///
/// The midpoint is projected radially, so an edge that also lies in a plane through `center`
/// (the rim of a [`hemisphere`](crate::generators::hemisphere)) keeps its new node in that plane.
/// Only *boundary* edges are ever projected; a boundary edge that is a chord across a flat face
/// with both ends on the sphere would be pulled onto the sphere too, which the
/// [`generators`](crate::generators) avoid by construction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereProjection<const D: usize> {
    /// Center of the circle or sphere.
    pub center: Point<D>,
    /// Radius of the circle or sphere.
    pub radius: Real,
}

impl<const D: usize> SphereProjection<D> {
    /// Relative tolerance `| |x − center| − radius | ≤ REL_TOL · radius` for a node to count as
    /// lying on the sphere.
    pub const REL_TOL: Real = 1e-9;

    /// A projection onto the sphere `|x − center| = radius`; fails with
    /// [`MeshError::InvalidParameter`] unless `radius` is positive and finite and `center` finite.
    pub fn new(center: Point<D>, radius: Real) -> Result<Self, MeshError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(MeshError::InvalidParameter(format!(
                "sphere projection: radius must be positive and finite, got {radius}"
            )));
        }
        if center.iter().any(|x| !x.is_finite()) {
            return Err(MeshError::InvalidParameter(
                "sphere projection: center has a non-finite coordinate".to_string(),
            ));
        }
        Ok(Self { center, radius })
    }

    /// `true` if `p` lies on the sphere within [`SphereProjection::REL_TOL`].
    pub fn contains(&self, p: &Point<D>) -> bool {
        ((p - self.center).norm() - self.radius).abs() <= Self::REL_TOL * self.radius
    }
}

impl<const D: usize> BoundaryProjection<D> for SphereProjection<D> {
    fn midpoint(&self, a: &Point<D>, b: &Point<D>) -> Point<D> {
        let m = (a + b) * 0.5;
        if !(self.contains(a) && self.contains(b)) {
            return m;
        }
        let r = m - self.center;
        let len = r.norm();
        if len > 0.0 && len.is_finite() {
            self.center + r * (self.radius / len)
        } else {
            m
        }
    }
}

/// An edge as its sorted pair of node indices.
type Edge = (usize, usize);

fn edge(a: usize, b: usize) -> Edge {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

/// The strict total order of edges: squared length, then the sorted node ids.
fn edge_cmp<const D: usize>(nodes: &[Point<D>], e: Edge, f: Edge) -> Ordering {
    let le = (nodes[e.0] - nodes[e.1]).norm_squared();
    let lf = (nodes[f.0] - nodes[f.1]).norm_squared();
    le.total_cmp(&lf).then(e.cmp(&f))
}

/// Refines `mesh` once: bisects every cell `c` with `mark(c)` along its longest edge, plus the
/// closure described in the [module documentation](self) that keeps the mesh conforming.
///
/// `mark` is called once for every cell index `0..mesh.n_cells()`. Midpoints of boundary edges
/// are placed by `proj`, all other midpoints at `(a + b) / 2`. Nodes of the input keep their
/// indices; the new midpoint nodes follow, numbered in the order of their edges. Every boundary
/// part is carried over (same name, kind and order); a facet belonging to several parts stays in
/// all of them. With no cell marked the result equals the input.
///
/// Errors: the orientation errors of [`Mesh::new`] if the boundary projection inverted or
/// flattened a cell, [`MeshError::NonFiniteNode`] if it returned a non-finite point.
pub fn refine_marked<const D: usize>(
    mesh: &Mesh<D>,
    mark: impl Fn(usize) -> bool,
    proj: &dyn BoundaryProjection<D>,
) -> Result<Mesh<D>, MeshError> {
    if !is_supported_dim(D) {
        return Err(MeshError::UnsupportedDimension(D));
    }
    let nodes = mesh.nodes();
    let n_old = nodes.len();
    let n_cells = mesh.n_cells();

    // Edge → cells adjacency and the longest edge of every cell.
    let mut edge_cells: HashMap<Edge, Vec<usize>> = HashMap::new();
    let mut longest: Vec<Edge> = Vec::with_capacity(n_cells);
    for c in 0..n_cells {
        let cell = mesh.cell(c);
        let mut best: Option<Edge> = None;
        for i in 0..=D {
            for j in (i + 1)..=D {
                let e = edge(cell[i], cell[j]);
                edge_cells.entry(e).or_default().push(c);
                best = match best {
                    Some(b) if edge_cmp(nodes, b, e) != Ordering::Less => Some(b),
                    _ => Some(e),
                };
            }
        }
        // D ≥ 2, so every cell has at least one edge.
        longest.push(best.unwrap_or((cell[0], cell[0])));
    }

    // Marked edges: longest edges of marked cells, then the closure.
    let mut marked: HashSet<Edge> = HashSet::new();
    let mut queue: Vec<usize> = Vec::new();
    for (c, &e) in longest.iter().enumerate() {
        if mark(c) && marked.insert(e) {
            if let Some(cs) = edge_cells.get(&e) {
                queue.extend_from_slice(cs);
            }
        }
    }
    while let Some(c) = queue.pop() {
        let e = longest[c];
        if marked.insert(e) {
            if let Some(cs) = edge_cells.get(&e) {
                queue.extend_from_slice(cs);
            }
        }
    }

    // Boundary edges of the input (edges of its boundary facets).
    let old_boundary = mesh.boundary_facets();
    let mut boundary_edges: HashSet<Edge> = HashSet::new();
    for f in &old_boundary {
        for i in 0..f.nodes.len() {
            for j in (i + 1)..f.nodes.len() {
                boundary_edges.insert(edge(f.nodes[i], f.nodes[j]));
            }
        }
    }

    // One midpoint per marked edge, in a deterministic order.
    let mut marked_sorted: Vec<Edge> = marked.iter().copied().collect();
    marked_sorted.sort_unstable();
    let mut new_nodes: Vec<Point<D>> = Vec::with_capacity(n_old + marked_sorted.len());
    new_nodes.extend_from_slice(nodes);
    let mut midpoint: HashMap<Edge, usize> = HashMap::with_capacity(marked_sorted.len());
    for &e in &marked_sorted {
        let (a, b) = (&nodes[e.0], &nodes[e.1]);
        let p = if boundary_edges.contains(&e) { proj.midpoint(a, b) } else { (a + b) * 0.5 };
        midpoint.insert(e, new_nodes.len());
        new_nodes.push(p);
    }

    // Recursive bisection of every cell along its marked old edges, largest key first.
    let mut new_cells: Vec<usize> = Vec::with_capacity(mesh.cells_flat().len() * 2);
    let mut stack: Vec<Vec<usize>> = Vec::new();
    for c in 0..n_cells {
        stack.push(mesh.cell(c).to_vec());
        while let Some(cell) = stack.pop() {
            let mut best: Option<(usize, usize, Edge)> = None;
            for i in 0..=D {
                for j in (i + 1)..=D {
                    if cell[i] >= n_old || cell[j] >= n_old {
                        continue;
                    }
                    let e = edge(cell[i], cell[j]);
                    if !marked.contains(&e) {
                        continue;
                    }
                    best = match best {
                        Some(b) if edge_cmp(nodes, b.2, e) != Ordering::Less => Some(b),
                        _ => Some((i, j, e)),
                    };
                }
            }
            match best.and_then(|(i, j, e)| midpoint.get(&e).map(|&m| (i, j, m))) {
                None => new_cells.extend_from_slice(&cell),
                Some((i, j, m)) => {
                    let mut first = cell.clone();
                    first[i] = m;
                    let mut second = cell;
                    second[j] = m;
                    stack.push(second);
                    stack.push(first);
                }
            }
        }
    }

    let parents: Vec<Edge> = marked_sorted;
    let mut refined = Mesh::new(new_nodes, new_cells)?;

    // Carry the boundary parts over.
    let parts = mesh.boundary_parts();
    if parts.is_empty() {
        return Ok(refined);
    }
    let mut facet_parts: HashMap<Vec<usize>, Vec<usize>> = HashMap::new();
    for f in &old_boundary {
        let mut key = f.nodes.clone();
        key.sort_unstable();
        facet_parts.insert(key, Vec::new());
    }
    for (pi, part) in parts.iter().enumerate() {
        for f in part.facets() {
            let mut key = f.to_vec();
            key.sort_unstable();
            facet_parts.entry(key).or_default().push(pi);
        }
    }
    let mut part_facets: Vec<Vec<Vec<usize>>> = vec![Vec::new(); parts.len()];
    for f in refined.boundary_facets() {
        let mut ancestors: Vec<usize> = Vec::with_capacity(2 * D);
        for &v in &f.nodes {
            if v < n_old {
                ancestors.push(v);
            } else if let Some(&(a, b)) = parents.get(v - n_old) {
                ancestors.push(a);
                ancestors.push(b);
            }
        }
        ancestors.sort_unstable();
        ancestors.dedup();
        match facet_parts.get(&ancestors) {
            Some(owners) => {
                for &pi in owners {
                    part_facets[pi].push(f.nodes.clone());
                }
            }
            None => return Err(MeshError::RefinementInconsistent { facet: f.nodes }),
        }
    }
    for (part, facets) in parts.iter().zip(part_facets) {
        refined.add_boundary_part_from_facets(part.name(), part.kind(), &facets)?;
    }
    Ok(refined)
}

/// Barycentric sample points of a simplex: the lattice of order 4 (vertices, edge points, face
/// points, …) plus the centroid.
fn sample_weights(d: usize) -> Vec<Vec<Real>> {
    const ORDER: usize = 4;
    let mut out: Vec<Vec<Real>> = Vec::new();
    let mut idx = vec![0usize; d + 1];
    fn rec(k: usize, left: usize, idx: &mut Vec<usize>, out: &mut Vec<Vec<Real>>) {
        if k + 1 == idx.len() {
            idx[k] = left;
            out.push(idx.iter().map(|&i| i as Real / ORDER as Real).collect());
            return;
        }
        for i in 0..=left {
            idx[k] = i;
            rec(k + 1, left - i, idx, out);
        }
    }
    rec(0, ORDER, &mut idx, &mut out);
    out.push(vec![1.0 / (d + 1) as Real; d + 1]);
    out
}

/// `true` if one of the sample points of cell `c` lies in `region`.
fn cell_touches<const D: usize>(
    mesh: &Mesh<D>,
    c: usize,
    weights: &[Vec<Real>],
    region: &impl Fn(&Point<D>) -> bool,
) -> bool {
    let pts = mesh.cell_points(c);
    weights.iter().any(|w| {
        let mut x = Point::<D>::zeros();
        for (p, &wi) in pts.iter().zip(w) {
            x += p * wi;
        }
        region(&x)
    })
}

/// Refines `levels` times toward `region`: at each level every cell that touches the region is
/// marked and [`refine_marked`] is applied.
///
/// A cell touches the region if `region(x)` holds for one of its sample points: the vertices,
/// the centroid and the barycentric lattice points of order 4 (15 lattice points per triangle,
/// 35 per tetrahedron), so a cell is refined as soon as the region covers a fair
/// part of it, even if the region contains none of its vertices. The iteration stops early when
/// no cell touches the region. `levels = 0` returns a copy of `mesh`.
///
/// In 2D one level halves the area of the touched cells, so their size `h` shrinks by `√2` per
/// level; in 3D `h` halves about every three levels.
pub fn refine_toward<const D: usize>(
    mesh: &Mesh<D>,
    region: impl Fn(&Point<D>) -> bool,
    levels: usize,
    proj: &dyn BoundaryProjection<D>,
) -> Result<Mesh<D>, MeshError> {
    refine_toward_within(mesh, region, levels, proj, usize::MAX)
}

/// [`refine_toward`] that stops with [`MeshError::InvalidParameter`] as soon as a level leaves
/// more than `max_cells` cells, before refining further: the guard of a caller that cannot
/// tell in advance how many cells a region and a number of levels make (a region that covers
/// the whole mesh refines every cell at every level, `2^levels` times the cells).
///
/// # Errors
/// As [`refine_marked`], and when the cell count exceeds `max_cells`.
pub fn refine_toward_within<const D: usize>(
    mesh: &Mesh<D>,
    region: impl Fn(&Point<D>) -> bool,
    levels: usize,
    proj: &dyn BoundaryProjection<D>,
    max_cells: usize,
) -> Result<Mesh<D>, MeshError> {
    let weights = sample_weights(D);
    let mut current = mesh.clone();
    for level in 0..levels {
        let marked: Vec<bool> =
            (0..current.n_cells()).map(|c| cell_touches(&current, c, &weights, &region)).collect();
        if !marked.iter().any(|&m| m) {
            break;
        }
        current = refine_marked(&current, |c| marked.get(c).copied().unwrap_or(false), proj)?;
        if current.n_cells() > max_cells {
            return Err(MeshError::InvalidParameter(format!(
                "refinement toward the region: {} cells after level {} of {levels}, more than the limit {max_cells}",
                current.n_cells(),
                level + 1
            )));
        }
    }
    Ok(current)
}

/// Uniform refinement: each level applies [`refine_marked`] `D` times with every cell marked, so
/// the mesh size `h` roughly halves per level (exactly, for the Kuhn meshes of the
/// [`generators`](crate::generators) in 2D). `levels = 0` returns a copy of `mesh`.
pub fn refine_uniform<const D: usize>(
    mesh: &Mesh<D>,
    levels: usize,
    proj: &dyn BoundaryProjection<D>,
) -> Result<Mesh<D>, MeshError> {
    let mut current = mesh.clone();
    for _ in 0..levels.saturating_mul(D) {
        current = refine_marked(&current, |_| true, proj)?;
    }
    Ok(current)
}

impl<const D: usize> Mesh<D> {
    /// The mesh refined `levels` times toward `region`; see [`refine_toward`].
    pub fn refined_toward(
        &self,
        region: impl Fn(&Point<D>) -> bool,
        levels: usize,
        proj: &dyn BoundaryProjection<D>,
    ) -> Result<Self, MeshError> {
        refine_toward(self, region, levels, proj)
    }
}
