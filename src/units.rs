//! A check of the model's units: synovia computes in any consistent units (the user's length
//! unit `L`, force unit `F`, moduli and pressures in `F/L²`), so it cannot tell a model in
//! millimetres from one in metres — but a mix (a mesh in metres with loads in N and moduli in
//! MPa) strains the bodies by far more than 100 %, which no linear elastic model is meant for.
//!
//! [`characteristic_strain`] estimates, per body, the strain the data would cause:
//!
//! * **loads**: `ε_F = F / (E · L^{D−1})` with `F` the largest (over the time levels) total
//!   magnitude of the body's tractions (`Σ_facets |P(x_c, n, t)| |facet|`) plus its body force
//!   (`max_nodes |f(x, t)|` times the volume of its bounding box), `E` the smallest directional
//!   Young's modulus `1/S_kk` of its material (`S = C⁻¹`; plane strain: `E/(1 − ν²)`) and `L`
//!   the diagonal
//!   of its bounding box (in 2D, forces per unit thickness over `E L`);
//! * **prescribed displacements**: `ε_u = max |u₂(x, t)| / L` over the prescribed parts' nodes.
//!
//! Both are order-of-magnitude figures (a body of size `L` under the force `F`); with
//! consistent units they are far below 1 (a knee implant of 70 mm, 1000 MPa, 2000 N:
//! `4·10⁻⁴`), with a mesh in metres and data in N and MPa far above (`400`).

use synovia_fem::Model;
use synovia_mesh::math::{Point, Real, Vector};

/// What strains a body most ([`characteristic_strain`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrainCause {
    /// Its tractions and body force.
    Load,
    /// Its prescribed displacements.
    Displacement,
}

/// The largest characteristic strain of a model's bodies (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct StrainEstimate {
    /// The strain (dimensionless; 1 = 100 %).
    pub strain: Real,
    /// The body.
    pub body: String,
    /// Load or displacement.
    pub cause: StrainCause,
    /// The body's total load `F` (force unit; 2D: per unit thickness), or the largest
    /// prescribed displacement (length unit).
    pub value: Real,
    /// The smallest directional Young's modulus of its material (pressure unit).
    pub modulus: Real,
    /// The diagonal `L` of its bounding box (length unit).
    pub size: Real,
}

impl StrainEstimate {
    /// A sentence about the estimate for an error or warning, with the unit labels `length`,
    /// `force` and `pressure` of the outputs.
    pub fn describe(&self, length: &str, force: &str, pressure: &str) -> String {
        let pct = 100.0 * self.strain;
        match self.cause {
            StrainCause::Load => format!(
                "the loads would strain body `{}` by about {pct:.3e} % (total load {:.3e} {force} on a body of size {:.3e} {length} with modulus {:.3e} {pressure})",
                self.body, self.value, self.size, self.modulus
            ),
            StrainCause::Displacement => format!(
                "the prescribed displacements of body `{}` ({:.3e} {length}) are {pct:.3e} % of its size ({:.3e} {length})",
                self.body, self.value, self.size
            ),
        }
    }
}

/// Measure (length in 2D, area in 3D) and unit normal of a facet.
fn facet_geometry<const D: usize>(x: &[Point<D>], f: &[usize]) -> (Real, Vector<D>) {
    let mut n = Vector::<D>::zeros();
    if D == 2 {
        let d = x[f[1]] - x[f[0]];
        n[0] = d[1];
        n[1] = -d[0];
    } else if D == 3 {
        let (a, b) = (x[f[1]] - x[f[0]], x[f[2]] - x[f[0]]);
        n[0] = 0.5 * (a[1] * b[2] - a[2] * b[1]);
        n[1] = 0.5 * (a[2] * b[0] - a[0] * b[2]);
        n[2] = 0.5 * (a[0] * b[1] - a[1] * b[0]);
    }
    let m = n.norm();
    (m, if m > 0.0 { n / m } else { n })
}

/// The smallest directional Young's modulus `1 / S_kk` of a material (`S = C⁻¹` of its
/// stiffness at small strain, columns from strains of `1e-3`); the smallest diagonal `C_kk`
/// when `C` is singular.
fn young_modulus<const D: usize>(material: &dyn synovia_material::Material<D>) -> Real {
    let n = if D == 2 { 3 } else { 6 };
    let mut c = nalgebra::DMatrix::<Real>::zeros(n, n);
    for j in 0..n {
        let mut e = synovia_material::VoigtVector::zeros(n);
        e[j] = 1e-3;
        let s = material.stress(&e);
        for i in 0..n {
            c[(i, j)] = s[i] / 1e-3;
        }
    }
    match c.clone().try_inverse() {
        Some(s) => (0..D).map(|k| 1.0 / s[(k, k)]).fold(Real::INFINITY, Real::min),
        None => (0..D).map(|k| c[(k, k)]).fold(Real::INFINITY, Real::min),
    }
}

/// The largest characteristic strain of the bodies of `model` over the time levels `times`
/// (see the [module docs](self)); `None` for a model without bodies or time levels.
pub fn characteristic_strain<const D: usize>(model: &Model<D>, times: &[Real]) -> Option<StrainEstimate> {
    // at most 64 of the time levels, evenly picked, and the last
    let step = times.len().div_ceil(64).max(1);
    let mut ts: Vec<Real> = times.iter().copied().step_by(step).collect();
    if let Some(&last) = times.last() {
        ts.push(last);
    }
    if ts.is_empty() {
        return None;
    }
    let mut best: Option<StrainEstimate> = None;
    for (b, body) in model.bodies().iter().enumerate() {
        let x = body.mesh.nodes();
        let Some(first) = x.first() else { continue };
        let (mut lo, mut hi) = (*first, *first);
        for p in x {
            for k in 0..D {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let size = (hi - lo).norm();
        if size.is_nan() || size <= 0.0 {
            continue;
        }
        let volume: Real = (0..D).map(|k| hi[k] - lo[k]).product();
        let modulus = young_modulus(body.material.as_ref());
        let mut load: Real = 0.0;
        let mut disp: Real = 0.0;
        for &t in &ts {
            let mut f = 0.0;
            for tr in model.tractions().iter().filter(|tr| tr.body.0 == b) {
                let Ok(part) = body.mesh.boundary_part(&tr.part) else { continue };
                for facet in part.facets() {
                    let (m, n) = facet_geometry(x, facet);
                    let c = facet.iter().fold(Vector::<D>::zeros(), |s, &i| s + x[i]) / facet.len() as Real;
                    f += (tr.value)(&c, &n, t).norm() * m;
                }
            }
            if let Some(bf) = &body.body_force {
                f += x.iter().map(|p| bf(p, t).norm()).fold(0.0, Real::max) * volume;
            }
            load = load.max(f);
            for pd in model.prescribed().iter().filter(|pd| pd.body.0 == b) {
                let Ok(part) = body.mesh.boundary_part(&pd.part) else { continue };
                for i in part.nodes() {
                    let u = (pd.value)(&x[i], t);
                    let m = (0..D)
                        .filter(|&k| pd.components.contains(k))
                        .map(|k| u[k] * u[k])
                        .sum::<Real>()
                        .sqrt();
                    disp = disp.max(m);
                }
            }
        }
        let area = size.powi(D as i32 - 1);
        let candidates = [
            (load / (modulus * area), StrainCause::Load, load),
            (disp / size, StrainCause::Displacement, disp),
        ];
        for (strain, cause, value) in candidates {
            let strain = if strain.is_nan() { 0.0 } else { strain };
            if best.as_ref().is_none_or(|e| strain > e.strain) {
                best = Some(StrainEstimate { strain, body: body.name.clone(), cause, value, modulus, size });
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prelude::*;

    fn block(scale: Real) -> JointModel<3> {
        let mesh = box_mesh([0.0; 3], [0.05 * scale; 3], [2, 2, 2], [Grading::Uniform; 3]).expect("mesh");
        let mut j = JointModel::<3>::new();
        let b = j.add_body("insert", mesh, isotropic(1.0e3, 0.45).expect("material")).expect("body");
        j.clamp(b, "bottom").expect("clamp");
        // 2000 N over the top face
        let area = (0.05 * scale) * (0.05 * scale);
        j.pressure(b, "top", 2000.0 / area, Constant(1.0)).expect("load");
        j
    }

    #[test]
    fn metres_with_newtons_and_megapascals_strain_far_beyond_one() {
        // in mm: 2000 N on a 50 mm cube of 1000 MPa: 2000 / (1000 · 86.6²) ≈ 2.7e-4
        let mm = characteristic_strain(block(1000.0).model(), &[0.0]).expect("estimate");
        assert_eq!(mm.cause, StrainCause::Load);
        assert!((mm.modulus - 1.0e3).abs() < 1e-6, "{mm:?}");
        assert!((mm.value - 2000.0).abs() < 1e-9 * 2000.0, "{mm:?}");
        assert!(mm.strain > 1e-4 && mm.strain < 1e-3, "{mm:?}");
        // the same numbers on a mesh in metres: a million times more
        let m = characteristic_strain(block(1.0).model(), &[0.0]).expect("estimate");
        assert!((m.strain / mm.strain - 1e6).abs() < 1e-3 * 1e6, "{m:?}");
        assert!(
            m.describe("mm", "N", "MPa").contains("strain body `insert`"),
            "{}",
            m.describe("mm", "N", "MPa")
        );
    }
}
