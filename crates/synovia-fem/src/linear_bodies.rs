//! The linear bodies of a nonlinear model: their internal force as a product with their
//! constant stiffness instead of an element loop.
//!
//! A body in small strain ([`Kinematics::SmallStrain`]) whose material has a constant
//! stiffness `C` ([`synovia_material::Material::linear_stiffness`]) has the element forces
//! `F_int,T = |T| Bᵀ C B u_T` of [`crate::nonlinear::element_response`], so its internal force is
//! linear in its nodal displacements (lift included),
//!
//! ```text
//! F_int,b(u) = K_b u_b,   K_b = Σ_T |T| P_Tᵀ Bᵀ C B P_T   (D dofs per node, node-major),
//! ```
//!
//! and its strain energy is `Σ_T |T| ½ εᵀ C ε = ½ u_bᵀ K_b u_b`. [`LinearBodies`] keeps `K_b`
//! for every such body (e.g. the bones of `knee2d` with neo-Hookean cartilage, 77 % of the
//! cells) and [`LinearBodies::internal_force`] evaluates `Pᵀ F_int(u)` as the element loop of
//! [`crate::nonlinear::internal_force`] over the other bodies plus `Pᵀ K_b u_b`: the same
//! algebra, the sums in another order (equal to rounding).
//!
//! The tangent of those bodies is constant too: [`LinearBodies::refresh_tangent`] assembles
//! their part `K̃_lin = Σ_b Pᵀ K_b P` of the reduced tangent once, and
//! [`LinearBodies::assemble_tangent`] assembles `K_T(u)` of
//! [`crate::nonlinear::assemble_tangent`] as the element loop over the other bodies plus
//! `K̃_lin`.
//!
//! `K_b` is that of the body's mesh and material when it was built: a body whose nodes,
//! cells or stiffness `C` have changed since (e.g. a mesh moved in place by
//! `Mesh::map_nodes`) is evaluated by the element loop until
//! [`LinearBodies::refresh`] rebuilds its `K_b`.

use synovia_linalg::SymmetricMatrix;
use synovia_material::VoigtMatrix;
use synovia_mesh::math::{Point, Real, Vector};

use crate::assembly::cell_geometry;
use crate::dofs::DofMap;
use crate::error::FemError;
use crate::model::{BodyId, Model};
use crate::nonlinear::{assemble_tangent_of, check_kinematics, internal_force_of, Kinematics};

/// The stiffness `K_b` of each linear body of a model (module docs), for
/// [`LinearBodies::internal_force`].
#[derive(Debug, Clone, Default)]
pub struct LinearBodies<const D: usize> {
    /// Per body: its `K_b` and what it was built from, for the linear bodies.
    bodies: Vec<Option<LinearBody<D>>>,
    /// `K̃_lin` on the tangent's pattern and the bodies (per body: included) it sums.
    tangent: Option<(Vec<bool>, SymmetricMatrix)>,
}

/// `K_b` of one body and the mesh and stiffness it was built from.
#[derive(Debug, Clone)]
struct LinearBody<const D: usize> {
    nodes: Vec<Point<D>>,
    cells: Vec<usize>,
    c: VoigtMatrix,
    k: SymmetricMatrix,
}

impl<const D: usize> LinearBody<D> {
    /// `K_b` of body `b` (small strain, constant stiffness `c`); on the pattern of `previous`
    /// when that was built on the same cells (a mesh moved in place keeps its node graph).
    fn build(model: &Model<D>, b: usize, c: VoigtMatrix, previous: Option<Self>) -> Result<Self, FemError> {
        let body = &model.bodies()[b];
        let mesh = &body.mesh;
        let mut k = match previous.filter(|p| p.cells.as_slice() == mesh.cells_flat()) {
            Some(p) => {
                let mut k = p.k;
                k.zero();
                k
            }
            None => Self::pattern(mesh)?,
        };
        let n = D * (D + 1);
        let mut ke = vec![0.0; n * n];
        for ci in 0..mesh.n_cells() {
            let (geo, _) = cell_geometry(model, b, ci)?;
            // the element stiffness |T| Bᵀ C B (the tangent of the small-strain element
            // response, without its stress and energy)
            crate::element::stiffness_into(&geo, &c, &mut ke);
            let cell = mesh.cell(ci);
            for (pa, &na) in cell.iter().enumerate() {
                for (pb, &nb) in cell.iter().enumerate() {
                    for i in 0..D {
                        for j in 0..D {
                            let (r, s) = (D * na + i, D * nb + j);
                            if r >= s {
                                k.add(r, s, ke[(D * pa + i) * n + D * pb + j])?;
                            }
                        }
                    }
                }
            }
        }
        Ok(Self { nodes: mesh.nodes().to_vec(), cells: mesh.cells_flat().to_vec(), c, k })
    }

    /// The pattern of `K_b`: the node graph of the cells, every node coupled to itself and
    /// its neighbours in all `D` components (lower triangle).
    fn pattern(mesh: &synovia_mesh::Mesh<D>) -> Result<SymmetricMatrix, FemError> {
        let nn = mesh.n_nodes();
        let mut adj: Vec<Vec<usize>> = (0..nn).map(|i| vec![i]).collect();
        for cell in mesh.cells() {
            for &p in cell {
                adj[p].extend_from_slice(cell);
            }
        }
        let columns: Vec<Vec<usize>> = (0..D * nn)
            .map(|col| {
                let a = col / D;
                let mut rows: Vec<usize> = adj[a]
                    .iter()
                    .flat_map(|&q| (0..D).map(move |k| D * q + k))
                    .filter(|&r| r >= col)
                    .collect();
                rows.sort_unstable();
                rows.dedup();
                rows
            })
            .collect();
        Ok(SymmetricMatrix::from_columns(D * nn, columns)?)
    }

    /// `K_b` is that of body `b` of `model` as it is now.
    fn fits(&self, model: &Model<D>, b: usize) -> bool {
        let body = &model.bodies()[b];
        body.mesh.nodes() == self.nodes.as_slice()
            && body.mesh.cells_flat() == self.cells.as_slice()
            && body.material.linear_stiffness().is_some_and(|c| c == self.c)
    }
}

/// The stiffness `C` of body `b` if it is linear in the sense of the module docs.
fn linear_stiffness<const D: usize>(
    model: &Model<D>,
    kinematics: &[Kinematics],
    b: usize,
) -> Option<VoigtMatrix> {
    if kinematics.get(b) != Some(&Kinematics::SmallStrain) {
        return None;
    }
    model.bodies()[b].material.linear_stiffness()
}

impl<const D: usize> LinearBodies<D> {
    /// No linear body: [`LinearBodies::internal_force`] is [`crate::nonlinear::internal_force`].
    pub fn none() -> Self {
        Self { bodies: Vec::new(), tangent: None }
    }

    /// `K_b` of every body of `model` in small strain (`kinematics`, one per body) whose
    /// material has a constant stiffness.
    ///
    /// # Errors
    /// [`FemError::Length`] for a wrong number of kinematics; degenerate cells.
    pub fn new(model: &Model<D>, kinematics: &[Kinematics]) -> Result<Self, FemError> {
        let mut out = Self::none();
        out.refresh(model, kinematics)?;
        Ok(out)
    }

    /// Rebuilds `K_b` of the linear bodies whose mesh or stiffness changed since it was built
    /// (and drops those that are no longer linear).
    ///
    /// # Errors
    /// As [`LinearBodies::new`].
    pub fn refresh(&mut self, model: &Model<D>, kinematics: &[Kinematics]) -> Result<(), FemError> {
        let nb = model.bodies().len();
        if kinematics.len() != nb {
            return Err(FemError::Length {
                what: "kinematics (one per body)",
                expected: nb,
                got: kinematics.len(),
            });
        }
        self.bodies.resize_with(nb, || None);
        for b in 0..nb {
            let Some(c) = linear_stiffness(model, kinematics, b) else {
                self.bodies[b] = None;
                continue;
            };
            if self.bodies[b].as_ref().is_some_and(|l| l.fits(model, b)) {
                continue;
            }
            let previous = self.bodies[b].take();
            self.bodies[b] = Some(LinearBody::build(model, b, c, previous)?);
            self.tangent = None;
        }
        Ok(())
    }

    /// The kept `K_b` that fit the bodies of `model` as they are now, per body.
    fn in_use(&self, model: &Model<D>, kinematics: &[Kinematics]) -> Vec<bool> {
        (0..model.bodies().len())
            .map(|b| {
                self.bodies
                    .get(b)
                    .and_then(Option::as_ref)
                    .is_some_and(|l| kinematics.get(b) == Some(&Kinematics::SmallStrain) && l.fits(model, b))
            })
            .collect()
    }

    /// Assembles `K̃_lin = Σ_b Pᵀ K_b P` of the kept bodies on the pattern of `template`
    /// (the reduced tangent's, [`crate::assembly::pattern`]) unless it is already kept for
    /// them; call after [`LinearBodies::refresh`].
    ///
    /// # Errors
    /// As [`crate::nonlinear::assemble_tangent`].
    pub fn refresh_tangent(
        &mut self,
        model: &Model<D>,
        dofs: &DofMap<D>,
        kinematics: &[Kinematics],
        template: &SymmetricMatrix,
    ) -> Result<(), FemError> {
        let use_k = self.in_use(model, kinematics);
        let fits = |(set, m): &(Vec<bool>, SymmetricMatrix)| {
            *set == use_k && m.n() == template.n() && m.nnz() == template.nnz()
        };
        if self.tangent.as_ref().is_some_and(fits) || !use_k.iter().any(|u| *u) {
            return Ok(());
        }
        let others: Vec<bool> = use_k.iter().map(|u| !u).collect();
        let zero: Vec<Vec<Vector<D>>> =
            model.bodies().iter().map(|b| vec![Vector::<D>::zeros(); b.mesh.n_nodes()]).collect();
        let mut k = template.clone();
        assemble_tangent_of(model, dofs, kinematics, &zero, &mut k, &others)?;
        self.tangent = Some((use_k, k));
        Ok(())
    }

    /// The reduced tangent `Pᵀ K_T(u) P` of [`crate::nonlinear::assemble_tangent`] into
    /// `matrix`: the element loop over the bodies without a kept `K_b` that fits them, plus
    /// `K̃_lin` of [`LinearBodies::refresh_tangent`] (when it sums exactly those bodies and is
    /// on the pattern of `matrix`; otherwise the element loop over every body).
    ///
    /// # Errors
    /// As [`crate::nonlinear::assemble_tangent`].
    pub fn assemble_tangent(
        &self,
        model: &Model<D>,
        dofs: &DofMap<D>,
        kinematics: &[Kinematics],
        displacement: &[Vec<Vector<D>>],
        matrix: &mut SymmetricMatrix,
    ) -> Result<(), FemError> {
        let use_k = self.in_use(model, kinematics);
        match &self.tangent {
            Some((set, k)) if *set == use_k && k.n() == matrix.n() && k.nnz() == matrix.nnz() => {
                assemble_tangent_of(model, dofs, kinematics, displacement, matrix, &use_k)?;
                matrix.add_scaled(1.0, k)?;
                Ok(())
            }
            _ => assemble_tangent_of(model, dofs, kinematics, displacement, matrix, &[]),
        }
    }

    /// The bodies whose `K_b` is kept.
    pub fn bodies(&self) -> Vec<BodyId> {
        self.bodies.iter().enumerate().filter(|(_, l)| l.is_some()).map(|(b, _)| BodyId(b)).collect()
    }

    /// The reduced internal force `Pᵀ F_int(u)` and the strain energy of
    /// [`crate::nonlinear::internal_force`]: the element loop over the bodies without a kept
    /// `K_b` that fits them (module docs), `Pᵀ K_b u_b` and `½ u_bᵀ K_b u_b` for the others.
    ///
    /// # Errors
    /// As [`crate::nonlinear::internal_force`].
    pub fn internal_force(
        &self,
        model: &Model<D>,
        dofs: &DofMap<D>,
        kinematics: &[Kinematics],
        displacement: &[Vec<Vector<D>>],
    ) -> Result<(Vec<Real>, Real), FemError> {
        check_kinematics(model, kinematics, displacement)?;
        let use_k = self.in_use(model, kinematics);
        let (mut out, mut energy) = internal_force_of(model, dofs, kinematics, displacement, &use_k)?;
        let groups = dofs.groups();
        for (b, l) in self.bodies.iter().enumerate() {
            let Some(l) = l.as_ref().filter(|_| use_k[b]) else { continue };
            let u: Vec<Real> = displacement[b].iter().flat_map(|v| v.iter().copied()).collect();
            let mut f = vec![0.0; u.len()];
            l.k.mul_vec(&u, &mut f);
            energy += 0.5 * u.iter().zip(&f).map(|(a, c)| a * c).sum::<Real>();
            for node in 0..displacement[b].len() {
                let g = &groups[dofs.group_of(BodyId(b), node)];
                let v = Vector::<D>::from_fn(|i, _| f[D * node + i]);
                for k in 0..g.n_dofs {
                    out[g.first_dof + k] += g.basis[k].dot(&v);
                }
            }
        }
        Ok((out, energy))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nonlinear::internal_force;
    use std::sync::Arc;
    use synovia_material::{neo_hookean, plane_strain, Material};
    use synovia_mesh::generators::{rectangle, Grading};

    /// A neo-Hookean (finite strain) body on a linear one (small strain).
    fn model() -> (Model<2>, [Kinematics; 2], DofMap<2>, Vec<Vec<Vector<2>>>) {
        let mut model = Model::<2>::new();
        let law: Arc<dyn Material<2>> = Arc::new(neo_hookean(10.0, 0.3).expect("law"));
        let linear: Arc<dyn Material<2>> = Arc::new(plane_strain(50.0, 0.25).expect("law"));
        for (k, (y0, mat)) in [(0.0, law), (1.0, linear)].into_iter().enumerate() {
            let mesh =
                rectangle(0.0, 2.0, y0, y0 + 1.0, 12, 6, Grading::Uniform, Grading::Uniform).expect("mesh");
            model.add_body(&format!("b{k}"), mesh, mat).expect("body");
        }
        let dofs = DofMap::new(&model).expect("dofs");
        let disp = displacement(&model);
        (model, [Kinematics::FiniteStrain, Kinematics::SmallStrain], dofs, disp)
    }

    fn displacement(model: &Model<2>) -> Vec<Vec<Vector<2>>> {
        model
            .bodies()
            .iter()
            .map(|b| {
                b.mesh
                    .nodes()
                    .iter()
                    .map(|x| Vector::<2>::new(0.05 * x[1] * x[0], -0.08 * x[1].sin()))
                    .collect()
            })
            .collect()
    }

    fn max_rel(a: &[Real], b: &[Real]) -> Real {
        let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale
    }

    #[test]
    fn product_with_the_stiffness_equals_the_element_loop() {
        let (model, kin, dofs, disp) = model();
        let linear = LinearBodies::new(&model, &kin).expect("linear bodies");
        // only the small-strain body with a constant stiffness is kept
        assert_eq!(linear.bodies(), vec![BodyId(1)]);
        let (want, want_e) = internal_force(&model, &dofs, &kin, &disp).expect("loop");
        let (got, got_e) = linear.internal_force(&model, &dofs, &kin, &disp).expect("product");
        let err = max_rel(&got, &want);
        assert!(err < 1e-13, "force {err:e}");
        assert!((got_e - want_e).abs() <= 1e-13 * want_e.abs(), "energy {got_e} vs {want_e}");
        // in finite strain the same body is not linear: nothing kept
        let none = LinearBodies::new(&model, &[Kinematics::FiniteStrain; 2]).expect("none");
        assert!(none.bodies().is_empty());
    }

    /// The largest difference of two matrices on the same pattern, relative to the largest
    /// entry of `b`.
    fn matrix_rel(a: &SymmetricMatrix, b: &SymmetricMatrix) -> Real {
        max_rel(a.values(), b.values())
    }

    #[test]
    fn tangent_with_the_kept_linear_part_equals_the_element_loop() {
        let (mut model, kin, dofs, disp) = model();
        let (template, _) = crate::assembly::pattern(&model, &dofs).expect("pattern");
        let mut linear = LinearBodies::new(&model, &kin).expect("linear bodies");
        linear.refresh_tangent(&model, &dofs, &kin, &template).expect("K_lin");
        let (mut want, mut got) = (template.clone(), template.clone());
        crate::nonlinear::assemble_tangent(&model, &dofs, &kin, &disp, &mut want).expect("loop");
        linear.assemble_tangent(&model, &dofs, &kin, &disp, &mut got).expect("split");
        let err = matrix_rel(&got, &want);
        assert!(err < 1e-13, "tangent {err:e}");
        // the linear body moved: the element loop until refreshed, then the new K_lin
        let (s, c) = (0.3_f64.sin(), 0.3_f64.cos());
        model
            .body_mut(BodyId(1))
            .expect("body")
            .mesh
            .map_nodes(|x| Point::<2>::new(c * x[0] - s * x[1], s * x[0] + c * x[1]))
            .expect("rotate");
        crate::nonlinear::assemble_tangent(&model, &dofs, &kin, &disp, &mut want).expect("loop");
        linear.assemble_tangent(&model, &dofs, &kin, &disp, &mut got).expect("fallback");
        assert!(matrix_rel(&got, &want) < 1e-13);
        linear.refresh(&model, &kin).expect("refresh");
        linear.refresh_tangent(&model, &dofs, &kin, &template).expect("K_lin");
        linear.assemble_tangent(&model, &dofs, &kin, &disp, &mut got).expect("split");
        let err = matrix_rel(&got, &want);
        assert!(err < 1e-13, "tangent after the move {err:e}");
    }

    #[test]
    fn a_moved_mesh_is_not_evaluated_with_its_old_stiffness() {
        let (mut model, kin, dofs, _) = model();
        let mut linear = LinearBodies::new(&model, &kin).expect("linear bodies");
        // rotate the linear body in place: its stiffness in global coordinates changes
        let (s, c) = (0.3_f64.sin(), 0.3_f64.cos());
        model
            .body_mut(BodyId(1))
            .expect("body")
            .mesh
            .map_nodes(|x| Point::<2>::new(c * x[0] - s * x[1], s * x[0] + c * x[1]))
            .expect("rotate");
        let disp = displacement(&model);
        let (want, want_e) = internal_force(&model, &dofs, &kin, &disp).expect("loop");
        let stale = linear.bodies[1].as_ref().map(|l| l.k.values().to_vec()).expect("kept");
        // before the refresh: the element loop for the moved body (its K_b no longer fits)
        let (got, got_e) = linear.internal_force(&model, &dofs, &kin, &disp).expect("fallback");
        assert!(max_rel(&got, &want) < 1e-13 && (got_e - want_e).abs() <= 1e-13 * want_e.abs());
        // after it: the product with the rebuilt K_b
        linear.refresh(&model, &kin).expect("refresh");
        let fresh = linear.bodies[1].as_ref().map(|l| l.k.values().to_vec()).expect("kept");
        assert!(stale.iter().zip(&fresh).any(|(a, b)| (a - b).abs() > 1e-6), "K_b rebuilt");
        // rebuilt on the kept pattern (same cells): the K_b of a fresh build, to the last bit
        let built = LinearBodies::new(&model, &kin).expect("fresh");
        let built = built.bodies[1].as_ref().map(|l| l.k.values().to_vec()).expect("kept");
        assert_eq!(fresh, built);
        let (got, got_e) = linear.internal_force(&model, &dofs, &kin, &disp).expect("product");
        let err = max_rel(&got, &want);
        assert!(err < 1e-13, "force {err:e}");
        assert!((got_e - want_e).abs() <= 1e-13 * want_e.abs());
    }
}
