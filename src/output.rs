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
