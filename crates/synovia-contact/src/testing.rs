//! Small self-contained contact problems for solver tests and benchmarks.
//!
//! [`BlockOnFoundation`] is an elastic block whose top is pushed down (and sideways) by a
//! prescribed displacement onto a rigid, curved foundation below its bottom face: node `r` of
//! the bottom face has the gap `d_r = c (x_r − ½)²` (and `(y − ½)²` in 3D), normal `n = −e_D`,
//! so the contact zone is a strict subset of the face. Friction is Tresca with a given slip
//! bound `g_c` on every bottom node.

use std::sync::Arc;

use synovia_fem::{DofMap, ElasticParams, ElasticSolver, Model};
use synovia_linalg::{SparseCholesky, SparseRows};
use synovia_material::{isotropic, plane_strain};
use synovia_mesh::generators::{box_mesh, rectangle, Grading};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::BoundaryKind;

use crate::error::ContactError;
use crate::problem::{ContactProblem, FrictionConstraints, NormalConstraints};

/// An owned contact problem (matrix and factorisation, load, operators).
#[derive(Debug, Clone)]
pub struct OwnedProblem {
    /// `A` and its factorisation.
    pub system: SparseCholesky,
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
            operator: &self.system,
            load: &self.load,
            normal: &self.normal,
            friction: self.friction.as_ref(),
            border: None,
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
    /// Young's modulus (default 1).
    pub young: f64,
    /// Poisson's ratio (default 0.3; plane strain in 2D).
    pub poisson: f64,
    /// Random displacement of the interior nodes, as a fraction of the cell size `h`
    /// (default 0: a structured mesh). Each coordinate moves by at most `jitter · h / 2`.
    pub jitter: f64,
    /// Seed of the node jitter.
    pub seed: u64,
    /// Constant added to every gap: `d = c (x − ½)² + gap_offset` (default 0; negative values
    /// are an initial penetration).
    pub gap_offset: f64,
}

impl Default for BlockOnFoundation {
    fn default() -> Self {
        Self {
            n: 16,
            push: 0.02,
            shift: 0.01,
            curvature: 0.5,
            slip_bound: Some(0.05),
            young: 1.0,
            poisson: 0.3,
            jitter: 0.0,
            seed: 0,
            gap_offset: 0.0,
        }
    }
}

impl BlockOnFoundation {
    /// Builds the problem in dimension `D` (2 or 3) with `E = young`, `ν = poisson` (plane
    /// strain in 2D), interior nodes jittered by `jitter` (fraction of `h`).
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
        if self.jitter != 0.0 {
            if !(self.jitter.is_finite() && self.jitter.abs() < 0.5) {
                return Err(ContactError::InvalidParameter(format!(
                    "jitter {} must be a finite fraction of h below 0.5",
                    self.jitter
                )));
            }
            let h = 1.0 / n as f64;
            let (amp, seed) = (0.5 * self.jitter * h, self.seed);
            let hi = [1.0, if D == 2 { 0.5 } else { 1.0 }, 0.5];
            mesh.map_nodes(|x| {
                let interior = (0..D).all(|k| x[k] > 1e-9 && x[k] < hi[k] - 1e-9);
                if !interior {
                    return *x;
                }
                let mut key = seed;
                for k in 0..D {
                    key = splitmix(key ^ x[k].to_bits());
                }
                Point::<D>::from_fn(|k, _| {
                    let r = splitmix(key.wrapping_add(k as u64 + 1));
                    let unit = (r >> 11) as f64 / (1u64 << 53) as f64; // [0, 1)
                    x[k] + amp * (2.0 * unit - 1.0)
                })
            })?;
        }
        mesh.set_part_kind(top, BoundaryKind::Prescribed)?;
        mesh.set_part_kind(bottom, BoundaryKind::Contact)?;
        let b = model.add_body("block", mesh, Arc::new(block_material::<D>(self.young, self.poisson)?))?;
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
            let mut d = self.gap_offset;
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
            system: SparseCholesky { matrix: solver.stiffness().clone(), factor: solver.cholesky().clone() },
            load,
            normal: NormalConstraints { rows: bn, weights: kappa, gap },
            friction,
        })
    }
}

/// SplitMix64 step (a small deterministic hash for the node jitter).
fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// `E`, `ν`: plane strain in 2D, isotropic in 3D.
fn block_material<const D: usize>(
    e: f64,
    nu: f64,
) -> Result<synovia_material::LinearElastic<D>, ContactError> {
    let c = if D == 2 {
        plane_strain(e, nu).map(|m| m.stiffness().clone())
    } else {
        isotropic(e, nu).map(|m| m.stiffness().clone())
    }
    .map_err(synovia_fem::FemError::from)?;
    Ok(synovia_material::anisotropic::<D>(c).map_err(synovia_fem::FemError::from)?)
}

/// A plane-strain block `[0, 1] × [0, ¼]` (`nx × ny` cells, E = 1, ν = 0.3) whose top follows
/// the prescribed displacement `top(t)` and whose bottom is the contact part of the pair
/// `floor` (Coulomb coefficient 0.3) against the rigid shallow bump
/// `φ(x) = (y + 0.1 (x − ½)²) / √(1 + g²)`, `g = 0.2 (x − ½)`: pressed down, only part of the
/// bottom touches. For tests of the contact machinery on a caller's matrix and load.
///
/// # Errors
/// Mesh, model or pair errors (none for `nx, ny ≥ 1`).
pub fn block_on_bump(
    nx: usize,
    ny: usize,
    top: impl Fn(f64) -> Vector<2> + Send + Sync + 'static,
) -> Result<(Model<2>, Vec<crate::operators::ContactPair<2>>), ContactError> {
    let mut mesh = rectangle(0.0, 1.0, 0.0, 0.25, nx, ny, Grading::Uniform, Grading::Uniform)?;
    mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
    mesh.set_part_kind("bottom", BoundaryKind::Contact)?;
    let mut model = Model::<2>::new();
    let material = plane_strain(1.0, 0.3).map_err(synovia_fem::FemError::from)?;
    let b = model.add_body("block", mesh, Arc::new(material))?;
    model.prescribe(b, "top", move |_, t| top(t))?;
    let bump = crate::operators::FnObstacle::new(|x: &Point<2>| {
        let g = 0.2 * (x[0] - 0.5);
        let n = (1.0 + g * g).sqrt();
        ((x[1] + 0.1 * (x[0] - 0.5).powi(2)) / n, Vector::<2>::new(g / n, 1.0 / n))
    });
    let pairs =
        vec![crate::operators::ContactPair::rigid("floor", b, "bottom", Arc::new(bump)).with_friction(0.3)];
    Ok((model, pairs))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_moves_interior_nodes_only_and_keeps_a_valid_problem() {
        let base = BlockOnFoundation { n: 6, ..Default::default() };
        let a = base.build::<2>().expect("structured");
        let b = BlockOnFoundation { jitter: 0.3, seed: 7, ..base }.build::<2>().expect("jittered");
        // same rows (boundary nodes do not move), different stiffness
        assert_eq!(a.normal.gap, b.normal.gap);
        assert_eq!(a.normal.weights, b.normal.weights);
        assert_ne!(a.system.matrix.diagonal(), b.system.matrix.diagonal());
        let bad = BlockOnFoundation { jitter: 0.7, ..base }.build::<2>();
        assert!(matches!(bad, Err(ContactError::InvalidParameter(_))));
    }
}
