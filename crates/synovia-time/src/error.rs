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
}
