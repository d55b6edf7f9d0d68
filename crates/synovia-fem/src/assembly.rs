//! Global assembly into the reduced unknowns of a [`DofMap`].
//!
//! For a cell `T` with element matrix `K_T` and element vector `f_T` the reduced contributions
//! are `P_Tᵀ K_T P_T` and `P_Tᵀ (f_T − K_T u_{p,T})`, where `P_T` stacks the bases `N` of the
//! cell's node groups and `u_{p,T}` their lifts (see [`crate::dofs`]). Matrices are accumulated
//! into the fixed lower-triangular pattern of [`SymmetricMatrix`]; [`pattern`] builds it once
//! and every later assembly only re-fills its values.

use nalgebra::DMatrix;
use rayon::prelude::*;
use synovia_mesh::math::{Point, Real, Vector};

use crate::dofs::DofMap;
use crate::element::{body_force_into, traction_into, SimplexGeometry};
use crate::error::FemError;
use crate::model::{BodyId, Model};
use crate::quadrature::QuadratureRule;
use synovia_linalg::Ordering;
use synovia_linalg::SymmetricMatrix;

/// Node-group adjacency of the model's cells (each group adjacent to the groups it shares a
/// cell with, itself excluded), sorted.
pub fn group_adjacency<const D: usize>(model: &Model<D>, dofs: &DofMap<D>) -> Vec<Vec<usize>> {
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); dofs.groups().len()];
    for (bi, body) in model.bodies().iter().enumerate() {
        for cell in body.mesh.cells() {
            for &a in cell {
                let ga = dofs.group_of(BodyId(bi), a);
                for &b in cell {
                    let gb = dofs.group_of(BodyId(bi), b);
                    if ga != gb {
                        adj[ga].push(gb);
                    }
                }
            }
        }
    }
    for a in adj.iter_mut() {
        a.sort_unstable();
        a.dedup();
    }
    adj
}

/// The lower-triangular pattern of the reduced operator, with zero values, and the METIS
/// ordering input for it.
pub fn pattern<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
) -> Result<(SymmetricMatrix, Ordering), FemError> {
    let adj = group_adjacency(model, dofs);
    let groups = dofs.groups();
    let mut columns: Vec<Vec<usize>> = Vec::with_capacity(dofs.n_dofs());
    for (g, grp) in groups.iter().enumerate() {
        for k in 0..grp.n_dofs {
            let mut rows: Vec<usize> = (grp.first_dof + k..grp.first_dof + grp.n_dofs).collect();
            for &h in &adj[g] {
                if h > g {
                    let gh = &groups[h];
                    rows.extend(gh.first_dof..gh.first_dof + gh.n_dofs);
                }
            }
            columns.push(rows);
        }
    }
    let blocks = groups.iter().map(|g| g.first_dof..g.first_dof + g.n_dofs).collect();
    let m = SymmetricMatrix::from_columns(dofs.n_dofs(), columns)?;
    Ok((m, Ordering::Metis { blocks, adjacency: adj }))
}

/// The constant Voigt stiffness `C⁽⁰⁾` of every body (errors for nonlinear materials and wrong
/// sizes).
pub fn body_stiffnesses<const D: usize>(model: &Model<D>) -> Result<Vec<DMatrix<Real>>, FemError> {
    let nv = D * (D + 1) / 2;
    model
        .bodies()
        .iter()
        .map(|b| {
            let c = b.material.linear_stiffness().ok_or_else(|| FemError::NonlinearMaterial {
                body: b.name.clone(),
                material: b.material.name(),
            })?;
            if c.nrows() != nv || c.ncols() != nv {
                return Err(FemError::MaterialSize { body: b.name.clone(), expected: nv, got: c.nrows() });
            }
            Ok(c)
        })
        .collect()
}

/// Geometry of cell `c` of body `b`, or the degenerate-cell error.
pub(crate) fn cell_geometry<const D: usize>(
    model: &Model<D>,
    b: usize,
    c: usize,
) -> Result<(SimplexGeometry<D>, Vec<Point<D>>), FemError> {
    let body = &model.bodies()[b];
    let pts = body.mesh.cell_points(c);
    match SimplexGeometry::new(&pts) {
        Some(g) if g.measure > 0.0 => Ok((g, pts)),
        _ => Err(FemError::Mesh {
            body: body.name.clone(),
            source: synovia_mesh::MeshError::DegenerateCell { cell: c, det: 0.0 },
        }),
    }
}

/// Assembles `Σ_T P_Tᵀ K_T P_T` into `matrix` (whose values are first set to zero), with the
/// element matrix `K_T` given by `kernel(body, cell, geometry, out)` (`D(D+1)` square,
/// row-major, node-major dofs).
///
/// Runs on rayon's pool (see [`assemble_matrix_with`]: one column block of the matrix per
/// thread); the values do not depend on the number of threads, and with one thread the
/// assembly runs in place with no parallel overhead.
pub fn assemble_matrix<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    matrix: &mut SymmetricMatrix,
    kernel: impl Fn(usize, usize, &SimplexGeometry<D>, &mut [Real]) + Sync,
) -> Result<(), FemError> {
    assemble_matrix_with(model, dofs, matrix, rayon::current_num_threads(), kernel)
}

/// Fewer cells than this are assembled sequentially (the parallel split would not pay).
const PARALLEL_MIN_CELLS: usize = 4096;

/// [`assemble_matrix`] with the matrix split into `blocks` column blocks of about equal
/// stored entries, assembled in parallel on rayon's pool (`blocks ≤ 1`, or fewer than 4096
/// cells: sequentially, in place).
///
/// Each block owns a contiguous range of columns and their values, and visits every cell that
/// has a dof in its range: it evaluates the kernel and adds the entries that fall into its
/// columns. No two blocks write the same value, so no synchronisation is needed, and every
/// entry receives its contributions in the same (body, cell, node pair) order whatever the
/// split: the values are bitwise the same for any `blocks`. The price is that a cell with dofs
/// in several blocks has its kernel evaluated once per block (a thin layer of cells at each
/// block boundary for a mesh whose nodes are numbered by locality, as the generators and
/// [`DofMap`] do), and a transient copy of the values (the blocks fill their own buffers,
/// copied into `matrix` at the end).
pub fn assemble_matrix_with<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    matrix: &mut SymmetricMatrix,
    blocks: usize,
    kernel: impl Fn(usize, usize, &SimplexGeometry<D>, &mut [Real]) + Sync,
) -> Result<(), FemError> {
    assemble_matrix_of(model, dofs, matrix, blocks, &[], kernel)
}

/// [`assemble_matrix_with`] over the cells of the bodies `b` with `skip.get(b) != Some(&true)`
/// only (the others contribute nothing).
pub(crate) fn assemble_matrix_of<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    matrix: &mut SymmetricMatrix,
    blocks: usize,
    skip: &[bool],
    kernel: impl Fn(usize, usize, &SimplexGeometry<D>, &mut [Real]) + Sync,
) -> Result<(), FemError> {
    if matrix.n() != dofs.n_dofs() {
        return Err(FemError::Length { what: "matrix", expected: dofs.n_dofs(), got: matrix.n() });
    }
    if D > 3 {
        return Err(FemError::InvalidParameter(format!("assembly of dimension {D}")));
    }
    let n_cells: usize = model
        .bodies()
        .iter()
        .enumerate()
        .filter(|(b, _)| skip.get(*b) != Some(&true))
        .map(|(_, b)| b.mesh.n_cells())
        .sum();
    let n = matrix.n();
    let nnz = matrix.nnz();
    let blocks = blocks.min(n).max(1);
    let spans: Vec<(usize, usize)> = dofs.groups().iter().map(|g| (g.first_dof, g.n_dofs)).collect();
    if blocks == 1 || n_cells < PARALLEL_MIN_CELLS {
        matrix.zero();
        return assemble_columns(model, dofs, &spans, 0..n, true, skip, matrix, &kernel).map_err(|e| e.2);
    }
    // column bounds with about nnz / blocks stored entries per block
    let cp = matrix.pattern().col_ptr();
    let mut bounds = vec![0];
    for k in 1..blocks {
        let j = cp.partition_point(|&p| p < k * nnz / blocks).min(n);
        if j > *bounds.last().unwrap_or(&0) {
            bounds.push(j);
        }
    }
    if *bounds.last().unwrap_or(&0) < n {
        bounds.push(n);
    }
    let shared: &SymmetricMatrix = matrix;
    let results: Vec<Result<Vec<Real>, (usize, usize, FemError)>> = bounds
        .par_windows(2)
        .enumerate()
        .map(|(k, w)| {
            let mut block =
                ColumnBlock { matrix: shared, offset: cp[w[0]], values: vec![0.0; cp[w[1]] - cp[w[0]]] };
            assemble_columns(model, dofs, &spans, w[0]..w[1], k == 0, skip, &mut block, &kernel)?;
            Ok(block.values)
        })
        .collect();
    let mut parts = Vec::with_capacity(results.len());
    let mut first_error: Option<(usize, usize, FemError)> = None;
    for r in results {
        match r {
            Ok(v) => parts.push(v),
            Err(e) => {
                if first_error.as_ref().is_none_or(|f| (e.0, e.1) < (f.0, f.1)) {
                    first_error = Some(e);
                }
            }
        }
    }
    if let Some(e) = first_error {
        return Err(e.2);
    }
    let mut rest = matrix.values_mut();
    let mut targets = Vec::with_capacity(parts.len());
    for p in &parts {
        let (head, tail) = rest.split_at_mut(p.len());
        targets.push(head);
        rest = tail;
    }
    targets.into_par_iter().zip(parts.par_iter()).for_each(|(t, p)| t.copy_from_slice(p));
    Ok(())
}

/// Where [`assemble_columns`] adds its entries: the whole matrix, in place, or one
/// [`ColumnBlock`].
trait Scatter {
    /// The matrix whose pattern the positions refer to.
    fn matrix(&self) -> &SymmetricMatrix;
    /// Adds `v` to the stored value at position `p` of the pattern.
    fn add(&mut self, p: usize, v: Real);
}

impl Scatter for SymmetricMatrix {
    #[inline]
    fn matrix(&self) -> &SymmetricMatrix {
        self
    }
    #[inline]
    fn add(&mut self, p: usize, v: Real) {
        self.values_mut()[p] += v;
    }
}

/// The values of a contiguous range of columns of `matrix`, starting at position `offset`.
struct ColumnBlock<'a> {
    matrix: &'a SymmetricMatrix,
    offset: usize,
    values: Vec<Real>,
}

impl Scatter for ColumnBlock<'_> {
    #[inline]
    fn matrix(&self) -> &SymmetricMatrix {
        self.matrix
    }
    #[inline]
    fn add(&mut self, p: usize, v: Real) {
        self.values[p - self.offset] += v;
    }
}

/// The error of an entry outside the pattern.
fn outside_pattern(r: usize, c: usize) -> FemError {
    FemError::Sparse(format!("entry ({r}, {c}) is outside the pattern"))
}

/// Geometry of cell `c` of body `b` (vertices copied to the stack), or the degenerate-cell
/// error.
#[inline]
fn cell_geometry_of<const D: usize>(
    model: &Model<D>,
    b: usize,
    c: usize,
) -> Result<SimplexGeometry<D>, FemError> {
    let body = &model.bodies()[b];
    let mut pts = [Point::<D>::zeros(); 4];
    for (p, &i) in pts.iter_mut().zip(body.mesh.cell(c)) {
        *p = *body.mesh.node(i);
    }
    match SimplexGeometry::new(&pts[..=D]) {
        Some(g) if g.measure > 0.0 => Ok(g),
        _ => Err(FemError::Mesh {
            body: body.name.clone(),
            source: synovia_mesh::MeshError::DegenerateCell { cell: c, det: 0.0 },
        }),
    }
}

/// Adds `P_Tᵀ K_T P_T` of every cell with a dof in `cols` to the entries of the columns `cols`
/// of `target` (lower triangle). `spans[g]` = (first dof, number of dofs) of group `g`. Cells
/// without any dof are only checked for degeneracy, and only if `dofless_cells`. Errors carry the (body, cell) where they happened.
#[allow(clippy::too_many_arguments)]
fn assemble_columns<const D: usize, S: Scatter>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    spans: &[(usize, usize)],
    cols: std::ops::Range<usize>,
    dofless_cells: bool,
    skip: &[bool],
    target: &mut S,
    kernel: &impl Fn(usize, usize, &SimplexGeometry<D>, &mut [Real]),
) -> Result<(), (usize, usize, FemError)> {
    let n = D * (D + 1);
    let mut ke = vec![0.0; n * n];
    let groups = dofs.groups();
    for (bi, body) in model.bodies().iter().enumerate() {
        if skip.get(bi) == Some(&true) {
            continue;
        }
        for c in 0..body.mesh.n_cells() {
            let cell = body.mesh.cell(c);
            let mut gid = [0usize; 4];
            let (mut touches, mut any_dof) = (false, false);
            for (g, &node) in gid.iter_mut().zip(cell) {
                *g = dofs.group_of(BodyId(bi), node);
                let (first, len) = spans[*g];
                if len > 0 {
                    any_dof = true;
                    touches |= first < cols.end && first + len > cols.start;
                }
            }
            if !touches {
                if dofless_cells && !any_dof {
                    cell_geometry_of(model, bi, c).map_err(|e| (bi, c, e))?;
                }
                continue;
            }
            let geo = cell_geometry_of(model, bi, c).map_err(|e| (bi, c, e))?;
            kernel(bi, c, &geo, &mut ke);
            scatter_cell::<D, S>(&gid[..=D], groups, &ke, &cols, target).map_err(|e| (bi, c, e))?;
        }
    }
    Ok(())
}

/// Adds the entries of the element matrix `ke` of a cell with node groups `gid` that lie in
/// the columns `cols` (lower triangle), in the order (node a, node b, row, column).
#[inline]
fn scatter_cell<const D: usize, S: Scatter>(
    gid: &[usize],
    groups: &[crate::dofs::NodeGroup<D>],
    ke: &[Real],
    cols: &std::ops::Range<usize>,
    target: &mut S,
) -> Result<(), FemError> {
    let n = D * (D + 1);
    for (a, &ia) in gid.iter().enumerate() {
        let ga = &groups[ia];
        if ga.n_dofs == 0 {
            continue;
        }
        for (b, &ib) in gid.iter().enumerate() {
            let gb = &groups[ib];
            // only blocks with rows ≥ columns: the group of a at or after the group of b
            if gb.n_dofs == 0 || ga.first_dof < gb.first_dof {
                continue;
            }
            let same = ia == ib;
            let free = ga.free && gb.free;
            // position of row `ga.first_dof` in the previous column of the group of b
            let mut prev: Option<(usize, usize)> = None;
            for l in 0..gb.n_dofs {
                let col = gb.first_dof + l;
                if col < cols.start || col >= cols.end {
                    continue;
                }
                let k0 = if same { l } else { 0 };
                let row0 = ga.first_dof + k0;
                // In a pattern built by `pattern` the rows of a group are consecutive, and
                // column `col + 1` is column `col` without its first row: one search per
                // block, every guess verified (a search otherwise).
                let pat = target.matrix();
                let cp = pat.pattern().col_ptr();
                let ri = pat.pattern().row_idx();
                let (lo, hi) = (cp[col], cp[col + 1]);
                let guess = if same {
                    lo
                } else {
                    match prev {
                        Some((pc, pp)) if pc + 1 == col && pp > cp[pc] => lo + (pp - cp[pc]) - 1,
                        _ => hi,
                    }
                };
                let p0 = if guess < hi && ri[guess] == row0 {
                    guess
                } else {
                    lo + ri[lo..hi].binary_search(&row0).map_err(|_| outside_pattern(row0, col))?
                };
                prev = Some((col, p0));
                for k in k0..ga.n_dofs {
                    let r = ga.first_dof + k;
                    let v = if free {
                        ke[(D * a + k) * n + D * b + l]
                    } else {
                        let mut v = 0.0;
                        for i in 0..D {
                            for j in 0..D {
                                v += ga.basis[k][i] * ke[(D * a + i) * n + D * b + j] * gb.basis[l][j];
                            }
                        }
                        v
                    };
                    let pat = target.matrix().pattern();
                    let ri = pat.row_idx();
                    let mut p = p0 + (k - k0);
                    if p >= hi || ri[p] != r {
                        p = lo + ri[lo..hi].binary_search(&r).map_err(|_| outside_pattern(r, col))?;
                    }
                    target.add(p, v);
                }
            }
        }
    }
    Ok(())
}

/// Subtracts the lift: `rhs −= Σ_T P_Tᵀ K_T u_{p,T}` over the cells touching a node with a
/// non-zero lift, with the same element kernel as [`assemble_matrix`].
pub fn subtract_lift<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    lifts: &[Vector<D>],
    rhs: &mut [Real],
    kernel: impl Fn(usize, usize, &SimplexGeometry<D>, &mut [Real]),
) -> Result<(), FemError> {
    let n = D * (D + 1);
    let mut ke = vec![0.0; n * n];
    let groups = dofs.groups();
    for (bi, body) in model.bodies().iter().enumerate() {
        for c in 0..body.mesh.n_cells() {
            let cell = body.mesh.cell(c);
            if cell.iter().all(|&i| lifts[dofs.group_of(BodyId(bi), i)].norm_squared() == 0.0) {
                continue;
            }
            let (geo, _) = cell_geometry(model, bi, c)?;
            kernel(bi, c, &geo, &mut ke);
            let mut up = vec![0.0; n];
            for (b, &nb) in cell.iter().enumerate() {
                let l = lifts[dofs.group_of(BodyId(bi), nb)];
                for j in 0..D {
                    up[D * b + j] = l[j];
                }
            }
            for (a, &na) in cell.iter().enumerate() {
                let ga = &groups[dofs.group_of(BodyId(bi), na)];
                let mut f = Vector::<D>::zeros();
                for i in 0..D {
                    f[i] = (0..n).map(|q| ke[(D * a + i) * n + q] * up[q]).sum();
                }
                for k in 0..ga.n_dofs {
                    rhs[ga.first_dof + k] -= ga.basis[k].dot(&f);
                }
            }
        }
    }
    Ok(())
}

/// Adds the nodal vector `f` of node `node` of body `b` to the reduced right-hand side.
#[inline]
fn add_nodal<const D: usize>(dofs: &DofMap<D>, b: usize, node: usize, f: &Vector<D>, rhs: &mut [Real]) {
    let g = &dofs.groups()[dofs.group_of(BodyId(b), node)];
    for k in 0..g.n_dofs {
        rhs[g.first_dof + k] += g.basis[k].dot(f);
    }
}

/// Adds the load `(f, v) = ∫ F · v dx + ∫_{¹Γ_τ} P · v ds` at time `t` (docs/model.md §2) to the
/// reduced right-hand side, with quadrature of degree `degree`.
pub fn add_loads<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    t: Real,
    degree: usize,
    rhs: &mut [Real],
) -> Result<(), FemError> {
    let cell_rule = QuadratureRule::simplex(D, degree)?;
    let facet_rule = QuadratureRule::simplex(D - 1, degree)?;
    let mut fe = vec![0.0; D * (D + 1)];
    for (bi, body) in model.bodies().iter().enumerate() {
        if let Some(force) = &body.body_force {
            let f = |x: &Point<D>| force(x, t);
            for c in 0..body.mesh.n_cells() {
                let (geo, pts) = cell_geometry(model, bi, c)?;
                body_force_into(&pts, geo.measure, &cell_rule, &f, &mut fe).map_err(|x| {
                    FemError::NonFiniteData {
                        what: format!("body force of body `{}`", body.name),
                        x: x.iter().copied().collect(),
                        t,
                    }
                })?;
                for (a, &na) in body.mesh.cell(c).iter().enumerate() {
                    let v = Vector::<D>::from_fn(|i, _| fe[D * a + i]);
                    add_nodal(dofs, bi, na, &v, rhs);
                }
            }
        }
    }
    for tr in model.tractions() {
        let body = model.body(tr.body)?;
        let part = body
            .mesh
            .boundary_part(&tr.part)
            .map_err(|source| FemError::Mesh { body: body.name.clone(), source })?;
        let p = |x: &Point<D>, n: &Vector<D>| (tr.value)(x, n, t);
        for facet in part.facets() {
            let pts: Vec<Point<D>> = facet.iter().map(|&i| *body.mesh.node(i)).collect();
            let normal = body.mesh.facet_normal(facet);
            let measure = body.mesh.facet_measure(facet);
            traction_into(&pts, measure, &normal, &facet_rule, &p, &mut fe).map_err(|x| {
                FemError::NonFiniteData {
                    what: format!("traction on part `{}` of body `{}`", tr.part, body.name),
                    x: x.iter().copied().collect(),
                    t,
                }
            })?;
            for (a, &na) in facet.iter().enumerate() {
                let v = Vector::<D>::from_fn(|i, _| fe[D * a + i]);
                add_nodal(dofs, tr.body.0, na, &v, rhs);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use synovia_material::{isotropic, plane_strain};
    use synovia_mesh::generators::{box_mesh, rectangle, Grading};
    use synovia_mesh::BoundaryKind;

    use super::*;
    use crate::element::{mass_into, stiffness_into};

    /// The assembly as it was before the column blocks: entry by entry through
    /// `SymmetricMatrix::add`.
    fn reference<const D: usize>(
        model: &Model<D>,
        dofs: &DofMap<D>,
        matrix: &mut SymmetricMatrix,
        kernel: impl Fn(usize, usize, &SimplexGeometry<D>, &mut [Real]),
    ) {
        matrix.zero();
        let n = D * (D + 1);
        let mut ke = vec![0.0; n * n];
        let groups = dofs.groups();
        for (bi, body) in model.bodies().iter().enumerate() {
            for c in 0..body.mesh.n_cells() {
                let (geo, _) = cell_geometry(model, bi, c).expect("geometry");
                kernel(bi, c, &geo, &mut ke);
                let cell = body.mesh.cell(c);
                for (a, &na) in cell.iter().enumerate() {
                    let ga = &groups[dofs.group_of(BodyId(bi), na)];
                    for (b, &nb) in cell.iter().enumerate() {
                        let gb = &groups[dofs.group_of(BodyId(bi), nb)];
                        for k in 0..ga.n_dofs {
                            for l in 0..gb.n_dofs {
                                let (r, col) = (ga.first_dof + k, gb.first_dof + l);
                                if r < col {
                                    continue;
                                }
                                let v = if ga.free && gb.free {
                                    ke[(D * a + k) * n + D * b + l]
                                } else {
                                    let mut v = 0.0;
                                    for i in 0..D {
                                        for j in 0..D {
                                            v += ga.basis[k][i]
                                                * ke[(D * a + i) * n + D * b + j]
                                                * gb.basis[l][j];
                                        }
                                    }
                                    v
                                };
                                matrix.add(r, col, v).expect("in pattern");
                            }
                        }
                    }
                }
            }
        }
    }

    /// Two stacked blocks tied along their interface, clamped at the bottom, with a symmetry
    /// side (constrained groups with a reduced basis) on each.
    fn model_2d(n: usize) -> Model<2> {
        let mut model = Model::<2>::new();
        let mut ids = Vec::new();
        for (k, (y0, y1)) in [(0.0, 1.0), (1.0, 1.5)].into_iter().enumerate() {
            let mut mesh =
                rectangle(0.0, 1.0, y0, y1, n, n / 2 + k, Grading::Uniform, Grading::Uniform).expect("mesh");
            mesh.set_part_kind("left", BoundaryKind::Symmetry).expect("part");
            if k == 0 {
                mesh.set_part_kind("bottom", BoundaryKind::Clamped).expect("part");
            }
            let e = 1.0 + 9.0 * k as Real;
            ids.push(
                model
                    .add_body(&format!("b{k}"), mesh, Arc::new(plane_strain(e, 0.3).expect("m")))
                    .expect("body"),
            );
        }
        model.tie(ids[0], "top", ids[1], "bottom").expect("tie");
        model
    }

    fn model_3d(n: usize) -> Model<3> {
        let mut model = Model::<3>::new();
        let mut ids = Vec::new();
        for (k, (z0, z1)) in [(0.0, 1.0), (1.0, 1.5)].into_iter().enumerate() {
            let mut mesh =
                box_mesh([0.0, 0.0, z0], [1.0, 1.0, z1], [n, n, n], [Grading::Uniform; 3]).expect("mesh");
            mesh.set_part_kind("left", BoundaryKind::Symmetry).expect("part");
            mesh.set_part_kind("front", BoundaryKind::Symmetry).expect("part");
            if k == 0 {
                mesh.set_part_kind("bottom", BoundaryKind::Clamped).expect("part");
            }
            let e = 1.0 + 9.0 * k as Real;
            ids.push(
                model
                    .add_body(&format!("b{k}"), mesh, Arc::new(isotropic(e, 0.3).expect("m")))
                    .expect("body"),
            );
        }
        model.tie(ids[0], "top", ids[1], "bottom").expect("tie");
        model
    }

    /// Column blocks of any number, and the default on a 2-thread pool, against the reference.
    fn check<const D: usize>(model: &Model<D>) {
        let dofs = DofMap::new(model).expect("dofs");
        let (empty, _) = pattern(model, &dofs).expect("pattern");
        let c = body_stiffnesses(model).expect("stiffness");
        let stiff =
            |b: usize, _: usize, geo: &SimplexGeometry<D>, out: &mut [Real]| stiffness_into(geo, &c[b], out);
        let mass =
            |_: usize, _: usize, geo: &SimplexGeometry<D>, out: &mut [Real]| mass_into(geo, 2.0, false, out);
        let cells: usize = model.bodies().iter().map(|b| b.mesh.n_cells()).sum();
        assert!(cells >= PARALLEL_MIN_CELLS, "{cells} cells: too few for the parallel path");
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
        for kernel in [&stiff as &(dyn Fn(usize, usize, &SimplexGeometry<D>, &mut [Real]) + Sync), &mass] {
            let mut want = empty.clone();
            reference(model, &dofs, &mut want, kernel);
            let scale = want.values().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            assert!(scale > 0.0);
            let mut results = Vec::new();
            for blocks in [1, 2, 3, 8] {
                let mut got = empty.clone();
                got.values_mut().iter_mut().for_each(|v| *v = 1.0); // must be overwritten
                assemble_matrix_with(model, &dofs, &mut got, blocks, kernel).expect("assembly");
                results.push(got);
            }
            let mut got = empty.clone();
            pool.install(|| assemble_matrix(model, &dofs, &mut got, kernel)).expect("assembly");
            results.push(got);
            for got in &results {
                let err =
                    got.values().iter().zip(want.values()).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(err <= 1e-14 * scale, "max error {err:e} (scale {scale:e})");
                // the split does not change the order of the sums
                assert_eq!(got.values(), results[0].values());
            }
        }
    }

    #[test]
    fn parallel_assembly_matches_sequential_2d() {
        check(&model_2d(48));
    }

    #[test]
    fn parallel_assembly_matches_sequential_3d() {
        check(&model_3d(10));
    }
}
