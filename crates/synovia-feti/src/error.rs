//! The error type of the crate.

use synovia_contact::ContactError;
use synovia_fem::FemError;
use synovia_linalg::LinalgError;

/// What can go wrong in a TFETI set-up or solve. Each variant names the offending entity.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FetiError {
    /// A parameter out of range or inconsistent sizes.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// METIS failed on the cell graph of a body.
    #[error("METIS could not partition body `{body}` into {parts} parts: {message}")]
    Partition {
        /// Body name.
        body: String,
        /// Requested parts.
        parts: usize,
        /// METIS' message.
        message: String,
    },
    /// A subdomain stiffness has a kernel other than its rigid-body modes (e.g. a subdomain
    /// whose cells hang together at a node only), or its regular part could not be factorised.
    #[error("subdomain {subdomain}: {message}")]
    Subdomain {
        /// Subdomain index.
        subdomain: usize,
        /// What was found.
        message: String,
    },
    /// The Dirichlet and gluing conditions alone do not fix the rigid-body modes of all
    /// subdomains (`G_E G_Eᵀ` singular): some body is held by contact only
    /// (semi-coercive, docs/model.md §4), which this TFETI version does not treat.
    #[error("the equality constraints do not fix every rigid-body mode (coarse matrix singular at pivot {pivot}): a body is held by contact only")]
    SemiCoercive {
        /// Index of the failing pivot of `G_E G_Eᵀ`.
        pivot: usize,
    },
    /// The contact problem's operator does not belong to the decomposition (its unknowns are
    /// not the decomposed model's reduced unknowns).
    #[error("the contact problem has {got} unknowns, the decomposition {expected}")]
    Mismatch {
        /// Reduced unknowns of the decomposition.
        expected: usize,
        /// Unknowns of the problem.
        got: usize,
    },
    /// SMALBE did not reach the tolerance.
    #[error("SMALBE stopped after {outer} outer and {inner} inner iterations: ‖g^P‖/‖b‖ = {gradient:.3e}, ‖Gλ‖/‖b‖ = {feasibility:.3e}")]
    NoConvergence {
        /// Outer iterations.
        outer: usize,
        /// Inner (MPRGP/MPGP) iterations.
        inner: usize,
        /// Relative projected gradient.
        gradient: f64,
        /// Relative violation of the coarse condition.
        feasibility: f64,
    },
    /// An error of the message-passing layer.
    #[error("communication: {0}")]
    Communication(String),
    /// From the finite-element layer.
    #[error(transparent)]
    Fem(#[from] FemError),
    /// From the linear algebra layer.
    #[error(transparent)]
    Linalg(#[from] LinalgError),
    /// From the contact layer (geometry, QP solvers).
    #[error(transparent)]
    Contact(#[from] ContactError),
}

impl From<FetiError> for ContactError {
    fn from(e: FetiError) -> Self {
        match e {
            FetiError::Contact(c) => c,
            FetiError::NoConvergence { outer, inner, gradient, feasibility } => ContactError::NoConvergence {
                solver: format!("tfeti (SMALBE: {inner} inner iterations, ‖Gλ‖/‖b‖ = {feasibility:.1e})"),
                iterations: outer,
                history: vec![synovia_contact::IterationResidual {
                    iteration: outer,
                    normal: gradient,
                    tangential: feasibility,
                    set_changes: 0,
                }],
            },
            other => ContactError::InvalidParameter(format!("tfeti: {other}")),
        }
    }
}
