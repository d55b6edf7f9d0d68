//! # synovia-nonlinear
//!
//! Nonlinear elasticity in contact (docs/model.md §2.3 and §8): bodies with any
//! [`synovia_material::Material`] — nonlinear small-strain laws, or hyperelastic laws
//! ([`synovia_material::neo_hookean`], [`synovia_material::mooney_rivlin`], a user's
//! [`synovia_material::InvariantEnergy`]) in total Lagrangian finite strain — pressed into each
//! other or into obstacles, with Tresca friction frozen per load level as in the linear model.
//!
//! ## The iteration (docs/model.md §8)
//!
//! At a load level `t` the unknowns `ũ` (reduced, `u = u_p(t) + P ũ`) solve
//!
//! ```text
//! F_int(u) + B_hnᵀ κ Λ_n + B_Htᵀ Λ_t = F_ext(t),   Λ_n ≥ 0 ⟂ B_hn u ≤ d,   Tresca on Λ_t.
//! ```
//!
//! Newton's method linearises the material around the iterate `ũ_k`:
//! `F_int(u) ≈ F_int(u_k) + K_T(u_k)(ũ − ũ_k)`. Each iteration is then exactly the linear contact
//! problem of docs/model.md §5 with the operator `A = K_T(u_k)` and the load
//! `F̄ = F_ext − F_int(u_k) + K_T(u_k) ũ_k` — solved by any [`ContactSolver`] (PDAS, the
//! semismooth Newton of the contact conditions, warm-started from the previous iteration's
//! multipliers, so the two Newton methods run nested: the material's outside, the contact's
//! inside; [`ActiveSetStrategy`] offers one semismooth Newton iteration on the whole system,
//! or the sets iterated around Newton, instead). With small-strain contact the constraints are
//! linear in `u`, so the iteration is Newton's method (sequential quadratic programming) on the
//! whole nonsmooth system. With finite strain the contact geometry (re-pairing, normals, gaps in
//! total form) is that of the deformed configuration: it is frozen during a pass of Newton
//! iterations — each pass is
//! Newton's method on a fixed constraint operator and converges quadratically — and rebuilt
//! on `x + u` between passes until a rebuild moves the solution by less than
//! [`NewtonParams::geometry_tolerance`] (a fixed point in the geometry: rebuilding it at every
//! iteration instead leaves out the derivative of the normals, and the iteration stalled at
//! relative residuals of 1e-7 on the `knee2d` model).
//!
//! **Predictor**: a level starts from the converged state with its own prescribed
//! displacements; the first iteration adds the change `Δu_p` of the prescribed displacements
//! through the tangent, `F̄ −= Pᵀ K_T Δu_p`, so the new boundary displacement is spread into the
//! body by the linearised problem instead of being imposed on the boundary nodes alone (which
//! inverts the boundary layer of elements on fine meshes).
//!
//! **Convergence** is measured on the equilibrium residual
//! `R = F_ext − F_int(u_{k+1}) − c_{k+1}` with the contact forces `c = F̄ − K_T ũ*` of the
//! linearised solve, relative to the largest of `‖F_ext‖`, `‖F_int‖`, `‖c‖` and the residual at
//! the start of the level; a full step whose relative increment `‖δũ‖/‖ũ‖` is below the
//! tolerance also ends the iteration (a level that barely changed, residual at rounding).
//! **Line search**: a backtracking (Armijo) search on `‖R‖` along `(δũ, δc)`; an iterate with an
//! inverted element is a failed trial. **Load stepping with cut-back**: a level whose Newton
//! iteration fails (no convergence, an inverted element, a failed contact solve) is bisected
//! up to [`NewtonParams::max_cutbacks`] times: in time from a converged level (histories
//! evaluated at the intermediate times), and in a load factor `s` that scales every load and
//! prescribed displacement of the level (`s F_ext(t)`, `s u_p(t)`) for the first level, which
//! starts from the undeformed reference configuration.
//!
//! The matrix changes every iteration, so each iteration refactorises `K_T` numerically
//! ([`StaticContact::refactorise`]): the symbolic analysis and the interface ordering are done
//! once.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

use std::sync::Arc;
use std::time::Instant;

use synovia_contact::friction::{slip_speeds, FrictionLaw, PairFrictionLaws};
use synovia_contact::operators::{ContactGeometry, ContactPair};
use synovia_contact::{ContactError, ContactSolution, ContactSolver, StaticContact, StaticContactResult};
use synovia_fem::assembly::add_loads;
use synovia_fem::linear_bodies::LinearBodies;
use synovia_fem::nonlinear::{assemble_tangent, subtract_tangent_lift};
use synovia_fem::{DofMap, ElasticParams, FemError, Kinematics, Model};
use synovia_mesh::math::{Real, Vector};

/// Errors of the nonlinear solves.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NonlinearError {
    /// Model, dof or element error (including [`FemError::InvertedElement`] at a converged level).
    #[error(transparent)]
    Fem(#[from] FemError),
    /// Contact set-up or solve error.
    #[error(transparent)]
    Contact(#[from] ContactError),
    /// Newton's method did not reach the tolerance at a level even after cutting the step back.
    #[error("no convergence at t = {time}: {reason} (after {cutbacks} cut-backs, last step {step:e}); reduce the load step or check the model")]
    NoConvergence {
        /// The level that failed.
        time: Real,
        /// Cut-backs tried.
        cutbacks: usize,
        /// The smallest step tried.
        step: Real,
        /// What failed last.
        reason: String,
    },
    /// Invalid parameters or arguments.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
}

/// Parameters of the Newton iteration and the load stepping.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct NewtonParams {
    /// Relative equilibrium residual to reach (default `1e-10`).
    pub tolerance: Real,
    /// Newton iterations per level (default `30`).
    pub max_iterations: usize,
    /// Backtracking line search on `‖R‖` (default `true`).
    pub line_search: bool,
    /// Halvings of a level in time after a failure (default `8`).
    pub max_cutbacks: usize,
    /// Load degree of the quadrature of loads (default `2`).
    pub load_degree: usize,
    /// Finite strain: relative change of the solution below which a rebuild of the contact
    /// geometry on the deformed configuration counts as settled (default `1e-8`).
    pub geometry_tolerance: Real,
    /// Finite strain: rebuilds of the contact geometry per level (default `20`).
    pub max_geometry_passes: usize,
    /// Finite strain: relaxation `ω ∈ (0, 1]` of the configuration the geometry is rebuilt on,
    /// `x_g ← x_g + ω (x_k − x_g)` (default `0.5`).
    pub geometry_relaxation: Real,
    /// Finite strain: when the contact geometry is rebuilt ([`GeometryUpdate`]).
    pub geometry_update: GeometryUpdate,
    /// Modified Newton: `Some(ρ)` keeps the factorised tangent of an earlier iterate (also
    /// across levels) while each full step reduces the residual at least by the factor `ρ`,
    /// and refactorises `K_T` at the current iterate otherwise; `None` (default) refactorises
    /// at every iteration (Newton's method). With a kept tangent `K̂` the iteration solves the
    /// contact problem with `A = K̂` and `F̄ = F_ext − F_int(u_k) + K̂ ũ_k`: its fixed point is
    /// the same solution, reached at a linear rate, and an iteration costs a residual and a
    /// re-solve on the kept factorisation instead of an assembly and a numeric factorisation.
    pub tangent_reuse: Option<Real>,
    /// Finite strain: Aitken's dynamic relaxation of the geometry fixed point (default
    /// `false`): the relaxation factor of rebuild `k + 1` is
    /// `ω_{k+1} = −ω_k r_k · (r_{k+1} − r_k) / |r_{k+1} − r_k|²` (clamped to `[0.05, 1]`), with
    /// `r_k = x_k − x_{g,k}` the lag of the geometry's configuration behind the iterate, starting
    /// from [`Self::geometry_relaxation`].
    pub geometry_aitken: bool,
    /// Finite strain: the relative residual that ends a pass of Newton iterations whose
    /// geometry has not settled yet (default `None`: [`Self::tolerance`]); the last pass is
    /// always converged to [`Self::tolerance`].
    pub geometry_pass_tolerance: Option<Real>,
    /// Finite strain: once the contact geometry has settled (the first step after its last
    /// rebuild moved the solution by at most [`Self::geometry_tolerance`]), the iteration also
    /// ends at a full step whose relative increment `‖Δu‖ / ‖u‖` is at most this (default
    /// `None`: only [`Self::tolerance`] ends it). The answer carries the geometry's error of
    /// up to [`Self::geometry_tolerance`] anyway, so a value of at most that tolerance (`knee2d`:
    /// equal to it) stops the equilibrium iteration where further steps no longer change the
    /// answer at that accuracy (docs/nonlinear.md, "Fifth round").
    pub settled_increment: Option<Real>,
    /// How the contact's active sets are iterated against the material's Newton iteration
    /// (default [`ActiveSetStrategy::Nested`]).
    pub active_sets: ActiveSetStrategy,
    /// The internal force and tangent of the linear bodies (small strain, a material with a
    /// constant stiffness) as the product `K_b u_b` with their stiffness and its constant part
    /// `Σ_b Pᵀ K_b P` of the tangent, kept from level to level and rebuilt when a body's mesh
    /// moves ([`synovia_fem::linear_bodies::LinearBodies`]), instead of the element loop
    /// (default `true`; the same force and tangent to rounding).
    pub linear_bodies_by_stiffness: bool,
}

/// How the active sets of the contact conditions (contact/no contact, stick/slip) are found
/// relative to the Newton iteration of the material (docs/nonlinear.md, "Active sets and the
/// Newton iteration").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ActiveSetStrategy {
    /// Each Newton iteration solves its linearised contact problem to convergence with the
    /// contact solver (PDAS: its semismooth Newton iterated until the sets settle),
    /// warm-started from the previous iteration's multipliers: the contact's Newton nested
    /// inside the material's. Works with any [`ContactSolver`] (default).
    #[default]
    Nested,
    /// One semismooth Newton iteration on the whole nonsmooth system: each Newton iteration
    /// takes a single active-set step of the contact solver
    /// ([`ContactSolver::active_set_step`], e.g. `synovia_pdas::PdasStep`) — the sets
    /// classified from the current iterate's multipliers and gaps `(ν_k, C ũ_k − d)` (in 3D
    /// the slip rows linearised at `ζ_k`), the linearised problem solved once on them. The
    /// iteration ends when the equilibrium residual is at [`NewtonParams::tolerance`] **and**
    /// the last step left the sets unchanged with its complementarity residuals at the same
    /// tolerance, so the result satisfies the contact conditions. Needs a contact solver with
    /// an active-set step ([`NonlinearError::InvalidParameter`] otherwise) and is not
    /// available under load control ([`NonlinearContact::step_controlled`]).
    Combined,
    /// Active sets around Newton: the sets (and in 3D the slip linearisation) are fixed —
    /// classified by the active-set step from an anchor `(ν_o, ũ_o)`, the level's starting
    /// state — while the material's Newton iteration converges the equilibrium residual to
    /// [`NewtonParams::tolerance`] with the contact rows of those sets (equalities on the
    /// active and sticking rows, the slip forces of the slipping cells); then the converged
    /// iterate becomes the anchor and the sets are updated by the PDAS rule; repeated until
    /// an update leaves the sets unchanged with the complementarity residuals at the
    /// tolerance. The first step on updated sets is taken whole (the equilibrium residual was
    /// at its minimum for the old sets, so the line search would refuse any move toward the
    /// new sets' solution). Same requirements as [`Self::Combined`].
    Outer,
}

/// When a finite-strain solve rebuilds the contact geometry on the deformed configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GeometryUpdate {
    /// Between passes of Newton iterations until a rebuild moves the solution by less than
    /// [`NewtonParams::geometry_tolerance`]: the contact conditions hold on the deformed
    /// configuration of the solution (default).
    #[default]
    Converged,
    /// Once per level (and sub-level), on the configuration the level starts from: the contact
    /// conditions of a level are linearised at its start, explicit in the load stepping (small
    /// steps keep the lag small; for node-to-segment pairs whose re-pairing switches segments
    /// the converged fixed point may not exist).
    PerLevel,
    /// Never: the contact geometry (pairing, normals, gaps) stays that of the model's
    /// reference configuration, and the gaps follow the displacements to first order,
    /// `d − B_hn u` — the *small-sliding* contact of the linear model, with the finite-strain
    /// material. Right when the surfaces slide little against each other relative to their
    /// curvature (gap error `≈ |u_t|² / 2R` for a relative sliding `u_t` over a radius `R`);
    /// the Newton iteration keeps its quadratic convergence because the constraint operator is
    /// fixed.
    Reference,
}

impl GeometryUpdate {
    /// The names of the variants in scenario files and the Python package.
    pub const NAMES: [(&'static str, GeometryUpdate); 3] = [
        ("converged", GeometryUpdate::Converged),
        ("per_level", GeometryUpdate::PerLevel),
        ("reference", GeometryUpdate::Reference),
    ];
}

impl Default for NewtonParams {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 30,
            line_search: true,
            max_cutbacks: 8,
            load_degree: 2,
            geometry_tolerance: 1e-8,
            max_geometry_passes: 20,
            geometry_relaxation: 0.5,
            geometry_update: GeometryUpdate::Converged,
            tangent_reuse: None,
            geometry_aitken: false,
            geometry_pass_tolerance: None,
            settled_increment: None,
            active_sets: ActiveSetStrategy::Nested,
            linear_bodies_by_stiffness: true,
        }
    }
}

impl NewtonParams {
    /// Sets [`Self::tolerance`].
    pub fn with_tolerance(mut self, tolerance: Real) -> Self {
        self.tolerance = tolerance;
        self
    }
    /// Sets [`Self::max_iterations`].
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }
    /// Sets [`Self::line_search`].
    pub fn with_line_search(mut self, line_search: bool) -> Self {
        self.line_search = line_search;
        self
    }
    /// Sets [`Self::geometry_update`].
    pub fn with_geometry_update(mut self, geometry_update: GeometryUpdate) -> Self {
        self.geometry_update = geometry_update;
        self
    }
    /// Sets [`Self::tangent_reuse`] (modified Newton with the contraction bound `rho`).
    pub fn with_tangent_reuse(mut self, rho: Option<Real>) -> Self {
        self.tangent_reuse = rho;
        self
    }
    /// Sets [`Self::geometry_relaxation`] (the first relaxation factor with
    /// [`Self::geometry_aitken`]).
    pub fn with_geometry_relaxation(mut self, omega: Real) -> Self {
        self.geometry_relaxation = omega;
        self
    }
    /// Sets [`Self::geometry_aitken`].
    pub fn with_geometry_aitken(mut self, aitken: bool) -> Self {
        self.geometry_aitken = aitken;
        self
    }
    /// Sets [`Self::geometry_pass_tolerance`].
    pub fn with_geometry_pass_tolerance(mut self, tolerance: Option<Real>) -> Self {
        self.geometry_pass_tolerance = tolerance;
        self
    }
    /// Sets [`Self::settled_increment`].
    pub fn with_settled_increment(mut self, increment: Option<Real>) -> Self {
        self.settled_increment = increment;
        self
    }
    /// Sets [`Self::max_geometry_passes`].
    pub fn with_max_geometry_passes(mut self, passes: usize) -> Self {
        self.max_geometry_passes = passes;
        self
    }
    /// Sets [`Self::geometry_tolerance`].
    pub fn with_geometry_tolerance(mut self, geometry_tolerance: Real) -> Self {
        self.geometry_tolerance = geometry_tolerance;
        self
    }
    /// Sets [`Self::load_degree`].
    pub fn with_load_degree(mut self, load_degree: usize) -> Self {
        self.load_degree = load_degree;
        self
    }
    /// Sets [`Self::active_sets`].
    pub fn with_active_sets(mut self, strategy: ActiveSetStrategy) -> Self {
        self.active_sets = strategy;
        self
    }
    /// Sets [`Self::max_cutbacks`].
    pub fn with_max_cutbacks(mut self, max_cutbacks: usize) -> Self {
        self.max_cutbacks = max_cutbacks;
        self
    }
    /// Sets [`Self::linear_bodies_by_stiffness`].
    pub fn with_linear_bodies_by_stiffness(mut self, on: bool) -> Self {
        self.linear_bodies_by_stiffness = on;
        self
    }

    /// Checks the parameters: tolerances in (0, 1), at least one iteration, the relaxation in
    /// (0, 1], the contraction bound of tangent reuse in (0, 1), a positive geometry tolerance,
    /// the pass tolerance and the settled increment in (0, 1).
    ///
    /// # Errors
    /// [`NonlinearError::InvalidParameter`] naming the first parameter out of its range.
    pub fn check(&self) -> Result<(), NonlinearError> {
        if !(self.geometry_relaxation > 0.0 && self.geometry_relaxation <= 1.0) {
            return Err(NonlinearError::InvalidParameter(format!(
                "the relaxation of the geometry rebuilds must lie in (0, 1], got {}",
                self.geometry_relaxation
            )));
        }
        if !(self.geometry_tolerance > 0.0 && self.geometry_tolerance.is_finite()) {
            return Err(NonlinearError::InvalidParameter(format!(
                "the geometry tolerance must be positive and finite, got {}",
                self.geometry_tolerance
            )));
        }
        if let Some(p) = self.geometry_pass_tolerance {
            if !(p > 0.0 && p < 1.0) {
                return Err(NonlinearError::InvalidParameter(format!(
                    "the pass tolerance of the geometry fixed point must lie in (0, 1), got {p}"
                )));
            }
        }
        if let Some(d) = self.settled_increment {
            if !(d > 0.0 && d < 1.0) {
                return Err(NonlinearError::InvalidParameter(format!(
                    "the settled increment (a full step that ends the iteration on a settled geometry) must lie in (0, 1), got {d}"
                )));
            }
        }
        if let Some(rho) = self.tangent_reuse {
            if !(rho > 0.0 && rho < 1.0) {
                return Err(NonlinearError::InvalidParameter(format!(
                    "the contraction bound of tangent reuse must lie in (0, 1), got {rho}"
                )));
            }
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) || self.max_iterations == 0 {
            return Err(NonlinearError::InvalidParameter(format!(
                "Newton tolerance must lie in (0, 1) and max_iterations be positive, got {} and {}",
                self.tolerance, self.max_iterations
            )));
        }
        Ok(())
    }
}

/// One Newton iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonIteration {
    /// Relative equilibrium residual after the iteration.
    pub residual: Real,
    /// `‖δũ‖ / max(‖ũ‖, tiny)` of the accepted step.
    pub increment: Real,
    /// Line-search step `α` accepted.
    pub step: Real,
    /// Iterations of the contact solver inside this Newton iteration.
    pub contact_iterations: usize,
    /// Active contact rows of the linearised solve.
    pub active: usize,
}

/// What the Newton iteration of one level did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NewtonReport {
    /// Every Newton iteration of the last (successful) solve of the level.
    pub iterations: Vec<NewtonIteration>,
    /// Cut-backs (halvings) the level needed.
    pub cutbacks: usize,
    /// Sub-levels solved to reach the level (1 without cut-back).
    pub sublevels: usize,
    /// Newton iterations over all sub-levels and failed trials.
    pub total_iterations: usize,
    /// Numeric factorisations of `K_T`.
    pub factorisations: usize,
    /// Iterations whose tangent was indefinite and was shifted (`K_T + γ diag K_T`).
    pub shifted_tangents: usize,
    /// Wall time (s).
    pub time_s: f64,
}

impl NewtonReport {
    /// The final relative residual.
    pub fn residual(&self) -> Real {
        self.iterations.last().map_or(0.0, |i| i.residual)
    }
}

/// A converged level.
#[derive(Debug, Clone)]
pub struct NonlinearResult<const D: usize> {
    /// Time of the level.
    pub time: Real,
    /// The linearised contact solve of the last Newton iteration: nodal displacements
    /// `u = u_p + P ũ` per body, multipliers, KKT residuals (of the linearised problem, which
    /// at convergence is the nonlinear one up to the residual of [`NewtonReport::residual`]).
    pub contact: StaticContactResult<D>,
    /// Strain energy `Σ_T |T| Φ(e)` at the solution.
    pub strain_energy: Real,
    /// The Newton report.
    pub report: NewtonReport,
}

/// Load control of a level ([`NonlinearContact::step_controlled`]): the level's time `t`
/// (e.g. the approach of a prescribed boundary) is an unknown with the equation
/// `R(t) = target` on a resultant `R` of the contact multipliers (e.g. `Σ κ_r Λ_n,r n_r · e`).
pub struct LoadControl<'a, const D: usize> {
    /// The resultant `R(geometry, Λ_n)`.
    pub resultant: &'a dyn Fn(&ContactGeometry<D>, &[Real]) -> Real,
    /// Its target value.
    pub target: Real,
    /// Absolute tolerance on `|R − target|` (each iteration's linearised problem is balanced to
    /// a tenth of it).
    pub tolerance: Real,
    /// `dR/dt`: the first secant step's slope, updated with every secant step taken.
    pub slope: Real,
    /// Out: contact solves (trials) of the secant iterations on `t`, summed over the Newton
    /// iterations of the level (at least one per iteration; the accepted trial of each
    /// iteration is completed by its displacement).
    pub trials: usize,
}

impl<const D: usize> std::fmt::Debug for LoadControl<'_, D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LoadControl")
            .field("target", &self.target)
            .field("tolerance", &self.tolerance)
            .field("slope", &self.slope)
            .field("trials", &self.trials)
            .finish_non_exhaustive()
    }
}

/// Control of a level by the position `w` of a rigid contact partner
/// ([`NonlinearContact::step_gap_controlled`]): `w` is an unknown with the equation
/// `R(w) = target` on a resultant `R` of the contact multipliers that does not decrease with `w`
/// (e.g. `w` the travel of a rigid body along its applied force, `R` the contact force on it
/// along that direction). The partner is posed at `w` whenever the contact geometry is built
/// (at the start of the level, and between the geometry passes of finite strain), and between
/// builds the gaps follow `w` to first order, `d_r(w) = d_r(w₀) + s_r (w − w₀)` with the
/// sensitivities `s_r = ∂d_r/∂w` of the geometry built at `w₀` (docs/model.md (10.4)).
pub struct GapControl<'a, const D: usize> {
    /// Poses the partner at `w` (read by the contact shapes when the geometry is built).
    pub pose: &'a dyn Fn(Real),
    /// `∂d_r/∂w` per contact node of a geometry built at the current pose.
    pub sensitivity: &'a dyn Fn(&ContactGeometry<D>) -> Vec<Real>,
    /// The resultant `R(geometry, Λ_n)`, non-decreasing in `w`.
    pub resultant: &'a dyn Fn(&ContactGeometry<D>, &[Real]) -> Real,
    /// Its target value.
    pub target: Real,
    /// Absolute tolerance on `|R − target|` (each iteration's linearised problem is balanced to
    /// a tenth of it).
    pub tolerance: Real,
    /// `dR/dw`: the first step's slope (`≤ 0` or not finite: estimated from the first trial),
    /// updated with every secant step.
    pub slope: Real,
    /// In: the guess of `w`; out: the `w` of the solution.
    pub w: Real,
    /// Without a slope: the overlap beyond the first contact of the first trials, doubled while
    /// the resultant stays zero, and the step of the finite difference that gives the first
    /// slope (e.g. 1e-4 of the model size).
    pub overlap: Real,
    /// The largest change of `w` in one trial (e.g. 1e-2 of the model size): the gaps are first
    /// order in `w`, no guide far from the pose they were built at.
    pub max_step: Real,
    /// Out: the `w` at which the last contact geometry was built (the solution's gaps are
    /// first order in `w − base`; a caller asking for the exact geometry solves again when
    /// they differ by more than its tolerance).
    pub base: Real,
    /// Out: contact solves (trials) of the search for `w`.
    pub trials: usize,
    /// Tresca friction against the moving partner (`None`: frictionless pairs only).
    pub friction: Option<GapFriction<'a, D>>,
}

/// Tresca friction against the partner of a [`GapControl`] (docs/model.md (10.5)): the slip
/// bounds `g_c = F_c |Λ_n|` of the committed state, the slip measured from it relative to the
/// partner, `[v_t] − ([u_t(t_{i−1})] + w_{r,t})`, with the partner's motion `w_r(w)` since the
/// committed state at the trial's `w`, and the friction forces' part of the resultant.
#[derive(Clone, Copy)]
#[allow(clippy::type_complexity)]
pub struct GapFriction<'a, const D: usize> {
    /// `w_r(w)` per contact node of the geometry, at the nodes' positions `y_r = x_r + [u](x_r)`
    /// of the committed displacement (the slice), for the partner at `w`
    /// ([`ContactGeometry::set_partner_motion`]).
    pub motion: &'a dyn Fn(&ContactGeometry<D>, &[Vec<Vector<D>>], Real) -> Vec<Vector<D>>,
    /// The friction forces' part of the resultant, `R_t(geometry, cell_node, g, Λ_t)` over the
    /// friction cells `c` (contact node `cell_node[c]`, slip bound `g[c]`, `Λ_t` of `D − 1`
    /// components per cell); `R = resultant(Λ_n) + R_t`.
    pub resultant: &'a dyn Fn(&ContactGeometry<D>, &[usize], &[Real], &[Real]) -> Real,
}

impl<const D: usize> std::fmt::Debug for GapFriction<'_, D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GapFriction").finish_non_exhaustive()
    }
}

impl<const D: usize> std::fmt::Debug for GapControl<'_, D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GapControl")
            .field("target", &self.target)
            .field("tolerance", &self.tolerance)
            .field("slope", &self.slope)
            .field("w", &self.w)
            .field("overlap", &self.overlap)
            .field("max_step", &self.max_step)
            .field("base", &self.base)
            .field("friction", &self.friction.is_some())
            .finish_non_exhaustive()
    }
}

/// The gaps of a geometry built at `base`, followed to first order in `w`.
struct FirstOrderGaps {
    base: Real,
    gaps: Vec<Real>,
    sens: Vec<Real>,
}

impl FirstOrderGaps {
    fn at(&self, w: Real) -> Vec<Real> {
        self.gaps.iter().zip(&self.sens).map(|(g, s)| g + s * (w - self.base)).collect()
    }
    /// The smallest `w ≥ from` at which a gap closes (`None`: no gap closes along `w`).
    fn first_contact(&self, from: Real) -> Option<Real> {
        self.gaps
            .iter()
            .zip(&self.sens)
            .filter(|(_, s)| **s < 0.0)
            .map(|(g, s)| self.base + g / -s)
            .filter(|w| w.is_finite())
            .fold(None, |m: Option<Real>, w| Some(m.map_or(w, |m| m.min(w))))
            .map(|w| w.max(from))
    }
}

/// The converged state the next level starts from.
#[derive(Debug, Clone)]
struct State<const D: usize> {
    time: Real,
    /// Load factor of the state (0 for the reference configuration, 1 for a converged level).
    scale: Real,
    reduced: Vec<Real>,
    /// Reduced contact forces `c` (for the line search's merit).
    contact_force: Vec<Real>,
    result: Option<StaticContactResult<D>>,
    /// Slip speed `v_r` per contact node over the last two converged levels (empty: 0 at every
    /// node), kept only when friction laws are set ([`NonlinearContact::set_friction_law`]).
    slip_rate: Vec<Real>,
}

/// A converged state of a [`NonlinearContact`] ([`NonlinearContact::checkpoint`]).
#[derive(Debug, Clone)]
pub struct NonlinearCheckpoint<const D: usize>(State<D>);

/// Nonlinear elasticity with contact: the Newton iteration of the module docs on one symbolic
/// factorisation, with load stepping. Holds the converged state (time, displacement,
/// multipliers) that the next level starts from.
#[derive(Debug)]
pub struct NonlinearContact<const D: usize> {
    contact: StaticContact<D>,
    dofs: DofMap<D>,
    pairs: Vec<ContactPair<D>>,
    kinematics: Vec<Kinematics>,
    params: NewtonParams,
    state: State<D>,
    /// The factorised matrix is a tangent (of some earlier iterate) that a modified Newton
    /// iteration may keep: false until the first factorisation at a loaded state and after
    /// a rebuilt geometry or a failed level.
    tangent_kept: bool,
    /// The constant matrix `B` of [`Self::with_constant_matrix`] (on the tangent's pattern),
    /// added to every tangent; `B ũ` is added to the internal force.
    constant: Option<synovia_linalg::SymmetricMatrix>,
    /// The stiffness of the linear bodies ([`NewtonParams::linear_bodies_by_stiffness`]),
    /// refreshed at the start of each level.
    linear_bodies: LinearBodies<D>,
    /// Friction laws `F_c(v)` of the pairs ([`Self::set_friction_law`]; `None`: every pair's
    /// constant coefficient).
    friction_laws: Option<PairFrictionLaws>,
}

/// The extra terms of one level of [`NonlinearContact::step_with_terms`] (docs/model.md
/// (12.1)): the level solves `B ũ + Pᵀ F_int(u) + c = Pᵀ F_ext(t) + g` with the constant
/// matrix `B` of [`NonlinearContact::with_constant_matrix`].
#[derive(Debug, Clone, Copy)]
pub struct LevelTerms<'a> {
    /// The extra load `g` (reduced, one value per unknown).
    pub load: &'a [Real],
    /// Tresca slip bounds `g_c` per contact node of the level (`None`: frictionless), slip
    /// measured from the committed state.
    pub slip_bound: Option<&'a [Real]>,
}

fn norm(x: &[Real]) -> Real {
    x.iter().map(|v| v * v).sum::<Real>().sqrt()
}

impl<const D: usize> NonlinearContact<D> {
    /// Sets up the contact pairs and the symbolic factorisation of the tangent on the model's
    /// pattern (contact dofs ordered last), with one [`Kinematics`] per body. The state is the
    /// unloaded reference configuration at `t = 0`.
    ///
    /// # Errors
    /// Invalid pairs, parameters or kinematics; a tangent at `u = 0` that is not positive
    /// definite (e.g. bodies that nothing holds).
    pub fn new(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        kinematics: &[Kinematics],
        elastic: ElasticParams,
        params: NewtonParams,
    ) -> Result<Self, NonlinearError> {
        Self::build(
            model,
            pairs,
            kinematics,
            elastic,
            params,
            None,
            synovia_linalg::InterfaceBlockParams::default(),
        )
    }

    /// As [`Self::new`], with the given choice of the interface dofs ordered last
    /// ([`synovia_linalg::InterfaceBlockParams`], as [`StaticContact::with_interface_block`]):
    /// e.g. no dense interface block (`max_dofs = 0`) for a large candidate surface whose
    /// contact patches move, with the whole-factor solves screened by
    /// [`Self::set_screening_band`].
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn with_interface_block(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        kinematics: &[Kinematics],
        elastic: ElasticParams,
        params: NewtonParams,
        block: synovia_linalg::InterfaceBlockParams,
    ) -> Result<Self, NonlinearError> {
        Self::build(model, pairs, kinematics, elastic, params, None, block)
    }

    /// Rebuilds the contact geometry of the pairs on the reference meshes
    /// ([`StaticContact::rebuild_geometry`]; e.g. after a rigid partner moved: a posed shape
    /// reads its pose when the geometry is built). In finite strain the next level rebuilds it
    /// on the deformed configuration anyway. Returns the geometry it replaced (to carry nodal
    /// data to the new rows, [`ContactGeometry::transfer`]).
    ///
    /// # Errors
    /// As [`StaticContact::rebuild_geometry`].
    pub fn rebuild_geometry(&mut self, model: &Model<D>) -> Result<ContactGeometry<D>, NonlinearError> {
        Ok(self.contact.rebuild_geometry(model, &self.pairs)?)
    }

    /// Places the bodies rigidly, `x ↦ R_b x + t_b` ([`StaticContact::place_bodies`], one
    /// [`BodyPlacement`](synovia_contact::operators::BodyPlacement) per body): the contact
    /// geometry pairs and measures the placed bodies, and in finite strain every rebuild on
    /// the deformed configuration keeps the placements (the configuration `P_b(x + u)`,
    /// [`ContactGeometry::updated`]). Displacements, loads, prescribed displacements and
    /// contact forces of a body stay in its own frame, so its stiffness does not change with
    /// the placement and the factorised tangent is **kept** (modified Newton,
    /// [`NewtonParams::tangent_reuse`], reuses it while it contracts): a body turned by a
    /// large rigid motion between levels (a flexing femur) costs no refactorisation, where
    /// moving its mesh ([`Self::map_state`]) does. The state is kept as it is; carry it with
    /// [`Self::map_state_in_frames`] if the caller's state should change with the move.
    /// [`Self::rebuild_geometry`] builds on the reference meshes without placements.
    ///
    /// # Errors
    /// As [`StaticContact::place_bodies`].
    pub fn place_bodies(
        &mut self,
        model: &Model<D>,
        placements: &[synovia_contact::operators::BodyPlacement<D>],
    ) -> Result<ContactGeometry<D>, NonlinearError> {
        Ok(self.contact.place_bodies(model, &self.pairs, placements)?)
    }

    /// [`Self::map_state`] for a state that changes while the meshes do not (e.g. bodies
    /// re-placed with [`Self::place_bodies`] and a displacement carried in space): the same
    /// mapping of `ũ` and `c̃`, but the factorised tangent is kept for modified Newton (the
    /// model's matrix is that of the same meshes; the next iterations contract on it or
    /// refactorise, [`NewtonParams::tangent_reuse`]).
    pub fn map_state_in_frames(
        &mut self,
        f_u: impl Fn(synovia_fem::BodyId, usize, &Vector<D>) -> Vector<D>,
        f_c: impl Fn(synovia_fem::BodyId, usize, &Vector<D>) -> Vector<D>,
    ) {
        let kept = self.tangent_kept;
        self.map_state(f_u, f_c);
        self.tangent_kept = kept;
    }

    /// Gap screening of the contact solves ([`StaticContact::set_screening_band`]).
    ///
    /// # Errors
    /// As [`StaticContact::set_screening_band`].
    pub fn set_screening_band(&mut self, band: Option<Real>) -> Result<(), NonlinearError> {
        Ok(self.contact.set_screening_band(band)?)
    }

    /// As [`Self::new`], with a constant symmetric matrix `B` (reduced, on the tangent's
    /// pattern) that `assemble(dofs, b)` fills into a zeroed matrix of that pattern: every
    /// tangent is `K_T(u) + B` and every internal force `Pᵀ F_int(u) + B ũ` (docs/model.md
    /// (12.1)). The dynamic scheme uses it for the inertia and damping terms
    /// `B = (M̃_ρ + Δt (M̃_α + Ã⁽¹⁾)) / Δt²` (docs/model.md (12.2)); a positive definite `B`
    /// makes the first tangent `K_T(0) + B` positive definite even for bodies that nothing
    /// holds.
    ///
    /// # Errors
    /// As [`Self::new`], and the errors of `assemble`.
    pub fn with_constant_matrix(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        kinematics: &[Kinematics],
        elastic: ElasticParams,
        params: NewtonParams,
        assemble: impl FnOnce(&DofMap<D>, &mut synovia_linalg::SymmetricMatrix) -> Result<(), FemError>,
    ) -> Result<Self, NonlinearError> {
        Self::build(
            model,
            pairs,
            kinematics,
            elastic,
            params,
            Some(Box::new(assemble)),
            synovia_linalg::InterfaceBlockParams::default(),
        )
    }

    #[allow(clippy::type_complexity)]
    fn build(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        kinematics: &[Kinematics],
        elastic: ElasticParams,
        params: NewtonParams,
        assemble: Option<
            Box<dyn FnOnce(&DofMap<D>, &mut synovia_linalg::SymmetricMatrix) -> Result<(), FemError> + '_>,
        >,
        block: synovia_linalg::InterfaceBlockParams,
    ) -> Result<Self, NonlinearError> {
        params.check()?;
        let nb = model.bodies().len();
        if kinematics.len() != nb {
            return Err(NonlinearError::InvalidParameter(format!(
                "{} kinematics given for {nb} bodies (one per body)",
                kinematics.len()
            )));
        }
        let zero: Vec<Vec<Vector<D>>> =
            model.bodies().iter().map(|b| vec![Vector::<D>::zeros(); b.mesh.n_nodes()]).collect();
        let mut constant = None;
        let contact = StaticContact::with_system_matrix_block(model, pairs, elastic, block, |dofs, m| {
            assemble_tangent(model, dofs, kinematics, &zero, m)?;
            if let Some(assemble) = assemble {
                let mut b = m.clone();
                b.zero();
                assemble(dofs, &mut b)?;
                m.add_scaled(1.0, &b)?;
                constant = Some(b);
            }
            Ok(())
        })?;
        let dofs = contact.elastic().dofs().clone();
        let n = dofs.n_dofs();
        Ok(Self {
            contact,
            dofs,
            pairs: pairs.to_vec(),
            kinematics: kinematics.to_vec(),
            params,
            state: State {
                time: 0.0,
                scale: 0.0,
                reduced: vec![0.0; n],
                contact_force: vec![0.0; n],
                result: None,
                slip_rate: Vec::new(),
            },
            tangent_kept: false,
            constant,
            linear_bodies: LinearBodies::none(),
            friction_laws: None,
        })
    }

    /// Replaces the friction law `F_c(|[u'_t]|)` of the contact pair `pair` (docs/model.md §3;
    /// default: the pair's constant coefficient), as the linear quasi-static scheme's
    /// `QuasiStaticStepper::set_friction_law` (`synovia-time`): the Tresca slip bounds of a
    /// level are
    ///
    /// ```text
    /// g_c,r = F_c(v_r) |Λ_n,r|,   v_r = ‖(I − n_r n_rᵀ)([u_{i−1}](s_r) − [u_{i−2}](s_r))‖ / (t_{i−1} − t_{i−2}),
    /// ```
    ///
    /// with the pressure `Λ_n` of the converged state `i − 1` the level starts from and the slip
    /// speed over the two converged states before it (relative to a moving partner,
    /// [`ContactGeometry::slip_origin`]; 0 when there is no state before it, e.g. the first
    /// level after the reference configuration). A law set on a pair built frictionless gives
    /// it friction.
    ///
    /// # Errors
    /// [`NonlinearError::InvalidParameter`] for an unknown pair name.
    pub fn set_friction_law(&mut self, pair: &str, law: Arc<dyn FrictionLaw>) -> Result<(), NonlinearError> {
        let laws = self.friction_laws.get_or_insert_with(|| PairFrictionLaws::new(self.contact.geometry()));
        laws.set(pair, law).map_err(|e| NonlinearError::InvalidParameter(e.to_string()))
    }

    /// The friction laws set with [`Self::set_friction_law`] (`None`: none set, every pair's
    /// constant coefficient).
    pub fn friction_laws(&self) -> Option<&PairFrictionLaws> {
        self.friction_laws.as_ref()
    }

    /// Slip speed `v_r` per contact node of the converged state (see [`Self::set_friction_law`];
    /// empty when no law is set or there is no state before it: 0 at every node).
    pub fn slip_rate(&self) -> &[Real] {
        &self.state.slip_rate
    }

    /// The converged state of a level at `time` (load factor `scale`) that replaces the present
    /// one, with the slip speeds of [`Self::set_friction_law`] when friction laws are set: the
    /// tangential jump from the present state's displacement over the time between them (both
    /// converged levels, `scale = 1`), else none.
    fn next_state(
        &self,
        time: Real,
        scale: Real,
        reduced: Vec<Real>,
        contact_force: Vec<Real>,
        result: StaticContactResult<D>,
    ) -> State<D> {
        let slip_rate = match (&self.friction_laws, &self.state.result) {
            (Some(_), Some(previous)) if scale >= 1.0 && self.state.scale >= 1.0 => slip_speeds(
                self.contact.geometry(),
                &result.displacement,
                &previous.displacement,
                time - self.state.time,
            ),
            _ => Vec::new(),
        };
        State { time, scale, reduced, contact_force, result: Some(result), slip_rate }
    }

    /// The constant matrix `B` of [`Self::with_constant_matrix`] (`None` for [`Self::new`]).
    pub fn constant_matrix(&self) -> Option<&synovia_linalg::SymmetricMatrix> {
        self.constant.as_ref()
    }

    /// Replaces the constant matrix `B` (same pattern as the one of
    /// [`Self::with_constant_matrix`]; e.g. the dynamic scheme's `B` of another time step).
    /// The tangent is refactorised at the next iteration.
    ///
    /// # Errors
    /// [`NonlinearError::InvalidParameter`] without a constant matrix or for another pattern.
    pub fn set_constant_matrix(&mut self, b: synovia_linalg::SymmetricMatrix) -> Result<(), NonlinearError> {
        match &self.constant {
            Some(old) if old.n() == b.n() && old.nnz() == b.nnz() => {
                self.constant = Some(b);
                self.tangent_kept = false;
                Ok(())
            }
            Some(_) => Err(NonlinearError::InvalidParameter(
                "the constant matrix must have the pattern of the tangent".into(),
            )),
            None => Err(NonlinearError::InvalidParameter(
                "set_constant_matrix needs a NonlinearContact built with with_constant_matrix".into(),
            )),
        }
    }

    /// Sets the committed state to the loaded configuration `ũ` at time `t` (load factor 1,
    /// no contact forces, no multipliers): the start of a time integration from an initial
    /// displacement `u(t) = u_p(t) + P ũ`.
    ///
    /// # Errors
    /// [`NonlinearError::InvalidParameter`] for a wrong length or non-finite values.
    pub fn set_state(&mut self, t: Real, reduced: &[Real]) -> Result<(), NonlinearError> {
        let n = self.dofs.n_dofs();
        if reduced.len() != n || !t.is_finite() || reduced.iter().any(|v| !v.is_finite()) {
            return Err(NonlinearError::InvalidParameter(format!(
                "state: {n} finite unknowns and a finite time needed, got {} at t = {t}",
                reduced.len()
            )));
        }
        self.state = State {
            time: t,
            scale: 1.0,
            reduced: reduced.to_vec(),
            contact_force: vec![0.0; n],
            result: None,
            slip_rate: Vec::new(),
        };
        self.tangent_kept = false;
        Ok(())
    }

    /// The contact machinery (geometry, factorisation of the last tangent).
    pub fn contact(&self) -> &StaticContact<D> {
        &self.contact
    }

    /// The contact geometry of the last iteration.
    pub fn geometry(&self) -> &ContactGeometry<D> {
        self.contact.geometry()
    }

    /// The dof map.
    pub fn dofs(&self) -> &DofMap<D> {
        &self.dofs
    }

    /// The kinematics of the bodies.
    pub fn kinematics(&self) -> &[Kinematics] {
        &self.kinematics
    }

    /// The parameters.
    pub fn params(&self) -> &NewtonParams {
        &self.params
    }

    /// Time of the converged state.
    pub fn time(&self) -> Real {
        self.state.time
    }

    /// Reduced unknowns `ũ` of the converged state.
    pub fn reduced(&self) -> &[Real] {
        &self.state.reduced
    }

    /// Reduced contact forces `c = B_hnᵀ κ Λ_n + B_Htᵀ Λ_t` (the linearised solve's
    /// `F̄ − A ũ*`) of the converged state.
    pub fn contact_force(&self) -> &[Real] {
        &self.state.contact_force
    }

    /// Back to the unloaded reference configuration at time `t0`.
    pub fn reset(&mut self, t0: Real) {
        let n = self.dofs.n_dofs();
        self.state = State {
            time: t0,
            scale: 0.0,
            reduced: vec![0.0; n],
            contact_force: vec![0.0; n],
            result: None,
            slip_rate: Vec::new(),
        };
        self.tangent_kept = false;
    }

    /// A copy of the converged state (time, load factor, displacement, contact forces and
    /// multipliers), to go back to with [`Self::restore`] — e.g. after a level that failed
    /// part-way, whose cut-backs left the state at a converged sub-level the caller did not
    /// ask for.
    pub fn checkpoint(&self) -> NonlinearCheckpoint<D> {
        NonlinearCheckpoint(self.state.clone())
    }

    /// Back to a state of [`Self::checkpoint`]. The tangent is refactorised at the next
    /// iteration (and, in finite strain, the contact geometry rebuilt on the restored
    /// configuration, as at the start of every level).
    ///
    /// # Errors
    /// [`NonlinearError::InvalidParameter`] for a checkpoint of another model (a different
    /// number of unknowns).
    pub fn restore(&mut self, checkpoint: NonlinearCheckpoint<D>) -> Result<(), NonlinearError> {
        let n = self.dofs.n_dofs();
        if checkpoint.0.reduced.len() != n {
            return Err(NonlinearError::InvalidParameter(format!(
                "checkpoint of {} unknowns for a model of {n}",
                checkpoint.0.reduced.len()
            )));
        }
        self.state = checkpoint.0;
        self.tangent_kept = false;
        Ok(())
    }

    /// Maps the converged state to a moved reference configuration, so that the next level
    /// continues from it instead of the reference (e.g. a body re-placed between poses by a
    /// rigid motion of its mesh, the model's nodes moved by the caller). For every dof group
    /// with basis `N` (orthonormal columns) and origin node `(b, i)`, the group's displacement
    /// and reduced contact force
    ///
    /// ```text
    /// u = N ũ,  c = N c̃   become   ũ' = Nᵀ f_u(b, i, u),   c̃' = Nᵀ f_c(b, i, c)
    /// ```
    ///
    /// (the lifts are not part of `ũ`: `f_u` acts on the free part of the displacement). For
    /// a rigid rotation `R` of a body's mesh about a point, with the body's prescribed
    /// displacement a translation `t`, `f_u = R (u − t) + t` and `f_c = R c` carry the
    /// deformed shape along with the mesh; `f_u` may also interpolate a displacement field
    /// at the node's new position. The tangent is refactorised at the next iteration and the
    /// contact geometry rebuilt; the state's time and load factor are kept.
    pub fn map_state(
        &mut self,
        f_u: impl Fn(synovia_fem::BodyId, usize, &Vector<D>) -> Vector<D>,
        f_c: impl Fn(synovia_fem::BodyId, usize, &Vector<D>) -> Vector<D>,
    ) {
        for grp in self.dofs.groups() {
            let (u, c) = (0..grp.n_dofs).fold((Vector::<D>::zeros(), Vector::<D>::zeros()), |(u, c), k| {
                let i = grp.first_dof + k;
                (u + grp.basis[k] * self.state.reduced[i], c + grp.basis[k] * self.state.contact_force[i])
            });
            let (b, node) = grp.origin;
            let (u, c) = (f_u(b, node, &u), f_c(b, node, &c));
            for k in 0..grp.n_dofs {
                let i = grp.first_dof + k;
                self.state.reduced[i] = grp.basis[k].dot(&u);
                self.state.contact_force[i] = grp.basis[k].dot(&c);
            }
        }
        self.tangent_kept = false;
    }

    /// `Pᵀ F_int(u) + B ũ` (with the constant matrix `B`, if any) and the strain energy.
    fn effective_force(
        &self,
        model: &Model<D>,
        displacement: &[Vec<Vector<D>>],
        reduced: &[Real],
    ) -> Result<(Vec<Real>, Real), FemError> {
        let (mut f, energy) =
            self.linear_bodies.internal_force(model, &self.dofs, &self.kinematics, displacement)?;
        if let Some(b) = &self.constant {
            let mut bu = vec![0.0; f.len()];
            b.mul_vec(reduced, &mut bu);
            f.iter_mut().zip(&bu).for_each(|(a, v)| *a += v);
        }
        Ok((f, energy))
    }

    /// The search for `w` of one Newton iteration under [`GapControl`] (see
    /// [`Self::step_gap_controlled`]): trials on the linearised problem with the load `load`,
    /// the gaps of `gaps` at each trial's `w`; returns the `w` found and its multipliers (the
    /// contact geometry's gaps left at that `w`). With friction (`g.friction`, the committed
    /// state's `slip_bound` and displacement `previous`) each trial sets the partner's motion
    /// at its `w` (left set for the accepted one) and adds the friction forces to `R`.
    #[allow(clippy::too_many_arguments)]
    fn search_gap_control(
        &mut self,
        g: &mut GapControl<'_, D>,
        gaps: &FirstOrderGaps,
        load: &[Real],
        lifts: &[Vector<D>],
        solver: &dyn ContactSolver,
        warm: Option<&ContactSolution>,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
    ) -> Result<(Real, ContactSolution), NonlinearError> {
        let rows = self.contact.geometry().len();
        // friction against the partner: the cells of the slip bounds (nodes with g_c > 0)
        let friction = match (g.friction, slip_bound.filter(|b| b.len() == rows), previous) {
            (Some(f), Some(bound), Some(prev)) => {
                let (cells, bounds): (Vec<usize>, Vec<Real>) =
                    bound.iter().enumerate().filter(|(_, v)| **v > 0.0).map(|(r, v)| (r, *v)).unzip();
                Some((f, bound, prev, cells, bounds))
            }
            _ => None,
        };
        let inner = 0.1 * g.tolerance;
        let fail = |w: Real, reason: String| NonlinearError::NoConvergence {
            time: w,
            cutbacks: 0,
            step: 0.0,
            reason,
        };
        let mut w = g.w;
        // trials below (`lo`) and above (`hi`) the target nearest to it, and the last one
        let mut lo: Option<(Real, Real)> = None;
        let mut hi: Option<(Real, Real)> = None;
        let mut last: Option<(Real, Real)> = None;
        let mut warm_trial = warm.filter(|s| s.lambda_n.len() == rows).cloned();
        // the first trial with `w` solved with the contact conditions (a solver that takes a
        // border, docs/model.md §10): its `R` is the target when the resultant is the
        // generalised contact force `−σᵀ ν` of the first-order gaps (a rigid partner's force
        // along its travel); otherwise, or when nothing in contact holds the partner, the
        // search below goes on from there
        if solver.solves_border() {
            if let Some((wb, solution, r)) =
                self.bordered_gap_trial(g, gaps, load, lifts, solver, warm_trial.as_ref(), friction.as_ref())?
            {
                if (r - g.target).abs() <= inner {
                    return Ok((wb, solution));
                }
                tracing::debug!(
                    w = wb,
                    r,
                    target = g.target,
                    "gap control: the bordered trial missed the target"
                );
                warm_trial = Some(solution);
                w = wb;
            }
        }
        let mut overlap = 0.5 * g.overlap.abs();
        // trials running that kept the lower / upper end of the bracket, and `|R − target|` of
        // every trial (Illinois and the bisection safeguard below)
        let (mut kept_lo, mut kept_hi) = (0usize, 0usize);
        let mut errors: Vec<Real> = Vec::new();
        for _ in 0..60 {
            self.contact.set_gaps(&gaps.at(w))?;
            let (solution, _) = match &friction {
                Some((f, bound, prev, _, _)) => {
                    let motion = (f.motion)(self.contact.geometry(), prev, w);
                    self.contact.set_partner_motion(motion)?;
                    self.contact.solve_load_multipliers(
                        load,
                        lifts,
                        solver,
                        Some(bound),
                        Some(prev),
                        warm_trial.as_ref(),
                    )?
                }
                None => self.contact.solve_load_multipliers(
                    load,
                    lifts,
                    solver,
                    None,
                    None,
                    warm_trial.as_ref(),
                )?,
            };
            g.trials += 1;
            let mut r = (g.resultant)(self.contact.geometry(), &solution.lambda_n);
            if let Some((f, _, _, cells, bounds)) = &friction {
                r += (f.resultant)(self.contact.geometry(), cells, bounds, &solution.lambda_t);
            }
            tracing::debug!(w, r, target = g.target, slope = g.slope, "gap-control trial");
            if !r.is_finite() {
                return Err(fail(w, format!("gap control: resultant {r} at w = {w}")));
            }
            if (r - g.target).abs() <= inner {
                return Ok((w, solution));
            }
            errors.push((r - g.target).abs());
            if r < g.target {
                if lo.is_none_or(|(a, _)| w > a) {
                    lo = Some((w, r));
                    (kept_lo, kept_hi) = (0, kept_hi + 1);
                }
            } else if hi.is_none_or(|(b, _)| w < b) {
                hi = Some((w, r));
                (kept_lo, kept_hi) = (kept_lo + 1, 0);
            }
            if let Some((wp, rp)) = last {
                let s = (r - rp) / (w - wp);
                if s > 0.0 && s.is_finite() {
                    g.slope = s;
                }
            }
            let slope = (g.slope > 0.0 && g.slope.is_finite()).then_some(g.slope);
            let next = match (lo, hi) {
                (Some((a, ra)), Some((b, rb))) => {
                    // the secant if it stays inside the bracket, else regula falsi (Illinois: the
                    // residual of an end kept k ≥ 2 trials running halved k − 1 times), else
                    // bisection; bisection also when three trials did not halve `|R − target|`. Plain
                    // regula falsi stalls on a strongly convex `R`: an end far above the target
                    // (a trial that pressed deep) is kept forever while the other creeps toward
                    // the root (measured: tkr3d's femur at pose 0, 52 trials from 0.27 to 9.4 of
                    // a 168 N target, each step a hundredth of the bracket)
                    let fa = (ra - g.target) * 0.5_f64.powi(kept_lo.saturating_sub(1).min(60) as i32);
                    let fb = (rb - g.target) * 0.5_f64.powi(kept_hi.saturating_sub(1).min(60) as i32);
                    let secant = slope.map(|s| w + (g.target - r) / s);
                    let falsi = a - fa * (b - a) / (fb - fa);
                    let slow = errors.len() > 3 && errors[errors.len() - 1] > 0.5 * errors[errors.len() - 4];
                    match secant {
                        _ if slow => 0.5 * (a + b),
                        Some(x) if x > a && x < b => x,
                        _ if falsi > a && falsi < b => falsi,
                        _ => 0.5 * (a + b),
                    }
                }
                _ if r <= 0.0 => {
                    // no contact force: on to the first contact, then by the slope
                    let touch = gaps.first_contact(w).ok_or_else(|| {
                        fail(
                            w,
                            "gap control: no contact gap closes along w (the partner is not resisted)".into(),
                        )
                    })?;
                    match slope {
                        Some(s) => touch.max(w) + g.target / s,
                        None => {
                            overlap *= 2.0;
                            touch.max(w) + overlap
                        }
                    }
                }
                _ => match slope {
                    Some(s) => w + (g.target - r) / s,
                    // a finite difference toward the target for the first slope
                    None => w + g.overlap.abs().copysign(g.target - r),
                },
            };
            // (a finite cap: a step beyond it is cut to it)
            let cap = g.max_step.abs();
            let next = if cap > 0.0 && (next - w).abs() > cap { w + cap.copysign(next - w) } else { next };
            if !next.is_finite() || next == w {
                return Err(fail(
                    w,
                    format!(
                        "gap control: the search stalled at w = {w} (resultant {r}, target {})",
                        g.target
                    ),
                ));
            }
            last = Some((w, r));
            warm_trial = Some(solution);
            w = next;
        }
        Err(fail(w, format!("gap control: no w balanced the resultant to {} in 60 contact solves", inner)))
    }

    /// One trial of [`Self::search_gap_control`] with `w` an unknown of the contact solve
    /// ([`synovia_contact::CoordinateBorder`]: the gap rates `∂d_r/∂w` of `gaps`, the partner's
    /// motion rates by a difference of `GapFriction::motion`, the target `−R*`): returns the
    /// `w` found, its multipliers and its resultant `R` by the caller's functions, with the
    /// contact's gaps and partner motion left at that `w`; `None` when the solve fails (e.g.
    /// nothing in contact holds the partner).
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn bordered_gap_trial(
        &mut self,
        g: &mut GapControl<'_, D>,
        gaps: &FirstOrderGaps,
        load: &[Real],
        lifts: &[Vector<D>],
        solver: &dyn ContactSolver,
        warm: Option<&ContactSolution>,
        friction: Option<&(GapFriction<'_, D>, &[Real], &[Vec<Vector<D>>], Vec<usize>, Vec<Real>)>,
    ) -> Result<Option<(Real, ContactSolution, Real)>, NonlinearError> {
        let w0 = g.w;
        self.contact.set_gaps(&gaps.at(w0))?;
        let rows = self.contact.geometry().len();
        let motion_rate = match friction {
            Some((f, _, prev, _, _)) => {
                // (the motion is affine in a translation: a long step keeps the rounding small)
                let step = if g.max_step.abs() > 0.0 { g.max_step.abs() } else { 1e-3 };
                let m0 = (f.motion)(self.contact.geometry(), prev, w0);
                let m1 = (f.motion)(self.contact.geometry(), prev, w0 + step);
                self.contact.set_partner_motion(m0.clone())?;
                m0.iter().zip(&m1).map(|(a, b)| (b - a) / step).collect()
            }
            None => vec![Vector::<D>::zeros(); rows],
        };
        let border =
            synovia_contact::CoordinateBorder { gap_rate: gaps.sens.clone(), motion_rate, target: -g.target };
        self.contact.set_coordinate_borders(vec![border])?;
        let solved = match friction {
            Some((_, bound, prev, _, _)) => {
                self.contact.solve_load_multipliers(load, lifts, solver, Some(bound), Some(prev), warm)
            }
            None => self.contact.solve_load_multipliers(load, lifts, solver, None, None, warm),
        };
        self.contact.set_coordinate_borders(Vec::new())?;
        g.trials += 1;
        let solution = match solved {
            Ok((solution, _)) => solution,
            Err(e) => {
                tracing::debug!(w = w0, error = %e, "gap control: bordered trial failed");
                return Ok(None);
            }
        };
        let Some(zeta) = solution.report.border_values.first().copied().filter(|z| z.is_finite()) else {
            return Ok(None);
        };
        let w = w0 + zeta;
        self.contact.set_gaps(&gaps.at(w))?;
        let mut r = (g.resultant)(self.contact.geometry(), &solution.lambda_n);
        if let Some((f, _, prev, cells, bounds)) = friction {
            self.contact.set_partner_motion((f.motion)(self.contact.geometry(), prev, w))?;
            r += (f.resultant)(self.contact.geometry(), cells, bounds, &solution.lambda_t);
        }
        tracing::debug!(w0, w, r, target = g.target, "gap-control bordered trial");
        Ok(Some((w, solution, r)))
    }

    fn finite_strain(&self) -> bool {
        self.kinematics.contains(&Kinematics::FiniteStrain)
    }

    /// Solves the level `t` from the converged state, halving the step (in time, or in the
    /// load factor for the first level) on failure (module docs), and commits the new state. Friction: Tresca with the slip bounds
    /// `g_c = F_c |Λ_n|` of the state each sub-level starts from (Coulomb frozen per level,
    /// docs/model.md §3), slip measured from that state; the first level from the reference
    /// configuration is frictionless.
    ///
    /// # Errors
    /// [`NonlinearError::NoConvergence`] when the cut-backs are exhausted (the state is left
    /// at the last converged sub-level); model and contact errors that no cut-back can cure.
    #[tracing::instrument(level = "debug", skip_all, fields(t))]
    pub fn step_to(
        &mut self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
    ) -> Result<NonlinearResult<D>, NonlinearError> {
        if !t.is_finite() {
            return Err(NonlinearError::InvalidParameter(format!("level t = {t} must be finite")));
        }
        let start = Instant::now();
        let mut report = NewtonReport::default();
        // the path to the level, parametrised by `frac ∈ (0, 1]`: from a converged level, the
        // time from the state's time to `t`; from the reference configuration (or a partial
        // ramp), the load factor from the state's to 1 at the time `t`
        let from_time = self.state.time;
        let from_scale = self.state.scale;
        let ramp = from_scale < 1.0;
        let point = |frac: Real| -> (Real, Real) {
            if ramp {
                (t, from_scale + frac * (1.0 - from_scale))
            } else {
                (from_time + frac * (t - from_time), 1.0)
            }
        };
        let (mut done, mut target) = (0.0, 1.0);
        let mut halvings = 0usize;
        loop {
            let (time, scale) = point(target);
            match self.newton(model, time, scale, solver, &mut report, None, None, None) {
                Ok((result, energy, iterations, reduced, force, _)) => {
                    report.sublevels += 1;
                    self.state = self.next_state(time, scale, reduced, force, result.clone());
                    if target >= 1.0 {
                        report.iterations = iterations;
                        report.time_s = start.elapsed().as_secs_f64();
                        return Ok(NonlinearResult {
                            time: t,
                            contact: result,
                            strain_energy: energy,
                            report,
                        });
                    }
                    done = target;
                    target = 1.0;
                }
                Err(e) => {
                    self.tangent_kept = false;
                    let recoverable = matches!(
                        e,
                        NonlinearError::NoConvergence { .. }
                            | NonlinearError::Fem(FemError::InvertedElement { .. })
                            | NonlinearError::Contact(_)
                            | NonlinearError::Fem(FemError::Linalg(_))
                    );
                    if !recoverable || halvings >= self.params.max_cutbacks {
                        let step = target - done;
                        return Err(match e {
                            NonlinearError::NoConvergence { reason, .. } => {
                                NonlinearError::NoConvergence { time: t, cutbacks: halvings, step, reason }
                            }
                            other if recoverable => NonlinearError::NoConvergence {
                                time: t,
                                cutbacks: halvings,
                                step,
                                reason: other.to_string(),
                            },
                            other => other,
                        });
                    }
                    halvings += 1;
                    report.cutbacks += 1;
                    target = done + 0.5 * (target - done);
                    tracing::debug!(target, ramp, "cut-back");
                }
            }
        }
    }

    /// Solves a level under load control from a converged loaded state: Newton's method as in
    /// [`Self::step_to`], where every iteration also chooses the level's time `t` by a secant
    /// iteration on the linearised problem (frozen tangent and geometry), so that its
    /// multipliers satisfy `R(t) = target` ([`LoadControl`]):
    ///
    /// ```text
    /// t_{j+1} = t_j + (target − R(t_j)) / s_j,   s_j = (R(t_j) − R(t_{j−1})) / (t_j − t_{j−1}),
    /// ```
    ///
    /// each trial `t_j` a contact solve of `K_T δũ = f_ext(t_j) − f_int − Pᵀ K_T Δu_p(t_j) − c`
    /// on the kept factorisation. At convergence the equilibrium residual is at the tolerance
    /// and `|R − target| ≤ tolerance / 10`. Starts at `t_guess`; commits the state at the final
    /// `t` (the result's `time`). No cut-back: on failure the state is unchanged and the caller
    /// may fall back to [`Self::step_to`] on `t`.
    ///
    /// # Errors
    /// [`NonlinearError::InvalidParameter`] from an unloaded state (ramp with
    /// [`Self::step_to`] first) or a non-finite guess or target;
    /// [`NonlinearError::NoConvergence`] when Newton or the secant fails.
    pub fn step_controlled(
        &mut self,
        model: &Model<D>,
        t_guess: Real,
        solver: &dyn ContactSolver,
        control: &mut LoadControl<'_, D>,
    ) -> Result<NonlinearResult<D>, NonlinearError> {
        if self.state.scale < 1.0 {
            return Err(NonlinearError::InvalidParameter(
                "load control starts from a converged loaded level".into(),
            ));
        }
        if !(t_guess.is_finite()
            && control.target.is_finite()
            && control.slope.is_finite()
            && control.slope != 0.0)
        {
            return Err(NonlinearError::InvalidParameter(format!(
                "load control: guess {t_guess}, target {}, slope {} must be finite (slope non-zero)",
                control.target, control.slope
            )));
        }
        control.trials = 0;
        self.whole_level(model, t_guess, solver, Some(control), None, None)
    }

    /// Solves the level `t` with a rigid contact partner's position `w` as an unknown
    /// ([`GapControl`]): Newton's method as in [`Self::step_to`] from the committed state
    /// (loaded or the reference configuration), where every iteration also chooses `w` on the
    /// linearised problem (frozen tangent, gaps first order in `w`) so that its multipliers
    /// satisfy `R(w) = target`:
    ///
    /// ```text
    /// K_T δũ + B_hnᵀ κ Λ_n = f_ext(t) − f_int(u_k),   Λ_n ≥ 0 ⟂ B_hn (ũ_k + δũ) ≤ d(w),   R(Λ_n) = target,
    /// ```
    ///
    /// by a safeguarded secant iteration on `w` (each trial a contact solve for the
    /// multipliers on the kept factorisation; once a trial on each side of the target is known,
    /// the secant inside the bracket `[a, b]`, else the Illinois form of regula falsi,
    /// `w = a − R̃_a (b − a) / (R̃_b − R̃_a)` with `R̃ = (R − target) / 2^(k−1)` for an end kept
    /// `k ≥ 2` trials running, and bisection when three trials did not halve `|R − target|`;
    /// from no contact, first to the `w` that closes the first gap). A step that moved `w` is taken whole, as a predictor. The contact geometry is built
    /// at the pose `w` at the start of the level (and, in finite strain, on the deformed
    /// configuration between passes); `control.base` tells where. At convergence the
    /// equilibrium residual is at the Newton tolerance and `|R − target| ≤ tolerance / 10`.
    /// Friction (`control.friction`): Tresca with the slip bounds `g_c = F_c |Λ_n|` of the
    /// committed state (the first level from the reference configuration is frictionless, as
    /// [`Self::step_to`]), the slip measured from the committed state relative to the partner
    /// posed at each trial's `w` (docs/model.md (10.5)), and the friction forces in `R`; pairs
    /// with a friction coefficient and no `control.friction` are refused. No cut-back; on
    /// failure the committed state is unchanged.
    ///
    /// # Errors
    /// [`NonlinearError::InvalidParameter`] for a non-finite `t`, guess, target or tolerance,
    /// or a pair with friction without `control.friction`; [`NonlinearError::NoConvergence`] when Newton or the search
    /// for `w` fails; model and contact errors.
    pub fn step_gap_controlled(
        &mut self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        control: &mut GapControl<'_, D>,
    ) -> Result<NonlinearResult<D>, NonlinearError> {
        if !(t.is_finite()
            && control.w.is_finite()
            && control.target.is_finite()
            && control.tolerance.is_finite()
            && control.tolerance > 0.0)
        {
            return Err(NonlinearError::InvalidParameter(format!(
                "gap control: t {t}, guess {}, target {}, tolerance {} must be finite (tolerance positive)",
                control.w, control.target, control.tolerance
            )));
        }
        if control.friction.is_none() && self.contact.geometry().nodes.iter().any(|n| n.friction > 0.0) {
            return Err(NonlinearError::InvalidParameter(
                "gap control with friction needs the partner's motion (GapControl::friction)".into(),
            ));
        }
        control.trials = 0;
        self.whole_level(model, t, solver, None, None, Some(control))
    }

    /// Solves the level `t` from the committed state with contact partners that moved by a
    /// prescribed motion since it (rigid bodies whose coordinates are all prescribed, already
    /// posed at `t`): Newton's method as in [`Self::step_gap_controlled`] with nothing to search
    /// for, the contact geometry built at the current poses (in finite strain on the deformed
    /// configuration between passes), and Tresca friction with the slip bounds
    /// `g_c = F_c |Λ_n|` of the committed state and the slip measured relative to the partners
    /// (docs/model.md (10.5)),
    ///
    /// ```text
    /// s_c = T_cᵀ ([u](x_c) − [u_{i−1}](x_c) − w_c),   w_c = motion(geometry, u_{i−1})_c,
    /// ```
    ///
    /// `w_c` the motion of the partner's material point at the node's position
    /// `y_c = x_c + [u_{i−1}](x_c)` since the committed state, evaluated on every geometry the
    /// iteration builds ([`ContactGeometry::set_partner_motion`]). The first level from the
    /// reference configuration is frictionless (as [`Self::step_to`]). No cut-back (a sub-level
    /// would need the partners' poses between the committed state and `t`): on failure the
    /// committed state is unchanged.
    ///
    /// # Errors
    /// As [`Self::step_gap_controlled`].
    #[allow(clippy::type_complexity)]
    pub fn step_with_partner_motion(
        &mut self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        motion: &dyn Fn(&ContactGeometry<D>, &[Vec<Vector<D>>]) -> Vec<Vector<D>>,
    ) -> Result<NonlinearResult<D>, NonlinearError> {
        if !t.is_finite() {
            return Err(NonlinearError::InvalidParameter(format!("level t = {t} must be finite")));
        }
        self.level_with_partner_motion(model, t, solver, None, motion)
    }

    /// The level of [`Self::step_with_partner_motion`] (and, with `terms`, of
    /// [`Self::step_with_terms_and_partner_motion`]): a gap control whose resultant is its
    /// target at any `w`, so the search accepts the first trial and the partners stay where
    /// they are posed, with the friction slip measured relative to `motion`.
    #[allow(clippy::type_complexity)]
    fn level_with_partner_motion(
        &mut self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        terms: Option<&LevelTerms<'_>>,
        motion: &dyn Fn(&ContactGeometry<D>, &[Vec<Vector<D>>]) -> Vec<Vector<D>>,
    ) -> Result<NonlinearResult<D>, NonlinearError> {
        let pose = |_: Real| {};
        let sensitivity = |geometry: &ContactGeometry<D>| vec![0.0; geometry.len()];
        let resultant = |_: &ContactGeometry<D>, _: &[Real]| 0.0;
        let moved =
            |geometry: &ContactGeometry<D>, previous: &[Vec<Vector<D>>], _: Real| motion(geometry, previous);
        let friction_resultant = |_: &ContactGeometry<D>, _: &[usize], _: &[Real], _: &[Real]| 0.0;
        let mut control = GapControl {
            pose: &pose,
            sensitivity: &sensitivity,
            resultant: &resultant,
            target: 0.0,
            tolerance: 1.0,
            slope: 0.0,
            w: 0.0,
            overlap: 0.0,
            max_step: 0.0,
            base: 0.0,
            trials: 0,
            friction: Some(GapFriction { motion: &moved, resultant: &friction_resultant }),
        };
        self.whole_level(model, t, solver, None, terms, Some(&mut control))
    }

    /// Solves one level `t` with extra terms from the committed state (docs/model.md (12.1)):
    ///
    /// ```text
    /// B ũ + Pᵀ F_int(u) + B_hnᵀ κ Λ_n + B_Htᵀ Λ_t = Pᵀ F_ext(t) + g,   u = u_p(t) + P ũ,
    /// ```
    ///
    /// with the constant matrix `B` of [`Self::with_constant_matrix`] (none for
    /// [`Self::new`]), the load `g` and the Tresca slip bounds of `terms` (slip measured from
    /// the committed state's displacement), by the Newton iteration of [`Self::step_to`] on
    /// the tangent `K_T(u) + B` (predictor, line search, deformed-configuration geometry in
    /// finite strain). The dynamic scheme solves each time step this way (docs/model.md
    /// (12.2)). No cut-back (the caller owns the meaning of `B` and `g`, e.g. a time step):
    /// on failure the committed state is unchanged; on success the level is committed.
    ///
    /// # Errors
    /// [`NonlinearError::InvalidParameter`] for a non-finite `t`, a `g` of the wrong length or
    /// from the unloaded reference (set a state first, [`Self::set_state`]);
    /// [`NonlinearError::NoConvergence`] and the errors of an iteration.
    pub fn step_with_terms(
        &mut self,
        model: &Model<D>,
        t: Real,
        terms: &LevelTerms<'_>,
        solver: &dyn ContactSolver,
    ) -> Result<NonlinearResult<D>, NonlinearError> {
        self.check_terms(t, terms)?;
        self.whole_level(model, t, solver, None, Some(terms), None)
    }

    /// `Err` unless `t` is finite, `terms.load` has one finite value per reduced dof and the
    /// committed state is loaded (what a level with extra terms starts from).
    fn check_terms(&self, t: Real, terms: &LevelTerms<'_>) -> Result<(), NonlinearError> {
        let n = self.dofs.n_dofs();
        if !t.is_finite() || terms.load.len() != n || terms.load.iter().any(|v| !v.is_finite()) {
            return Err(NonlinearError::InvalidParameter(format!(
                "level with extra terms: a finite time and {n} finite load values needed, got t = {t} and {} values",
                terms.load.len()
            )));
        }
        if self.state.scale < 1.0 {
            return Err(NonlinearError::InvalidParameter(
                "a level with extra terms starts from a loaded state (set_state)".into(),
            ));
        }
        Ok(())
    }

    /// [`Self::step_with_terms`] with contact partners that moved by a prescribed motion since
    /// the committed state (rigid bodies posed at `t`), the Tresca slip of `terms`' bounds
    /// measured relative to them as in [`Self::step_with_partner_motion`]:
    /// `s_c = T_cᵀ ([u](x_c) − [u_{i−1}](x_c) − w_c)`, `w_c = motion(geometry, u_{i−1})_c` on
    /// every geometry the iteration builds. The dynamic scheme's step against moving rigid
    /// bodies (docs/dynamics.md §9).
    ///
    /// # Errors
    /// As [`Self::step_with_terms`].
    #[allow(clippy::type_complexity)]
    pub fn step_with_terms_and_partner_motion(
        &mut self,
        model: &Model<D>,
        t: Real,
        terms: &LevelTerms<'_>,
        solver: &dyn ContactSolver,
        motion: &dyn Fn(&ContactGeometry<D>, &[Vec<Vector<D>>]) -> Vec<Vector<D>>,
    ) -> Result<NonlinearResult<D>, NonlinearError> {
        self.check_terms(t, terms)?;
        self.level_with_partner_motion(model, t, solver, Some(terms), motion)
    }

    /// One level solved whole (no cut-back) from the committed state by the Newton iteration,
    /// with load control and/or extra terms, committed on success at the level's time (the
    /// one load control found, else `t`); on failure the committed state is unchanged and the
    /// kept tangent dropped.
    fn whole_level(
        &mut self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        control: Option<&mut LoadControl<'_, D>>,
        terms: Option<&LevelTerms<'_>>,
        gap: Option<&mut GapControl<'_, D>>,
    ) -> Result<NonlinearResult<D>, NonlinearError> {
        let start = Instant::now();
        let mut report = NewtonReport::default();
        match self.newton(model, t, 1.0, solver, &mut report, control, terms, gap) {
            Ok((result, energy, iterations, reduced, force, t)) => {
                report.sublevels = 1;
                report.iterations = iterations;
                report.time_s = start.elapsed().as_secs_f64();
                self.state = self.next_state(t, 1.0, reduced, force, result.clone());
                Ok(NonlinearResult { time: t, contact: result, strain_energy: energy, report })
            }
            Err(e) => {
                self.tangent_kept = false;
                Err(e)
            }
        }
    }

    /// Runs the levels `times` (in order; a level before the state's time is reached by going
    /// back along the histories, e.g. unloading) with [`Self::step_to`],
    /// calling `observer` after each.
    ///
    /// # Errors
    /// As [`Self::step_to`], and the observer's errors.
    pub fn run(
        &mut self,
        model: &Model<D>,
        times: &[Real],
        solver: &dyn ContactSolver,
        mut observer: impl FnMut(&NonlinearResult<D>) -> Result<(), NonlinearError>,
    ) -> Result<Vec<NonlinearResult<D>>, NonlinearError> {
        let mut out = Vec::with_capacity(times.len());
        for &t in times {
            let r = self.step_to(model, t, solver)?;
            observer(&r)?;
            out.push(r);
        }
        Ok(out)
    }

    /// Newton's method at `t` with the loads and prescribed displacements scaled by `scale`,
    /// from the committed state, with the extra terms of a level (`B` of the constant matrix,
    /// `g`, slip bounds); nothing is committed.
    #[allow(clippy::type_complexity, clippy::too_many_arguments)]
    fn newton(
        &mut self,
        model: &Model<D>,
        t: Real,
        scale: Real,
        solver: &dyn ContactSolver,
        report: &mut NewtonReport,
        mut control: Option<&mut LoadControl<'_, D>>,
        terms: Option<&LevelTerms<'_>>,
        mut gap: Option<&mut GapControl<'_, D>>,
    ) -> Result<
        (StaticContactResult<D>, Real, Vec<NewtonIteration>, Vec<Real>, Vec<Real>, Real),
        NonlinearError,
    > {
        // the contact solve of an iteration: the solver itself, or its single active-set step
        let step_solver = match self.params.active_sets {
            ActiveSetStrategy::Nested => None,
            strategy @ (ActiveSetStrategy::Combined | ActiveSetStrategy::Outer) => {
                if control.is_some() || gap.is_some() {
                    return Err(NonlinearError::InvalidParameter(format!(
                        "the {strategy:?} active-set strategy is not available under load control; use ActiveSetStrategy::Nested"
                    )));
                }
                Some(solver.active_set_step().ok_or_else(|| {
                    NonlinearError::InvalidParameter(format!(
                        "the {strategy:?} active-set strategy needs a contact solver with an active-set step (e.g. PDAS); `{}` has none",
                        solver.name()
                    ))
                })?)
            }
        };
        let single_steps = step_solver.is_some();
        let outer = self.params.active_sets == ActiveSetStrategy::Outer;
        let solver: &dyn ContactSolver = step_solver.as_deref().unwrap_or(solver);
        let mut t = t;
        let n = self.dofs.n_dofs();
        if self.params.linear_bodies_by_stiffness {
            self.linear_bodies.refresh(model, &self.kinematics)?;
            let template = self.contact.elastic().stiffness();
            self.linear_bodies.refresh_tangent(model, &self.dofs, &self.kinematics, template)?;
        } else {
            self.linear_bodies = LinearBodies::none();
        }
        let finite_geometry =
            self.finite_strain() && self.params.geometry_update != GeometryUpdate::Reference;
        // gap control: the partner posed at the guess and, in small strain, the geometry built
        // there (finite strain: on the deformed configuration at the first pass, below)
        let mut first_order: Option<FirstOrderGaps> = None;
        if let Some(g) = gap.as_deref_mut() {
            (g.pose)(g.w);
            if !finite_geometry {
                self.contact.rebuild_geometry(model, &self.pairs)?;
                let geometry = self.contact.geometry();
                first_order = Some(FirstOrderGaps {
                    base: g.w,
                    gaps: geometry.nodes.iter().map(|node| node.gap).collect(),
                    sens: (g.sensitivity)(geometry),
                });
                g.base = g.w;
            }
        }
        let mut lifts: Vec<Vector<D>> = self.dofs.lifts(model, t)?.into_iter().map(|l| l * scale).collect();
        let mut f_ext = vec![0.0; n];
        add_loads(model, &self.dofs, t, self.params.load_degree, &mut f_ext)?;
        f_ext.iter_mut().for_each(|f| *f *= scale);
        if let Some(terms) = terms {
            f_ext.iter_mut().zip(terms.load).for_each(|(f, g)| *f += g);
        }
        let mut u = self.state.reduced.clone();
        // the converged state (the undeformed reference before the first level): the new
        // prescribed displacements enter through the predictor of the first iteration
        let lifts_old: Vec<Vector<D>> = if self.state.scale > 0.0 {
            self.dofs.lifts(model, self.state.time)?.into_iter().map(|l| l * self.state.scale).collect()
        } else {
            vec![Vector::<D>::zeros(); lifts.len()]
        };
        let delta_lifts: Vec<Vector<D>> = lifts.iter().zip(&lifts_old).map(|(a, b)| a - b).collect();
        let mut predictor = delta_lifts.iter().any(|d| d.norm_squared() > 0.0);
        // the lifts of the current iterate (load control moves `t`, so the lifts with it)
        let mut current_lifts = lifts_old.clone();
        let mut disp = self.dofs.expand(&u, &lifts_old)?;
        let (mut f_int, _) = self.effective_force(model, &disp, &u)?;
        let mut c = self.state.contact_force.clone();
        // friction frozen from the committed state (none from the reference configuration),
        // or the slip bounds given with the level's extra terms
        let previous = self.state.result.as_ref();
        let (slip_bound, previous_disp) = match terms {
            Some(terms) => match terms.slip_bound.filter(|g| g.iter().any(|v| *v > 0.0)) {
                Some(g) => (Some(g.to_vec()), Some(disp.clone())),
                None => (None, None),
            },
            None => {
                let geometry = self.contact.geometry();
                let friction = previous.is_some()
                    && match &self.friction_laws {
                        Some(laws) => laws.any_friction(geometry),
                        None => geometry.nodes.iter().any(|node| node.friction > 0.0),
                    };
                // g_c = F_c(v) |Λ_n| with the laws (Self::set_friction_law), else F_c |Λ_n|
                let slip_bound = match (friction, previous, &self.friction_laws) {
                    (true, Some(p), Some(laws)) => {
                        Some(laws.slip_bounds(geometry, &p.solution.lambda_n, &self.state.slip_rate))
                    }
                    (true, Some(p), None) => Some(geometry.slip_bounds_from_pressure(&p.solution.lambda_n)),
                    _ => None,
                };
                (slip_bound, if friction { previous.map(|p| p.displacement.clone()) } else { None })
            }
        };
        // (`Λ_t` on the friction cells of this level's slip bounds: the committed level may
        // have had other cells, or none from the reference configuration)
        let mut warm: Option<ContactSolution> = previous.map(|p| match slip_bound.as_deref() {
            Some(g) => synovia_contact::warm::warm_start(self.contact.geometry(), p, g),
            None => ContactSolution { lambda_t: Vec::new(), ..p.solution.clone() },
        });
        let residual_of = |f_ext: &[Real], f_int: &[Real], c: &[Real]| -> Vec<Real> {
            (0..n).map(|i| f_ext[i] - f_int[i] - c[i]).collect()
        };
        let mut r_norm = norm(&residual_of(&f_ext, &f_int, &c));
        // the force scale of the level: its initial residual (e.g. the forces of a prescribed
        // displacement's jump, which leave the reduced rows once balanced)
        let mut r_start = r_norm;
        let mut iterations = Vec::new();
        // finite strain: the contact geometry is frozen during a pass of Newton iterations (so
        // each pass converges quadratically on a fixed constraint operator) and rebuilt on the
        // deformed configuration between passes, until a rebuild no longer moves the solution
        let finite = self.finite_strain() && self.params.geometry_update != GeometryUpdate::Reference;
        let mut refresh = finite;
        // the configuration the contact geometry is built on, relaxed toward the iterate
        let mut geometry_at: Option<Vec<Vec<Vector<D>>>> = None;
        let mut omega = self.params.geometry_relaxation;
        let mut previous_lag: Option<Vec<Real>> = None;
        let mut first_of_pass = true;
        let mut pass_increment = 0.0;
        let mut passes = 0usize;
        let passes_allowed = match self.params.geometry_update {
            GeometryUpdate::Converged if finite => 1 + self.params.max_geometry_passes,
            _ => 1,
        };
        // consecutive steps the line search took without a decrease of the residual
        let mut forced_steps = 0usize;
        // Outer: the anchor (and so the sets) changed in the last iteration
        let mut new_anchor = false;
        for _ in 0..self.params.max_iterations * passes_allowed {
            report.total_iterations += 1;
            if refresh {
                let at = match geometry_at.take() {
                    Some(g) => {
                        // the lag r = x_k − x_g of the geometry's configuration
                        let lag: Vec<Real> = g
                            .iter()
                            .zip(&disp)
                            .flat_map(|(gb, db)| {
                                gb.iter()
                                    .zip(db)
                                    .flat_map(|(x, y)| (y - x).iter().copied().collect::<Vec<_>>())
                            })
                            .collect();
                        if self.params.geometry_aitken {
                            if let Some(prev) = &previous_lag {
                                let dr: Vec<Real> = lag.iter().zip(prev).map(|(a, b)| a - b).collect();
                                let dd: Real = dr.iter().map(|v| v * v).sum();
                                if dd > 0.0 {
                                    let rd: Real = prev.iter().zip(&dr).map(|(a, b)| a * b).sum();
                                    omega = (-omega * rd / dd).clamp(0.05, 1.0);
                                }
                            }
                            previous_lag = Some(lag);
                        }
                        tracing::debug!(omega, passes, "geometry rebuilt, relaxed toward the iterate");
                        g.iter()
                            .zip(&disp)
                            .map(|(gb, db)| gb.iter().zip(db).map(|(x, y)| x + (y - x) * omega).collect())
                            .collect()
                    }
                    None => disp.clone(),
                };
                if let Some(g) = gap.as_deref() {
                    (g.pose)(g.w);
                }
                self.contact.update_geometry(model, &self.pairs, &at)?;
                if let Some(g) = gap.as_deref_mut() {
                    let geometry = self.contact.geometry();
                    first_order = Some(FirstOrderGaps {
                        base: g.w,
                        gaps: geometry.nodes.iter().map(|node| node.gap).collect(),
                        sens: (g.sensitivity)(geometry),
                    });
                    g.base = g.w;
                }
                geometry_at = Some(at);
                refresh = false;
                first_of_pass = true;
                passes += 1;
            }
            let kin = &self.kinematics;
            let at = &disp;
            let constant = self.constant.as_ref();
            let linear = &self.linear_bodies;
            let reuse = self.params.tangent_reuse.is_some() && self.tangent_kept;
            // K_T away from equilibrium (strong compression, the geometric stiffness of
            // compressive stresses) may be indefinite: then K_T + γ D (D = diag K_T, γ = 1e-4,
            // 1e-3, …, 1) — a damped Newton step, still a descent direction
            let mut shift = 0.0;
            if !reuse {
                loop {
                    let result = self.contact.refactorise(|dofs, m| {
                        linear.assemble_tangent(model, dofs, kin, at, m)?;
                        if let Some(b) = constant {
                            m.add_scaled(1.0, b)?;
                        }
                        if shift > 0.0 {
                            for (k, d) in m.diagonal().into_iter().enumerate() {
                                m.add(k, k, shift * d.abs())?;
                            }
                        }
                        Ok(())
                    });
                    report.factorisations += 1;
                    match result {
                        Ok(()) => {
                            self.tangent_kept = true;
                            break;
                        }
                        Err(ContactError::Fem(FemError::Linalg(
                            synovia_linalg::LinalgError::NotPositiveDefinite { .. },
                        ))) if shift < 1.0 => {
                            shift = if shift == 0.0 { 1e-4 } else { shift * 10.0 };
                            tracing::debug!(shift, "indefinite tangent: shifted");
                        }
                        Err(e) => return Err(e.into()),
                    }
                }
            }
            report.shifted_tangents += usize::from(shift > 0.0);
            let k = self.contact.elastic().stiffness();
            let mut ku = vec![0.0; n];
            k.mul_vec(&u, &mut ku);
            let rows = self.contact.geometry().len();
            let (load, result) = if let Some(ctl) = control.as_deref_mut() {
                // load control: the level's time `t` of this iteration is the one at which the
                // linearised problem's resultant equals the target (secant on `t`; each trial a
                // contact solve on the kept factorisation, for the multipliers only: the
                // displacement is completed for the accepted trial alone)
                let resultant = ctl.resultant;
                let trial = |tt: Real,
                             warm: Option<&ContactSolution>|
                 -> Result<
                    (Real, Vec<Real>, Vec<Vector<D>>, Vec<Real>, Real, ContactSolution),
                    NonlinearError,
                > {
                    let lt: Vec<Vector<D>> =
                        self.dofs.lifts(model, tt)?.into_iter().map(|l| l * scale).collect();
                    let mut fe = vec![0.0; n];
                    add_loads(model, &self.dofs, tt, self.params.load_degree, &mut fe)?;
                    fe.iter_mut().for_each(|f| *f *= scale);
                    let mut ld: Vec<Real> = (0..n).map(|i| fe[i] - f_int[i] + ku[i]).collect();
                    let dl: Vec<Vector<D>> = lt.iter().zip(&current_lifts).map(|(a, b)| a - b).collect();
                    let mut lift_force = 0.0;
                    if dl.iter().any(|d| d.norm_squared() > 0.0) {
                        let before = ld.clone();
                        subtract_tangent_lift(model, &self.dofs, kin, at, &dl, &mut ld)?;
                        lift_force = norm(&(0..n).map(|i| ld[i] - before[i]).collect::<Vec<_>>());
                    }
                    let (res, _) = self.contact.solve_load_multipliers(
                        &ld,
                        &lt,
                        solver,
                        slip_bound.as_deref().filter(|g| g.len() == rows),
                        previous_disp.as_deref(),
                        warm.filter(|w| w.lambda_n.len() == rows),
                    )?;
                    let f = resultant(self.contact.geometry(), &res.lambda_n);
                    Ok((f, ld, lt, fe, lift_force, res))
                };
                let inner = 0.1 * ctl.tolerance;
                let (mut ta, mut tb) = (t, t);
                let mut b = trial(tb, warm.as_ref())?;
                ctl.trials += 1;
                let mut fa = b.0;
                for _ in 0..30 {
                    if (b.0 - ctl.target).abs() <= inner {
                        break;
                    }
                    if tb != ta {
                        let s = (b.0 - fa) / (tb - ta);
                        if s > 0.0 && s.is_finite() {
                            ctl.slope = s;
                        }
                    }
                    let tc = tb + (ctl.target - b.0) / ctl.slope;
                    if !tc.is_finite() {
                        break;
                    }
                    (ta, fa) = (tb, b.0);
                    tb = tc;
                    b = trial(tb, Some(&b.5))?;
                    ctl.trials += 1;
                }
                if (b.0 - ctl.target).abs() > inner {
                    return Err(NonlinearError::NoConvergence {
                        time: tb,
                        cutbacks: 0,
                        step: 0.0,
                        reason: format!("load control: resultant {} for the target {}", b.0, ctl.target),
                    });
                }
                let (_, ld, lt, fe, lift_force, solution) = b;
                let res = self.contact.complete_load(
                    &ld,
                    &lt,
                    slip_bound.as_deref().filter(|g| g.len() == rows),
                    previous_disp.as_deref(),
                    solution,
                )?;
                predictor = lift_force > 0.0;
                r_start = r_start.max(lift_force);
                t = tb;
                lifts = lt;
                f_ext = fe;
                (ld, res)
            } else if let Some(g) = gap.as_deref_mut() {
                // gap control: the partner's position `w` of this iteration is the one at which
                // the linearised problem's resultant equals the target (safeguarded secant on
                // `w`, the gaps first order in `w`; each trial a contact solve for the
                // multipliers on the kept factorisation)
                let fo = first_order.as_ref().ok_or_else(|| {
                    NonlinearError::InvalidParameter("internal: gap control without a geometry".into())
                })?;
                let mut load: Vec<Real> = (0..n).map(|i| f_ext[i] - f_int[i] + ku[i]).collect();
                if predictor {
                    let before = load.clone();
                    subtract_tangent_lift(model, &self.dofs, kin, at, &delta_lifts, &mut load)?;
                    let lift_force: Vec<Real> = (0..n).map(|i| load[i] - before[i]).collect();
                    r_start = r_start.max(norm(&lift_force));
                }
                // friction: the slip bounds and origin of the committed state (the partner's
                // motion of the accepted trial is left set on the geometry)
                let frozen = slip_bound.as_deref().filter(|b| g.friction.is_some() && b.len() == rows);
                let origin = previous_disp.as_deref().filter(|_| frozen.is_some());
                let (w, solution) =
                    self.search_gap_control(g, fo, &load, &lifts, solver, warm.as_ref(), frozen, origin)?;
                let res = self.contact.complete_load(&load, &lifts, frozen, origin, solution)?;
                predictor = predictor || w != g.w;
                g.w = w;
                (load, res)
            } else {
                let mut load: Vec<Real> = (0..n).map(|i| f_ext[i] - f_int[i] + ku[i]).collect();
                if predictor {
                    let before = load.clone();
                    subtract_tangent_lift(model, &self.dofs, kin, at, &delta_lifts, &mut load)?;
                    let lift_force: Vec<Real> = (0..n).map(|i| load[i] - before[i]).collect();
                    r_start = r_start.max(norm(&lift_force));
                }
                let warm_start = warm.as_ref().filter(|w| w.lambda_n.len() == rows);
                let result = self.contact.solve_load(
                    &load,
                    &lifts,
                    solver,
                    slip_bound.as_deref().filter(|g| g.len() == rows),
                    previous_disp.as_deref(),
                    warm_start,
                )?;
                (load, result)
            };
            let u_star = &result.solution.u;
            let k = self.contact.elastic().stiffness();
            let mut k_star = vec![0.0; n];
            k.mul_vec(u_star, &mut k_star);
            let c_star: Vec<Real> = (0..n).map(|i| load[i] - k_star[i]).collect();
            let delta: Vec<Real> = (0..n).map(|i| u_star[i] - u[i]).collect();
            // a level with extra terms (a time step): a Newton correction below √tol of the
            // solution is taken whole and ends the iteration — with quadratic convergence the
            // error left is of the order of its square; this is what ends the iteration when
            // the residual is at its rounding floor (the cancellation in the stress of tiny
            // strains, e.g. `μ (I − C⁻¹)`, caps its relative accuracy at `ε_mach / |e|`)
            let tiny = terms.is_some()
                && !reuse
                && norm(&delta) <= self.params.tolerance.sqrt() * norm(u_star).max(Real::MIN_POSITIVE);
            // backtracking line search on ‖R‖ along (δũ, δc); a trial whose residual is already
            // at the tolerance is accepted (no decrease can be asked of rounding noise)
            let settled =
                self.params.tolerance * norm(&f_ext).max(norm(&f_int)).max(norm(&c_star)).max(r_start);
            // the first step on a geometry rebuilt at a loaded configuration (a later pass, or
            // the first pass of a level that starts from a converged loaded state): the merit
            // `‖R‖` of the old geometry was at its minimum there, so any move toward the new
            // geometry's solution raises it; the step is taken whole, as the predictor
            let rebuilt = finite && first_of_pass && (passes > 1 || self.state.scale > 0.0);
            // Outer: the first step on updated sets is taken whole for the same reason: the
            // equilibrium residual was at its minimum for the old sets (measured: damped to
            // α = 1/128 three times running, a failed level, on every Hertz case)
            let rebuilt = rebuilt || std::mem::take(&mut new_anchor);
            // the first step of a level that starts in equilibrium (its residual at the
            // tolerance), e.g. a rigid partner moved by prescribed coordinates: only the gaps
            // changed, which the merit `‖R‖` does not see (it was at its minimum, zero, before
            // the step), so the step is taken whole, as the predictor
            let rebuilt = rebuilt || (iterations.is_empty() && r_norm <= settled);
            let mut alpha = 1.0;
            let mut forced = false;
            let accepted = loop {
                let u_try: Vec<Real> = (0..n).map(|i| u[i] + alpha * delta[i]).collect();
                let c_try: Vec<Real> = (0..n).map(|i| c[i] + alpha * (c_star[i] - c[i])).collect();
                let disp_try = self.dofs.expand(&u_try, &lifts)?;
                match self.effective_force(model, &disp_try, &u_try) {
                    Ok((f_try, e_try)) => {
                        let r_try = norm(&residual_of(&f_ext, &f_try, &c_try));
                        if !self.params.line_search
                            || predictor
                            || rebuilt
                            || tiny
                            || r_try <= settled
                            || r_try <= (1.0 - 1e-4 * alpha) * r_norm
                            || alpha < 1.0 / 64.0
                        {
                            forced = self.params.line_search
                                && !predictor
                                && !rebuilt
                                && !tiny
                                && r_try > settled
                                && r_try > (1.0 - 1e-4 * alpha) * r_norm;
                            break Some((u_try, c_try, disp_try, f_try, e_try, r_try));
                        }
                    }
                    Err(FemError::InvertedElement { .. })
                        if self.params.line_search && alpha >= 1.0 / 64.0 => {}
                    Err(e) => return Err(e.into()),
                }
                alpha *= 0.5;
                if alpha < 1.0 / 128.0 {
                    break None;
                }
            };
            let Some((u_new, c_new, disp_new, f_new, e_new, r_new)) = accepted else {
                return Err(NonlinearError::NoConvergence {
                    time: t,
                    cutbacks: 0,
                    step: 0.0,
                    reason: "the line search found no admissible step".into(),
                });
            };
            // a Newton direction that fails to decrease the residual three times running (a
            // tangent shifted far from the true one, a stalled active set) is a failed level:
            // the cut-back takes a smaller step instead of creeping along it
            forced_steps = if forced && !reuse { forced_steps + 1 } else { 0 };
            if forced_steps >= 3 {
                return Err(NonlinearError::NoConvergence {
                    time: t,
                    cutbacks: 0,
                    step: 0.0,
                    reason: format!(
                        "the line search found no decrease of the residual in 3 iterations running (relative residual {:e})",
                        r_norm / norm(&f_ext).max(norm(&f_int)).max(norm(&c)).max(r_start).max(Real::MIN_POSITIVE)
                    ),
                });
            }
            let increment = alpha * norm(&delta) / norm(&u_new).max(Real::MIN_POSITIVE);
            predictor = false;
            current_lifts.clone_from(&lifts);
            u = u_new;
            c = c_new;
            disp = disp_new;
            f_int = f_new;
            let energy = e_new;
            // modified Newton: the tangent is kept while full steps contract the residual
            // by the bound ρ (a line-searched or slow step asks for a fresh one)
            if let Some(rho) = self.params.tangent_reuse {
                let contracted = alpha == 1.0 && r_new <= rho * r_norm;
                self.tangent_kept = contracted || r_new <= settled;
            }
            r_norm = r_new;
            let force_scale = norm(&f_ext).max(norm(&f_int)).max(norm(&c)).max(r_start);
            let relative = if force_scale > 0.0 { r_norm / force_scale } else { 0.0 };
            if first_of_pass {
                pass_increment = increment;
                first_of_pass = false;
                tracing::debug!(pass_increment, omega, passes, "first step of a geometry pass");
            }
            iterations.push(NewtonIteration {
                residual: relative,
                increment,
                step: alpha,
                contact_iterations: result.solution.report.iterations,
                active: result.solution.report.active,
            });
            tracing::debug!(relative, increment, alpha, "Newton iteration");
            if !relative.is_finite() {
                break;
            }
            // converged: the residual at the tolerance, or a full step that no longer moves
            // the iterate (a residual at rounding level of a level that barely changed)
            // Combined, Outer: the last active-set step left its sets unchanged and solved the
            // complementarity conditions (the slip rows of 3D are linearised in a step)
            let contact_settled = !single_steps
                || result.solution.report.history.last().is_some_and(|h| {
                    h.set_changes == 0
                        && h.normal <= self.params.tolerance
                        && h.tangential <= self.params.tolerance
                });
            // the pass started from the solution's geometry: its first step moved the iterate
            // by at most the geometry tolerance
            let pass_on_settled_geometry = pass_increment <= self.params.geometry_tolerance;
            // finite strain on a settled geometry: a full step below the settled increment
            let settled_step = finite
                && alpha == 1.0
                && pass_on_settled_geometry
                && self.params.settled_increment.is_some_and(|d| increment <= d);
            let equilibrium = relative <= self.params.tolerance
                || force_scale == 0.0
                || (alpha == 1.0 && increment <= self.params.tolerance)
                || (tiny && alpha == 1.0)
                || settled_step;
            let converged = contact_settled && equilibrium;
            // a pass whose geometry is still moving ends at the looser pass tolerance
            let pass_converged = converged
                || (finite
                    && contact_settled
                    && !pass_on_settled_geometry
                    && self.params.geometry_pass_tolerance.is_some_and(|p| relative <= p));
            // a converged pass ends the level when the geometry it started from was already
            // that of the solution; otherwise the geometry is rebuilt for another pass
            let geometry_settled = !finite
                || pass_on_settled_geometry
                || self.params.geometry_update == GeometryUpdate::PerLevel;
            if pass_converged && !geometry_settled {
                if passes > self.params.max_geometry_passes {
                    return Err(NonlinearError::NoConvergence {
                        time: t,
                        cutbacks: 0,
                        step: 0.0,
                        reason: format!(
                            "the contact geometry on the deformed configuration did not settle in {} rebuilds \
                             (last change {pass_increment:e}, tolerance {:e}); GeometryUpdate::PerLevel rebuilds it once per level",
                            self.params.max_geometry_passes, self.params.geometry_tolerance
                        ),
                    });
                }
                refresh = true;
            }
            let done = converged && geometry_settled;
            // Outer: the anchor the sets are classified from is kept while the equilibrium
            // converges on its sets (unless it does not fit the rows, e.g. after a rebuild of the
            // geometry: then this iteration's state is the anchor); Nested, Combined: the last
            // solution warm-starts the next iteration
            let keep_anchor =
                outer && !equilibrium && warm.as_ref().is_some_and(|w| w.lambda_n.len() == rows);
            new_anchor = outer && equilibrium && !contact_settled;
            if !keep_anchor {
                warm = Some(result.solution.clone());
                if single_steps {
                    // the next step's sets come from the iterate reached (after the line search)
                    if let Some(w) = warm.as_mut() {
                        w.u.clone_from(&u);
                    }
                }
            }
            if done {
                let mut result = result;
                result.displacement = disp;
                result.solution.u = u.clone();
                return Ok((result, energy, iterations, u, c, t));
            }
        }
        let last = iterations.last().map_or(Real::NAN, |i| i.residual);
        Err(NonlinearError::NoConvergence {
            time: t,
            cutbacks: 0,
            step: 0.0,
            reason: format!(
                "{} Newton iterations left the relative residual at {last:e} (tolerance {:e})",
                iterations.len(),
                self.params.tolerance
            ),
        })
    }
}
