//! Contact discretisations behind one open trait (docs/model.md §5).
//!
//! A contact discretisation turns one contact pair `Γ_c^{kl}` into **contact rows**: for every
//! row `r` the slave node `s_r` of body `k`, the nodes of the other side with their weights
//! (the jump), the unit normal `n_r`, the weight `κ_r` and the gap `d_r`, so that the discrete
//! non-penetration condition of docs/model.md §5 reads
//!
//! ```text
//! (B_hn U)_r = [U_n](s_r) = n_r · (u^k(s_r) − Σ_j w_rj u^l_j) ≤ d_r,     κ_r = ∫_{Γ_c} φ_r ds
//! ```
//!
//! Rows, gaps and weights are the whole contract (as in GetFEM's nodal contact bricks, where
//! the higher bricks compute `B_N`, the gap and `α` and hand them to the basic brick):
//! [`crate::operators::ContactGeometry`] adds the pair's friction coefficient, the tangent basis
//! of `n_r` and the placements, and assembles `B_hn`, `κ`, `d` and the friction rows `B_Ht`
//! for every solver. The four built-in discretisations, one file each:
//!
//! | type | pair constructor | rows |
//! |------|------------------|------|
//! | [`NodeToNode`] | [`ContactPair::node_to_node`] | matching meshes: `[u] = u^k_i − u^l_j` |
//! | [`NodeToSegment`] | [`ContactPair::node_to_segment`] | closest master facet, `w_j` barycentric |
//! | [`DualMortar`] | [`ContactPair::mortar`] | dual mortar, `w_jk = M_jk / D_jj`, `κ_j = D_jj` |
//! | [`RigidObstacle`] | [`ContactPair::rigid`] | signed distance `φ`, no other side |
//!
//! # Adding a discretisation
//!
//! Implement [`ContactDiscretisation`] for a type (in any crate) and build the pair with
//! [`ContactPair::custom`]; nothing in this crate needs to change. `rows` gets a
//! [`PairContext`] with the model, the positions of every body in the configuration the
//! geometry is built on, and the outward nodal normals, lumped weights and shortest edge of
//! the slave part there. It returns the rows **measured in that configuration** (the gap
//! `d_r` is the distance at the given positions); the geometry converts them to the total form
//! of a pose (see [`crate::operators`]).
//!
//! [`ContactPair::node_to_node`]: crate::operators::ContactPair::node_to_node
//! [`ContactPair::node_to_segment`]: crate::operators::ContactPair::node_to_segment
//! [`ContactPair::mortar`]: crate::operators::ContactPair::mortar
//! [`ContactPair::rigid`]: crate::operators::ContactPair::rigid
//! [`ContactPair::custom`]: crate::operators::ContactPair::custom

use std::any::Any;
use std::collections::HashMap;
use std::fmt;

use synovia_fem::{BodyId, Model};
use synovia_mesh::math::{Point, Real, Vector};

use crate::error::ContactError;
use crate::operators::ContactNode;

pub mod mortar;
pub mod node_to_node;
pub mod node_to_segment;
pub mod rigid;

pub use mortar::DualMortar;
pub use node_to_node::{NodeToNode, NormalChoice};
pub use node_to_segment::NodeToSegment;
pub use rigid::RigidObstacle;

/// One contact row of a pair, in the configuration of its [`PairContext`] (docs/model.md §5):
/// `(B_hn U)_r = n_r · (u^k_{node} − u^l_{partner} − Σ_j w_j u^{l_j}_j) ≤ d_r` with weight `κ_r`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRow<const D: usize> {
    /// The slave node `s_r` (mesh index in body `k`, a node of the slave part).
    pub node: usize,
    /// A partner node `(body l, node j)` with weight 1 (node-to-node), or `None`.
    pub partner: Option<(BodyId, usize)>,
    /// Further nodes `(body, node j, w_j)` of the other side (node-to-segment, mortar); empty
    /// for a rigid obstacle.
    pub master: Vec<(BodyId, usize, Real)>,
    /// The unit normal `n_r`, pointing from body `k` toward the other side.
    pub normal: Vector<D>,
    /// The weight `κ_r = ∫_{Γ_c} φ_r ds` (lumped; mortar: `D_rr`).
    pub weight: Real,
    /// The gap `d_r` at the positions of the context: `n_r · (x_other(s_r) − x_k(s_r))`,
    /// negative for a penetration.
    pub gap: Real,
}

/// What a [`ContactDiscretisation`] sees of one contact pair: the model, the positions of every
/// body in the configuration the geometry is built on, and the slave part `k` there.
#[derive(Debug)]
pub struct PairContext<'a, const D: usize> {
    pub(crate) model: &'a Model<D>,
    pub(crate) name: &'a str,
    pub(crate) body: BodyId,
    pub(crate) part: &'a str,
    pub(crate) positions: &'a [Vec<Point<D>>],
    pub(crate) posed: bool,
    pub(crate) normals: &'a [(usize, Vector<D>)],
    pub(crate) weights: &'a HashMap<usize, Real>,
    pub(crate) min_edge: Real,
}

impl<'a, const D: usize> PairContext<'a, D> {
    /// The model (meshes in the reference configuration).
    pub fn model(&self) -> &'a Model<D> {
        self.model
    }
    /// The pair's name.
    pub fn name(&self) -> &'a str {
        self.name
    }
    /// The slave body `k`.
    pub fn body(&self) -> BodyId {
        self.body
    }
    /// The slave part of body `k`.
    pub fn part(&self) -> &'a str {
        self.part
    }
    /// Node positions of `body` in the configuration the geometry is built on (the reference
    /// mesh, or `x + u⁰` at a pose / placement); `None` for an unknown body.
    pub fn positions(&self, body: BodyId) -> Option<&'a [Point<D>]> {
        self.positions.get(body.0).map(Vec::as_slice)
    }
    /// `true` if the positions are a pose or placement rather than the reference meshes.
    pub fn is_posed(&self) -> bool {
        self.posed
    }
    /// The nodes of the slave part with their outward unit nodal normals `n^k` at the positions
    /// (docs/model.md §1), in the part's node order.
    pub fn normals(&self) -> &'a [(usize, Vector<D>)] {
        self.normals
    }
    /// The lumped weight `κ_i = ∫_{Γ_c} φ_i ds` of slave node `i` at the positions (0 for a
    /// node not on the part).
    pub fn weight(&self, node: usize) -> Real {
        self.weights.get(&node).copied().unwrap_or(0.0)
    }
    /// The shortest facet edge of the slave part (reference mesh).
    pub fn min_edge(&self) -> Real {
        self.min_edge
    }
    /// A [`ContactError::InvalidPair`] of this pair with `reason`.
    pub fn invalid(&self, reason: impl Into<String>) -> ContactError {
        ContactError::InvalidPair { pair: self.name.to_string(), reason: reason.into() }
    }
}

/// A contact discretisation: produces the contact rows of one pair (see the
/// [module docs](self)): per row the slave node, the other side's nodes with their weights,
/// the normal `n_r`, the weight `κ_r = ∫ φ_r ds` and the gap `d_r`, so that
/// `(B_hn U)_r = [U_n](s_r) ≤ d_r` (docs/model.md §5).
///
/// Object safe: a [`crate::operators::ContactPair`] holds an
/// `Arc<dyn ContactDiscretisation<D>>`.
pub trait ContactDiscretisation<const D: usize>: Any + Send + Sync + fmt::Debug {
    /// A short name of the kind of discretisation (`"node-to-node"`, …) for reports.
    fn kind(&self) -> &str;

    /// The other side's body and contact part (`None` for a rigid obstacle): its nodes are
    /// interface unknowns and the part is a contact part.
    fn partner_part(&self) -> Option<(BodyId, &str)>;

    /// The contact rows of the pair at the positions of `context`, gaps measured there.
    ///
    /// # Errors
    /// [`ContactError::InvalidPair`] (see [`PairContext::invalid`]) for a pair that cannot be
    /// discretised; mesh and model errors for unknown bodies or parts.
    fn rows(&self, context: &PairContext<'_, D>) -> Result<Vec<ContactRow<D>>, ContactError>;

    /// The rows at new positions (re-pairing), given the pair's contact nodes in the geometry
    /// being replaced (gaps there in total form). Default: [`ContactDiscretisation::rows`], a
    /// full rebuild.
    ///
    /// # Errors
    /// As [`ContactDiscretisation::rows`].
    fn update(
        &self,
        context: &PairContext<'_, D>,
        previous: &[ContactNode<D>],
    ) -> Result<Vec<ContactRow<D>>, ContactError> {
        let _ = previous;
        self.rows(context)
    }
}

/// The master side of a node-to-segment or mortar pair: another body, a valid search distance.
pub(crate) fn check_master(
    slave: BodyId,
    master: BodyId,
    search_distance: Option<Real>,
) -> Result<(), String> {
    if master == slave {
        return Err("self-contact (master body = slave body) is not supported".into());
    }
    match search_distance {
        Some(s) if !(s.is_finite() && s >= 0.0) => Err(format!("search distance {s} must be finite and ≥ 0")),
        _ => Ok(()),
    }
}

/// `Σ_j w_j x_j` over `(node, w)` of `positions`.
pub(crate) fn weighted_point<const D: usize>(positions: &[Point<D>], weights: &[(usize, Real)]) -> Point<D> {
    weights.iter().fold(Point::<D>::zeros(), |acc, &(j, w)| acc + positions[j] * w)
}
