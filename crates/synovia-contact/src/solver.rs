//! The [`ContactSolver`] trait that every contact solver implements, its parameters and report.

use crate::context::SolveContext;
use crate::error::{ContactError, IterationResidual};
use crate::problem::ContactProblem;

/// Parameters shared by the contact solvers.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ContactParams {
    /// Stopping tolerance on the relative complementarity residuals (default `1e-10`). The
    /// PDAS solvers also accept an iterate whose interface residuals stall at rounding level
    /// when all relative residuals of [`crate::check_kkt`] are below it (see `synovia_pdas`).
    pub tolerance: f64,
    /// Maximum outer iterations (default `200`).
    pub max_iterations: usize,
    /// Scale of the complementarity parameter `ρ` relative to the automatic choice
    /// `mean diag(A) / ‖C_r‖²` (default `1`). The solution does not depend on it.
    pub rho_scale: f64,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self { tolerance: 1e-10, max_iterations: 200, rho_scale: 1.0 }
    }
}

impl ContactParams {
    /// Sets [`Self::tolerance`].
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }
    /// Sets [`Self::max_iterations`].
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }
    /// Sets [`Self::rho_scale`].
    pub fn with_rho_scale(mut self, rho_scale: f64) -> Self {
        self.rho_scale = rho_scale;
        self
    }
}

/// What a solver did: iterations, residuals, set sizes, time.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SolverReport {
    /// Solver name.
    pub solver: String,
    /// Outer iterations.
    pub iterations: usize,
    /// Inner iterations (projected-gradient steps, Uzawa inner solves), if any.
    pub inner_iterations: usize,
    /// Linear solves with the factorisation of `A`.
    pub linear_solves: usize,
    /// Residual history, one entry per outer iteration.
    pub history: Vec<IterationResidual>,
    /// Normal rows in contact (`Λ_n > 0` or active).
    pub active: usize,
    /// Friction cells sticking (`‖Λ_t‖ < 1`).
    pub stick: usize,
    /// Friction cells slipping (`‖Λ_t‖ = 1`).
    pub slip: usize,
    /// Wall time (s).
    pub time_s: f64,
    /// An active-set configuration (normal and stick/slip states) recurred within the last
    /// few iterations without a decrease of the residual (PDAS; see `synovia_pdas::Pdas`).
    pub cycling_detected: bool,
    /// The residual stopped decreasing over several iterations (PDAS).
    pub stagnation_detected: bool,
    /// The fallback that produced this solution, if any (e.g. the `pdas-fallback` solver of
    /// the `synovia` facade hands a cycling PDAS iteration over to `dual-mprgp`).
    pub fallback: Option<String>,
    /// The increments `ζ_j` of the rigid partners' coordinates of a problem with a
    /// [`crate::RigidBorder`] (empty without one).
    pub border_values: Vec<f64>,
}

/// A solution of the contact problem of docs/model.md §5.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSolution {
    /// Displacement `U` (reduced unknowns).
    pub u: Vec<f64>,
    /// Normal multipliers `Λ_n` (contact pressure at the nodes), one per normal row.
    pub lambda_n: Vec<f64>,
    /// Tangential multipliers `Λ_t` (`components` per friction cell, `‖Λ_t‖ ≤ 1`); the
    /// friction traction is `−g_c Λ_t`.
    pub lambda_t: Vec<f64>,
    /// What the solver did.
    pub report: SolverReport,
}

/// A solver of the contact problem of docs/model.md §5 (frictionless or Tresca).
///
/// Implemented by the PDAS and AU-PDAS solvers (`synovia-pdas`) and the Uzawa solvers
/// (`synovia-uzawa`). The caller's [`SolveContext`] carries the warm start (a previous
/// solution of a nearby problem with the same rows, which seeds the multipliers and active
/// sets), the columns of `S` kept from earlier solves and the recycled load solves; the
/// solver reads it and leaves what it computed there for the next solve.
pub trait ContactSolver {
    /// Short name for reports.
    fn name(&self) -> &str;
    /// Solves the problem. Errors carry the residual history when the iteration fails.
    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        context: &SolveContext,
    ) -> Result<ContactSolution, ContactError>;

    /// The solver's single active-set update, as a solver of its own: one semismooth Newton
    /// step of the contact conditions from the warm start's displacement and multipliers,
    /// returned whether or not it solves the problem (its report's one history entry says
    /// how far it is: `set_changes` and the NCP residuals after the step). Used by a caller
    /// that iterates on the sets itself, e.g. the `Combined` active-set strategy of
    /// `synovia-nonlinear`. `None` (the default) for a solver without such a step; `synovia-pdas`'s
    /// `Pdas` returns its `PdasStep`.
    fn active_set_step(&self) -> Option<Box<dyn ContactSolver>> {
        None
    }

    /// Whether the solver takes a problem with a [`crate::RigidBorder`] (a rigid partner's
    /// force-controlled coordinate solved with the contact conditions). `false` (the
    /// default): such a problem is refused with [`ContactError::InvalidParameter`].
    fn solves_border(&self) -> bool {
        false
    }
}
