//! One floating subdomain: its stiffness `K_s` (all nodal dofs, no Dirichlet data: *total*
//! FETI), its kernel `R_s` (rigid-body modes) and the generalised inverse `K_s⁺` by fixing
//! dofs.
//!
//! **Kernel.** The rigid-body modes at the subdomain's nodes (translations and rotations about
//! the centroid, positions scaled by the subdomain's size) are orthonormalised by modified
//! Gram–Schmidt with re-orthogonalisation, dropping modes whose remaining norm is below
//! `1e-10` (a subdomain with few nodes in degenerate position keeps only the modes its nodes
//! can distinguish). The result is checked against the data: `‖K_s R_s‖_F ≤ 1e-9 ‖K_s‖_F`,
//! and the rank of `K_s` must be `n_s − r_s` (the factorisation of `K_rr` below succeeds only
//! then).
//!
//! **Generalised inverse** (Brzobohatý, Dostál, Kozubek, Kovář, Markopoulos 2011,
//! *Cholesky decomposition with fixing nodes to stable computation of a generalized inverse of
//! the stiffness matrix of a floating structure*). `r_s` dofs `f` are chosen by pivoted
//! Gram–Schmidt on the rows of `R_s` so that `R_s[f, :]` is non-singular; then the rest
//! `K_rr` is symmetric positive definite and
//!
//! ```text
//! K_s⁺ = Pᵀ [K_rr⁻¹ 0; 0 0] P,        K_s K_s⁺ K_s = K_s,
//! ```
//!
//! since the Schur complement `K_ff − K_fr K_rr⁻¹ K_rf` vanishes when `rank K_rr = rank K_s`.

use nalgebra::DMatrix;
use synovia_fem::element::{stiffness_into, SimplexGeometry};
use synovia_linalg::{FactorisedOperator, Ordering, SparseCholesky, SymmetricMatrix};
use synovia_mesh::Mesh;

use crate::error::FetiError;

/// One subdomain of one body.
#[derive(Debug)]
pub struct Subdomain {
    /// The body.
    pub body: usize,
    /// Its cells (indices into the body's mesh), sorted.
    pub cells: Vec<usize>,
    /// Its nodes (body node indices), sorted; local node `a` has dofs `D a .. D a + D`.
    pub nodes: Vec<usize>,
    /// Orthonormal kernel basis `R_s` (`D · nodes` × `r_s`).
    pub kernel: DMatrix<f64>,
    /// The fixing dofs (sorted).
    pub fixing: Vec<usize>,
    /// Local dof → index into `K_rr` (`usize::MAX` for fixing dofs).
    free_index: Vec<usize>,
    /// The factorisation of `K_rr` (on the rank that owns the subdomain only).
    factor: Option<SparseCholesky>,
    /// `K_s` by rows (all local dofs; entries sorted by column), kept for the preconditioners.
    stiffness: Vec<Vec<(usize, f64)>>,
}

/// Rigid-body modes of points `x` (scaled, centred), orthonormalised with rank detection.
pub fn rigid_body_modes<const D: usize>(points: &[synovia_mesh::math::Point<D>]) -> DMatrix<f64> {
    let n = points.len();
    let nm = if D == 2 { 3 } else { 6 };
    let mut c = nalgebra::SVector::<f64, D>::zeros();
    for p in points {
        c += p;
    }
    c /= n.max(1) as f64;
    let scale = points.iter().map(|p| (p - c).norm()).fold(0.0_f64, f64::max).max(f64::MIN_POSITIVE);
    let mut r = DMatrix::<f64>::zeros(D * n, nm);
    for (a, p) in points.iter().enumerate() {
        let y = (p - c) / scale;
        for k in 0..D {
            r[(D * a + k, k)] = 1.0;
        }
        if D == 2 {
            r[(D * a, 2)] = -y[1];
            r[(D * a + 1, 2)] = y[0];
        } else {
            // e_x × y = (0, −y_z, y_y), e_y × y = (y_z, 0, −y_x), e_z × y = (−y_y, y_x, 0)
            r[(D * a + 1, 3)] = -y[2];
            r[(D * a + 2, 3)] = y[1];
            r[(D * a, 4)] = y[2];
            r[(D * a + 2, 4)] = -y[0];
            r[(D * a, 5)] = -y[1];
            r[(D * a + 1, 5)] = y[0];
        }
    }
    orthonormal_columns(r, 1e-10)
}

/// Modified Gram–Schmidt (twice) on the columns; columns whose remaining norm is below
/// `tol ×` their original norm are dropped.
pub fn orthonormal_columns(m: DMatrix<f64>, tol: f64) -> DMatrix<f64> {
    let mut kept: Vec<nalgebra::DVector<f64>> = Vec::new();
    for j in 0..m.ncols() {
        let mut v = m.column(j).into_owned();
        let n0 = v.norm();
        if n0 == 0.0 {
            continue;
        }
        for _ in 0..2 {
            for q in &kept {
                let d = q.dot(&v);
                v.axpy(-d, q, 1.0);
            }
        }
        let n1 = v.norm();
        if n1 > tol * n0 {
            kept.push(v / n1);
        }
    }
    let rows = m.nrows();
    DMatrix::from_fn(rows, kept.len(), |i, j| kept[j][i])
}

/// `r` rows of `kernel` (dofs) whose square submatrix is well conditioned: pivoted
/// Gram–Schmidt on the rows (largest remaining norm first).
fn fixing_dofs(kernel: &DMatrix<f64>) -> Vec<usize> {
    let (n, r) = (kernel.nrows(), kernel.ncols());
    let mut rows: Vec<nalgebra::DVector<f64>> = (0..n).map(|i| kernel.row(i).transpose()).collect();
    let mut chosen = Vec::with_capacity(r);
    for _ in 0..r {
        let mut best = (0.0, usize::MAX);
        for (i, v) in rows.iter().enumerate() {
            let nv = v.norm_squared();
            if nv > best.0 && !chosen.contains(&i) {
                best = (nv, i);
            }
        }
        if best.1 == usize::MAX {
            break;
        }
        let q = rows[best.1].clone() / best.0.sqrt();
        chosen.push(best.1);
        for v in rows.iter_mut() {
            let d = q.dot(v);
            v.axpy(-d, &q, 1.0);
        }
    }
    chosen.sort_unstable();
    chosen
}

impl Subdomain {
    /// Builds the subdomain of `cells` of body `body` (mesh `mesh`, Voigt stiffness `c`):
    /// nodes, kernel and fixing dofs; with `factorise`, also assembles and factorises `K_rr`
    /// and checks the kernel against the element matrices (`index` names the subdomain in
    /// errors).
    pub fn new<const D: usize>(
        index: usize,
        body: usize,
        mesh: &Mesh<D>,
        c: &DMatrix<f64>,
        cells: Vec<usize>,
        factorise: bool,
    ) -> Result<Self, FetiError> {
        let mut nodes: Vec<usize> = cells.iter().flat_map(|&e| mesh.cell(e).iter().copied()).collect();
        nodes.sort_unstable();
        nodes.dedup();
        let points: Vec<_> = nodes.iter().map(|&i| *mesh.node(i)).collect();
        let kernel = rigid_body_modes::<D>(&points);
        let fixing = fixing_dofs(&kernel);
        let n = D * nodes.len();
        let mut free_index = vec![usize::MAX; n];
        let mut nf = 0;
        for (i, fi) in free_index.iter_mut().enumerate() {
            if fixing.binary_search(&i).is_err() {
                *fi = nf;
                nf += 1;
            }
        }
        let mut s =
            Self { body, cells, nodes, kernel, fixing, free_index, factor: None, stiffness: Vec::new() };
        if factorise {
            s.factorise::<D>(index, mesh, c)?;
        }
        Ok(s)
    }

    /// Number of dofs `D · nodes`.
    pub fn n_dofs(&self) -> usize {
        self.free_index.len()
    }

    /// Local index of body node `node`, if it belongs to the subdomain.
    pub fn local_node(&self, node: usize) -> Option<usize> {
        self.nodes.binary_search(&node).ok()
    }

    /// `true` if `K_rr` is factorised here.
    pub fn is_factorised(&self) -> bool {
        self.factor.is_some()
    }

    fn local_cell_dofs<const D: usize>(&self, mesh: &Mesh<D>, e: usize) -> Vec<usize> {
        let mut dofs = Vec::with_capacity(D * (D + 1));
        for &n in mesh.cell(e) {
            let a = self.local_node(n).unwrap_or(0);
            dofs.extend((0..D).map(|k| D * a + k));
        }
        dofs
    }

    fn factorise<const D: usize>(
        &mut self,
        index: usize,
        mesh: &Mesh<D>,
        c: &DMatrix<f64>,
    ) -> Result<(), FetiError> {
        let ne = D * (D + 1);
        let nf = self.free_index.iter().filter(|&&i| i != usize::MAX).count();
        // pattern of K_rr (lower triangle by columns)
        let mut columns: Vec<Vec<usize>> = vec![Vec::new(); nf];
        let mut cell_dofs = Vec::with_capacity(self.cells.len());
        for &e in &self.cells {
            let dofs = self.local_cell_dofs::<D>(mesh, e);
            for &i in &dofs {
                for &j in &dofs {
                    let (fi, fj) = (self.free_index[i], self.free_index[j]);
                    if fi != usize::MAX && fj != usize::MAX && fi >= fj {
                        columns[fj].push(fi);
                    }
                }
            }
            cell_dofs.push(dofs);
        }
        for col in columns.iter_mut() {
            col.sort_unstable();
            col.dedup();
        }
        let mut k = SymmetricMatrix::from_columns(nf, columns)?;
        let mut ke = vec![0.0; ne * ne];
        let r = &self.kernel;
        let mut kr = DMatrix::<f64>::zeros(self.n_dofs(), r.ncols());
        let mut k_norm2 = 0.0;
        let mut full: Vec<Vec<(usize, f64)>> = vec![Vec::new(); self.n_dofs()];
        for (&e, dofs) in self.cells.iter().zip(&cell_dofs) {
            let pts = mesh.cell_points(e);
            let geo = SimplexGeometry::new(&pts).ok_or_else(|| FetiError::Subdomain {
                subdomain: index,
                message: format!("cell {e} of body {} is degenerate", self.body),
            })?;
            stiffness_into(&geo, c, &mut ke);
            for (a, &i) in dofs.iter().enumerate() {
                for (b, &j) in dofs.iter().enumerate() {
                    let v = ke[a * ne + b];
                    k_norm2 += v * v;
                    full[i].push((j, v));
                    for m in 0..r.ncols() {
                        kr[(i, m)] += v * r[(j, m)];
                    }
                    let (fi, fj) = (self.free_index[i], self.free_index[j]);
                    if fi != usize::MAX && fj != usize::MAX && fi >= fj {
                        k.add(fi, fj, v)?;
                    }
                }
            }
        }
        let defect = kr.norm();
        if defect > 1e-9 * k_norm2.sqrt() {
            return Err(FetiError::Subdomain {
                subdomain: index,
                message: format!(
                    "the rigid-body modes are not in the kernel of the stiffness: ‖K R‖ = {defect:.3e}, ‖K‖ ≈ {:.3e}",
                    k_norm2.sqrt()
                ),
            });
        }
        let factor = SparseCholesky::new(k, &Ordering::Amd).map_err(|e| FetiError::Subdomain {
            subdomain: index,
            message: format!(
                "the stiffness without the {} fixing dofs is not positive definite (kernel larger than the rigid-body modes?): {e}",
                self.fixing.len()
            ),
        })?;
        self.factor = Some(factor);
        for row in full.iter_mut() {
            row.sort_by_key(|e| e.0);
            let mut merged: Vec<(usize, f64)> = Vec::with_capacity(row.len());
            for &(j, v) in row.iter() {
                match merged.last_mut() {
                    Some(l) if l.0 == j => l.1 += v,
                    _ => merged.push((j, v)),
                }
            }
            *row = merged;
        }
        self.stiffness = full;
        Ok(())
    }

    /// `y = K_s x` (all local dofs; `K_s` is kept by the rank that factorised it).
    pub fn apply_stiffness(&self, x: &[f64], y: &mut [f64]) {
        for (yi, row) in y.iter_mut().zip(&self.stiffness) {
            *yi = row.iter().map(|&(j, v)| v * x[j]).sum();
        }
    }

    /// The Schur complement `S_s = K_bb − K_bi K_ii⁻¹ K_ib` of `K_s` on the local dofs
    /// `boundary` (sorted; the dofs the dual rows touch), with `K_ii` factorised
    /// ([`DirichletBlock::apply`]).
    ///
    /// # Errors
    /// [`FetiError::Subdomain`] if `K_ii` is not positive definite (the boundary dofs do not fix
    /// the rigid-body modes) or the subdomain is not factorised here.
    pub fn dirichlet_block(&self, boundary: &[usize], index: usize) -> Result<DirichletBlock, FetiError> {
        if self.stiffness.is_empty() {
            return Err(FetiError::Subdomain {
                subdomain: index,
                message: "not factorised on this rank".into(),
            });
        }
        let n = self.n_dofs();
        let mut interior = vec![usize::MAX; n];
        let mut ni = 0;
        for (i, slot) in interior.iter_mut().enumerate() {
            if boundary.binary_search(&i).is_err() {
                *slot = ni;
                ni += 1;
            }
        }
        let factor = if ni == 0 {
            None
        } else {
            let mut columns: Vec<Vec<usize>> = vec![Vec::new(); ni];
            for (i, row) in self.stiffness.iter().enumerate() {
                for &(j, _) in row {
                    let (a, b) = (interior[i], interior[j]);
                    if a != usize::MAX && b != usize::MAX && a >= b {
                        columns[b].push(a);
                    }
                }
            }
            let mut k = SymmetricMatrix::from_columns(ni, columns)?;
            for (i, row) in self.stiffness.iter().enumerate() {
                for &(j, v) in row {
                    let (a, b) = (interior[i], interior[j]);
                    if a != usize::MAX && b != usize::MAX && a >= b {
                        k.add(a, b, v)?;
                    }
                }
            }
            Some(SparseCholesky::new(k, &Ordering::Amd).map_err(|e| FetiError::Subdomain {
                subdomain: index,
                message: format!(
                    "the interior block K_ii of the Dirichlet preconditioner is not positive definite: {e}"
                ),
            })?)
        };
        Ok(DirichletBlock { interior, n_interior: ni, factor })
    }
}

/// The Dirichlet preconditioner's block of one subdomain: `K_ii` factorised (see
/// [`Subdomain::dirichlet_block`]).
pub struct DirichletBlock {
    interior: Vec<usize>,
    n_interior: usize,
    factor: Option<SparseCholesky>,
}

impl std::fmt::Debug for DirichletBlock {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DirichletBlock").field("n_interior", &self.n_interior).finish()
    }
}

impl DirichletBlock {
    /// `y = S_s x` for `x` zero on the interior dofs: `t = K_s x`, `w_i = K_ii⁻¹ t_i`,
    /// `y_b = t_b − (K_s w)_b` (`w` zero on the boundary); `y` is zero on the interior.
    ///
    /// # Errors
    /// Errors of the triangular solves.
    pub fn apply(&self, sub: &Subdomain, x: &[f64], y: &mut [f64]) -> Result<(), FetiError> {
        sub.apply_stiffness(x, y);
        let Some(f) = &self.factor else { return Ok(()) };
        let mut wi = vec![0.0; self.n_interior];
        for (i, &a) in self.interior.iter().enumerate() {
            if a != usize::MAX {
                wi[a] = y[i];
            }
        }
        f.solve_in_place(&mut wi)?;
        let w: Vec<f64> = self.interior.iter().map(|&a| if a != usize::MAX { wi[a] } else { 0.0 }).collect();
        let mut kw = vec![0.0; w.len()];
        sub.apply_stiffness(&w, &mut kw);
        for ((yi, &a), k) in y.iter_mut().zip(&self.interior).zip(&kw) {
            *yi = if a == usize::MAX { *yi - k } else { 0.0 };
        }
        Ok(())
    }
}

impl Subdomain {
    /// `x ← K_s⁺ x` (the fixing dofs of the result are 0).
    pub fn pinv_in_place(&self, x: &mut [f64], index: usize) -> Result<(), FetiError> {
        let f = self.factor.as_ref().ok_or_else(|| FetiError::Subdomain {
            subdomain: index,
            message: "not factorised on this rank".into(),
        })?;
        let nf = f.matrix.n();
        let mut b = vec![0.0; nf];
        for (i, &fi) in self.free_index.iter().enumerate() {
            if fi != usize::MAX {
                b[fi] = x[i];
            }
        }
        f.solve_in_place(&mut b)?;
        for (i, &fi) in self.free_index.iter().enumerate() {
            x[i] = if fi != usize::MAX { b[fi] } else { 0.0 };
        }
        Ok(())
    }
}
