//! Named data arrays attached to the points or cells of a mesh.

use synovia_mesh::{Tensor, Vector};

/// Where a [`Field`] lives: one tuple per mesh node or one per cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FieldLocation {
    /// One tuple per node (`<PointData>`), interpolated linearly by ParaView.
    Point,
    /// One tuple per cell (`<CellData>`), constant on each cell.
    Cell,
}

/// A named data array: `components` values per entity, stored flat (entity-major:
/// `values[i * components + k]` is component `k` of entity `i`).
///
/// Common component counts: 1 (scalar), 3 (vector), 9 (full `3 × 3` tensor, row-major, which
/// ParaView shows as a tensor). A field given with 2 components (a 2D vector) is padded with
/// `z = 0` by the writer and read back with 3 components. Use [`Field::point_vectors`],
/// [`Field::cell_tensors`] and friends to build fields from nalgebra values of either dimension.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Array name shown in ParaView (any non-empty string; XML special characters are escaped).
    pub name: String,
    /// Points or cells.
    pub location: FieldLocation,
    /// Values per entity (at least 1).
    pub components: usize,
    /// The values, `components` per entity.
    pub values: Vec<f64>,
}

impl Field {
    /// A field from its parts (validated when added to a writer).
    pub fn new(
        name: impl Into<String>,
        location: FieldLocation,
        components: usize,
        values: Vec<f64>,
    ) -> Self {
        Self { name: name.into(), location, components, values }
    }

    /// A scalar field on the points (one value per node).
    pub fn point_scalars(name: impl Into<String>, values: Vec<f64>) -> Self {
        Self::new(name, FieldLocation::Point, 1, values)
    }

    /// A scalar field on the cells (one value per cell).
    pub fn cell_scalars(name: impl Into<String>, values: Vec<f64>) -> Self {
        Self::new(name, FieldLocation::Cell, 1, values)
    }

    /// A vector field on the points, stored with 3 components (`z = 0` in 2D).
    pub fn point_vectors<const D: usize>(name: impl Into<String>, vectors: &[Vector<D>]) -> Self {
        Self::new(name, FieldLocation::Point, 3, pad_vectors(vectors))
    }

    /// A vector field on the cells, stored with 3 components (`z = 0` in 2D).
    pub fn cell_vectors<const D: usize>(name: impl Into<String>, vectors: &[Vector<D>]) -> Self {
        Self::new(name, FieldLocation::Cell, 3, pad_vectors(vectors))
    }

    /// A tensor field on the points, stored as full `3 × 3` row-major tensors (9 components;
    /// a 2D tensor fills the upper-left `2 × 2` block, the rest is zero).
    pub fn point_tensors<const D: usize>(name: impl Into<String>, tensors: &[Tensor<D>]) -> Self {
        Self::new(name, FieldLocation::Point, 9, pad_tensors(tensors))
    }

    /// A tensor field on the cells, stored as full `3 × 3` row-major tensors (9 components;
    /// a 2D tensor fills the upper-left `2 × 2` block, the rest is zero).
    pub fn cell_tensors<const D: usize>(name: impl Into<String>, tensors: &[Tensor<D>]) -> Self {
        Self::new(name, FieldLocation::Cell, 9, pad_tensors(tensors))
    }

    /// Number of tuples (`values.len() / components`; 0 when `components` is 0).
    pub fn n_tuples(&self) -> usize {
        self.values.len().checked_div(self.components).unwrap_or(0)
    }

    /// The `components` values of entity `i`, or `None` when out of range.
    pub fn tuple(&self, i: usize) -> Option<&[f64]> {
        let start = i.checked_mul(self.components)?;
        self.values.get(start..start.checked_add(self.components)?)
    }

    /// The field as written: 2-component fields padded to 3 components with zeros.
    pub(crate) fn padded(self) -> Field {
        if self.components != 2 {
            return self;
        }
        let values = self.values.chunks_exact(2).flat_map(|c| [c[0], c[1], 0.0]).collect();
        Field { values, components: 3, ..self }
    }
}

fn pad_vectors<const D: usize>(vectors: &[Vector<D>]) -> Vec<f64> {
    let mut out = Vec::with_capacity(3 * vectors.len());
    for v in vectors {
        for k in 0..3 {
            out.push(if k < D { v[k] } else { 0.0 });
        }
    }
    out
}

fn pad_tensors<const D: usize>(tensors: &[Tensor<D>]) -> Vec<f64> {
    let mut out = Vec::with_capacity(9 * tensors.len());
    for t in tensors {
        for i in 0..3 {
            for j in 0..3 {
                out.push(if i < D && j < D { t[(i, j)] } else { 0.0 });
            }
        }
    }
    out
}
