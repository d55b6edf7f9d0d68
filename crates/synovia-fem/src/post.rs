//! Post-processing: strain and stress per cell, recovery to nodes, von Mises and principal
//! stresses, strain energy.

use nalgebra::{DVector, Matrix2, Matrix3};
use synovia_mesh::math::{Real, Vector};

use crate::element::{voigt_strain, SimplexGeometry};
use crate::error::FemError;
use crate::model::Model;

/// Stress and strain fields of one body.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyFields {
    /// Voigt strain per cell (engineering shear), `voigt_len(D)` each.
    pub cell_strain: Vec<Vec<Real>>,
    /// Voigt stress per cell.
    pub cell_stress: Vec<Vec<Real>>,
    /// Out-of-plane stress `σ_zz` per cell (2D; 0 in plane stress and 3D).
    pub cell_stress_zz: Vec<Real>,
    /// Von Mises stress per cell.
    pub cell_von_mises: Vec<Real>,
    /// Principal stresses per cell, descending (3 values: in 2D the in-plane pair and `σ_zz`,
    /// sorted together).
    pub cell_principal: Vec<[Real; 3]>,
    /// Voigt stress recovered to nodes (measure-weighted average of the adjacent cells).
    pub nodal_stress: Vec<Vec<Real>>,
    /// Von Mises stress recovered to nodes.
    pub nodal_von_mises: Vec<Real>,
    /// Strain energy `½ ∫ C e(u) : e(u) dx` of the body.
    pub strain_energy: Real,
}

/// Von Mises stress of a Voigt stress (with `σ_zz` for 2D):
/// `σ_vm = sqrt(½[(σ1−σ2)² + (σ2−σ3)² + (σ3−σ1)²] + 3(τ_xy² + τ_yz² + τ_xz²))`.
pub fn von_mises(voigt: &[Real], sigma_zz: Real) -> Real {
    let (sx, sy, sz, tyz, txz, txy) = if voigt.len() == 3 {
        (voigt[0], voigt[1], sigma_zz, 0.0, 0.0, voigt[2])
    } else {
        (voigt[0], voigt[1], voigt[2], voigt[3], voigt[4], voigt[5])
    };
    (0.5 * ((sx - sy).powi(2) + (sy - sz).powi(2) + (sz - sx).powi(2))
        + 3.0 * (txy * txy + tyz * tyz + txz * txz))
        .max(0.0)
        .sqrt()
}

/// Principal stresses (descending) of a Voigt stress; in 2D the in-plane eigenvalues and
/// `σ_zz`.
pub fn principal_stresses(voigt: &[Real], sigma_zz: Real) -> [Real; 3] {
    let mut p = if voigt.len() == 3 {
        let m = Matrix2::new(voigt[0], voigt[2], voigt[2], voigt[1]);
        let e = m.symmetric_eigenvalues();
        [e[0], e[1], sigma_zz]
    } else {
        let m = Matrix3::new(
            voigt[0], voigt[5], voigt[4], voigt[5], voigt[1], voigt[3], voigt[4], voigt[3], voigt[2],
        );
        let e = m.symmetric_eigenvalues();
        [e[0], e[1], e[2]]
    };
    p.sort_by(|a, b| b.total_cmp(a));
    p
}

/// The strain energy of all bodies, `Σ_bodies ½ ∫ ε : C ε` ([`BodyFields::strain_energy`]
/// summed over [`body_fields`]).
///
/// # Errors
/// As [`body_fields`].
///
/// Computes only the energy (no stresses kept, no principal stresses, no nodal recovery):
/// quasi-static and dynamic records call it at every step.
#[tracing::instrument(level = "debug", skip_all)]
pub fn total_strain_energy<const D: usize>(
    model: &Model<D>,
    displacement: &[Vec<Vector<D>>],
) -> Result<Real, FemError> {
    check_displacement(model, displacement)?;
    let mut energy = 0.0;
    let mut ue = vec![0.0; D * (D + 1)];
    for (body, u) in model.bodies().iter().zip(displacement) {
        for c in 0..body.mesh.n_cells() {
            let geo = cell_geometry(body, c)?;
            for (a, &n) in body.mesh.cell(c).iter().enumerate() {
                for i in 0..D {
                    ue[D * a + i] = u[n][i];
                }
            }
            let eps = DVector::from_vec(voigt_strain::<D>(&geo.displacement_gradient(&ue)));
            energy += geo.measure * body.material.energy_density(&eps);
        }
    }
    Ok(energy)
}

/// One displacement per body and per node of it.
fn check_displacement<const D: usize>(
    model: &Model<D>,
    displacement: &[Vec<Vector<D>>],
) -> Result<(), FemError> {
    if displacement.len() != model.bodies().len() {
        return Err(FemError::Length {
            what: "displacement bodies",
            expected: model.bodies().len(),
            got: displacement.len(),
        });
    }
    for (body, u) in model.bodies().iter().zip(displacement) {
        if u.len() != body.mesh.n_nodes() {
            return Err(FemError::Length {
                what: "body displacement",
                expected: body.mesh.n_nodes(),
                got: u.len(),
            });
        }
    }
    Ok(())
}

/// The geometry of cell `c` of `body` (an error for a degenerate cell).
fn cell_geometry<const D: usize>(
    body: &crate::model::Body<D>,
    c: usize,
) -> Result<SimplexGeometry<D>, FemError> {
    SimplexGeometry::<D>::new(&body.mesh.cell_points(c)).ok_or_else(|| FemError::Mesh {
        body: body.name.clone(),
        source: synovia_mesh::MeshError::DegenerateCell { cell: c, det: 0.0 },
    })
}

/// Computes the fields of every body from nodal displacements (`displacement[body][node]`).
#[tracing::instrument(level = "debug", skip_all)]
pub fn body_fields<const D: usize>(
    model: &Model<D>,
    displacement: &[Vec<Vector<D>>],
) -> Result<Vec<BodyFields>, FemError> {
    body_fields_with_kinematics(model, displacement, &[])
}

/// [`body_fields`] with the kinematics of each body (`kinematics[body]`; missing entries are
/// small strain): for a finite-strain body the strain is the Green–Lagrange strain
/// `E = ½(FᵀF − I)` and the stress the Cauchy stress `σ = J⁻¹ F S Fᵀ` (in 2D, `σ_zz = S_zz / J`),
/// and the energy `Σ_T |T| W(E)` on the reference cells (docs/model.md §2.3).
///
/// # Errors
/// As [`body_fields`]; [`FemError::InvertedElement`] for a cell with `det F ≤ 0`.
pub fn body_fields_with_kinematics<const D: usize>(
    model: &Model<D>,
    displacement: &[Vec<Vector<D>>],
    kinematics: &[crate::Kinematics],
) -> Result<Vec<BodyFields>, FemError> {
    check_displacement(model, displacement)?;
    let mut out = Vec::with_capacity(model.bodies().len());
    for (bi, (body, u)) in model.bodies().iter().zip(displacement).enumerate() {
        let finite = kinematics.get(bi) == Some(&crate::Kinematics::FiniteStrain);
        let nc = body.mesh.n_cells();
        let mut f = BodyFields {
            cell_strain: Vec::with_capacity(nc),
            cell_stress: Vec::with_capacity(nc),
            cell_stress_zz: Vec::with_capacity(nc),
            cell_von_mises: Vec::with_capacity(nc),
            cell_principal: Vec::with_capacity(nc),
            nodal_stress: Vec::new(),
            nodal_von_mises: Vec::new(),
            strain_energy: 0.0,
        };
        let nv = D * (D + 1) / 2;
        let mut acc = vec![vec![0.0; nv]; body.mesh.n_nodes()];
        let mut acc_vm = vec![0.0; body.mesh.n_nodes()];
        let mut weight = vec![0.0; body.mesh.n_nodes()];
        let mut ue = vec![0.0; D * (D + 1)];
        for c in 0..nc {
            let geo = cell_geometry(body, c)?;
            for (a, &n) in body.mesh.cell(c).iter().enumerate() {
                for i in 0..D {
                    ue[D * a + i] = u[n][i];
                }
            }
            let grad_u = geo.displacement_gradient(&ue);
            let (eps, sig, szz) = if finite {
                let e = crate::nonlinear::strain_measure::<D>(crate::Kinematics::FiniteStrain, &grad_u);
                let e = DVector::from_vec(e);
                let s = body.material.stress(&e);
                let det_f = synovia_mesh::math::det(&(synovia_mesh::math::Tensor::<D>::identity() + grad_u));
                let sigma = crate::nonlinear::cauchy_stress::<D>(&grad_u, s.as_slice())
                    .ok_or_else(|| FemError::InvertedElement { body: body.name.clone(), cell: c, det_f })?;
                let szz = if D == 2 { body.material.out_of_plane_stress(&e) / det_f } else { 0.0 };
                (e, DVector::from_vec(sigma), szz)
            } else {
                let eps = DVector::from_vec(voigt_strain::<D>(&grad_u));
                let sig = body.material.stress(&eps);
                let szz = if D == 2 { body.material.out_of_plane_stress(&eps) } else { 0.0 };
                (eps, sig, szz)
            };
            f.strain_energy += geo.measure * body.material.energy_density(&eps);
            let vm = von_mises(sig.as_slice(), szz);
            for &n in body.mesh.cell(c) {
                for (k, s) in sig.iter().enumerate() {
                    acc[n][k] += geo.measure * s;
                }
                acc_vm[n] += geo.measure * vm;
                weight[n] += geo.measure;
            }
            f.cell_principal.push(principal_stresses(sig.as_slice(), szz));
            f.cell_von_mises.push(vm);
            f.cell_stress_zz.push(szz);
            f.cell_strain.push(eps.iter().copied().collect());
            f.cell_stress.push(sig.iter().copied().collect());
        }
        for ((s, vm), w) in acc.iter_mut().zip(acc_vm.iter_mut()).zip(&weight) {
            if *w > 0.0 {
                s.iter_mut().for_each(|x| *x /= w);
                *vm /= w;
            }
        }
        f.nodal_stress = acc;
        f.nodal_von_mises = acc_vm;
        out.push(f);
    }
    Ok(out)
}

/// Reaction forces at the nodes of a part held by prescribed displacements (a clamped face, a
/// face tied to a rigid plate): the force the support exerts on the body at node `i`,
///
/// ```text
/// R_i = Σ_{T ∋ i} (K_T u_T)_i − Σ_{T ∋ i} ∫_T f φ_i dx,
/// ```
///
/// the internal (elastic) force at the node minus the body-force load it carries (a prescribed
/// part carries no traction and, being a Dirichlet part, no contact force of its own). With the
/// solution `displacement[body][node]` of an equilibrium problem, `Σ_i R_i` balances the
/// other loads on the body. Returns `(node, R_i)` for the part's nodes in ascending order.
///
/// # Errors
/// Unknown body or part, a nonlinear material ([`FemError::NonlinearMaterial`]), a degenerate
/// cell, a non-finite body force, or a displacement that does not fit the body.
pub fn part_reactions<const D: usize>(
    model: &Model<D>,
    body: crate::BodyId,
    part: &str,
    displacement: &[Vector<D>],
    t: Real,
) -> Result<Vec<(usize, Vector<D>)>, FemError> {
    use crate::element::stiffness_into;
    let b = model.body(body)?;
    let c = b
        .material
        .linear_stiffness()
        .ok_or_else(|| FemError::NonlinearMaterial { body: b.name.clone(), material: b.material.name() })?;
    let n = D * (D + 1);
    let mut ke = vec![0.0; n * n];
    // R_i = Σ_T ((K_T u_T)_i − f_T,i), summed in that order per component
    part_reactions_by(model, body, part, displacement, t, |geo, cell, _, fe, out| {
        stiffness_into(geo, &c, &mut ke);
        for (a, slot) in out.iter_mut().enumerate() {
            for p in 0..D {
                let row = &ke[(D * a + p) * n..(D * a + p + 1) * n];
                let mut s = -fe[D * a + p];
                for (bb, &j) in cell.iter().enumerate() {
                    for q in 0..D {
                        s += row[D * bb + q] * displacement[j][q];
                    }
                }
                slot[p] = s;
            }
        }
        Ok(())
    })
}

/// [`part_reactions`] of a body with any material and [`Kinematics`] (docs/nonlinear.md): the
/// internal force of `element_response` (`F_int,T = ∫_T Bᵀ S(e(u))`, the total Lagrangian
/// first Piola–Kirchhoff force in finite strain) in place of `K_T u_T`,
///
/// ```text
/// R_i = Σ_{T ∋ i} F_int,T,i(u_T) − Σ_{T ∋ i} ∫_T f φ_i dx,
/// ```
///
/// (the body force per reference volume). For a linear material in small strain it equals
/// [`part_reactions`] up to rounding.
///
/// # Errors
/// As [`part_reactions`] (but any material), and [`FemError::InvertedElement`] for a cell
/// with `det F ≤ 0`.
pub fn part_reactions_with_kinematics<const D: usize>(
    model: &Model<D>,
    body: crate::BodyId,
    part: &str,
    displacement: &[Vector<D>],
    t: Real,
    kinematics: crate::Kinematics,
) -> Result<Vec<(usize, Vector<D>)>, FemError> {
    let b = model.body(body)?;
    let n = D * (D + 1);
    let (mut ue, mut fi) = (vec![0.0; n], vec![0.0; n]);
    part_reactions_by(model, body, part, displacement, t, |geo, cell, ci, fe, out| {
        for (a, &j) in cell.iter().enumerate() {
            ue[D * a..D * a + D].copy_from_slice(displacement[j].as_slice());
        }
        crate::nonlinear::element_response(geo, b.material.as_ref(), kinematics, &ue, &mut fi, None)
            .map_err(|e| crate::nonlinear::failure(model, body.0, ci, e))?;
        for (a, slot) in out.iter_mut().enumerate() {
            for p in 0..D {
                slot[p] = fi[D * a + p] - fe[D * a + p];
            }
        }
        Ok(())
    })
}

/// The loop of [`part_reactions`]: for each cell with a node on the part, `element(geometry,
/// cell nodes, cell index, body-force load f_T, out)` writes the cell's reaction share per
/// cell node into `out`; the shares of the part's nodes are summed.
fn part_reactions_by<const D: usize>(
    model: &Model<D>,
    body: crate::BodyId,
    part: &str,
    displacement: &[Vector<D>],
    t: Real,
    mut element: impl FnMut(
        &SimplexGeometry<D>,
        &[usize],
        usize,
        &[Real],
        &mut [Vector<D>],
    ) -> Result<(), FemError>,
) -> Result<Vec<(usize, Vector<D>)>, FemError> {
    use crate::element::body_force_into;
    let b = model.body(body)?;
    let mesh = &b.mesh;
    if displacement.len() != mesh.nodes().len() {
        return Err(FemError::InvalidParameter(format!(
            "body `{}`: {} displacements for {} nodes",
            b.name,
            displacement.len(),
            mesh.nodes().len()
        )));
    }
    let nodes =
        mesh.boundary_part(part).map_err(|source| FemError::Mesh { body: b.name.clone(), source })?.nodes();
    let mut slot = vec![usize::MAX; mesh.nodes().len()];
    for (k, &i) in nodes.iter().enumerate() {
        slot[i] = k;
    }
    let rule = crate::QuadratureRule::simplex(D, 2)?;
    let n = D * (D + 1);
    let mut fe = vec![0.0; n];
    let mut share = vec![Vector::<D>::zeros(); D + 1];
    let mut out = vec![Vector::<D>::zeros(); nodes.len()];
    for (ci, cell) in mesh.cells().enumerate() {
        if cell.iter().all(|&i| slot[i] == usize::MAX) {
            continue;
        }
        let pts = mesh.cell_points(ci);
        let geo = SimplexGeometry::new(&pts).filter(|g| g.measure > 0.0).ok_or_else(|| FemError::Mesh {
            body: b.name.clone(),
            source: synovia_mesh::MeshError::DegenerateCell { cell: ci, det: 0.0 },
        })?;
        match &b.body_force {
            Some(f) => {
                let f = |x: &synovia_mesh::math::Point<D>| f(x, t);
                body_force_into(&pts, geo.measure, &rule, &f, &mut fe).map_err(|x| {
                    FemError::InvalidParameter(format!("body `{}`: body force not finite at {x:?}", b.name))
                })?;
            }
            None => fe.iter_mut().for_each(|v| *v = 0.0),
        }
        element(&geo, cell, ci, &fe, &mut share)?;
        for (a, &i) in cell.iter().enumerate() {
            if slot[i] != usize::MAX {
                out[slot[i]] += share[a];
            }
        }
    }
    Ok(nodes.into_iter().zip(out).collect())
}
