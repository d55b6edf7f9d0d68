//! Warm starts of a contact solve from the solution of another level.

use synovia_mesh::math::Real;

use crate::operators::ContactGeometry;
use crate::solver::{ContactSolution, SolverReport};
use crate::static_contact::StaticContactResult;

/// A warm start for the Tresca problem with slip bounds `g` from the solution `from` of
/// another level: `U` and `Λ_n` copied; `Λ_t` of each new friction cell (the nodes with
/// `g_r > 0`, in node order, as built by [`ContactGeometry::friction_constraints`]) copied from
/// the cell of the same contact node in `from`, or 0 if that node had no cell there.
pub fn warm_start<const D: usize>(
    geometry: &ContactGeometry<D>,
    from: &StaticContactResult<D>,
    g: &[Real],
) -> ContactSolution {
    let comps = D.saturating_sub(1);
    let mut cell_of = vec![None; geometry.len()];
    for (c, &r) in from.cell_node.iter().enumerate() {
        if let Some(slot) = cell_of.get_mut(r) {
            *slot = Some(c);
        }
    }
    let mut lambda_t = Vec::new();
    for (r, &gr) in g.iter().enumerate() {
        if gr > 0.0 {
            let cell = cell_of.get(r).copied().flatten();
            for k in 0..comps {
                let v = cell.and_then(|c| from.solution.lambda_t.get(c * comps + k)).copied().unwrap_or(0.0);
                lambda_t.push(v);
            }
        }
    }
    ContactSolution {
        u: from.solution.u.clone(),
        lambda_n: from.solution.lambda_n.clone(),
        lambda_t,
        report: SolverReport::default(),
    }
}
