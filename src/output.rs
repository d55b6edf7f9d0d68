//! Writing solutions for ParaView (and any VTK or meshio reader): every body in one VTU piece
//! with the displacement, the contact fields, and the stress and strain fields of
//! [`solid_fields`] (stress and strain tensors, principal and von Mises stresses, the
//! recovered nodal stress).

use synovia_fem::{BodyFields, ElasticSolution, Model};
use synovia_io::{Encoding, Field, IoError, VtuWriter};
use synovia_time::solid_fields::solid_fields;

/// A [`VtuWriter`] holding every body of `model` with the fields of `solution`: point
/// `displacement` and the fields of [`solid_fields`] computed from `fields` (point
/// `von_mises_nodal`, `stress_nodal`; cell `stress`, `strain`, `von_mises`,
/// `principal_stress`, `strain_energy_density`).
pub fn elastic_vtu<const D: usize>(
    model: &Model<D>,
    solution: &ElasticSolution<D>,
    fields: &[BodyFields],
    encoding: Encoding,
) -> Result<VtuWriter, IoError> {
    let mut w = VtuWriter::new(encoding);
    for (bi, body) in model.bodies().iter().enumerate() {
        let (Some(f), Some(u)) = (fields.get(bi), solution.displacement.get(bi)) else {
            return Err(IoError::InvalidField {
                name: "displacement".into(),
                reason: format!("no solution or fields for body {bi}"),
            });
        };
        let mut all = vec![Field::point_vectors("displacement", u)];
        all.extend(solid_fields::<D>(f, |v| *v));
        w.add_piece(&body.mesh, all)?;
    }
    Ok(w)
}

/// A [`VtuWriter`] with every body of `model` and the contact state of `result`: point fields
/// `displacement`, `contact_pressure` (`Λ_n` at the contact nodes of body `k`, 0 elsewhere),
/// `contact_active` (1 where `Λ_n > 0`), `friction_traction` (the tangential traction
/// `−g_c Λ_t T` at the nodes of friction cells) and `stick` (1 sticking, −1 slipping, 0 none),
/// and the stress and strain fields of [`solid_fields`].
///
/// Bodies placed by the geometry ([`synovia_contact::operators::ContactGeometry::new_placed`])
/// are written where they are placed, with their displacements turned from the body frame
/// into space (`R u`) and their tensors likewise (`R T Rᵀ`).
///
/// # Errors
/// [`IoError`] from the writer, and [`IoError::InvalidField`] when `result` does not fit
/// `model` (its stresses cannot be computed).
pub fn contact_vtu<const D: usize>(
    model: &Model<D>,
    geometry: &synovia_contact::operators::ContactGeometry<D>,
    result: &synovia_contact::StaticContactResult<D>,
    encoding: Encoding,
) -> Result<VtuWriter, IoError> {
    solution_vtu(model, geometry, result, encoding, true)
}

/// [`contact_vtu`] without the stress and strain fields: the displacement and the contact state
/// only, for long series where the contact is what is looked at (a gait cycle's files are
/// 5–7× smaller: `docs/output.md`).
///
/// # Errors
/// [`IoError`] from the writer.
pub fn contact_state_vtu<const D: usize>(
    model: &Model<D>,
    geometry: &synovia_contact::operators::ContactGeometry<D>,
    result: &synovia_contact::StaticContactResult<D>,
    encoding: Encoding,
) -> Result<VtuWriter, IoError> {
    solution_vtu(model, geometry, result, encoding, false)
}

fn solution_vtu<const D: usize>(
    model: &Model<D>,
    geometry: &synovia_contact::operators::ContactGeometry<D>,
    result: &synovia_contact::StaticContactResult<D>,
    encoding: Encoding,
    with_solid_fields: bool,
) -> Result<VtuWriter, IoError> {
    use synovia_mesh::math::Vector;
    let nb = model.bodies().len();
    let mut pressure: Vec<Vec<f64>> = model.bodies().iter().map(|b| vec![0.0; b.mesh.n_nodes()]).collect();
    let mut active = pressure.clone();
    let mut stick = pressure.clone();
    let mut traction: Vec<Vec<Vector<D>>> =
        model.bodies().iter().map(|b| vec![Vector::<D>::zeros(); b.mesh.n_nodes()]).collect();
    for (r, node) in geometry.nodes.iter().enumerate() {
        let (b, i) = (node.node.0 .0, node.node.1);
        if b < nb {
            let l = result.solution.lambda_n.get(r).copied().unwrap_or(0.0);
            pressure[b][i] = l;
            active[b][i] = if l > 0.0 { 1.0 } else { 0.0 };
        }
    }
    let comps = D - 1;
    for (c, (&r, &g)) in result.cell_node.iter().zip(&result.slip_bound).enumerate() {
        let node = &geometry.nodes[r];
        let (b, i) = (node.node.0 .0, node.node.1);
        let l = &result.solution.lambda_t[c * comps..(c + 1) * comps];
        let mut t = Vector::<D>::zeros();
        for (k, lk) in l.iter().enumerate() {
            t -= node.tangents[k] * (g * lk);
        }
        if b < nb {
            traction[b][i] = t;
            let ln = l.iter().map(|v| v * v).sum::<f64>().sqrt();
            stick[b][i] = if ln < 1.0 - 1e-6 { 1.0 } else { -1.0 };
        }
    }
    let solid = if with_solid_fields {
        synovia_fem::post::body_fields(model, &result.displacement)
            .map_err(|e| IoError::InvalidField { name: "stress".into(), reason: e.to_string() })?
    } else {
        Vec::new()
    };
    let mut w = VtuWriter::new(encoding);
    for (bi, body) in model.bodies().iter().enumerate() {
        let placement = geometry.placement(synovia_fem::BodyId(bi));
        let placed;
        let (mesh, displacement) = if placement.is_identity() {
            (&body.mesh, result.displacement[bi].clone())
        } else {
            let mut m = body.mesh.clone();
            m.map_nodes(|x| placement.position(x))?;
            placed = m;
            (&placed, result.displacement[bi].iter().map(|u| placement.to_global(u)).collect())
        };
        let mut all = vec![
            Field::point_vectors("displacement", &displacement),
            Field::point_scalars("contact_pressure", pressure[bi].clone()),
            Field::point_scalars("contact_active", active[bi].clone()),
            Field::point_vectors("friction_traction", &traction[bi]),
            Field::point_scalars("stick", stick[bi].clone()),
        ];
        if let Some(f) = solid.get(bi) {
            all.extend(solid_fields::<D>(f, |v| placement.to_global(v)));
        }
        w.add_piece(mesh, all)?;
    }
    Ok(w)
}
