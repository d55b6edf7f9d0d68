//! # synovia-feti
//!
//! TFETI (total FETI) domain decomposition for the frictionless and Tresca contact problems of
//! docs/model.md §5 (docs/model.md §11, docs/scale-out.md).
//!
//! * [`Decomposition`]: each body's cells cut by METIS into subdomains (split into their
//!   facet-connected pieces), every subdomain floating — its stiffness `K_s` has all nodal
//!   dofs, its kernel `R_s` are the rigid-body modes (built from the nodes, checked against
//!   the element matrices, rank-revealing for subdomains with few nodes) and `K_s⁺` comes from a
//!   faer sparse Cholesky of `K_s` without `r_s` fixing dofs ([`subdomain`]); gluing and
//!   Dirichlet conditions are equality rows `B_E`.
//! * [`solve`]: the dual problem with the contact rows as bound multipliers (`λ_n ≥ 0`) and
//!   the Tresca rows as disc multipliers, the natural coarse space `G = Rᵀ Bᵀ` and its
//!   projector, SMALBE-M with MPRGP (2D) / MPGP (3D) from `synovia-uzawa` ([`dual`]), their
//!   conjugate gradient steps preconditioned in face by the projected Dirichlet (or lumped)
//!   preconditioner ([`Preconditioner`]); or ([`CoarseConstraint::Projector`]) the coarse
//!   condition eliminated by an oblique projector along the equality rows and one MPRGP/MPGP
//!   run; [`face_spectrum`] estimates the condition number the inner iterations see.
//! * Parallel execution: rayon's threads over the subdomains of a process, and — with the
//!   cargo feature `mpi` — MPI ranks ([`comm`]), one code: each rank factorises its own
//!   subdomains and only interface values travel. Sums are taken in subdomain order, so the
//!   result does not depend on the number of ranks or threads.
//! * [`Tfeti`]: the contact solver `"tfeti"` behind the `ContactSolver` seam, for a
//!   decomposition of the model whose contact problem it is given (see its docs for why it
//!   cannot be built from a name alone); [`ModelProblem`] builds the load and contact rows of a
//!   model without factorising the undecomposed stiffness (for models too large for that).
#![deny(unsafe_code)]

pub mod comm;
pub mod decomposition;
pub mod dual;
pub mod error;
pub mod partition;
pub mod subdomain;

use std::sync::Arc;

use synovia_contact::operators::{ContactGeometry, ContactPair};
use synovia_contact::{
    ContactError, ContactProblem, ContactSolution, ContactSolver, FrictionConstraints, NormalConstraints,
    SolveContext, SolverReport,
};
use synovia_fem::assembly::{add_loads, body_stiffnesses, subtract_lift};
use synovia_fem::element::stiffness_into;
use synovia_fem::model::Model;
use synovia_fem::DofMap;
use synovia_mesh::math::{Real, Vector};

#[cfg(feature = "mpi")]
pub use comm::MpiCommunicator;
pub use comm::{Communicator, SingleProcess};
pub use decomposition::{Decomposition, DecompositionParams, Gluing};
pub use dual::{
    face_spectrum, solve, CoarseConstraint, Preconditioner, SpectrumEstimate, TfetiParams, TfetiReport,
    TfetiSolution,
};
pub use error::FetiError;
pub use partition::Partitioner;
pub use synovia_uzawa::Expansion;

/// The contact solver `"tfeti"`: TFETI on a [`Decomposition`] of the model whose contact
/// problems it solves, in one process (rayon threads over the subdomains).
///
/// **Why it is built from a decomposition, not from a name.** The `ContactSolver` seam hands a
/// solver the *assembled* operator `A` of the undecomposed problem (`&dyn FactorisedOperator`).
/// TFETI needs the subdomain stiffnesses `K_s` before assembly — an assembled SPD matrix cannot
/// in general be split back into symmetric positive semi-definite subdomain parts — so the
/// solver must be given the model's decomposition. It then accepts any [`ContactProblem`] on
/// the model's reduced unknowns (the load, normal and friction rows come from the problem; the
/// operator is only checked for its size), so it runs behind `StaticContact::solve` like the
/// other solvers; `synovia::solvers::by_name("tfeti")` explains this in its error.
#[derive(Debug, Clone)]
pub struct Tfeti {
    decomposition: Arc<Decomposition>,
    params: TfetiParams,
}

impl Tfeti {
    /// The solver on `decomposition` with `params`.
    pub fn new(decomposition: Arc<Decomposition>, params: TfetiParams) -> Self {
        Self { decomposition, params }
    }
    /// Decomposes `model` (one process) and returns the solver.
    ///
    /// # Errors
    /// As [`Decomposition::new`].
    pub fn for_model<const D: usize>(
        model: &Model<D>,
        decomposition: &DecompositionParams,
        params: TfetiParams,
    ) -> Result<Self, FetiError> {
        Ok(Self::new(Arc::new(Decomposition::new(model, decomposition, &SingleProcess)?), params))
    }
    /// The decomposition.
    pub fn decomposition(&self) -> &Decomposition {
        &self.decomposition
    }
    /// Solves `problem` and returns the full TFETI report.
    ///
    /// # Errors
    /// As [`solve`].
    pub fn solve_traced(&self, problem: &ContactProblem<'_>) -> Result<TfetiSolution, FetiError> {
        if problem.operator.n() != self.decomposition.n_reduced() {
            return Err(FetiError::Mismatch {
                expected: self.decomposition.n_reduced(),
                got: problem.operator.n(),
            });
        }
        problem.validate()?;
        problem.refuse_border("tfeti")?;
        solve(
            &self.decomposition,
            &SingleProcess,
            problem.load,
            problem.normal,
            problem.friction,
            &self.params,
        )
    }
}

impl ContactSolver for Tfeti {
    fn name(&self) -> &str {
        "tfeti"
    }

    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        _context: &SolveContext,
    ) -> Result<ContactSolution, ContactError> {
        let s = self.solve_traced(problem)?;
        let (active, stick, slip) = contact_counts(&s.lambda_n, &s.lambda_t, problem.components());
        Ok(ContactSolution {
            u: s.u,
            lambda_n: s.lambda_n,
            lambda_t: s.lambda_t,
            report: SolverReport {
                solver: "tfeti".into(),
                iterations: s.report.outer_iterations,
                inner_iterations: s.report.inner_iterations,
                linear_solves: s.report.f_products,
                active,
                stick,
                slip,
                time_s: s.report.setup_s + s.report.solve_s,
                ..Default::default()
            },
        })
    }
}

fn contact_counts(ln: &[f64], lt: &[f64], comps: usize) -> (usize, usize, usize) {
    let active = ln.iter().filter(|&&l| l > 0.0).count();
    let mut stick = 0;
    let mut slip = 0;
    for c in lt.chunks(comps.max(1)) {
        if c.iter().map(|v| v * v).sum::<f64>().sqrt() < 1.0 - 1e-8 {
            stick += 1;
        } else {
            slip += 1;
        }
    }
    (active, stick, slip)
}

/// The load and contact rows of a model at time `t` in its reduced unknowns, built without
/// factorising the undecomposed stiffness: `F = Pᵀ (f − K u_p)` (docs/model.md §5.1, loads of
/// quadrature degree 2 as `ElasticParams::default`), `B_hn`, `κ`, `d` and, with slip bounds,
/// `B_Ht` and the shift from `previous` displacements (docs/model.md §5.4).
#[derive(Debug, Clone)]
pub struct ModelProblem<const D: usize> {
    /// The contact geometry of the pairs.
    pub geometry: ContactGeometry<D>,
    /// The dof map.
    pub dofs: DofMap<D>,
    /// `F`.
    pub load: Vec<f64>,
    /// Lifts of the prescribed displacements.
    pub lifts: Vec<Vector<D>>,
    /// Normal rows.
    pub normal: NormalConstraints,
    /// Tresca rows (with slip bounds).
    pub friction: Option<FrictionConstraints>,
}

impl<const D: usize> ModelProblem<D> {
    /// Builds the problem (see the type's docs).
    ///
    /// # Errors
    /// Errors of the geometry, the dof map and the load assembly.
    pub fn new(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        t: Real,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
    ) -> Result<Self, FetiError> {
        let geometry = ContactGeometry::new(model, pairs)?;
        let dofs = DofMap::new(model)?;
        let lifts = dofs.lifts(model, t)?;
        let mut load = vec![0.0; dofs.n_dofs()];
        add_loads(model, &dofs, t, 2, &mut load)?;
        let c = body_stiffnesses(model)?;
        subtract_lift(model, &dofs, &lifts, &mut load, |b, _, geo, out| stiffness_into(geo, &c[b], out))?;
        let normal = geometry.normal_constraints(&dofs, &lifts);
        let friction = match slip_bound {
            Some(g) => Some(geometry.friction_constraints(&dofs, &lifts, g, previous)?.constraints),
            None => None,
        };
        Ok(Self { geometry, dofs, load, lifts, normal, friction })
    }

    /// Solves it by TFETI on `decomposition` (collective over `comm`).
    ///
    /// # Errors
    /// As [`solve`].
    pub fn solve(
        &self,
        decomposition: &Decomposition,
        comm: &dyn Communicator,
        params: &TfetiParams,
    ) -> Result<TfetiSolution, FetiError> {
        solve(decomposition, comm, &self.load, &self.normal, self.friction.as_ref(), params)
    }
}
