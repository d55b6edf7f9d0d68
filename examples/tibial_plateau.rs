//! # Tibial plateau under condylar load (static, bonded cartilage on bone)
//!
//! A sagittal (plane-strain) slice of the medial tibial plateau: subchondral/cancellous bone
//! (60 × 20 mm, E = 500 MPa, ν = 0.3) carrying a 2.5 mm articular cartilage layer
//! (E = 10 MPa, ν = 0.45) bonded to it. The femoral condyle (radius R = 40 mm) presses on the
//! cartilage with the Hertz pressure of an axial load of P = 60 N per mm of slice thickness
//! (≈ 2.5 × body weight over a 30 mm wide condyle):
//!
//! ```text
//! a = sqrt(4 P R / (π E*)),  p(x) = p₀ sqrt(1 − x²/a²),  p₀ = 2P/(π a),  E* = E_c/(1 − ν_c²)
//! ```
//!
//! The bone's base is clamped. The example solves the bonded two-body elastic problem
//! (spec §1–§2), checks that the support reaction balances the applied load, writes the fields
//! for ParaView, and ends with one JSON line. Contact between condyle and plateau replaces the
//! prescribed pressure once the contact solvers land; the geometry and materials stay.
//!
//! Run: `cargo run --release --example tibial_plateau [OUT_DIR]` (default `out/tibial_plateau`).
//! Open `OUT_DIR/tibial_plateau.vtu` in ParaView, colour by `von_mises`, and use
//! *Warp By Vector* on `displacement` to see the deformation.

use std::sync::Arc;
use std::time::Instant;

use synovia::fem::{ElasticParams, ElasticSolver};
use synovia::io::Encoding;
use synovia::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "out/tibial_plateau".to_string());
    std::fs::create_dir_all(&out)?;
    let t0 = Instant::now();

    // ## Step 1: load and the Hertz pressure it produces on cartilage
    let (p_total, radius) = (60.0, 40.0); // N/mm, mm
    let (e_c, nu_c) = (10.0, 0.45); // MPa
    let e_star = e_c / (1.0 - nu_c * nu_c);
    let a = (4.0 * p_total * radius / (std::f64::consts::PI * e_star)).sqrt();
    let p0 = 2.0 * p_total / (std::f64::consts::PI * a);
    println!("Hertz estimate: half-width a = {a:.2} mm, peak pressure p0 = {p0:.3} MPa");

    // ## Step 2: meshes with matching nodes on the bone–cartilage interface, refined under the condyle
    let nx = 240;
    let gx = Grading::Refined { center: 0.0, width: 2.0 * a, ratio: 4.0 };
    let mut bone = rectangle(-30.0, 30.0, -20.0, 0.0, nx, 40, gx, Grading::TowardHigh { ratio: 1.06 })?;
    let mut cartilage = rectangle(-30.0, 30.0, 0.0, 2.5, nx, 8, gx, Grading::Uniform)?;
    bone.set_part_kind("bottom", BoundaryKind::Clamped)?;
    cartilage.set_part_kind("top", BoundaryKind::Traction)?;

    // ## Step 3: the bonded two-body model
    let mut model = Model::<2>::new();
    let b = model.add_body("bone", bone, Arc::new(plane_strain(500.0, 0.3)?))?;
    let c = model.add_body("cartilage", cartilage, Arc::new(plane_strain(e_c, nu_c)?))?;
    model.tie(b, "top", c, "bottom")?;
    model.traction(c, "top", move |x, n, _| {
        let s = 1.0 - (x[0] / a).powi(2);
        let p = if s > 0.0 { p0 * s.sqrt() } else { 0.0 };
        -p * n
    })?;

    // ## Step 4: factorise and solve
    let mut solver = ElasticSolver::new(&model, ElasticParams::default())?;
    let sol = solver.solve(&model, 0.0)?;
    let fields = solver.fields(&model, &sol)?;
    let info = solver.info();

    // ## Step 5: check equilibrium: the load applied equals ∫ p dx (Hertz: P)
    let (rhs, _) = solver.rhs(&model, 0.0)?;
    let applied: f64 = {
        // the reduced rhs carries the nodal forces of free dofs; the y-components sum to −P
        let mut s = 0.0;
        for g in solver.dofs().groups() {
            for k in 0..g.n_dofs {
                s += g.basis[k][1] * rhs[g.first_dof + k];
            }
        }
        -s
    };
    let rel = (applied - p_total).abs() / p_total;
    println!("applied load {applied:.4} N/mm (target {p_total}), relative error {rel:.2e}");
    assert!(rel < 5e-3, "pressure resultant does not match the load");

    let settle = sol.displacement[1].iter().map(|u| -u[1]).fold(0.0, f64::max);
    let vm_cart = fields[1].cell_von_mises.iter().copied().fold(0.0, f64::max);
    let vm_bone = fields[0].cell_von_mises.iter().copied().fold(0.0, f64::max);
    println!("max cartilage settlement {settle:.4} mm, max von Mises: cartilage {vm_cart:.3} MPa, bone {vm_bone:.3} MPa");

    // ## Step 6: write results
    let path = std::path::Path::new(&out).join("tibial_plateau.vtu");
    synovia::output::elastic_vtu(&model, &sol, &fields, Encoding::Base64)?.write(&path)?;
    println!(
        "wrote {} (open in ParaView; colour by von_mises, Warp By Vector on displacement)",
        path.display()
    );
    let total = t0.elapsed().as_secs_f64();
    println!(
        "{{\"problem\":\"tibial_plateau\",\"dofs\":{},\"hertz_a_mm\":{a:.4},\"hertz_p0_mpa\":{p0:.4},\"load_rel_err\":{rel:.3e},\"max_settlement_mm\":{settle:.5},\"max_von_mises_cartilage_mpa\":{vm_cart:.4},\"max_von_mises_bone_mpa\":{vm_bone:.4},\"assembly_s\":{:.4},\"symbolic_s\":{:.4},\"numeric_s\":{:.4},\"solve_s\":{:.4},\"total_s\":{total:.3}}}",
        info.n_dofs, info.assembly_s, info.symbolic_s, info.numeric_s, info.solve_s
    );
    Ok(())
}
