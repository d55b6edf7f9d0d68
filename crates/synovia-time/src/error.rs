//! Errors of time stepping.

use thiserror::Error;

use synovia_contact::ContactError;
use synovia_fem::FemError;
use synovia_io::IoError;

/// Everything that can go wrong while stepping in time.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum TimeError {
    /// A contact error (solver non-convergence, infeasible step, …), with the step it happened at.
    #[error("time step {step} (t = {time}): {source}")]
    Contact {
        /// Step index.
        step: usize,
        /// Time.
        time: f64,
        /// The error.
        #[source]
        source: ContactError,
    },
    /// A contact error outside a step (set-up).
    #[error(transparent)]
    ContactSetup(#[from] ContactError),
    /// A step of the nonlinear dynamic scheme failed after its cut-backs
    /// ([`crate::nonlinear_dynamic::NonlinearDynamicStepper`]).
    #[error("time step {step} (t = {time}): {source}")]
    Nonlinear {
        /// Step index.
        step: usize,
        /// Time of the sub-step that failed.
        time: f64,
        /// The error of the Newton iteration.
        #[source]
        source: synovia_nonlinear::NonlinearError,
    },
    /// An error of the Newton iteration outside a step (set-up, initial state).
    #[error(transparent)]
    NonlinearSetup(#[from] synovia_nonlinear::NonlinearError),
    /// A finite-element error.
    #[error(transparent)]
    Fem(#[from] FemError),
    /// A linear-algebra error (factorisation, solve).
    #[error(transparent)]
    Linalg(#[from] synovia_linalg::LinalgError),
    /// An output error.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A history or stepper parameter is invalid.
    #[error("invalid time-stepping parameter: {0}")]
    InvalidParameter(String),
    /// The Coulomb fixed point did not converge.
    #[error("time step {step}: Coulomb fixed point did not converge in {iterations} iterations (last change {change:e})")]
    FixedPoint {
        /// Step index.
        step: usize,
        /// Iterations done.
        iterations: usize,
        /// Last relative change of the slip bound.
        change: f64,
    },
    /// Bodies held only by contact carry a tangential load above what Coulomb friction can
    /// hold at this level, `|Q_t| > Σ_r F_c κ_r |Λ_n,r| = μ·P` (docs/model.md §7.1): no static
    /// equilibrium exists, the body slides. Forces in the model's force unit (newtons for the
    /// usual mm–N–MPa units; per unit thickness in 2D).
    #[error("time step {step} (t = {time}): the tangential load {tangential:.6e} N on {bodies:?} exceeds the friction capacity μ·P = {capacity:.6e} N (normal force P = {normal:.6e} N); the body slides")]
    Slides {
        /// Step index.
        step: usize,
        /// Time.
        time: f64,
        /// The bodies held by friction (one floating component).
        bodies: Vec<String>,
        /// Magnitude of the tangential part of the load resultant on those bodies.
        tangential: f64,
        /// The friction capacity `Σ_r g_c,r κ_r` (`μ·P` for a constant coefficient).
        capacity: f64,
        /// The normal contact force `P = Σ_r κ_r Λ_n,r` on those bodies.
        normal: f64,
    },
}
