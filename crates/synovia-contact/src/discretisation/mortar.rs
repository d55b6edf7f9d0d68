//! Dual mortar contact on non-matching meshes (Wohlmuth's biorthogonal multipliers;
//! docs/model.md §5, the integrals in [`crate::mortar`]).
//!
//! Slave part `k` carries the multipliers, part `l` is the master side. `D` is diagonal, so each
//! slave node `j` keeps one row of the nodal form
//! `(B_hn U)_j = n_j · (u_j − Σ_k w_jk u_k) ≤ d_j` with `w_jk = M_jk / D_jj`, weight
//! `κ_j = D_jj` and gap `d_j = n_j · (Σ_k w_jk x_k − x_j)` (the weighted gap `g̃_j / D_jj`),
//! `n_j` the slave outward nodal normal. A uniform pressure is transmitted exactly.

use synovia_fem::BodyId;
use synovia_mesh::math::{Real, Vector};

use super::{check_master, weighted_point, ContactDiscretisation, ContactRow, PairContext};
use crate::error::ContactError;

/// Dual mortar coupling of the slave part with part `part` of body `body` (see the
/// [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct DualMortar {
    /// The other (master) body `l`.
    pub body: BodyId,
    /// Its contact part.
    pub part: String,
    /// Largest gap (along the slave facet normal) of an integration cell; farther master
    /// facets are not coupled (`None`: every master facet facing and overlapping a slave
    /// facet near its closest master facet).
    pub search_distance: Option<Real>,
}

impl DualMortar {
    /// Master part `part` of body `body`, no search-distance limit.
    pub fn new(body: BodyId, part: &str) -> Self {
        Self { body, part: part.to_string(), search_distance: None }
    }
}

impl<const D: usize> ContactDiscretisation<D> for DualMortar {
    fn kind(&self) -> &str {
        "mortar"
    }

    fn partner_part(&self) -> Option<(BodyId, &str)> {
        Some((self.body, &self.part))
    }

    fn rows(&self, cx: &PairContext<'_, D>) -> Result<Vec<ContactRow<D>>, ContactError> {
        check_master(cx.body(), self.body, self.search_distance).map_err(|m| cx.invalid(m))?;
        let model = cx.model();
        let other = model.body(self.body)?;
        let lfacets: Vec<Vec<usize>> =
            other.mesh.boundary_part(&self.part)?.facets().map(<[usize]>::to_vec).collect();
        let sfacets: Vec<Vec<usize>> =
            model.body(cx.body())?.mesh.boundary_part(cx.part())?.facets().map(<[usize]>::to_vec).collect();
        let (pos_k, pos_l) = match (cx.positions(cx.body()), cx.positions(self.body)) {
            (Some(k), Some(l)) => (k, l),
            _ => return Err(cx.invalid("unknown body")),
        };
        let mortar = crate::mortar::mortar_rows(pos_k, &sfacets, pos_l, &lfacets, self.search_distance);
        let normal_of: std::collections::HashMap<usize, Vector<D>> = cx.normals().iter().copied().collect();
        let mut rows = Vec::with_capacity(mortar.len());
        for row in mortar {
            let Some(&n) = normal_of.get(&row.slave) else { continue };
            let xm = weighted_point(pos_l, &row.master);
            rows.push(ContactRow {
                node: row.slave,
                partner: None,
                master: row.master.iter().map(|&(j, w)| (self.body, j, w)).collect(),
                normal: n,
                weight: row.d,
                gap: (xm - pos_k[row.slave]).dot(&n),
            });
        }
        if rows.is_empty() {
            return Err(cx.invalid(format!(
                "no node of part `{}` has enough mortar overlap with part `{}` (search distance {:?})",
                cx.part(),
                self.part,
                self.search_distance
            )));
        }
        Ok(rows)
    }
}
