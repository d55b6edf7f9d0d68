//! The simplicial mesh of one body: nodes, P1 cells, named boundary parts.

use std::collections::HashMap;

use crate::error::MeshError;
use crate::math::{factorial, is_supported_dim, simplex_det, Point, Real, Vector};

/// Relative determinant below which a cell counts as degenerate (`|det| / h^D`).
pub const DEGENERACY_TOLERANCE: Real = 1e-12;

/// The kind of a boundary part, following docs/model.md §1.
///
/// The mesh only records *where* each part is and *what kind* it is; the data (`u₂(t)`, `P(t)`,
/// the contact partner) are given by the problem that uses the mesh, keyed by the part's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BoundaryKind {
    /// `¹Γ_u`: prescribed displacement `u = u₂(t)`.
    Prescribed,
    /// `²Γ_u`: clamped, `u = 0`.
    Clamped,
    /// `¹Γ_τ`: prescribed traction `τ n = P(t)`.
    Traction,
    /// `²Γ_τ`: traction free.
    TractionFree,
    /// `Γ_0`: symmetry / bilateral sliding, `u · n = 0`, `τ_t = 0`, along the node's normal.
    Symmetry,
    /// `Γ_c`: a contact part, paired with another body's part (or a rigid obstacle) by the problem.
    Contact,
}

/// A named set of boundary facets of one kind.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryPart {
    name: String,
    kind: BoundaryKind,
    /// Flat list of facet nodes, `D` per facet, each facet ordered so that its normal computed by
    /// [`Mesh::facet_normal`] points out of the body.
    facets: Vec<usize>,
    /// The cell each facet belongs to.
    cells: Vec<usize>,
    dim: usize,
}

impl BoundaryPart {
    /// Name of the part.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Kind of the part.
    pub fn kind(&self) -> BoundaryKind {
        self.kind
    }
    /// Number of facets.
    pub fn n_facets(&self) -> usize {
        self.cells.len()
    }
    /// Nodes of facet `f` (`D` of them, outward orientation).
    pub fn facet(&self, f: usize) -> &[usize] {
        &self.facets[f * self.dim..(f + 1) * self.dim]
    }
    /// Iterator over the facets' node lists.
    pub fn facets(&self) -> impl Iterator<Item = &[usize]> + '_ {
        self.facets.chunks_exact(self.dim)
    }
    /// The cell that facet `f` bounds.
    pub fn facet_cell(&self, f: usize) -> usize {
        self.cells[f]
    }
    /// Sorted, deduplicated nodes of the part.
    pub fn nodes(&self) -> Vec<usize> {
        let mut n = self.facets.clone();
        n.sort_unstable();
        n.dedup();
        n
    }
}

/// A boundary facet: the `D` nodes of a cell face that no other cell shares.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BoundaryFacet {
    /// The cell the facet belongs to.
    pub cell: usize,
    /// Index (0..=D) of the cell vertex opposite the facet.
    pub opposite: usize,
    /// Facet nodes, ordered so that the normal of [`Mesh::facet_normal`] points outward.
    pub nodes: Vec<usize>,
}

/// A conforming P1 simplicial mesh of one body in `R^D` (triangles for `D = 2`, tetrahedra for
/// `D = 3`), with named boundary parts.
///
/// Invariants kept by every constructor: coordinates are finite, cell node indices are in range
/// and distinct, every cell is positively oriented with a non-degenerate measure.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh<const D: usize> {
    nodes: Vec<Point<D>>,
    cells: Vec<usize>,
    parts: Vec<BoundaryPart>,
    facet_index: FacetIndex,
}

/// Lazily built index of the boundary facets by their sorted node lists (a cache: it takes no
/// part in comparisons and is reset whenever cells change).
#[derive(Debug, Clone, Default)]
struct FacetIndex(std::sync::OnceLock<HashMap<Vec<usize>, BoundaryFacet>>);

impl PartialEq for FacetIndex {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// [`MeshError::NonFiniteNode`] for the first node with a non-finite coordinate.
fn check_finite<const D: usize>(nodes: &[Point<D>]) -> Result<(), MeshError> {
    match nodes.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
        Some(node) => Err(MeshError::NonFiniteNode { node }),
        None => Ok(()),
    }
}

/// Outcome of validating one cell's orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CellOrientation {
    /// Positive measure.
    Positive,
    /// Negative measure (inverted): `det / h^D` given.
    Inverted(Real),
    /// Zero measure: `det / h^D` given.
    Degenerate(Real),
}

impl<const D: usize> Mesh<D> {
    /// Builds a mesh from node coordinates and a flat cell array (`D + 1` node indices per cell).
    ///
    /// Fails on non-finite coordinates, out-of-range or repeated indices, nodes that belong to
    /// no cell, degenerate cells, inverted cells (see [`Mesh::new_with_repair`] to flip those
    /// instead), and non-conforming cells ([`Mesh::check_conformity`]: duplicated or overlapping
    /// cells).
    pub fn new(nodes: Vec<Point<D>>, cells: Vec<usize>) -> Result<Self, MeshError> {
        let mesh = Self::unchecked(nodes, cells)?;
        mesh.check_orientation()?;
        mesh.check_conformity()?;
        Ok(mesh)
    }

    /// Checks that every cell is positively oriented: the first inverted or degenerate cell
    /// as [`MeshError::InvertedCell`] / [`MeshError::DegenerateCell`].
    fn check_orientation(&self) -> Result<(), MeshError> {
        for c in 0..self.n_cells() {
            match self.cell_orientation(c) {
                CellOrientation::Positive => {}
                CellOrientation::Inverted(det) => return Err(MeshError::InvertedCell { cell: c, det }),
                CellOrientation::Degenerate(det) => return Err(MeshError::DegenerateCell { cell: c, det }),
            }
        }
        Ok(())
    }

    /// Checks that the (positively oriented) cells form a conforming mesh: every facet is
    /// shared by at most two cells, and two cells sharing a facet lie on opposite sides of it
    /// (they induce opposite orientations on it). A duplicated cell, or two cells folded over
    /// each other, fail with [`MeshError::OverlappingCells`] naming both cells and the facet.
    pub fn check_conformity(&self) -> Result<(), MeshError> {
        // facet → (first cell, its induced parity, already shared by two cells)
        let mut seen: HashMap<[usize; 3], (usize, bool, bool)> =
            HashMap::with_capacity(self.n_cells() * (D + 1));
        let mut overlap = None;
        self.for_each_facet(|c, _, facet, parity| {
            if overlap.is_some() {
                return;
            }
            match seen.get_mut(&facet) {
                None => {
                    seen.insert(facet, (c, parity, false));
                }
                Some(entry) => {
                    let (other, other_parity, interior) = *entry;
                    if interior || other_parity == parity {
                        overlap = Some(MeshError::OverlappingCells {
                            cell: c,
                            other,
                            facet: facet[..D].to_vec(),
                            more_than_two: interior,
                        });
                    }
                    entry.2 = true;
                }
            }
        });
        overlap.map_or(Ok(()), Err)
    }

    /// Calls `f(cell, opposite, key, parity)` for the facet of every cell opposite each of its
    /// local vertices: `key` = the facet's nodes sorted (first `D` entries used), `parity` = the
    /// orientation the cell induces on it, `(−1)^opposite` times the parity of the permutation
    /// that sorts the facet's nodes (two cells on opposite sides of a facet induce opposite
    /// parities).
    fn for_each_facet(&self, mut f: impl FnMut(usize, usize, [usize; 3], bool)) {
        let per = D + 1;
        for (c, cell) in self.cells.chunks_exact(per).enumerate() {
            for opposite in 0..per {
                let mut facet = [usize::MAX; 3];
                let mut k = 0;
                for (i, &n) in cell.iter().enumerate() {
                    if i != opposite {
                        facet[k] = n;
                        k += 1;
                    }
                }
                let mut parity = opposite % 2 == 1;
                let sorted = &mut facet[..D];
                for i in 0..sorted.len() {
                    for j in 0..sorted.len() - 1 - i {
                        if sorted[j] > sorted[j + 1] {
                            sorted.swap(j, j + 1);
                            parity = !parity;
                        }
                    }
                }
                f(c, opposite, facet, parity);
            }
        }
    }

    /// Like [`Mesh::new`], but flips inverted cells (swapping their last two nodes) instead of
    /// failing. Degenerate cells are still an error. Returns the mesh and the number of flipped
    /// cells.
    pub fn new_with_repair(nodes: Vec<Point<D>>, cells: Vec<usize>) -> Result<(Self, usize), MeshError> {
        let mut mesh = Self::unchecked(nodes, cells)?;
        let flipped = mesh.repair_orientation()?;
        mesh.check_conformity()?;
        Ok((mesh, flipped))
    }

    fn unchecked(nodes: Vec<Point<D>>, cells: Vec<usize>) -> Result<Self, MeshError> {
        if !is_supported_dim(D) {
            return Err(MeshError::UnsupportedDimension(D));
        }
        check_finite(&nodes)?;
        let per = D + 1;
        if cells.len() % per != 0 {
            return Err(MeshError::RaggedCells { len: cells.len(), per_cell: per });
        }
        if cells.is_empty() {
            return Err(MeshError::Empty);
        }
        for (cell, c) in cells.chunks_exact(per).enumerate() {
            for (i, &node) in c.iter().enumerate() {
                if node >= nodes.len() {
                    return Err(MeshError::NodeOutOfRange { cell, node, n_nodes: nodes.len() });
                }
                if c[..i].contains(&node) {
                    return Err(MeshError::RepeatedNode { cell, node });
                }
            }
        }
        let mut used = vec![false; nodes.len()];
        for &n in &cells {
            used[n] = true;
        }
        if let Some(node) = used.iter().position(|u| !u) {
            return Err(MeshError::UnusedNode { node });
        }
        Ok(Self { nodes, cells, parts: Vec::new(), facet_index: FacetIndex::default() })
    }

    /// Classifies the orientation of cell `c` by its relative determinant `det / h^D`
    /// (`h` its longest edge), with [`DEGENERACY_TOLERANCE`].
    pub fn cell_orientation(&self, c: usize) -> CellOrientation {
        let v = self.cell_points(c);
        let det = simplex_det::<D>(&v);
        let mut h2: Real = 0.0;
        for i in 0..=D {
            for j in 0..i {
                h2 = h2.max((v[i] - v[j]).norm_squared());
            }
        }
        let rel = det / h2.sqrt().powi(D as i32);
        if !rel.is_finite() || rel.abs() <= DEGENERACY_TOLERANCE {
            CellOrientation::Degenerate(rel)
        } else if rel < 0.0 {
            CellOrientation::Inverted(rel)
        } else {
            CellOrientation::Positive
        }
    }

    /// Indices of the inverted cells (orientation check).
    pub fn inverted_cells(&self) -> Vec<usize> {
        (0..self.n_cells())
            .filter(|&c| matches!(self.cell_orientation(c), CellOrientation::Inverted(_)))
            .collect()
    }

    /// Flips every inverted cell so that all cells are positively oriented; returns how many
    /// were flipped. Fails on the first degenerate cell.
    pub fn repair_orientation(&mut self) -> Result<usize, MeshError> {
        let mut flipped = 0;
        for c in 0..self.n_cells() {
            match self.cell_orientation(c) {
                CellOrientation::Positive => {}
                CellOrientation::Inverted(_) => {
                    let per = D + 1;
                    self.cells.swap(c * per + D - 1, c * per + D);
                    self.facet_index = FacetIndex::default();
                    flipped += 1;
                }
                CellOrientation::Degenerate(det) => return Err(MeshError::DegenerateCell { cell: c, det }),
            }
        }
        Ok(flipped)
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }
    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.cells.len() / (D + 1)
    }
    /// Node coordinates.
    pub fn nodes(&self) -> &[Point<D>] {
        &self.nodes
    }
    /// Coordinates of node `i`.
    pub fn node(&self, i: usize) -> &Point<D> {
        &self.nodes[i]
    }
    /// The flat cell array, `D + 1` node indices per cell.
    pub fn cells_flat(&self) -> &[usize] {
        &self.cells
    }
    /// Node indices of cell `c`.
    pub fn cell(&self, c: usize) -> &[usize] {
        &self.cells[c * (D + 1)..(c + 1) * (D + 1)]
    }
    /// Iterator over the cells' node lists.
    pub fn cells(&self) -> impl ExactSizeIterator<Item = &[usize]> + '_ {
        self.cells.chunks_exact(D + 1)
    }
    /// Vertex coordinates of cell `c`.
    pub fn cell_points(&self, c: usize) -> Vec<Point<D>> {
        self.cell(c).iter().map(|&i| self.nodes[i]).collect()
    }
    /// Measure (area or volume) of cell `c`: `det / D!`.
    pub fn cell_measure(&self, c: usize) -> Real {
        simplex_det::<D>(&self.cell_points(c)) / factorial(D)
    }
    /// Centroid of cell `c`.
    pub fn cell_centroid(&self, c: usize) -> Point<D> {
        let mut s = Point::<D>::zeros();
        for &i in self.cell(c) {
            s += self.nodes[i];
        }
        s / (D + 1) as Real
    }
    /// Total measure of the mesh.
    pub fn measure(&self) -> Real {
        (0..self.n_cells()).map(|c| self.cell_measure(c)).sum()
    }
    /// Longest edge over all cells (mesh size `h`).
    pub fn max_edge_length(&self) -> Real {
        self.edge_lengths().fold(0.0, Real::max)
    }
    /// Shortest edge over all cells.
    pub fn min_edge_length(&self) -> Real {
        self.edge_lengths().fold(Real::INFINITY, Real::min)
    }
    /// Shape quality of cell `c`: the normalised radius ratio `D · r_in / r_circ` (inradius over
    /// circumradius), `1` for the equilateral triangle / regular tetrahedron, tending to `0` for
    /// flat cells (`0` if the circumsphere does not exist).
    pub fn radius_ratio(&self, c: usize) -> Real {
        let v = self.cell_points(c);
        let cell = self.cell(c);
        let facet_sum: Real = (0..=D)
            .map(|opp| {
                let face: Vec<usize> = (0..=D).filter(|&k| k != opp).map(|k| cell[k]).collect();
                self.facet_measure(&face)
            })
            .sum();
        let measure = self.cell_measure(c).abs();
        if facet_sum <= 0.0 {
            return 0.0;
        }
        let r_in = D as Real * measure / facet_sum;
        // Circumcenter x_0 + y with 2 (x_i − x_0) · y = |x_i − x_0|².
        let mut m = crate::math::Tensor::<D>::zeros();
        let mut rhs = Vector::<D>::zeros();
        for i in 1..=D {
            let e = v[i] - v[0];
            m.set_row(i - 1, &e.transpose());
            rhs[i - 1] = 0.5 * e.norm_squared();
        }
        match crate::math::inverse_with_det(&m) {
            Some((inv, _)) => {
                let r_circ = (inv * rhs).norm();
                if r_circ > 0.0 && r_circ.is_finite() {
                    D as Real * r_in / r_circ
                } else {
                    0.0
                }
            }
            None => 0.0,
        }
    }

    fn edge_lengths(&self) -> impl Iterator<Item = Real> + '_ {
        self.cells().flat_map(move |c| {
            (0..=D).flat_map(move |i| (0..i).map(move |j| (self.nodes[c[i]] - self.nodes[c[j]]).norm()))
        })
    }

    /// Moves every node by `f(x)`. Fails (leaving the mesh unchanged) if a cell becomes
    /// inverted, degenerate, or a coordinate non-finite.
    ///
    /// The cells and boundary parts are kept: with every cell still positively oriented, the
    /// facets' sharing and their induced orientations (what [`Self::check_conformity`]
    /// checks, and the boundary facets' outward node order) depend on the cells alone, so the
    /// conformity of the mesh and its facet index carry over.
    pub fn map_nodes(&mut self, f: impl Fn(&Point<D>) -> Point<D>) -> Result<(), MeshError> {
        let new_nodes: Vec<Point<D>> = self.nodes.iter().map(f).collect();
        check_finite(&new_nodes)?;
        let old = std::mem::replace(&mut self.nodes, new_nodes);
        self.check_orientation().inspect_err(|_| self.nodes = old)
    }

    /// The same mesh typed with the dimension parameter `B`, which must equal `D` (lets
    /// dimension-generic code use the dimension-specific generators). Errors otherwise.
    pub fn recast<const B: usize>(&self) -> Result<Mesh<B>, MeshError> {
        if B != D {
            return Err(MeshError::InvalidParameter(format!("cannot recast a {D}D mesh as {B}D")));
        }
        let nodes: Vec<Point<B>> = self.nodes.iter().map(|p| Point::<B>::from_fn(|i, _| p[i])).collect();
        let parts = self
            .parts
            .iter()
            .map(|p| (p.name.clone(), p.kind, p.facets().map(|f| f.to_vec()).collect()))
            .collect();
        Mesh::<B>::from_parts(nodes, self.cells.clone(), parts)
    }

    /// The mirror image of the mesh in the plane `x_axis = plane` (e.g. the upper of two
    /// contacting cylinders from the lower one). Cells are re-oriented and boundary parts kept
    /// (with their outward orientation).
    pub fn reflected(&self, axis: usize, plane: Real) -> Result<Self, MeshError> {
        if axis >= D || !plane.is_finite() {
            return Err(MeshError::InvalidParameter(format!("reflection axis {axis} / plane {plane}")));
        }
        let nodes: Vec<Point<D>> = self
            .nodes
            .iter()
            .map(|p| {
                let mut q = *p;
                q[axis] = 2.0 * plane - q[axis];
                q
            })
            .collect();
        let mut cells = self.cells.clone();
        for c in cells.chunks_exact_mut(D + 1) {
            c.swap(D - 1, D);
        }
        let parts = self
            .parts
            .iter()
            .map(|p| (p.name.clone(), p.kind, p.facets().map(|f| f.to_vec()).collect()))
            .collect();
        Self::from_parts(nodes, cells, parts)
    }

    /// All boundary facets: faces of exactly one cell, oriented outward.
    pub fn boundary_facets(&self) -> Vec<BoundaryFacet> {
        let mut count: HashMap<[usize; 3], (usize, usize, u32)> = HashMap::new();
        self.for_each_facet(|c, opp, key, _| {
            count.entry(key).and_modify(|e| e.2 += 1).or_insert((c, opp, 1));
        });
        let mut out: Vec<BoundaryFacet> = count
            .into_values()
            .filter(|e| e.2 == 1)
            .map(|(cell, opposite, _)| BoundaryFacet {
                cell,
                opposite,
                nodes: self.oriented_face(cell, opposite),
            })
            .collect();
        out.sort_by_key(|a| (a.cell, a.opposite));
        out
    }

    /// Face of cell `c` opposite its local vertex `opposite`, ordered so that
    /// [`Mesh::facet_normal`] points out of the cell.
    pub fn oriented_face(&self, c: usize, opposite: usize) -> Vec<usize> {
        let cell = self.cell(c);
        let mut face: Vec<usize> = (0..=D).filter(|&k| k != opposite).map(|k| cell[k]).collect();
        let n = self.facet_normal(&face);
        let to_opp = self.nodes[cell[opposite]] - self.nodes[face[0]];
        if n.dot(&to_opp) > 0.0 {
            face.swap(0, 1);
        }
        face
    }

    /// Unit normal of a facet given by its `D` nodes: in 2D the segment `(a, b)` has normal
    /// `(b − a)^⊥ = (t_y, −t_x)/|t|`; in 3D the triangle `(a, b, c)` has `(b − a) × (c − a)`
    /// normalised. Facets of [`BoundaryPart`]s and [`Mesh::boundary_facets`] are ordered so this
    /// is the outward normal.
    pub fn facet_normal(&self, facet: &[usize]) -> Vector<D> {
        let n = self.facet_area_normal(facet);
        let len = n.norm();
        if len > 0.0 {
            n / len
        } else {
            n
        }
    }

    /// Normal of a facet scaled by its measure (length in 2D, area in 3D).
    pub fn facet_area_normal(&self, facet: &[usize]) -> Vector<D> {
        facet_area_normal_at(&self.nodes, facet)
    }

    /// Measure of a facet (length in 2D, area in 3D).
    pub fn facet_measure(&self, facet: &[usize]) -> Real {
        self.facet_area_normal(facet).norm()
    }

    /// Centroid of a facet.
    pub fn facet_centroid(&self, facet: &[usize]) -> Point<D> {
        let mut s = Point::<D>::zeros();
        for &i in facet {
            s += self.nodes[i];
        }
        s / facet.len() as Real
    }

    /// Adds a boundary part made of the boundary facets whose centroid `x` and outward unit
    /// normal `n` satisfy `select(x, n)`.
    ///
    /// Errors if the name is taken or nothing is selected. Parts may overlap (a node can lie on
    /// two parts); the problem that uses the mesh decides precedence.
    pub fn add_boundary_part(
        &mut self,
        name: &str,
        kind: BoundaryKind,
        select: impl Fn(&Point<D>, &Vector<D>) -> bool,
    ) -> Result<&BoundaryPart, MeshError> {
        let selected: Vec<BoundaryFacet> = self
            .boundary_facets()
            .into_iter()
            .filter(|f| select(&self.facet_centroid(&f.nodes), &self.facet_normal(&f.nodes)))
            .collect();
        self.insert_part(name, kind, selected)
    }

    /// Adds a boundary part from explicit facets (each `D` node indices, any order). Every facet
    /// must be a boundary facet of the mesh; they are re-oriented outward.
    pub fn add_boundary_part_from_facets(
        &mut self,
        name: &str,
        kind: BoundaryKind,
        facets: &[Vec<usize>],
    ) -> Result<&BoundaryPart, MeshError> {
        let index = self.facet_index.0.get_or_init(|| {
            self.boundary_facets()
                .into_iter()
                .map(|f| {
                    let mut key = f.nodes.clone();
                    key.sort_unstable();
                    (key, f)
                })
                .collect()
        });
        let mut selected = Vec::with_capacity(facets.len());
        for f in facets {
            let mut key = f.clone();
            key.sort_unstable();
            match index.get(&key) {
                Some(bf) if f.len() == D => selected.push(bf.clone()),
                _ => return Err(MeshError::NotABoundaryFacet { part: name.to_string(), facet: f.clone() }),
            }
        }
        self.insert_part(name, kind, selected)
    }

    fn insert_part(
        &mut self,
        name: &str,
        kind: BoundaryKind,
        selected: Vec<BoundaryFacet>,
    ) -> Result<&BoundaryPart, MeshError> {
        if self.parts.iter().any(|p| p.name == name) {
            return Err(MeshError::DuplicatePart(name.to_string()));
        }
        if selected.is_empty() {
            return Err(MeshError::EmptyPart(name.to_string()));
        }
        let mut facets = Vec::with_capacity(selected.len() * D);
        let mut cells = Vec::with_capacity(selected.len());
        for f in selected {
            facets.extend_from_slice(&f.nodes);
            cells.push(f.cell);
        }
        self.parts.push(BoundaryPart { name: name.to_string(), kind, facets, cells, dim: D });
        Ok(self.parts.last().expect("just pushed"))
    }

    /// Removes a boundary part by name and returns it.
    pub fn remove_boundary_part(&mut self, name: &str) -> Result<BoundaryPart, MeshError> {
        let i = self.part_index(name)?;
        Ok(self.parts.remove(i))
    }

    fn part_index(&self, name: &str) -> Result<usize, MeshError> {
        self.parts.iter().position(|p| p.name == name).ok_or_else(|| MeshError::UnknownPart(name.to_string()))
    }

    /// Changes the kind of the part called `name` (generators create geometric parts as
    /// [`BoundaryKind::TractionFree`]; a model re-tags them, e.g. to `Clamped`).
    pub fn set_part_kind(&mut self, name: &str, kind: BoundaryKind) -> Result<(), MeshError> {
        let i = self.part_index(name)?;
        self.parts[i].kind = kind;
        Ok(())
    }

    /// Builder form of [`Mesh::set_part_kind`].
    pub fn with_part_kind(mut self, name: &str, kind: BoundaryKind) -> Result<Self, MeshError> {
        self.set_part_kind(name, kind)?;
        Ok(self)
    }

    /// The boundary parts.
    pub fn boundary_parts(&self) -> &[BoundaryPart] {
        &self.parts
    }

    /// The boundary part called `name`.
    pub fn boundary_part(&self, name: &str) -> Result<&BoundaryPart, MeshError> {
        Ok(&self.parts[self.part_index(name)?])
    }

    /// Outward unit nodal normals of a boundary part: for each node of the part (in the order
    /// of [`BoundaryPart::nodes`]), the normalised sum of the measure-weighted normals of the
    /// part's facets around it.
    pub fn nodal_normals(&self, name: &str) -> Result<Vec<(usize, Vector<D>)>, MeshError> {
        let part = self.boundary_part(name)?;
        Ok(self.nodal_normals_of(part.facets()))
    }

    /// Outward unit nodal normals of any set of outward-oriented facets.
    pub fn nodal_normals_of<'a>(&self, facets: impl Iterator<Item = &'a [usize]>) -> Vec<(usize, Vector<D>)> {
        nodal_normals_at(&self.nodes, facets)
    }

    /// Replaces nodes and cells wholesale, keeping the boundary parts given (used by
    /// refinement); validates like [`Mesh::new`].
    pub fn from_parts(
        nodes: Vec<Point<D>>,
        cells: Vec<usize>,
        parts: Vec<(String, BoundaryKind, Vec<Vec<usize>>)>,
    ) -> Result<Self, MeshError> {
        let mut mesh = Self::new(nodes, cells)?;
        for (name, kind, facets) in parts {
            mesh.add_boundary_part_from_facets(&name, kind, &facets)?;
        }
        Ok(mesh)
    }
}

/// Normal of the facet `facet` (node indices into `positions`) scaled by its measure: in 2D
/// `(b − a)^⊥ = (t_y, −t_x)`, in 3D `½ (b − a) × (c − a)` — outward for outward-ordered facets.
/// Used with the reference nodes by [`Mesh::facet_area_normal`] and with deformed positions by
/// contact search.
pub fn facet_area_normal_at<const D: usize>(positions: &[Point<D>], facet: &[usize]) -> Vector<D> {
    let mut n = Vector::<D>::zeros();
    match D {
        2 => {
            let t = positions[facet[1]] - positions[facet[0]];
            n[0] = t[1];
            n[1] = -t[0];
        }
        3 => {
            let a = positions[facet[0]];
            let u = positions[facet[1]] - a;
            let v = positions[facet[2]] - a;
            n[0] = 0.5 * (u[1] * v[2] - u[2] * v[1]);
            n[1] = 0.5 * (u[2] * v[0] - u[0] * v[2]);
            n[2] = 0.5 * (u[0] * v[1] - u[1] * v[0]);
        }
        _ => {}
    }
    n
}

/// Unit nodal normals of outward-oriented facets at the given positions: for each node the
/// normalised sum of the measure-weighted normals of its facets, sorted by node.
pub fn nodal_normals_at<'a, const D: usize>(
    positions: &[Point<D>],
    facets: impl Iterator<Item = &'a [usize]>,
) -> Vec<(usize, Vector<D>)> {
    let mut acc: HashMap<usize, Vector<D>> = HashMap::new();
    for f in facets {
        let n = facet_area_normal_at(positions, f);
        for &i in f {
            *acc.entry(i).or_insert_with(Vector::<D>::zeros) += n;
        }
    }
    let mut out: Vec<(usize, Vector<D>)> = acc
        .into_iter()
        .map(|(i, n)| {
            let len = n.norm();
            (i, if len > 0.0 { n / len } else { n })
        })
        .collect();
    out.sort_by_key(|e| e.0);
    out
}
