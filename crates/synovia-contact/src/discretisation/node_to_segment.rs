//! Node-to-segment (2D) / node-to-facet (3D) contact on non-matching meshes (docs/model.md §5).
//!
//! Part `k` is the *slave* side, part `l` the *master* side. Every slave node `x_s` is
//! projected onto the master facets with the R*-tree search of [`crate::search`] (closest facet
//! containing the orthogonal projection; see there for the rule at convex master edges and at
//! the rim of the master part). The row uses
//!
//! * the normal `n = −n_l`, the master facet's outward unit normal negated (it points from `k`
//!   into `l`, like `n^k` of a conforming pair): then `d` is the exact distance of `x_s` to the
//!   master facet plane and a flat master surface gives the exact normal whatever the slave mesh;
//! * the master point `x_m = Σ_j w_j x_{l,j}` (barycentric weights on the facet's nodes),
//!   `[u_n] = (u_k − Σ_j w_j u_{l,j}) · n`, `d = (x_m − x_s) · n` (negative if `x_s` is inside
//!   body `l`);
//! * the weight `κ_s = ∫ φ_s ds` from the slave facets (the multipliers live on the slave side).
//!
//! Slave nodes without a master facet — farther than the search distance, facing no master
//! facet, or beyond the rim of the master part — are left out; they can enter the pair when the
//! geometry is rebuilt at a later pose.

use synovia_fem::BodyId;
use synovia_mesh::math::Real;

use super::{check_master, weighted_point, ContactDiscretisation, ContactRow, PairContext};
use crate::error::ContactError;
use crate::search::FacetSearch;

/// Node-to-segment / node-to-facet projection of the slave nodes onto the facets of part
/// `part` of body `body` (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeToSegment {
    /// The other (master) body `l`.
    pub body: BodyId,
    /// Its contact part.
    pub part: String,
    /// Largest distance from a slave node to its master point; slave nodes farther away are
    /// left out of the pair (`None`: every slave node is paired with its closest master facet).
    pub search_distance: Option<Real>,
}

impl NodeToSegment {
    /// Master part `part` of body `body`, no search-distance limit.
    pub fn new(body: BodyId, part: &str) -> Self {
        Self { body, part: part.to_string(), search_distance: None }
    }
}

impl<const D: usize> ContactDiscretisation<D> for NodeToSegment {
    fn kind(&self) -> &str {
        "node-to-segment"
    }

    fn partner_part(&self) -> Option<(BodyId, &str)> {
        Some((self.body, &self.part))
    }

    fn rows(&self, cx: &PairContext<'_, D>) -> Result<Vec<ContactRow<D>>, ContactError> {
        check_master(cx.body(), self.body, self.search_distance).map_err(|m| cx.invalid(m))?;
        let other = cx.model().body(self.body)?;
        let lfacets: Vec<Vec<usize>> =
            other.mesh.boundary_part(&self.part)?.facets().map(<[usize]>::to_vec).collect();
        let (pos_k, pos_l) = match (cx.positions(cx.body()), cx.positions(self.body)) {
            (Some(k), Some(l)) => (k, l),
            _ => return Err(cx.invalid("unknown body")),
        };
        let search = FacetSearch::new(pos_l, &lfacets);
        let mut rows = Vec::new();
        for &(i, nk) in cx.normals() {
            let Some(p) = search.project(&pos_k[i], Some(&nk), self.search_distance) else {
                continue;
            };
            let n = -p.normal;
            let xm = weighted_point(pos_l, &p.weights);
            rows.push(ContactRow {
                node: i,
                partner: None,
                master: p.weights.iter().map(|&(j, w)| (self.body, j, w)).collect(),
                normal: n,
                weight: cx.weight(i),
                gap: (xm - pos_k[i]).dot(&n),
            });
        }
        if rows.is_empty() {
            return Err(cx.invalid(format!(
                "no node of part `{}` has a master facet of part `{}` (search distance {:?})",
                cx.part(),
                self.part,
                self.search_distance
            )));
        }
        Ok(rows)
    }
}
