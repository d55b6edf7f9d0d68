//! Contact with a rigid obstacle given by a signed distance `φ` (docs/model.md §5, the
//! foundation case).
//!
//! Every node `i` of the slave part gives the row `(B_hn U)_r = n_r · u^k_i ≤ d_r = φ(x_i)` with
//! `n_r = −∇φ(x_i) / |∇φ(x_i)|` (pointing from the body into the obstacle) and the lumped weight
//! `κ_r = ∫_{Γ_c} φ_i ds`; there is no other side.

use std::sync::Arc;

use rayon::prelude::*;
use synovia_fem::BodyId;
use synovia_mesh::math::{Real, Vector};

use super::{ContactDiscretisation, ContactRow, PairContext};
use crate::error::ContactError;
use crate::operators::SignedDistance;

/// The slave part against a rigid obstacle (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct RigidObstacle<const D: usize> {
    /// The obstacle's signed distance (positive in the free space).
    pub obstacle: Arc<dyn SignedDistance<D>>,
    /// Nodes farther than this from the obstacle (`φ > search_distance`), and nodes outside it
    /// that the obstacle faces away from, keep their row with the body's own outward normal
    /// and their gap `φ`: constraints that cannot become active near this configuration (a
    /// femoral component above the far side of an insert), kept so that the pair's nodes do
    /// not change from pose to pose; nodes inside the obstacle keep its normal whichever way
    /// it faces. `None` (default): every node uses the obstacle's normal, and an obstacle
    /// facing away from a node is an error.
    pub search_distance: Option<Real>,
}

impl<const D: usize> RigidObstacle<D> {
    /// Against `obstacle`.
    pub fn new(obstacle: Arc<dyn SignedDistance<D>>) -> Self {
        Self { obstacle, search_distance: None }
    }
}

impl<const D: usize> ContactDiscretisation<D> for RigidObstacle<D> {
    fn kind(&self) -> &str {
        "rigid"
    }

    fn partner_part(&self) -> Option<(BodyId, &str)> {
        None
    }

    fn rows(&self, cx: &PairContext<'_, D>) -> Result<Vec<ContactRow<D>>, ContactError> {
        self.obstacle.validate().map_err(|m| cx.invalid(format!("obstacle: {m}")))?;
        let pos_k = cx.positions(cx.body()).ok_or_else(|| cx.invalid("unknown body"))?;
        // the obstacle queries (closest points on a surface) are independent per node
        // (beyond the search distance only "farther than it" matters: a bounded query)
        let span = tracing::debug_span!("obstacle_queries").entered();
        let queries: Vec<(Real, Vector<D>)> = cx
            .normals()
            .par_iter()
            .map(|&(i, _)| match self.search_distance {
                Some(reach) => self.obstacle.distance_and_gradient_within(&pos_k[i], reach),
                None => self.obstacle.distance_and_gradient(&pos_k[i]),
            })
            .collect();
        drop(span);
        let mut rows = Vec::with_capacity(cx.normals().len());
        for (&(i, nk), &(phi, grad)) in cx.normals().iter().zip(&queries) {
            let gl = grad.norm();
            if !(phi.is_finite() && gl.is_finite() && gl > 0.0) {
                return Err(cx.invalid(format!("obstacle distance or gradient not finite/zero at node {i}")));
            }
            let n = -grad / gl;
            if let Some(reach) = self.search_distance {
                if phi > reach || (phi > 0.0 && n.dot(&nk) <= 0.0) {
                    rows.push(ContactRow {
                        node: i,
                        partner: None,
                        master: Vec::new(),
                        normal: nk,
                        weight: cx.weight(i),
                        gap: phi,
                    });
                    continue;
                }
            }
            // with a search distance, a node inside the obstacle keeps the obstacle's normal
            // whichever way it faces (a rim node overlapped from the side at a measured pose)
            if n.dot(&nk) <= 0.0 && self.search_distance.is_none() {
                return Err(cx.invalid(format!(
                    "at node {i} the obstacle faces away from the body (outward normal · obstacle normal = {:.3} ≤ 0)",
                    n.dot(&nk)
                )));
            }
            rows.push(ContactRow {
                node: i,
                partner: None,
                master: Vec::new(),
                normal: n,
                weight: cx.weight(i),
                gap: phi,
            });
        }
        Ok(rows)
    }
}
