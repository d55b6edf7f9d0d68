//! # Tibiofemoral contact on the tibial plateau (static, 2D sagittal slice)
//!
//! A sagittal (plane-strain) slice of the medial tibial plateau: subchondral/cancellous bone
//! (60 × 20 mm, E = 500 MPa, ν = 0.3) carrying a 2.5 mm articular cartilage layer
//! (E = 10 MPa, ν = 0.45) bonded to it. The femoral condyle — much stiffer than cartilage on the
//! scale of this model — is a rigid circle of radius R = 40 mm. The tibia's base is pushed up
//! against the condyle until the contact force reaches P = 60 N per mm of slice thickness
//! (≈ 2.5 × body weight over a 30 mm wide condyle); the push is found by a secant iteration on
//! the prescribed base displacement, each step one unilateral contact solve (docs/model.md §3–§5) with
//! the PDAS solver on a factorisation of `A` computed once.
//!
//! For comparison the example prints the Hertz estimate for a cylinder on a cartilage half-space,
//! `a = sqrt(4 P R / (π E*))`, `p₀ = 2P/(π a)`, `E* = E_c/(1 − ν_c²)`: a thin cartilage layer on
//! stiff bone concentrates the load, so the computed peak pressure is higher and the contact
//! narrower than the half-space value.
//!
//! Run: `cargo run --release --example tibial_plateau [OUT_DIR]` (default `out/tibial_plateau`).
//! Open `OUT_DIR/tibial_plateau.vtu` in ParaView: colour by `contact_pressure` or `von_mises`,
//! and use *Warp By Vector* on `displacement` to see the deformation. The example ends with one
//! JSON line of key figures.

use std::sync::Arc;
use std::time::Instant;

use synovia::contact::StaticContact;
use synovia::contact_ops::operators::{ContactPair, SphereObstacle};
use synovia::io::Encoding;
use synovia::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "out/tibial_plateau".to_string());
    std::fs::create_dir_all(&out)?;
    let t0 = Instant::now();

    // ## Step 1: load, geometry and the half-space Hertz estimate
    let (p_target, radius, thickness) = (60.0, 40.0, 2.5); // N/mm, mm, mm
    let (e_c, nu_c) = (10.0, 0.45); // MPa
    let e_star = e_c / (1.0 - nu_c * nu_c);
    let a_hertz = (4.0 * p_target * radius / (std::f64::consts::PI * e_star)).sqrt();
    let p0_hertz = 2.0 * p_target / (std::f64::consts::PI * a_hertz);
    println!("half-space Hertz estimate: a = {a_hertz:.2} mm, p0 = {p0_hertz:.3} MPa");

    // ## Step 2: meshes with matching nodes on the bone–cartilage interface, refined under the condyle
    let nx = 240;
    let gx = Grading::Refined { center: 0.0, width: 24.0, ratio: 4.0 };
    let mut bone = rectangle(-30.0, 30.0, -20.0, 0.0, nx, 40, gx, Grading::TowardHigh { ratio: 1.06 })?;
    let mut cartilage = rectangle(-30.0, 30.0, 0.0, thickness, nx, 8, gx, Grading::Uniform)?;
    bone.set_part_kind("bottom", BoundaryKind::Prescribed)?;
    cartilage.set_part_kind("top", BoundaryKind::Contact)?;

    // ## Step 3: the bonded two-body model; the base rises by t (time = push)
    let mut model = Model::<2>::new();
    let b = model.add_body("bone", bone, Arc::new(plane_strain(500.0, 0.3)?))?;
    let c = model.add_body("cartilage", cartilage, Arc::new(plane_strain(e_c, nu_c)?))?;
    model.tie(b, "top", c, "bottom")?;
    model.prescribe(b, "bottom", |_, t| Vector::<2>::new(0.0, t))?;
    // the condyle touches the cartilage surface at x = 0
    let condyle = SphereObstacle { center: Point::<2>::new(0.0, thickness + radius), radius, cavity: false };
    let pairs = vec![ContactPair::rigid("condyle-plateau", c, "top", Arc::new(condyle))];

    // ## Step 4: factorise once, then find the push giving P by secant steps
    let sc = StaticContact::new(&model, &pairs, Default::default())?;
    let solver = synovia::solvers::by_name("pdas")?;
    let geo = sc.geometry();
    let force =
        |t: f64| -> Result<(f64, synovia::contact::StaticContactResult<2>), Box<dyn std::error::Error>> {
            let res = sc.solve(&model, t, solver.as_ref(), None, None, None)?;
            Ok((res.normal_force(geo, 0..geo.len()), res))
        };
    let (mut t0_, mut t1) = (0.05, 0.2);
    let (mut f0, _) = force(t0_)?;
    let (mut f1, mut res) = force(t1)?;
    let mut iterations = res.solution.report.iterations;
    for _ in 0..30 {
        if (f1 - p_target).abs() < 1e-4 * p_target {
            break;
        }
        let t2 = (t1 + (p_target - f1) * (t1 - t0_) / (f1 - f0)).max(1e-6);
        t0_ = t1;
        f0 = f1;
        t1 = t2;
        let (f2, r2) = force(t1)?;
        f1 = f2;
        res = r2;
        iterations += res.solution.report.iterations;
    }
    let rel = (f1 - p_target).abs() / p_target;
    println!(
        "base push {t1:.4} mm gives the contact force {f1:.4} N/mm (target {p_target}); KKT residual {:.1e}",
        res.kkt.max()
    );
    if rel > 1e-3 || !res.kkt.satisfied(1e-8) {
        return Err(format!("load not reached or KKT violated: force {f1}, KKT {:?}", res.kkt).into());
    }

    // ## Step 5: contact figures and stresses
    let active: Vec<usize> = (0..geo.len()).filter(|&r| res.solution.lambda_n[r] > 0.0).collect();
    let width = active.iter().map(|&r| geo.nodes[r].position[0]).fold(f64::NEG_INFINITY, f64::max)
        - active.iter().map(|&r| geo.nodes[r].position[0]).fold(f64::INFINITY, f64::min);
    let peak = res.solution.lambda_n.iter().copied().fold(0.0, f64::max);
    let fields = synovia::fem::post::body_fields(&model, &res.displacement)?;
    let vm_cart = fields[1].cell_von_mises.iter().copied().fold(0.0, f64::max);
    let vm_bone = fields[0].cell_von_mises.iter().copied().fold(0.0, f64::max);
    println!("contact width {width:.2} mm (Hertz half-space: {:.2} mm), peak pressure {peak:.3} MPa (Hertz: {p0_hertz:.3} MPa)", 2.0 * a_hertz);
    println!("max von Mises: cartilage {vm_cart:.3} MPa, bone {vm_bone:.3} MPa");

    // ## Step 6: write results
    let path = std::path::Path::new(&out).join("tibial_plateau.vtu");
    synovia::output::contact_vtu(&model, geo, &res, Encoding::Zlib)?.write(&path)?;
    println!(
        "wrote {} (open in ParaView; colour by contact_pressure, Warp By Vector on displacement)",
        path.display()
    );
    let info = sc.elastic().info();
    let total = t0.elapsed().as_secs_f64();
    println!(
        "{{\"problem\":\"tibial_plateau\",\"dofs\":{},\"contact_nodes\":{},\"active_nodes\":{},\"solver\":\"pdas\",\"iterations\":{iterations},\"force_n_per_mm\":{f1:.5},\"push_mm\":{t1:.5},\"contact_width_mm\":{width:.4},\"peak_pressure_mpa\":{peak:.4},\"hertz_width_mm\":{:.4},\"hertz_p0_mpa\":{p0_hertz:.4},\"max_von_mises_cartilage_mpa\":{vm_cart:.4},\"max_von_mises_bone_mpa\":{vm_bone:.4},\"kkt\":{:.2e},\"numeric_s\":{:.4},\"total_s\":{total:.3}}}",
        info.n_dofs,
        geo.len(),
        active.len(),
        2.0 * a_hertz,
        res.kkt.max(),
        info.numeric_s
    );
    Ok(())
}
