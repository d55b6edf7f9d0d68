//! Node-to-node contact on matching meshes (docs/model.md §5, the conforming case).
//!
//! Every node `i` of the slave part of body `k` is paired with the node `j` of the partner part
//! of body `l` at the same position after projecting out the pairing direction `e` (default:
//! the mean outward normal of part `k`). The row is
//! `(B_hn U)_r = n_r · (u^k_i − u^l_j) ≤ d_r = n_r · (x^l_j − x^k_i)`, with `n_r` the outward
//! nodal normal `n^k` of body `k` (docs/model.md §1) or a fixed direction, and the lumped weight
//! `κ_r = ∫_{Γ_c} φ_i ds`. The pairing is made in the reference configuration (a pose keeps
//! it; normals and weights are those of the pose).

use synovia_fem::BodyId;
use synovia_mesh::matching::match_nodes;
use synovia_mesh::math::{Point, Real, Vector};

use super::{ContactDiscretisation, ContactRow, PairContext};
use crate::error::ContactError;

/// Which normal a node-to-node pair uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalChoice<const D: usize> {
    /// The outward nodal normal `n^k` of body `k` (docs/model.md §1; default).
    BodyK,
    /// A fixed unit direction from body `k` toward body `l` for every node.
    Fixed(Vector<D>),
}

/// Node-to-node pairing of the slave part with the contact part `part` of body `body` (see the
/// [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeToNode<const D: usize> {
    /// The other body `l`.
    pub body: BodyId,
    /// Its contact part.
    pub part: String,
    /// Pairing direction: nodes are paired when their positions agree after projecting out
    /// this direction (default: the mean outward normal of part `k`).
    pub direction: Option<Vector<D>>,
    /// Pairing tolerance (absolute; default `1e-6 ×` the shortest facet edge of part `k`).
    pub tolerance: Option<Real>,
    /// Normal used for the pairs.
    pub normal: NormalChoice<D>,
}

impl<const D: usize> NodeToNode<D> {
    /// Pairs with part `part` of body `body`, default direction, tolerance and normal.
    pub fn new(body: BodyId, part: &str) -> Self {
        Self { body, part: part.to_string(), direction: None, tolerance: None, normal: NormalChoice::BodyK }
    }
    /// Uses the fixed normal `direction` (also the pairing direction).
    #[must_use]
    pub fn with_fixed_normal(mut self, direction: Vector<D>) -> Self {
        self.normal = NormalChoice::Fixed(direction);
        self.direction = Some(direction);
        self
    }
    /// Sets the absolute pairing tolerance.
    #[must_use]
    pub fn with_tolerance(mut self, tolerance: Real) -> Self {
        self.tolerance = Some(tolerance);
        self
    }
}

impl<const D: usize> ContactDiscretisation<D> for NodeToNode<D> {
    fn kind(&self) -> &str {
        "node-to-node"
    }

    fn partner_part(&self) -> Option<(BodyId, &str)> {
        Some((self.body, &self.part))
    }

    fn rows(&self, cx: &PairContext<'_, D>) -> Result<Vec<ContactRow<D>>, ContactError> {
        let model = cx.model();
        let body = model.body(cx.body())?;
        let other = model.body(self.body)?;
        let lnodes = other.mesh.boundary_part(&self.part)?.nodes();
        let normals = cx.normals();
        // the pairing is made in the reference configuration
        let ref_normals = if cx.is_posed() { body.mesh.nodal_normals(cx.part())? } else { normals.to_vec() };
        let mean_n: Vector<D> = ref_normals.iter().fold(Vector::<D>::zeros(), |a, (_, n)| a + n);
        let e = self.direction.unwrap_or(mean_n);
        let el = e.norm();
        if !(el.is_finite() && el > 0.0) {
            return Err(cx.invalid("pairing direction is zero"));
        }
        let e = e / el;
        let proj = |x: &Point<D>| x - e * x.dot(&e);
        let knodes: Vec<usize> = normals.iter().map(|(i, _)| *i).collect();
        let xk: Vec<Point<D>> = knodes.iter().map(|&i| proj(body.mesh.node(i))).collect();
        let xl: Vec<Point<D>> = lnodes.iter().map(|&i| proj(other.mesh.node(i))).collect();
        let min_edge = cx.min_edge();
        let tol = self.tolerance.unwrap_or(1e-6 * min_edge);
        let pairs_found = match match_nodes(&xk, &xl, tol) {
            Ok(p) => p,
            Err(u) => {
                if !u.first.is_empty() {
                    return Err(ContactError::UnmatchedNodes {
                        pair: cx.name().to_string(),
                        body: body.name.clone(),
                        count: u.first.len(),
                        nodes: u.first.iter().take(10).map(|&i| knodes[i]).collect(),
                    });
                }
                // extra nodes on body l are allowed: redo the matching on the matched subset
                let used: std::collections::HashSet<usize> = u.second.iter().copied().collect();
                let keep: Vec<usize> = (0..lnodes.len()).filter(|j| !used.contains(j)).collect();
                let xl2: Vec<Point<D>> = keep.iter().map(|&j| xl[j]).collect();
                match_nodes(&xk, &xl2, tol)
                    .map_err(|_| cx.invalid("node pairing is ambiguous"))?
                    .into_iter()
                    .map(|(a, b)| (a, keep[b]))
                    .collect()
            }
        };
        let fixed = match self.normal {
            NormalChoice::BodyK => None,
            NormalChoice::Fixed(v) => {
                let l = v.norm();
                if !(l.is_finite() && l > 0.0) {
                    return Err(cx.invalid("fixed normal is zero"));
                }
                Some(v / l)
            }
        };
        let (pos_k, pos_l) = match (cx.positions(cx.body()), cx.positions(self.body)) {
            (Some(k), Some(l)) => (k, l),
            _ => return Err(cx.invalid("unknown body")),
        };
        let mut rows = Vec::with_capacity(pairs_found.len());
        let mut largest_gap = Real::NEG_INFINITY;
        for (a, b) in pairs_found {
            let (i, j) = (knodes[a], lnodes[b]);
            let n = fixed.unwrap_or(normals[a].1);
            // the sanity check below uses the reference gap
            largest_gap = largest_gap.max((other.mesh.node(j) - body.mesh.node(i)).dot(&n));
            rows.push(ContactRow {
                node: i,
                partner: Some((self.body, j)),
                master: Vec::new(),
                normal: n,
                weight: cx.weight(i),
                gap: (pos_l[j] - pos_k[i]).dot(&n),
            });
        }
        // every node penetrating its partner by more than an element edge: the normals of
        // part k point away from part l (or the parts are swapped)
        if !rows.is_empty() && largest_gap < -min_edge {
            let (pk, pl) = (cx.part(), &self.part);
            return Err(cx.invalid(format!(
                "every node of part `{pk}` lies more than one element edge ({min_edge:.3e}) behind its partner on part `{pl}` (largest gap {largest_gap:.3e}): do the normals of `{pk}` point away from `{pl}`?"
            )));
        }
        Ok(rows)
    }
}
