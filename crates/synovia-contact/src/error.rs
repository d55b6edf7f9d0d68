//! Errors of contact set-up and contact solvers.

use thiserror::Error;

use synovia_fem::FemError;
use synovia_mesh::MeshError;

/// One line of a solver's residual history (docs/model.md §5 residuals).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct IterationResidual {
    /// Iteration number (1-based).
    pub iteration: usize,
    /// `‖Λ_n − (Λ_n + ρ(B_hn U − d))⁺‖_∞` (relative to the multiplier scale).
    pub normal: f64,
    /// `‖Λ_t − π(Λ_t + ρ B_Ht (U − U_prev))‖_∞`.
    pub tangential: f64,
    /// Number of rows whose active/stick/slip state changed in this iteration.
    pub set_changes: usize,
}

/// Everything that can go wrong in a contact computation.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ContactError {
    /// A finite-element error (model, assembly, factorisation).
    #[error(transparent)]
    Fem(#[from] FemError),
    /// A linear-algebra error (factorisation, solve).
    #[error(transparent)]
    Linalg(#[from] synovia_linalg::LinalgError),
    /// A mesh error.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Contact nodes without a partner on the other body.
    #[error("contact pair `{pair}`: {count} node(s) of `{body}` have no partner within the tolerance (first: {nodes:?})")]
    UnmatchedNodes {
        /// Pair name.
        pair: String,
        /// Body whose nodes are unmatched.
        body: String,
        /// Number of unmatched nodes.
        count: usize,
        /// Some of them (mesh indices).
        nodes: Vec<usize>,
    },
    /// A contact pair is badly defined (empty part, normals pointing the wrong way, …).
    #[error("contact pair `{pair}`: {reason}")]
    InvalidPair {
        /// Pair name.
        pair: String,
        /// What is wrong.
        reason: String,
    },
    /// The constraints cannot all be met (e.g. prescribed displacements force a penetration
    /// that no free unknown can undo).
    #[error("infeasible contact problem: {0}")]
    Infeasible(String),
    /// The solver did not converge; the residual history is attached.
    #[error("{solver} did not converge in {iterations} iterations (last residuals: normal {:.3e}, tangential {:.3e})", history.last().map_or(f64::NAN, |r| r.normal), history.last().map_or(f64::NAN, |r| r.tangential))]
    NoConvergence {
        /// Solver name.
        solver: String,
        /// Iterations done.
        iterations: usize,
        /// Residual history.
        history: Vec<IterationResidual>,
    },
    /// A dense interface system was singular (e.g. linearly dependent active constraints).
    #[error("{solver}: singular interface system at iteration {iteration} ({size} unknowns)")]
    Singular {
        /// Solver name.
        solver: String,
        /// Iteration.
        iteration: usize,
        /// Size of the system.
        size: usize,
    },
    /// Bodies held only by contact (semi-coercive, docs/model.md §4) carry a load whose rigid part no
    /// admissible contact force balances: the load pulls them away from, or slides them off,
    /// their contact partners.
    #[error("bodies {} are held only by contact, and contact forces cannot balance their load: an unbalanced net force of {} N (rigid-body load norm {residual:.3e} of {load:.3e}) pulls them away or slides them off; add Dirichlet or symmetry data, friction, or change the load", synovia_fem::error::fmt_names(bodies), fmt_force(force))]
    Unbalanced {
        /// The floating bodies.
        bodies: Vec<String>,
        /// The net force (Cartesian components, in the model's force unit — newtons for SI
        /// models) of the part of the load that no contact force balances; empty if unknown.
        force: Vec<f64>,
        /// Norm of the part of the rigid-body load that no contact force balances.
        residual: f64,
        /// Norm of the rigid-body load `Rᵀ F`.
        load: f64,
    },
    /// A parameter is out of range or vectors have inconsistent sizes.
    #[error("invalid contact parameter: {0}")]
    InvalidParameter(String),
}

/// `(1.000e0, -2.000e-3)` for a force vector, `unknown` for an empty one.
fn fmt_force(force: &[f64]) -> String {
    if force.is_empty() {
        return "unknown".into();
    }
    let parts: Vec<String> = force.iter().map(|f| format!("{f:.4e}")).collect();
    format!("({})", parts.join(", "))
}
