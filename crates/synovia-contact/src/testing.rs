//! Small self-contained contact problems for solver tests and benchmarks.
//!
//! [`BlockOnFoundation`] is an elastic block whose top is pushed down (and sideways) by a
//! prescribed displacement onto a rigid, curved foundation below its bottom face: node `r` of
//! the bottom face has the gap `d_r = c (x_r − ½)²` (and `(y − ½)²` in 3D), normal `n = −e_D`,
//! so the contact zone is a strict subset of the face. Friction is Tresca with a given slip
//! bound `g_c` on every bottom node.

use std::sync::Arc;

use synovia_fem::{CholeskySolver, DofMap, ElasticParams, ElasticSolver, Model, SymmetricMatrix};
use synovia_material::{isotropic, plane_strain};
use synovia_mesh::generators::{box_mesh, rectangle, Grading};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::BoundaryKind;

use crate::error::ContactError;
use crate::problem::{ContactProblem, FrictionConstraints, NormalConstraints};
use crate::rows::SparseRows;

/// An owned contact problem (matrix, factorisation, load, operators).
#[derive(Debug, Clone)]
pub struct OwnedProblem {
    /// `A`.
    pub matrix: SymmetricMatrix,
    /// Its factorisation.
    pub factor: CholeskySolver,
    /// `F`.
    pub load: Vec<f64>,
    /// Normal constraints.
    pub normal: NormalConstraints,
    /// Friction constraints.
    pub friction: Option<FrictionConstraints>,
}

impl OwnedProblem {
    /// The borrowed problem view.
    pub fn problem(&self) -> ContactProblem<'_> {
        ContactProblem {
            matrix: &self.matrix,
            factor: &self.factor,
            load: &self.load,
            normal: &self.normal,
            friction: self.friction.as_ref(),
        }
    }
}

/// Parameters of the block-on-foundation test problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockOnFoundation {
    /// Cells along x (and y in 3D); the block is `1 × ½` (`1 × 1 × ½`).
    pub n: usize,
    /// Vertical push of the top (positive = down).
    pub push: f64,
    /// Horizontal shift of the top along x.
    pub shift: f64,
    /// Curvature of the foundation: `d = c (x − ½)²`.
    pub curvature: f64,
    /// Slip bound `g_c` (force per area); `None` = frictionless.
    pub slip_bound: Option<f64>,
}

impl Default for BlockOnFoundation {
    fn default() -> Self {
        Self { n: 16, push: 0.02, shift: 0.01, curvature: 0.5, slip_bound: Some(0.05) }
    }
}

impl BlockOnFoundation {
    /// Builds the problem in dimension `D` (2 or 3); E = 1, ν = 0.3 (plane strain in 2D).
    pub fn build<const D: usize>(&self) -> Result<OwnedProblem, ContactError> {
        let n = self.n.max(2);
        let (push, shift) = (self.push, self.shift);
        let mut model = Model::<D>::new();
        let top = "top";
        let bottom = "bottom";
        let mut mesh = if D == 2 {
            rectangle(0.0, 1.0, 0.0, 0.5, n, n / 2, Grading::Uniform, Grading::Uniform)?.recast::<D>()?
        } else {
            box_mesh([0.0; 3], [1.0, 1.0, 0.5], [n, n, n / 2], [Grading::Uniform; 3])?.recast::<D>()?
        };
        mesh.set_part_kind(top, BoundaryKind::Prescribed)?;
        mesh.set_part_kind(bottom, BoundaryKind::Contact)?;
        let b = model.add_body("block", mesh, Arc::new(block_material::<D>()?))?;
        model.prescribe(b, top, move |_, _| {
            Vector::<D>::from_fn(|i, _| {
                if i == 0 {
                    shift
                } else if i == D - 1 {
                    -push
                } else {
                    0.0
                }
            })
        })?;
        let mut solver = ElasticSolver::new(&model, ElasticParams::default())?;
        let (load, lifts) = solver.rhs(&model, 0.0)?;
        let _ = solver.solve(&model, 0.0)?;
        let dofs: &DofMap<D> = solver.dofs();
        let mesh = &model.bodies()[0].mesh;
        let part = mesh.boundary_part(bottom)?;
        let nodes = part.nodes();
        let mut weights = vec![0.0; mesh.n_nodes()];
        for f in part.facets() {
            let m = mesh.facet_measure(f) / D as f64;
            for &i in f {
                weights[i] += m;
            }
        }
        let ndofs = dofs.n_dofs();
        let mut bn = SparseRows::new(ndofs);
        let mut bt = SparseRows::new(ndofs);
        let (mut kappa, mut gap, mut shift_t) = (Vec::new(), Vec::new(), Vec::new());
        let normal = Vector::<D>::from_fn(|i, _| if i == D - 1 { -1.0 } else { 0.0 });
        for &node in &nodes {
            let gi = dofs.group_of(synovia_fem::BodyId(0), node);
            let g = &dofs.groups()[gi];
            let x: Point<D> = *mesh.node(node);
            let mut d = 0.0;
            for k in 0..D - 1 {
                d += self.curvature * (x[k] - 0.5).powi(2);
            }
            // [u_n] = u · n of the block (the foundation does not move)
            bn.push_row((0..g.n_dofs).map(|k| (g.first_dof + k, g.basis[k].dot(&normal))));
            kappa.push(weights[node]);
            gap.push(d - lifts[gi].dot(&normal));
            if let Some(gc) = self.slip_bound {
                for t in 0..D - 1 {
                    let tv = Vector::<D>::from_fn(|i, _| if i == t { 1.0 } else { 0.0 });
                    let s = gc * weights[node];
                    bt.push_row((0..g.n_dofs).map(|k| (g.first_dof + k, s * g.basis[k].dot(&tv))));
                    shift_t.push(0.0);
                }
            }
        }
        let friction =
            self.slip_bound.map(|_| FrictionConstraints { rows: bt, components: D - 1, shift: shift_t });
        Ok(OwnedProblem {
            matrix: solver.stiffness().clone(),
            factor: solver.cholesky().clone(),
            load,
            normal: NormalConstraints { rows: bn, weights: kappa, gap },
            friction,
        })
    }
}

/// E = 1, ν = 0.3: plane strain in 2D, isotropic in 3D.
fn block_material<const D: usize>() -> Result<synovia_material::LinearElastic<D>, ContactError> {
    let c = if D == 2 {
        plane_strain(1.0, 0.3).map(|m| m.stiffness().clone())
    } else {
        isotropic(1.0, 0.3).map(|m| m.stiffness().clone())
    }
    .map_err(synovia_fem::FemError::from)?;
    Ok(synovia_material::anisotropic::<D>(c).map_err(synovia_fem::FemError::from)?)
}
