//! The linear elastic solve (docs/model.md §4 without contact): `K̃ ũ = F̃(t)` with the reduced stiffness
//! `K̃ = Pᵀ K P`, factorised once by sparse Cholesky and reused for any number of load cases
//! and times.

use std::time::Instant;

use nalgebra::DMatrix;
use synovia_mesh::math::{Real, Vector};

use crate::assembly::{add_loads, assemble_matrix, body_stiffnesses, pattern, subtract_lift};
use crate::dofs::{DofMap, FloatingComponent};
use crate::element::stiffness_into;
use crate::error::FemError;
use crate::model::Model;
use crate::post::{body_fields, BodyFields};
use synovia_linalg::SymmetricMatrix;
use synovia_linalg::{CholeskySolver, Ordering};

/// Which fill-reducing ordering to use.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum OrderingChoice {
    /// AMD in 2D, METIS nested dissection in 3D (default).
    #[default]
    Auto,
    /// faer's AMD.
    Amd,
    /// METIS nested dissection.
    Metis,
}

/// A choice of the fill-reducing ordering from the dof map and the default ordering
/// ([`ElasticSolver::new_with_ordering`]).
pub type Reorder<'a, const D: usize> = dyn Fn(&DofMap<D>, Ordering) -> Result<Ordering, FemError> + 'a;

/// Parameters of the elastic solve.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ElasticParams {
    /// Fill-reducing ordering (default: [`OrderingChoice::Auto`]).
    pub ordering: OrderingChoice,
    /// Quadrature degree of the load integrals (default: 2).
    pub load_degree: usize,
    /// Most bytes the numeric factorisation may use (default `None`: the environment variable
    /// `SYNOVIA_MEMORY_LIMIT_MB`, else the available memory of the system;
    /// [`CholeskySolver::check_memory`]).
    pub memory_limit: Option<u64>,
}

impl Default for ElasticParams {
    fn default() -> Self {
        Self { ordering: OrderingChoice::Auto, load_degree: 2, memory_limit: None }
    }
}

impl ElasticParams {
    /// Sets [`Self::ordering`].
    pub fn with_ordering(mut self, ordering: OrderingChoice) -> Self {
        self.ordering = ordering;
        self
    }
    /// Sets [`Self::load_degree`].
    pub fn with_load_degree(mut self, load_degree: usize) -> Self {
        self.load_degree = load_degree;
        self
    }
    /// Sets [`Self::memory_limit`] (bytes).
    pub fn with_memory_limit(mut self, bytes: Option<u64>) -> Self {
        self.memory_limit = bytes;
        self
    }
}

/// What a factorisation of the model would be, from the symbolic analysis only
/// ([`ElasticSolver::estimate_with_ordering`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElasticEstimate {
    /// Reduced unknowns.
    pub n_dofs: usize,
    /// Stored entries of the lower triangle of the matrix.
    pub matrix_nnz: usize,
    /// Memory of the numeric factorisation.
    pub memory: synovia_linalg::MemoryEstimate,
}

/// Sizes and stage timings of an elastic solve, in seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ElasticInfo {
    /// Reduced unknowns.
    pub n_dofs: usize,
    /// Stored entries of the lower triangle of `K̃`.
    pub matrix_nnz: usize,
    /// Stored entries of the Cholesky factor.
    pub factor_nnz: usize,
    /// Dof map and pattern construction.
    pub setup_s: f64,
    /// Stiffness assembly.
    pub assembly_s: f64,
    /// Ordering and symbolic analysis.
    pub symbolic_s: f64,
    /// Numeric factorisation.
    pub numeric_s: f64,
    /// Last right-hand side assembly + triangular solves.
    pub solve_s: f64,
}

/// The displacement of every body at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct ElasticSolution<const D: usize> {
    /// Time of the load case.
    pub time: Real,
    /// Reduced unknowns `ũ`.
    pub reduced: Vec<Real>,
    /// Nodal displacements `u = u_p + N ũ`, per body.
    pub displacement: Vec<Vec<Vector<D>>>,
}

/// A factorised elastic problem: solves any load case / time of the same model with one
/// factorisation.
#[derive(Debug, Clone)]
pub struct ElasticSolver<const D: usize> {
    dofs: DofMap<D>,
    stiffness: SymmetricMatrix,
    cholesky: CholeskySolver,
    /// The constant stiffness of every body; `None` for a caller-assembled matrix of a model
    /// with nonlinear materials.
    body_c: Option<Vec<DMatrix<Real>>>,
    params: ElasticParams,
    info: ElasticInfo,
    stabilisation: Option<Stabilisation>,
}

/// The regularisation of a semi-coercive model (docs/model.md §4): the floating components, the
/// diagonal spring `S` on their unknowns, and `A + S` (which is what the factorisation holds).
///
/// `S_ii = ε A_ii` on the unknowns of every floating component (`ε` =
/// [`Stabilisation::EPSILON`]) makes `A + S` positive definite without changing the solution
/// of a contact problem: the contact solve iterates the proximal-point scheme
/// `min_u L(u) + ½ (u − u_k)ᵀ S (u − u_k)`, whose fixed point is a minimiser of `L` (see
/// `synovia_contact::StaticContact::solve`).
#[derive(Debug, Clone)]
pub struct Stabilisation {
    /// The floating components (kernel of `A`).
    pub components: Vec<FloatingComponent>,
    /// The diagonal of `S` (one entry per reduced unknown, zero outside the components).
    pub spring: Vec<Real>,
    /// `A + S`.
    pub matrix: SymmetricMatrix,
}

impl Stabilisation {
    /// Relative spring stiffness `ε`.
    pub const EPSILON: Real = 1e-5;

    /// `S x` (diagonal).
    pub fn spring_mul(&self, x: &[Real]) -> Vec<Real> {
        self.spring.iter().zip(x).map(|(s, v)| s * v).collect()
    }
}

impl<const D: usize> ElasticSolver<D> {
    /// Validates the model, builds the dofs, checks coercivity (docs/model.md §4), assembles `K̃`, and
    /// factorises it.
    pub fn new(model: &Model<D>, params: ElasticParams) -> Result<Self, FemError> {
        Self::build(model, params, false, None, None)
    }

    /// Like [`ElasticSolver::new_semi_coercive`] (or [`ElasticSolver::new`] when
    /// `semi_coercive` is `false`), with the fill-reducing ordering chosen by `reorder` from the
    /// dof map and the default ordering of [`ElasticParams::ordering`] (e.g. a contact problem
    /// orders its interface dofs last, `synovia_contact::StaticContact`).
    ///
    /// # Errors
    /// As [`ElasticSolver::new`], and the errors of `reorder`.
    pub fn new_with_ordering(
        model: &Model<D>,
        params: ElasticParams,
        semi_coercive: bool,
        reorder: &Reorder<'_, D>,
    ) -> Result<Self, FemError> {
        Self::build(model, params, semi_coercive, Some(reorder), None)
    }

    /// Like [`ElasticSolver::new`], but a semi-coercive model (bodies whose rigid motions no
    /// Dirichlet or symmetry data restrain, docs/model.md §4) is accepted: the factorisation is of
    /// `A + S` with the [`Stabilisation`] spring `S` on the floating components, for contact
    /// problems whose contact conditions hold those bodies. [`ElasticSolver::solve`] still
    /// refuses such a model ([`FemError::SemiCoercive`]): without contact it has no unique
    /// solution.
    pub fn new_semi_coercive(model: &Model<D>, params: ElasticParams) -> Result<Self, FemError> {
        Self::build(model, params, true, None, None)
    }

    /// The factorisation of a caller-assembled symmetric positive definite matrix `A` on the
    /// model's reduced dofs and sparsity pattern, e.g. the time-step matrix
    /// `A = M_ρ + Δt M_α + Δt² A⁽⁰⁾ + Δt A⁽¹⁾` of the dynamic scheme (docs/model.md §7), with the
    /// ordering chosen by `reorder` as in [`ElasticSolver::new_with_ordering`]. `assemble`
    /// receives the dof map and the zero matrix on the pattern and fills it with `A`.
    /// No coercivity check (the caller's `A` must be positive definite: the factorisation
    /// fails otherwise) and no stabilisation; [`ElasticSolver::stiffness`] and
    /// [`ElasticSolver::system_matrix`] return `A`, while [`ElasticSolver::rhs`] and
    /// [`ElasticSolver::solve`] still evaluate the elastic load case `Pᵀ (F(t) − K u_p(t))`
    /// (the caller builds its own right-hand side for `A`).
    ///
    /// # Errors
    /// Model and dof errors, the errors of `assemble`, [`FemError`] of the factorisation.
    pub fn with_system_matrix(
        model: &Model<D>,
        params: ElasticParams,
        reorder: &Reorder<'_, D>,
        assemble: impl FnOnce(&DofMap<D>, &mut SymmetricMatrix) -> Result<(), FemError>,
    ) -> Result<Self, FemError> {
        let mut assemble = Some(assemble);
        let mut call = |dofs: &DofMap<D>, a: &mut SymmetricMatrix| match assemble.take() {
            Some(f) => f(dofs, a),
            None => Ok(()),
        };
        Self::build(model, params, true, Some(reorder), Some(&mut call))
    }

    /// Everything [`ElasticSolver::new_with_ordering`] does before the numeric factorisation
    /// (dofs, coercivity, pattern, ordering, symbolic analysis) and the memory check of the
    /// factorisation ([`CholeskySolver::check_memory`] with [`ElasticParams::memory_limit`]),
    /// without assembling or factorising: a cheap check that the model can be solved.
    ///
    /// # Errors
    /// As [`ElasticSolver::new_with_ordering`] up to the factorisation, and
    /// [`synovia_linalg::LinalgError::OutOfMemory`].
    pub fn estimate_with_ordering(
        model: &Model<D>,
        params: ElasticParams,
        semi_coercive: bool,
        reorder: &Reorder<'_, D>,
    ) -> Result<ElasticEstimate, FemError> {
        let dofs = DofMap::new(model)?;
        if !semi_coercive {
            if let Some(c) = dofs.floating_components(model).first() {
                return Err(FemError::SemiCoercive { bodies: c.bodies.clone(), free_modes: c.modes.len() });
            }
        }
        let (stiffness, metis) = pattern(model, &dofs)?;
        let ordering = match (params.ordering, D) {
            (OrderingChoice::Amd, _) | (OrderingChoice::Auto, 2) => Ordering::Amd,
            _ => metis,
        };
        let ordering = reorder(&dofs, ordering)?;
        let mut cholesky = CholeskySolver::analyse(&stiffness, &ordering)?;
        cholesky.set_memory_limit(params.memory_limit);
        let memory = cholesky.check_memory()?;
        Ok(ElasticEstimate { n_dofs: dofs.n_dofs(), matrix_nnz: stiffness.nnz(), memory })
    }

    /// `system`: a caller's assembly of the matrix instead of the stiffness (no floating
    /// components are looked for).
    #[allow(clippy::type_complexity)]
    fn build(
        model: &Model<D>,
        params: ElasticParams,
        allow_floating: bool,
        reorder: Option<&Reorder<'_, D>>,
        system: Option<&mut dyn FnMut(&DofMap<D>, &mut SymmetricMatrix) -> Result<(), FemError>>,
    ) -> Result<Self, FemError> {
        let t0 = Instant::now();
        let dofs = DofMap::new(model)?;
        let floating = if system.is_some() { Vec::new() } else { dofs.floating_components(model) };
        if let (false, Some(c)) = (allow_floating, floating.first()) {
            return Err(FemError::SemiCoercive { bodies: c.bodies.clone(), free_modes: c.modes.len() });
        }
        let (mut stiffness, metis) = pattern(model, &dofs)?;
        let setup_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let body_c = match system {
            Some(assemble) => {
                assemble(&dofs, &mut stiffness)?;
                body_stiffnesses(model).ok()
            }
            None => {
                let body_c = body_stiffnesses(model)?;
                assemble_matrix(model, &dofs, &mut stiffness, |b, _, geo, out| {
                    stiffness_into(geo, &body_c[b], out)
                })?;
                Some(body_c)
            }
        };
        let assembly_s = t1.elapsed().as_secs_f64();
        let mut ordering = match (params.ordering, D) {
            (OrderingChoice::Amd, _) | (OrderingChoice::Auto, 2) => Ordering::Amd,
            _ => metis,
        };
        if let Some(reorder) = reorder {
            ordering = reorder(&dofs, ordering)?;
        }
        let stabilisation = if floating.is_empty() {
            None
        } else {
            let diag = stiffness.diagonal();
            let mut spring = vec![0.0; dofs.n_dofs()];
            for c in &floating {
                for &k in &c.dofs {
                    spring[k] = Stabilisation::EPSILON * diag[k];
                }
            }
            let mut matrix = stiffness.clone();
            for (k, s) in spring.iter().enumerate() {
                if *s != 0.0 {
                    matrix.add(k, k, *s)?;
                }
            }
            Some(Stabilisation { components: floating, spring, matrix })
        };
        let system = stabilisation.as_ref().map_or(&stiffness, |s| &s.matrix);
        let mut cholesky = CholeskySolver::analyse(system, &ordering)?;
        cholesky.set_memory_limit(params.memory_limit);
        cholesky.factorize(system)?;
        let ci = cholesky.info();
        let info = ElasticInfo {
            n_dofs: dofs.n_dofs(),
            matrix_nnz: stiffness.nnz(),
            factor_nnz: ci.factor_nnz,
            setup_s,
            assembly_s,
            symbolic_s: ci.symbolic_s,
            numeric_s: ci.numeric_s,
            solve_s: 0.0,
        };
        Ok(Self { dofs, stiffness, cholesky, body_c, params, info, stabilisation })
    }

    /// A new numeric factorisation on the same pattern and ordering (the symbolic analysis is
    /// kept): `assemble` receives the dof map and the zeroed matrix and fills it with the new
    /// symmetric positive definite `A` (e.g. the tangent stiffness `K_T(u)` of a Newton
    /// iteration, [`crate::nonlinear::assemble_tangent`]). [`ElasticSolver::stiffness`] and
    /// [`ElasticSolver::system_matrix`] return the new `A` afterwards.
    ///
    /// # Errors
    /// [`FemError::InvalidParameter`] for a semi-coercive solver (its stabilisation belongs to
    /// the original stiffness); the errors of `assemble` and of the factorisation (a matrix that
    /// is not positive definite). After an error the solver must not be used for solves.
    pub fn refactorise(
        &mut self,
        assemble: impl FnOnce(&DofMap<D>, &mut SymmetricMatrix) -> Result<(), FemError>,
    ) -> Result<(), FemError> {
        if self.stabilisation.is_some() {
            return Err(FemError::InvalidParameter(
                "a semi-coercive (stabilised) factorisation cannot be refactorised with a new matrix".into(),
            ));
        }
        let t0 = Instant::now();
        self.stiffness.zero();
        assemble(&self.dofs, &mut self.stiffness)?;
        self.info.assembly_s = t0.elapsed().as_secs_f64();
        self.cholesky.factorize(&self.stiffness)?;
        self.info.numeric_s = self.cholesky.info().numeric_s;
        Ok(())
    }

    /// The reduced right-hand side `F̃(t) = Pᵀ (F(t) − K u_p(t))`.
    pub fn rhs(&self, model: &Model<D>, t: Real) -> Result<(Vec<Real>, Vec<Vector<D>>), FemError> {
        let lifts = self.dofs.lifts(model, t)?;
        let mut rhs = vec![0.0; self.dofs.n_dofs()];
        add_loads(model, &self.dofs, t, self.params.load_degree, &mut rhs)?;
        let c = match &self.body_c {
            Some(c) => c,
            None => &body_stiffnesses(model)?,
        };
        subtract_lift(model, &self.dofs, &lifts, &mut rhs, |b, _, geo, out| stiffness_into(geo, &c[b], out))?;
        Ok((rhs, lifts))
    }

    /// Solves the load case at time `t` (loads `F(t)`, `P(t)`, prescribed `u₂(t)`).
    pub fn solve(&mut self, model: &Model<D>, t: Real) -> Result<ElasticSolution<D>, FemError> {
        if let Some(c) = self.stabilisation.as_ref().and_then(|s| s.components.first()) {
            return Err(FemError::SemiCoercive { bodies: c.bodies.clone(), free_modes: c.modes.len() });
        }
        let t0 = Instant::now();
        let (mut x, lifts) = self.rhs(model, t)?;
        self.cholesky.solve_in_place(&mut x)?;
        let displacement = self.dofs.expand(&x, &lifts)?;
        self.info.solve_s = t0.elapsed().as_secs_f64();
        Ok(ElasticSolution { time: t, reduced: x, displacement })
    }

    /// Strain, stress, von Mises, principal stresses and energy of a solution.
    pub fn fields(
        &self,
        model: &Model<D>,
        solution: &ElasticSolution<D>,
    ) -> Result<Vec<BodyFields>, FemError> {
        body_fields(model, &solution.displacement)
    }

    /// The dof map.
    pub fn dofs(&self) -> &DofMap<D> {
        &self.dofs
    }
    /// The reduced stiffness `K̃`.
    pub fn stiffness(&self) -> &SymmetricMatrix {
        &self.stiffness
    }
    /// The factorisation of [`ElasticSolver::system_matrix`].
    pub fn cholesky(&self) -> &CholeskySolver {
        &self.cholesky
    }
    /// The matrix that [`ElasticSolver::cholesky`] factorises: `K̃`, or `K̃ + S` for a
    /// semi-coercive model ([`ElasticSolver::new_semi_coercive`]).
    pub fn system_matrix(&self) -> &SymmetricMatrix {
        self.stabilisation.as_ref().map_or(&self.stiffness, |s| &s.matrix)
    }
    /// The stabilisation of a semi-coercive model (`None` if the model is coercive).
    pub fn stabilisation(&self) -> Option<&Stabilisation> {
        self.stabilisation.as_ref()
    }
    /// Sizes and timings.
    pub fn info(&self) -> ElasticInfo {
        self.info
    }
}

/// One-shot convenience: factorise and solve the model at time `t` with default parameters.
pub fn solve_elastic<const D: usize>(model: &Model<D>, t: Real) -> Result<ElasticSolution<D>, FemError> {
    ElasticSolver::new(model, ElasticParams::default())?.solve(model, t)
}
