//! Nonlinear elasticity on P1 simplices (docs/model.md §2.3): the internal force `F_int(u)` and
//! the tangent stiffness `K_T(u) = ∂F_int/∂u` of bodies with any [`Material`] (linear or not),
//! in small-strain or total Lagrangian finite-strain kinematics.
//!
//! ## Small strain (`Kinematics::SmallStrain`)
//!
//! With `ε = B u` (the strain–displacement matrix of [`crate::element`]), `τ = τ(ε)` the
//! material's stress and `C_T = ∂τ/∂ε` its tangent:
//!
//! ```text
//! F_int,T = |T| Bᵀ τ(B u_T),     K_T = |T| Bᵀ C_T(B u_T) B.
//! ```
//!
//! ## Finite strain, total Lagrangian (`Kinematics::FiniteStrain`)
//!
//! On the reference cell, `F = I + ∇u` (constant on a P1 cell), the Green–Lagrange strain
//! `E = ½(FᵀF − I)`, the second Piola–Kirchhoff stress `S = τ(E)` and `𝕔 = ∂S/∂E` (the same
//! [`Material`] evaluated at `E`). The variation of `E` for the nodal displacement `δu_{a,i}` is
//! `δE_JK = ½(F_iJ ∂_K φ_a + F_iK ∂_J φ_a)`, i.e. the rows of the nonlinear strain–displacement
//! matrix `B_NL(F)`, and
//!
//! ```text
//! F_int,T = |T| B_NLᵀ S,
//! K_T = |T| (B_NLᵀ 𝕔 B_NL + G),   G_(a,i),(b,k) = δ_ik ∇φ_aᵀ S ∇φ_b   (geometric stiffness),
//! ```
//!
//! the first variation of `Π_int = Σ_T |T| W(E)` and its Hessian. In 2D the kinematics are
//! plane strain. Loads (body forces, tractions) are dead loads on the reference configuration.
//! The Cauchy stress is `σ = J⁻¹ F S Fᵀ` ([`cauchy_stress`]).
//!
//! An element whose `det F ≤ 0` or whose material returns a non-finite stress is reported as
//! [`FemError::InvertedElement`]; the nonlinear solvers treat it as a failed step and cut it back.

use synovia_linalg::SymmetricMatrix;
use synovia_material::{Material, VoigtVector};
use synovia_mesh::math::{det, Real, Tensor, Vector};

use crate::dofs::DofMap;
use crate::element::{voigt_strain, SimplexGeometry};
use crate::error::FemError;
use crate::model::{BodyId, Model};

/// The kinematics of a body's strain measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Kinematics {
    /// `ε = ½(∇u + ∇uᵀ)`, equilibrium on the reference configuration (the model's default).
    #[default]
    SmallStrain,
    /// Total Lagrangian: `E = ½(FᵀF − I)`, `F = I + ∇u`, second Piola–Kirchhoff stress.
    FiniteStrain,
}

impl Kinematics {
    /// `"small"` or `"finite"`.
    pub fn name(&self) -> &'static str {
        match self {
            Kinematics::SmallStrain => "small",
            Kinematics::FiniteStrain => "finite",
        }
    }
}

/// The strain measure of the displacement gradient `∇u`: `ε(u)` (small strain) or the
/// Green–Lagrange strain `E = ½(∇u + ∇uᵀ + ∇uᵀ∇u)` (finite strain), Voigt with engineering shear.
pub fn strain_measure<const D: usize>(kinematics: Kinematics, grad_u: &Tensor<D>) -> Vec<Real> {
    match kinematics {
        Kinematics::SmallStrain => voigt_strain(grad_u),
        Kinematics::FiniteStrain => {
            let f = Tensor::<D>::identity() + grad_u;
            let e = (f.transpose() * f - Tensor::<D>::identity()) * 0.5;
            if D == 2 {
                vec![e[(0, 0)], e[(1, 1)], 2.0 * e[(0, 1)]]
            } else {
                vec![e[(0, 0)], e[(1, 1)], e[(2, 2)], 2.0 * e[(1, 2)], 2.0 * e[(0, 2)], 2.0 * e[(0, 1)]]
            }
        }
    }
}

/// The Cauchy stress `σ = J⁻¹ F S Fᵀ` (Voigt, plain shear) of a second Piola–Kirchhoff stress
/// `s` (Voigt) at the displacement gradient `∇u`; `None` if `det F ≤ 0`. In 2D (plane strain)
/// the in-plane components.
pub fn cauchy_stress<const D: usize>(grad_u: &Tensor<D>, s: &[Real]) -> Option<Vec<Real>> {
    let f = Tensor::<D>::identity() + grad_u;
    let j = det(&f);
    if j.is_nan() || j <= 0.0 {
        return None;
    }
    let st = crate::element::stress_tensor::<D>(s);
    let sigma = f * st * f.transpose() / j;
    Some(if D == 2 {
        vec![sigma[(0, 0)], sigma[(1, 1)], sigma[(0, 1)]]
    } else {
        vec![sigma[(0, 0)], sigma[(1, 1)], sigma[(2, 2)], sigma[(1, 2)], sigma[(0, 2)], sigma[(0, 1)]]
    })
}

/// The Voigt rows `(J, K)` of dimension `D` (engineering shear order of [`voigt_strain`]).
fn pairs<const D: usize>() -> &'static [(usize, usize)] {
    const P2: [(usize, usize); 3] = [(0, 0), (1, 1), (0, 1)];
    const P3: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)];
    if D == 2 {
        &P2
    } else {
        &P3
    }
}

/// Why an element could not be evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementFailure {
    /// `det F` (finite strain; 1 for small strain).
    pub det_f: Real,
}

/// The response of one cell at nodal displacements `u` (node-major, `D(D+1)` entries):
/// writes the internal force `F_int,T` into `force`, the tangent `K_T` (row-major
/// `D(D+1)` square) into `tangent` if given, and returns the strain energy `|T| Φ`.
///
/// # Errors
/// [`ElementFailure`] if `det F ≤ 0` or the material's stress, tangent or energy is not finite.
pub fn element_response<const D: usize>(
    geo: &SimplexGeometry<D>,
    material: &dyn Material<D>,
    kinematics: Kinematics,
    u: &[Real],
    force: &mut [Real],
    tangent: Option<&mut [Real]>,
) -> Result<Real, ElementFailure> {
    let n = D * (D + 1);
    let grad_u = geo.displacement_gradient(u);
    let f = Tensor::<D>::identity() + grad_u;
    let det_f = match kinematics {
        Kinematics::SmallStrain => 1.0,
        Kinematics::FiniteStrain => det(&f),
    };
    if det_f.is_nan() || det_f <= 0.0 {
        return Err(ElementFailure { det_f });
    }
    let strain = VoigtVector::from_vec(strain_measure::<D>(kinematics, &grad_u));
    // the stress, energy and (if asked) tangent of one evaluation of the material
    let (stress, energy_density, material_tangent) = material.response(&strain, tangent.is_some());
    let energy = energy_density * geo.measure;
    if stress.iter().any(|v| !v.is_finite()) || !energy.is_finite() {
        return Err(ElementFailure { det_f });
    }
    let pr = pairs::<D>();
    let nv = pr.len();
    // B (nv × n): rows of δe for each nodal dof (a, i)
    let mut b = [[0.0; 12]; 6];
    let mut grads = [Vector::<D>::zeros(); 4];
    for (a, g) in grads.iter_mut().enumerate().take(D + 1) {
        *g = geo.grad(a);
    }
    let grads = &grads[..=D];
    for (a, g) in grads.iter().enumerate() {
        for i in 0..D {
            for (r, &(jj, kk)) in pr.iter().enumerate() {
                // small strain: F = I in the formula below
                let (fij, fik) = match kinematics {
                    Kinematics::SmallStrain => {
                        (if i == jj { 1.0 } else { 0.0 }, if i == kk { 1.0 } else { 0.0 })
                    }
                    Kinematics::FiniteStrain => (f[(i, jj)], f[(i, kk)]),
                };
                b[r][D * a + i] = if jj == kk { fij * g[jj] } else { fij * g[kk] + fik * g[jj] };
            }
        }
    }
    for (q, fq) in force.iter_mut().enumerate().take(n) {
        *fq = geo.measure * (0..nv).map(|r| b[r][q] * stress[r]).sum::<Real>();
    }
    if let (Some(kt), Some(c)) = (tangent, material_tangent) {
        if c.iter().any(|v| !v.is_finite()) {
            return Err(ElementFailure { det_f });
        }
        let mut cb = [[0.0; 12]; 6];
        for r in 0..nv {
            for q in 0..n {
                cb[r][q] = (0..nv).map(|s| c[(r, s)] * b[s][q]).sum();
            }
        }
        for p in 0..n {
            for q in 0..n {
                kt[p * n + q] = geo.measure * (0..nv).map(|r| b[r][p] * cb[r][q]).sum::<Real>();
            }
        }
        if kinematics == Kinematics::FiniteStrain {
            let s = crate::element::stress_tensor::<D>(stress.as_slice());
            for a in 0..=D {
                let sga = s * grads[a];
                for bb in 0..=D {
                    let g = geo.measure * grads[bb].dot(&sga);
                    for i in 0..D {
                        kt[(D * a + i) * n + D * bb + i] += g;
                    }
                }
            }
        }
    }
    Ok(energy)
}

/// Nodal displacements of cell `c` of body `b` (node-major).
fn cell_displacement<const D: usize>(
    model: &Model<D>,
    b: usize,
    c: usize,
    displacement: &[Vec<Vector<D>>],
    out: &mut [Real],
) {
    for (a, &node) in model.bodies()[b].mesh.cell(c).iter().enumerate() {
        let u = displacement[b][node];
        for i in 0..D {
            out[D * a + i] = u[i];
        }
    }
}

/// The tangent `K_T` of cell `c` of body `b` at `displacement` into `out` (zeroed on failure),
/// the element kernel of [`assemble_tangent`] and [`subtract_tangent_lift`].
fn cell_tangent<const D: usize>(
    model: &Model<D>,
    kinematics: &[Kinematics],
    displacement: &[Vec<Vector<D>>],
    b: usize,
    c: usize,
    geo: &SimplexGeometry<D>,
    out: &mut [Real],
) -> Result<(), ElementFailure> {
    let n = D * (D + 1);
    let mut ue = [0.0; 12];
    let mut fe = [0.0; 12];
    cell_displacement(model, b, c, displacement, &mut ue[..n]);
    let material = model.bodies()[b].material.as_ref();
    let result = element_response(geo, material, kinematics[b], &ue[..n], &mut fe[..n], Some(&mut *out));
    if result.is_err() {
        out.iter_mut().for_each(|v| *v = 0.0);
    }
    result.map(|_| ())
}

pub(crate) fn check_kinematics<const D: usize>(
    model: &Model<D>,
    kinematics: &[Kinematics],
    displacement: &[Vec<Vector<D>>],
) -> Result<(), FemError> {
    let nb = model.bodies().len();
    if kinematics.len() != nb {
        return Err(FemError::Length {
            what: "kinematics (one per body)",
            expected: nb,
            got: kinematics.len(),
        });
    }
    if displacement.len() != nb {
        return Err(FemError::Length {
            what: "displacement (one field per body)",
            expected: nb,
            got: displacement.len(),
        });
    }
    for (b, body) in model.bodies().iter().enumerate() {
        if displacement[b].len() != body.mesh.n_nodes() {
            return Err(FemError::Length {
                what: "nodal displacements of a body",
                expected: body.mesh.n_nodes(),
                got: displacement[b].len(),
            });
        }
    }
    Ok(())
}

pub(crate) fn failure<const D: usize>(model: &Model<D>, b: usize, c: usize, e: ElementFailure) -> FemError {
    FemError::InvertedElement { body: model.bodies()[b].name.clone(), cell: c, det_f: e.det_f }
}

/// The reduced internal force `Pᵀ F_int(u)` and the strain energy `Σ_T |T| Φ` at the nodal
/// displacements `displacement[body][node]` (the full field, lift included), with one
/// [`Kinematics`] per body: `F_int = Σ_T ∫_T Bᵀ S(e(u))` (the element forces of
/// `element_response`) gathered on the dof groups, `(Pᵀ F)_g = N_gᵀ F_node`.
///
/// A model of at least [`INTERNAL_FORCE_CHUNK`] cells is evaluated in parallel on rayon's
/// pool, in chunks of that many cells (in (body, cell) order) whose partial sums are added in
/// chunk order: the result does not depend on the number of threads.
///
/// # Errors
/// [`FemError::Length`] for inconsistent sizes, [`FemError::InvertedElement`] (of the first
/// failing cell in (body, cell) order), degenerate cells.
pub fn internal_force<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    kinematics: &[Kinematics],
    displacement: &[Vec<Vector<D>>],
) -> Result<(Vec<Real>, Real), FemError> {
    internal_force_of(model, dofs, kinematics, displacement, &[])
}

/// [`internal_force`] of the bodies `b` with `skip.get(b) != Some(&true)` only (the element
/// loop, in parallel chunks of the cells of those bodies, in (body, cell) order).
pub(crate) fn internal_force_of<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    kinematics: &[Kinematics],
    displacement: &[Vec<Vector<D>>],
    skip: &[bool],
) -> Result<(Vec<Real>, Real), FemError> {
    use rayon::prelude::*;
    check_kinematics(model, kinematics, displacement)?;
    let cells: Vec<(usize, usize)> = model
        .bodies()
        .iter()
        .enumerate()
        .filter(|(b, _)| skip.get(*b) != Some(&true))
        .flat_map(|(b, body)| (0..body.mesh.n_cells()).map(move |c| (b, c)))
        .collect();
    // the element forces of `cells` added into `out`, their energies summed
    let accumulate = |cells: &[(usize, usize)], out: &mut [Real]| -> Result<Real, FemError> {
        let n = D * (D + 1);
        let mut energy = 0.0;
        let mut ue = vec![0.0; n];
        let mut fe = vec![0.0; n];
        let groups = dofs.groups();
        for &(b, c) in cells {
            let body = &model.bodies()[b];
            let (geo, _) = crate::assembly::cell_geometry(model, b, c)?;
            cell_displacement(model, b, c, displacement, &mut ue);
            energy += element_response(&geo, body.material.as_ref(), kinematics[b], &ue, &mut fe, None)
                .map_err(|e| failure(model, b, c, e))?;
            for (a, &node) in body.mesh.cell(c).iter().enumerate() {
                let g = &groups[dofs.group_of(BodyId(b), node)];
                let v = Vector::<D>::from_fn(|i, _| fe[D * a + i]);
                for k in 0..g.n_dofs {
                    out[g.first_dof + k] += g.basis[k].dot(&v);
                }
            }
        }
        Ok(energy)
    };
    let mut out = vec![0.0; dofs.n_dofs()];
    if cells.len() < INTERNAL_FORCE_CHUNK {
        let energy = accumulate(&cells, &mut out)?;
        return Ok((out, energy));
    }
    let partial: Vec<Result<(Vec<Real>, Real), FemError>> = cells
        .par_chunks(INTERNAL_FORCE_CHUNK)
        .map(|chunk| {
            let mut part = vec![0.0; dofs.n_dofs()];
            let energy = accumulate(chunk, &mut part)?;
            Ok((part, energy))
        })
        .collect();
    let mut energy = 0.0;
    for p in partial {
        let (part, e) = p?;
        out.iter_mut().zip(&part).for_each(|(o, v)| *o += v);
        energy += e;
    }
    Ok((out, energy))
}

/// Cells per parallel chunk of [`internal_force`] (a model with fewer cells is evaluated
/// sequentially).
pub const INTERNAL_FORCE_CHUNK: usize = 2048;

/// Assembles the reduced tangent stiffness `Pᵀ K_T(u) P` at the nodal displacements
/// `displacement` into `matrix` (on the model's pattern, [`crate::assembly::pattern`]; values
/// first set to zero), with one [`Kinematics`] per body. With linear materials and small
/// strain it is the stiffness `K̃` of the linear solve.
///
/// # Errors
/// As [`internal_force`], and the errors of [`crate::assembly::assemble_matrix`].
pub fn assemble_tangent<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    kinematics: &[Kinematics],
    displacement: &[Vec<Vector<D>>],
    matrix: &mut SymmetricMatrix,
) -> Result<(), FemError> {
    assemble_tangent_of(model, dofs, kinematics, displacement, matrix, &[])
}

/// [`assemble_tangent`] over the cells of the bodies `b` with `skip.get(b) != Some(&true)` only.
pub(crate) fn assemble_tangent_of<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    kinematics: &[Kinematics],
    displacement: &[Vec<Vector<D>>],
    matrix: &mut SymmetricMatrix,
    skip: &[bool],
) -> Result<(), FemError> {
    check_kinematics(model, kinematics, displacement)?;
    let first_failure = std::sync::Mutex::new(None::<(usize, usize, ElementFailure)>);
    let blocks = rayon::current_num_threads();
    crate::assembly::assemble_matrix_of(model, dofs, matrix, blocks, skip, |b, c, geo, out| {
        if let Err(e) = cell_tangent(model, kinematics, displacement, b, c, geo, out) {
            if let Ok(mut f) = first_failure.lock() {
                if f.as_ref().is_none_or(|x| (x.0, x.1) > (b, c)) {
                    *f = Some((b, c, e));
                }
            }
        }
    })?;
    let failed = first_failure.lock().ok().and_then(|f| *f);
    if let Some((b, c, e)) = failed {
        return Err(failure(model, b, c, e));
    }
    Ok(())
}

/// Subtracts the tangent's action on a change of the prescribed displacements:
/// `rhs −= Pᵀ K_T(u) Δu_p` with `Δu_p` given per dof group (`delta_lifts`, as
/// [`DofMap::lifts`]): the linearised response of the free unknowns to a new boundary
/// displacement (the predictor of a load level, so that a jump of the prescribed displacement
/// is not applied to the boundary nodes alone).
///
/// # Errors
/// As [`internal_force`]; [`FemError::Length`] for `delta_lifts` of the wrong length.
pub fn subtract_tangent_lift<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    kinematics: &[Kinematics],
    displacement: &[Vec<Vector<D>>],
    delta_lifts: &[Vector<D>],
    rhs: &mut [Real],
) -> Result<(), FemError> {
    check_kinematics(model, kinematics, displacement)?;
    if delta_lifts.len() != dofs.groups().len() {
        return Err(FemError::Length {
            what: "lift changes (one per dof group)",
            expected: dofs.groups().len(),
            got: delta_lifts.len(),
        });
    }
    let failed = std::cell::Cell::new(None::<(usize, usize, ElementFailure)>);
    crate::assembly::subtract_lift(model, dofs, delta_lifts, rhs, |b, c, geo, out| {
        if let Err(e) = cell_tangent(model, kinematics, displacement, b, c, geo, out) {
            if failed.get().is_none() {
                failed.set(Some((b, c, e)));
            }
        }
    })?;
    if let Some((b, c, e)) = failed.get() {
        return Err(failure(model, b, c, e));
    }
    Ok(())
}

/// Per cell of every body: the strain measure `e` (small-strain `ε` or Green–Lagrange `E`),
/// the stress (small strain: `τ`; finite strain: the Cauchy stress `σ = J⁻¹ F S Fᵀ`) and
/// `det F`, all Voigt (strain with engineering shear, stress plain).
///
/// # Errors
/// As [`internal_force`].
#[allow(clippy::type_complexity)]
pub fn cell_stresses<const D: usize>(
    model: &Model<D>,
    kinematics: &[Kinematics],
    displacement: &[Vec<Vector<D>>],
) -> Result<Vec<Vec<(Vec<Real>, Vec<Real>, Real)>>, FemError> {
    check_kinematics(model, kinematics, displacement)?;
    let n = D * (D + 1);
    let mut ue = vec![0.0; n];
    let mut out = Vec::with_capacity(model.bodies().len());
    for (b, body) in model.bodies().iter().enumerate() {
        let mut cells = Vec::with_capacity(body.mesh.n_cells());
        for c in 0..body.mesh.n_cells() {
            let pts = body.mesh.cell_points(c);
            let geo = SimplexGeometry::new(&pts).ok_or_else(|| FemError::Mesh {
                body: body.name.clone(),
                source: synovia_mesh::MeshError::DegenerateCell { cell: c, det: 0.0 },
            })?;
            cell_displacement(model, b, c, displacement, &mut ue);
            let grad_u = geo.displacement_gradient(&ue);
            let e = strain_measure::<D>(kinematics[b], &grad_u);
            let s = body.material.stress(&VoigtVector::from_vec(e.clone()));
            let (stress, det_f) = match kinematics[b] {
                Kinematics::SmallStrain => (s.iter().copied().collect::<Vec<_>>(), 1.0),
                Kinematics::FiniteStrain => {
                    let det_f = det(&(Tensor::<D>::identity() + grad_u));
                    let sigma = cauchy_stress::<D>(&grad_u, s.as_slice())
                        .ok_or(ElementFailure { det_f })
                        .map_err(|e| failure(model, b, c, e))?;
                    (sigma, det_f)
                }
            };
            if stress.iter().any(|v| !v.is_finite()) {
                return Err(failure(model, b, c, ElementFailure { det_f }));
            }
            cells.push((e, stress, det_f));
        }
        out.push(cells);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use synovia_material::neo_hookean;
    use synovia_mesh::math::Point;

    fn tet() -> SimplexGeometry<3> {
        let p = [
            Point::<3>::new(0.1, 0.0, 0.0),
            Point::<3>::new(1.0, 0.2, 0.0),
            Point::<3>::new(0.0, 1.1, 0.1),
            Point::<3>::new(0.2, 0.1, 0.9),
        ];
        SimplexGeometry::new(&p).expect("test data")
    }

    /// `F_int = ∂(|T|Φ)/∂u` and `K_T = ∂F_int/∂u` by central differences, both kinematics.
    #[test]
    fn force_and_tangent_are_derivatives_of_the_energy() {
        let geo = tet();
        let law = neo_hookean(10.0, 0.35).expect("test data");
        let u: Vec<Real> = (0..12).map(|k| 0.07 * ((k * 7 % 5) as Real - 2.0) + 0.01 * k as Real).collect();
        for kin in [Kinematics::SmallStrain, Kinematics::FiniteStrain] {
            let mut f = vec![0.0; 12];
            let mut k = vec![0.0; 144];
            element_response(&geo, &law, kin, &u, &mut f, Some(&mut k)).expect("test data");
            let h = 1e-6;
            for q in 0..12 {
                let (mut up, mut um) = (u.clone(), u.clone());
                up[q] += h;
                um[q] -= h;
                let (mut fp, mut fm) = (vec![0.0; 12], vec![0.0; 12]);
                let wp = element_response(&geo, &law, kin, &up, &mut fp, None).expect("test data");
                let wm = element_response(&geo, &law, kin, &um, &mut fm, None).expect("test data");
                let dw = (wp - wm) / (2.0 * h);
                assert!((dw - f[q]).abs() < 1e-6 * (1.0 + f[q].abs()), "{kin:?}: dW/du{q} {dw} vs {}", f[q]);
                for p in 0..12 {
                    let df = (fp[p] - fm[p]) / (2.0 * h);
                    assert!(
                        (df - k[p * 12 + q]).abs() < 1e-5 * (1.0 + k[p * 12 + q].abs()),
                        "{kin:?}: K[{p},{q}]"
                    );
                }
            }
            // symmetric
            for p in 0..12 {
                for q in 0..12 {
                    assert!((k[p * 12 + q] - k[q * 12 + p]).abs() < 1e-9 * (1.0 + k[p * 12 + q].abs()));
                }
            }
        }
    }

    /// The parallel [`internal_force`] (a model above [`INTERNAL_FORCE_CHUNK`] cells, a
    /// neo-Hookean finite-strain body and a linear small-strain one) equals the element forces
    /// gathered cell by cell in order to 1e-13, with the same energy, on 1 and 2 threads; an
    /// inverted element is reported as the first failing cell.
    #[test]
    fn parallel_internal_force_equals_the_sequential_sum() {
        use std::sync::Arc;
        use synovia_mesh::generators::{rectangle, Grading};
        let mut model = Model::<2>::new();
        let law = Arc::new(neo_hookean(10.0, 0.3).expect("law"));
        let linear = Arc::new(synovia_material::plane_strain(50.0, 0.25).expect("law"));
        for (k, (y0, mat)) in [(0.0, law as Arc<dyn Material<2>>), (1.0, linear)].into_iter().enumerate() {
            let mesh =
                rectangle(0.0, 2.0, y0, y0 + 1.0, 48, 24, Grading::Uniform, Grading::Uniform).expect("mesh");
            model.add_body(&format!("b{k}"), mesh, mat).expect("body");
        }
        let kinematics = [Kinematics::FiniteStrain, Kinematics::SmallStrain];
        let cells: usize = model.bodies().iter().map(|b| b.mesh.n_cells()).sum();
        assert!(cells > 2 * INTERNAL_FORCE_CHUNK);
        let dofs = DofMap::new(&model).expect("dofs");
        let disp: Vec<Vec<Vector<2>>> = model
            .bodies()
            .iter()
            .map(|b| {
                b.mesh
                    .nodes()
                    .iter()
                    .map(|x| Vector::<2>::new(0.05 * x[1] * x[0], -0.08 * x[1].sin()))
                    .collect()
            })
            .collect();
        // the reference: cell by cell, in (body, cell) order
        let mut want = vec![0.0; dofs.n_dofs()];
        let mut want_energy = 0.0;
        let (mut ue, mut fe) = (vec![0.0; 6], vec![0.0; 6]);
        for (b, body) in model.bodies().iter().enumerate() {
            for c in 0..body.mesh.n_cells() {
                let (geo, _) = crate::assembly::cell_geometry(&model, b, c).expect("geometry");
                cell_displacement(&model, b, c, &disp, &mut ue);
                want_energy +=
                    element_response(&geo, body.material.as_ref(), kinematics[b], &ue, &mut fe, None)
                        .expect("element");
                for (a, &node) in body.mesh.cell(c).iter().enumerate() {
                    let g = &dofs.groups()[dofs.group_of(BodyId(b), node)];
                    let v = Vector::<2>::new(fe[2 * a], fe[2 * a + 1]);
                    for k in 0..g.n_dofs {
                        want[g.first_dof + k] += g.basis[k].dot(&v);
                    }
                }
            }
        }
        let scale = want.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            let (got, energy) =
                pool.install(|| internal_force(&model, &dofs, &kinematics, &disp)).expect("force");
            let err = got.iter().zip(&want).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(err <= 1e-13 * scale, "{threads} threads: {err:e} (scale {scale:e})");
            assert!((energy - want_energy).abs() <= 1e-13 * want_energy.abs());
        }
        // two inverted cells of the finite-strain body: the first one in cell order is named
        let mut bad = disp.clone();
        let body = &model.bodies()[0];
        let (c1, c2) = (5, body.mesh.n_cells() - 3);
        for c in [c2, c1] {
            let first = body.mesh.cell(c)[0];
            let others: Vec<usize> = body.mesh.cell(c)[1..].to_vec();
            let mid = (body.mesh.node(others[0]) + body.mesh.node(others[1])) / 2.0;
            bad[0][first] = (mid - body.mesh.node(first)) * 2.0;
        }
        match internal_force(&model, &dofs, &kinematics, &bad) {
            Err(FemError::InvertedElement { cell, .. }) => assert!(cell <= c1, "cell {cell}"),
            other => panic!("expected an inverted element, got {other:?}"),
        }
    }

    #[test]
    fn rigid_rotation_is_stress_free_in_finite_strain() {
        let geo = tet();
        let law = neo_hookean(10.0, 0.3).expect("test data");
        let (s, c) = (0.6f64.sin(), 0.6f64.cos());
        let rot = Tensor::<3>::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        let verts = [[0.1, 0.0, 0.0], [1.0, 0.2, 0.0], [0.0, 1.1, 0.1], [0.2, 0.1, 0.9]];
        let mut u = vec![0.0; 12];
        for (a, x) in verts.iter().enumerate() {
            let x = Vector::<3>::new(x[0], x[1], x[2]);
            let y = rot * x - x;
            for i in 0..3 {
                u[3 * a + i] = y[i];
            }
        }
        let mut f = vec![0.0; 12];
        let w = element_response(&geo, &law, Kinematics::FiniteStrain, &u, &mut f, None).expect("test data");
        assert!(w.abs() < 1e-12 && f.iter().all(|v| v.abs() < 1e-12), "{w} {f:?}");
        // small strain sees a (spurious) strain for a finite rotation
        let w_small =
            element_response(&geo, &law, Kinematics::SmallStrain, &u, &mut f, None).expect("test data");
        assert!(w_small > 1e-3);
        // inverted
        let mut u_inv = vec![0.0; 12];
        for (a, x) in verts.iter().enumerate() {
            u_inv[3 * a] = -2.0 * x[0];
        }
        assert!(element_response(&geo, &law, Kinematics::FiniteStrain, &u_inv, &mut f, None).is_err());
    }
}
