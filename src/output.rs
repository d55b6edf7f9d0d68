//! Writing solutions for ParaView: one VTU piece per body with the displacement, the stress
//! tensor, von Mises and principal stresses, and the recovered nodal stress.

use synovia_fem::{BodyFields, ElasticSolution, Model};
use synovia_io::{Encoding, Field, FieldLocation, IoError, VtuWriter};
use synovia_mesh::math::Tensor;

use synovia_fem::element::stress_tensor;

/// A [`VtuWriter`] holding every body of `model` with the fields of `solution`:
/// point `displacement` (vector), `von_mises_nodal`; cell `stress` (tensor), `von_mises`,
/// `principal_stress` (3 values, descending), `strain_energy_density`.
pub fn elastic_vtu<const D: usize>(
    model: &Model<D>,
    solution: &ElasticSolution<D>,
    fields: &[BodyFields],
    encoding: Encoding,
) -> Result<VtuWriter, IoError> {
    let mut w = VtuWriter::new(encoding);
    for (bi, body) in model.bodies().iter().enumerate() {
        let f = &fields[bi];
        let stress: Vec<Tensor<D>> = f.cell_stress.iter().map(|s| stress_tensor::<D>(s)).collect();
        let energy: Vec<f64> = f
            .cell_strain
            .iter()
            .zip(&f.cell_stress)
            .map(|(e, s)| 0.5 * e.iter().zip(s).map(|(a, b)| a * b).sum::<f64>())
            .collect();
        let principal: Vec<f64> = f.cell_principal.iter().flat_map(|p| p.iter().copied()).collect();
        w.add_piece(
            &body.mesh,
            vec![
                Field::point_vectors("displacement", &solution.displacement[bi]),
                Field::point_scalars("von_mises_nodal", f.nodal_von_mises.clone()),
                Field::cell_tensors("stress", &stress),
                Field::cell_scalars("von_mises", f.cell_von_mises.clone()),
                Field::new("principal_stress", FieldLocation::Cell, 3, principal),
                Field::cell_scalars("strain_energy_density", energy),
            ],
        )?;
    }
    Ok(w)
}

/// A [`VtuWriter`] with every body of `model` and the contact state of `result`: point fields
/// `displacement`, `contact_pressure` (`Λ_n` at the contact nodes of body `k`, 0 elsewhere),
/// `contact_active` (1 where `Λ_n > 0`), `friction_traction` (the tangential traction
/// `−g_c Λ_t T` at the nodes of friction cells) and `stick` (1 sticking, −1 slipping, 0 none).
///
/// Bodies placed by the geometry ([`synovia_contact::operators::ContactGeometry::new_placed`])
/// are written where they are placed, with their displacements turned from the body frame
/// into space (`R u`).
pub fn contact_vtu<const D: usize>(
    model: &Model<D>,
    geometry: &synovia_contact::operators::ContactGeometry<D>,
    result: &synovia_contact::StaticContactResult<D>,
    encoding: Encoding,
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
        w.add_piece(
            mesh,
            vec![
                Field::point_vectors("displacement", &displacement),
                Field::point_scalars("contact_pressure", pressure[bi].clone()),
                Field::point_scalars("contact_active", active[bi].clone()),
                Field::point_vectors("friction_traction", &traction[bi]),
                Field::point_scalars("stick", stick[bi].clone()),
            ],
        )?;
    }
    Ok(w)
}
