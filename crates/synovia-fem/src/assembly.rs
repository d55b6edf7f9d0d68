//! Global assembly into the reduced unknowns of a [`DofMap`].
//!
//! For a cell `T` with element matrix `K_T` and element vector `f_T` the reduced contributions
//! are `P_Tᵀ K_T P_T` and `P_Tᵀ (f_T − K_T u_{p,T})`, where `P_T` stacks the bases `N` of the
//! cell's node groups and `u_{p,T}` their lifts (see [`crate::dofs`]). Matrices are accumulated
//! into the fixed lower-triangular pattern of [`SymmetricMatrix`]; [`pattern`] builds it once
//! and every later assembly only re-fills its values.

use nalgebra::DMatrix;
use synovia_mesh::math::{Point, Real, Vector};

use crate::dofs::DofMap;
use crate::element::{body_force_into, traction_into, SimplexGeometry};
use crate::error::FemError;
use crate::model::{BodyId, Model};
use crate::quadrature::QuadratureRule;
use crate::solver::Ordering;
use crate::sparse::SymmetricMatrix;

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
fn cell_geometry<const D: usize>(
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
pub fn assemble_matrix<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    matrix: &mut SymmetricMatrix,
    kernel: impl Fn(usize, usize, &SimplexGeometry<D>, &mut [Real]),
) -> Result<(), FemError> {
    if matrix.n() != dofs.n_dofs() {
        return Err(FemError::Length { what: "matrix", expected: dofs.n_dofs(), got: matrix.n() });
    }
    matrix.zero();
    let n = D * (D + 1);
    let mut ke = vec![0.0; n * n];
    let groups = dofs.groups();
    for (bi, body) in model.bodies().iter().enumerate() {
        for c in 0..body.mesh.n_cells() {
            let (geo, _) = cell_geometry(model, bi, c)?;
            kernel(bi, c, &geo, &mut ke);
            let cell = body.mesh.cell(c);
            for (a, &na) in cell.iter().enumerate() {
                let ga = &groups[dofs.group_of(BodyId(bi), na)];
                for (b, &nb) in cell.iter().enumerate() {
                    let gb = &groups[dofs.group_of(BodyId(bi), nb)];
                    if ga.free && gb.free {
                        for k in 0..D {
                            let r = ga.first_dof + k;
                            for l in 0..D {
                                let col = gb.first_dof + l;
                                if r >= col {
                                    matrix.add(r, col, ke[(D * a + k) * n + D * b + l])?;
                                }
                            }
                        }
                        continue;
                    }
                    for k in 0..ga.n_dofs {
                        let r = ga.first_dof + k;
                        for l in 0..gb.n_dofs {
                            let col = gb.first_dof + l;
                            if r < col {
                                continue;
                            }
                            let mut v = 0.0;
                            for i in 0..D {
                                for j in 0..D {
                                    v += ga.basis[k][i] * ke[(D * a + i) * n + D * b + j] * gb.basis[l][j];
                                }
                            }
                            matrix.add(r, col, v)?;
                        }
                    }
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

/// Adds the load `(f, v) = ∫ F · v dx + ∫_{¹Γ_τ} P · v ds` at time `t` (spec §2) to the
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
