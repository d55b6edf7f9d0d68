//! A symmetric sparse matrix stored as its lower triangle in compressed sparse columns, with a
//! fixed pattern whose values are re-assembled in place (no reallocation), as time stepping
//! needs.
//!
//! The pattern is a `faer` [`SymbolicSparseColMat`], so the matrix is handed to faer's sparse
//! Cholesky without copying ([`SymmetricMatrix::as_faer`]). Conversions to and from
//! `sprs::CsMat` (the full symmetric matrix) serve the public boundary.

use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};

use crate::error::LinalgError;

/// Symmetric sparse matrix, lower triangle (row ≥ column) in CSC.
#[derive(Debug, Clone)]
pub struct SymmetricMatrix {
    pattern: SymbolicSparseColMat<usize>,
    values: Vec<f64>,
}

impl SymmetricMatrix {
    /// Builds the pattern from, for each column `j`, its sorted row indices `≥ j`.
    pub fn from_columns(n: usize, columns: Vec<Vec<usize>>) -> Result<Self, LinalgError> {
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(columns.iter().map(Vec::len).sum());
        col_ptr.push(0);
        for (j, rows) in columns.into_iter().enumerate() {
            debug_assert!(rows.windows(2).all(|w| w[0] < w[1]));
            debug_assert!(rows.first().is_none_or(|&r| r >= j));
            row_idx.extend_from_slice(&rows);
            col_ptr.push(row_idx.len());
        }
        let nnz = row_idx.len();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Ok(Self { pattern, values: vec![0.0; nnz] })
    }

    /// Dimension.
    pub fn n(&self) -> usize {
        self.pattern.nrows()
    }
    /// Stored entries (lower triangle).
    pub fn nnz(&self) -> usize {
        self.values.len()
    }
    /// The stored values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
    /// Mutable stored values (same order as the pattern).
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }
    /// Sets every stored value to zero, keeping the pattern.
    pub fn zero(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
    }
    /// The pattern.
    pub fn pattern(&self) -> &SymbolicSparseColMat<usize> {
        &self.pattern
    }
    /// A faer view of the lower triangle (for `Side::Lower` factorisations).
    pub fn as_faer(&self) -> SparseColMatRef<'_, usize, f64> {
        SparseColMatRef::new(self.pattern.as_ref(), &self.values)
    }

    /// Position of entry `(i, j)` (`i ≥ j`) in the value array, if it is in the pattern.
    #[inline]
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        let cp = self.pattern.col_ptr();
        let rows = &self.pattern.row_idx()[cp[j]..cp[j + 1]];
        rows.binary_search(&i).ok().map(|k| cp[j] + k)
    }

    /// Adds `v` to entry `(i, j)` of the symmetric matrix (either triangle). Entries outside
    /// the pattern are an error.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, v: f64) -> Result<(), LinalgError> {
        let (r, c) = if i >= j { (i, j) } else { (j, i) };
        match self.position(r, c) {
            Some(p) => {
                self.values[p] += v;
                Ok(())
            }
            None => Err(LinalgError::Sparse(format!("entry ({r}, {c}) is outside the pattern"))),
        }
    }

    /// Entry `(i, j)` (0 outside the pattern).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (r, c) = if i >= j { (i, j) } else { (j, i) };
        self.position(r, c).map_or(0.0, |p| self.values[p])
    }

    /// Diagonal.
    pub fn diagonal(&self) -> Vec<f64> {
        // rows sorted within a column of the lower triangle: the diagonal entry comes first
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        (0..self.n())
            .map(|j| if cp[j] < cp[j + 1] && ri[cp[j]] == j { self.values[cp[j]] } else { 0.0 })
            .collect()
    }

    /// `y = A x` for the full symmetric matrix.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        for j in 0..self.n() {
            let xj = x[j];
            let mut acc = 0.0;
            for (&i, &a) in ri[cp[j]..cp[j + 1]].iter().zip(&self.values[cp[j]..cp[j + 1]]) {
                if i == j {
                    acc += a * xj;
                } else {
                    y[i] += a * xj;
                    acc += a * x[i];
                }
            }
            y[j] += acc;
        }
    }

    /// `xᵀ A x`.
    pub fn quadratic_form(&self, x: &[f64]) -> f64 {
        let mut y = vec![0.0; self.n()];
        self.mul_vec(x, &mut y);
        x.iter().zip(&y).map(|(a, b)| a * b).sum()
    }

    /// `self += alpha · other` for a matrix with the same pattern.
    pub fn add_scaled(&mut self, alpha: f64, other: &SymmetricMatrix) -> Result<(), LinalgError> {
        if other.values.len() != self.values.len() || other.n() != self.n() {
            return Err(LinalgError::Sparse("add_scaled: patterns differ".into()));
        }
        for (a, b) in self.values.iter_mut().zip(&other.values) {
            *a += alpha * b;
        }
        Ok(())
    }

    /// The full symmetric matrix as an `sprs` CSC matrix (both triangles).
    pub fn to_sprs(&self) -> sprs::CsMat<f64> {
        let n = self.n();
        let mut tri = sprs::TriMat::new((n, n));
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        for j in 0..n {
            for (&i, &v) in ri[cp[j]..cp[j + 1]].iter().zip(&self.values[cp[j]..cp[j + 1]]) {
                tri.add_triplet(i, j, v);
                if i != j {
                    tri.add_triplet(j, i, v);
                }
            }
        }
        tri.to_csc()
    }

    /// Builds from a full symmetric or a lower-triangular `sprs` matrix. Errors on a
    /// non-square matrix, non-finite entries, and a full matrix that is not symmetric (an
    /// upper entry differing from its lower mirror by more than `1e-12 max |a_ij|`).
    pub fn from_sprs(m: &sprs::CsMat<f64>) -> Result<Self, LinalgError> {
        if m.rows() != m.cols() {
            return Err(LinalgError::Sparse(format!("matrix is {}×{}, not square", m.rows(), m.cols())));
        }
        let n = m.rows();
        let mut upper: std::collections::HashMap<(usize, usize), f64> = std::collections::HashMap::new();
        let mut lower: std::collections::HashMap<(usize, usize), f64> = std::collections::HashMap::new();
        let mut amax: f64 = 0.0;
        for (v, (i, j)) in m.iter() {
            if !v.is_finite() {
                return Err(LinalgError::Sparse(format!("entry ({i}, {j}) is {v}")));
            }
            amax = amax.max(v.abs());
            match i.cmp(&j) {
                std::cmp::Ordering::Less => *upper.entry((j, i)).or_insert(0.0) += v,
                std::cmp::Ordering::Greater => *lower.entry((i, j)).or_insert(0.0) += v,
                std::cmp::Ordering::Equal => {}
            }
        }
        if !upper.is_empty() {
            let tol = 1e-12 * amax;
            for &(i, j) in lower.keys().chain(upper.keys()) {
                let (a, b) =
                    (lower.get(&(i, j)).copied().unwrap_or(0.0), upper.get(&(i, j)).copied().unwrap_or(0.0));
                if (a - b).abs() > tol {
                    return Err(LinalgError::Sparse(format!(
                        "matrix is not symmetric: a[{i}][{j}] = {a:e} but a[{j}][{i}] = {b:e}"
                    )));
                }
            }
        }
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for (v, (i, j)) in m.iter() {
            if i >= j {
                cols[j].push((i, *v));
            }
        }
        let mut columns = Vec::with_capacity(n);
        let mut values = Vec::new();
        for mut c in cols {
            c.sort_by_key(|e| e.0);
            let mut rows: Vec<usize> = Vec::with_capacity(c.len());
            for (i, v) in c {
                if rows.last() == Some(&i) {
                    if let Some(last) = values.last_mut() {
                        *last += v;
                    }
                } else {
                    rows.push(i);
                    values.push(v);
                }
            }
            columns.push(rows);
        }
        let mut s = Self::from_columns(n, columns)?;
        s.values = values;
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The diagonal read from the first entry of each column equals `get(j, j)`, with a zero
    /// where a column stores no diagonal entry.
    #[test]
    fn diagonal_equals_the_entries_and_is_zero_where_not_stored() {
        // column 1 holds only row 2: no diagonal entry
        let mut a = SymmetricMatrix::from_columns(3, vec![vec![0, 2], vec![2], vec![2]]).expect("pattern");
        a.add(0, 0, 4.0).expect("in pattern");
        a.add(2, 0, -1.5).expect("in pattern");
        a.add(1, 2, 0.5).expect("in pattern");
        a.add(2, 2, 3.0).expect("in pattern");
        let want: Vec<f64> = (0..3).map(|j| a.get(j, j)).collect();
        assert_eq!(a.diagonal(), want);
        assert_eq!(a.diagonal(), vec![4.0, 0.0, 3.0]);
    }
}
