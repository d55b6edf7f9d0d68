//! A contact discretisation defined outside the contact crate, solved with the default solver.
//!
//! **Problem.** A plane-strain block `[0, W] × [0, H]` (`E`, `ν`) rests above a rigid surface
//! given as a *height field* `y = h(x)` — the kind of description a user has for a scanned
//! plateau — with the initial gap `g₀` (`h = −g₀`). The left side is a symmetry plane
//! (`u_x = 0`), the top is pushed down by `δ > g₀` (`u_y = −δ`, `u_x` free), the bottom is in
//! frictionless contact with the surface.
//!
//! **Discretisation.** `HeightField` implements `ContactDiscretisation<2>` here, with its own
//! closest-point rule (vertical projection, first-order distance): for a bottom node
//! `x = (x₁, x₂)` the row is `(B_hn U)_r = n_r · u(x) ≤ d_r` with
//! `n_r = (h'(x₁), −1) / √(1 + h'²)` and `d_r = (x₂ − h(x₁)) / √(1 + h'²)` (docs/model.md §5),
//! and the lumped weight `κ_r = ∫ φ_r ds` handed over by the geometry. The crate is not edited:
//! the pair is `ContactPair::custom`.
//!
//! **Expected result.** The exact solution is a uniform uniaxial stress state:
//! `ε_yy = −(δ − g₀)/H`, `σ_xx = 0`, so the contact pressure is uniform,
//! `p = E (δ − g₀) / ((1 − ν²) H)`, and P1 elements reproduce it exactly: every nodal pressure
//! `Λ_n,r` equals `p` to round-off, the bottom moves down by `g₀`, the KKT residual of the
//! solution is ≤ 1e-8. The same model with the built-in rigid obstacle (`PlaneObstacle` at
//! `y = −g₀`) gives the same displacements to 1e-10.
//!
//! Prints one JSON line: `kkt_residual`, `pressure_error` (max relative error of `Λ_n`),
//! `settlement_error`, `builtin_difference`.

use std::sync::Arc;

use synovia::contact_ops::operators::ContactPair;
use synovia::contact_ops::{ContactDiscretisation, ContactError, ContactRow, PairContext};
use synovia::prelude::*;

/// A rigid surface `y = h(x)` below a 2D body, with the slope `h'(x)`.
#[derive(Debug, Clone, Copy)]
struct HeightField {
    /// `h(x)`.
    height: fn(Real) -> Real,
    /// `h'(x)`.
    slope: fn(Real) -> Real,
}

impl ContactDiscretisation<2> for HeightField {
    fn kind(&self) -> &str {
        "height-field"
    }

    fn partner_part(&self) -> Option<(BodyId, &str)> {
        None // rigid: no other body
    }

    fn rows(&self, cx: &PairContext<'_, 2>) -> Result<Vec<ContactRow<2>>, ContactError> {
        let x = cx.positions(cx.body()).ok_or_else(|| cx.invalid("unknown body"))?;
        cx.normals()
            .iter()
            .map(|&(i, _outward)| {
                let p = x[i];
                let (h, s) = ((self.height)(p[0]), (self.slope)(p[0]));
                if !(h.is_finite() && s.is_finite()) {
                    return Err(cx.invalid(format!("height field not finite at x = {}", p[0])));
                }
                let len = (1.0 + s * s).sqrt();
                Ok(ContactRow {
                    node: i,
                    partner: None,
                    master: Vec::new(),
                    normal: Vector::<2>::new(s, -1.0) / len,
                    weight: cx.weight(i),
                    gap: (p[1] - h) / len,
                })
            })
            .collect()
    }
}

const WIDTH: Real = 2.0;
const HEIGHT: Real = 1.0;
const E: Real = 1.0e3;
const NU: Real = 0.3;
const DELTA: Real = 0.01;
const GAP: Real = 0.002;

/// The block with its supports; the bottom pair is added by the caller.
fn block() -> Result<(JointModel<2>, BodyId), Box<dyn std::error::Error>> {
    let mesh = rectangle(0.0, WIDTH, 0.0, HEIGHT, 12, 6, Grading::Uniform, Grading::Uniform)?;
    let mut joint = JointModel::<2>::new();
    let b = joint.add_body("block", mesh, plane_strain(E, NU)?)?;
    joint.symmetry(b, "left")?;
    joint.prescribe_components(
        b,
        "top",
        ComponentMask::only(1),
        Vector::<2>::new(0.0, -DELTA),
        Constant(1.0),
    )?;
    Ok((joint, b))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // the custom discretisation
    let (mut joint, b) = block()?;
    let surface = HeightField { height: |_| -GAP, slope: |_| 0.0 };
    joint.add_contact(ContactPair::custom("block-plateau", b, "bottom", Arc::new(surface)))?;
    let mut session = joint.prepare()?;
    session.solve_static(1.0)?;
    let result = session.result().ok_or("no result")?;
    let kkt = result.kkt.max();

    // exact reference: uniform pressure and settlement g₀
    let p = E * (DELTA - GAP) / ((1.0 - NU * NU) * HEIGHT);
    let pressure_error = result.solution.lambda_n.iter().map(|l| (l - p).abs() / p).fold(0.0, Real::max);
    let geometry = session.geometry();
    let settlement_error = geometry
        .nodes
        .iter()
        .map(|n| (result.displacement[n.node.0 .0][n.node.1][1] + GAP).abs() / GAP)
        .fold(0.0, Real::max);

    // the built-in rigid obstacle on the same surface
    let (mut builtin, bb) = block()?;
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, -GAP), Vector::<2>::new(0.0, 1.0))?;
    builtin.contact_rigid("block-plane", bb, "bottom", flat, 0.0)?;
    let mut other = builtin.prepare()?;
    other.solve_static(1.0)?;
    let u_ref = other.displacement().ok_or("no reference result")?;
    let scale = DELTA;
    let builtin_difference = result
        .displacement
        .iter()
        .flatten()
        .zip(u_ref.iter().flatten())
        .map(|(a, b)| (a - b).amax() / scale)
        .fold(0.0, Real::max);

    assert!(kkt <= 1e-8, "KKT residual {kkt:e}");
    assert!(pressure_error <= 1e-8, "pressure error {pressure_error:e}");
    assert!(settlement_error <= 1e-8, "settlement error {settlement_error:e}");
    assert!(builtin_difference <= 1e-10, "difference to the built-in obstacle {builtin_difference:e}");
    println!(
        "{{\"example\":\"custom_discretisation\",\"contact_nodes\":{},\"pressure\":{p:.6e},\"kkt_residual\":{kkt:.3e},\"pressure_error\":{pressure_error:.3e},\"settlement_error\":{settlement_error:.3e},\"builtin_difference\":{builtin_difference:.3e}}}",
        geometry.len()
    );
    Ok(())
}
