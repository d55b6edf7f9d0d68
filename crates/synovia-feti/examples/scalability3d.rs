//! Numerical scalability of TFETI in 3D (docs/scale-out.md): a unit cube of P1 tetrahedra pressed
//! onto a rigid sphere and sheared, frictionless and Tresca (MPGP inner solves), cut into `k³`
//! subdomains with the mesh refined with `k` so that `H/h` stays fixed. Prints one JSON line with
//! a row per `k`.
//!
//! `cargo run --release -p synovia-feti --example scalability3d [-- H/h k_max] [metis]
//! [prec=none|lumped|dirichlet] [rho=F]` (defaults 4, 4, recursive coordinate bisection,
//! Dirichlet, `ρ = 10 ‖PFP‖`).

use std::sync::Arc;

use synovia_contact::obstacle::SphereObstacle;
use synovia_contact::operators::ContactPair;
use synovia_fem::model::Model;
use synovia_feti::{
    CoarseConstraint, Decomposition, DecompositionParams, Expansion, ModelProblem, Partitioner,
    Preconditioner, SingleProcess, TfetiParams,
};
use synovia_material::isotropic;
use synovia_mesh::generators::{box_mesh, Grading};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::BoundaryKind;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let hh = args.first().copied().unwrap_or(4);
    let kmax = args.get(1).copied().unwrap_or(4);
    let partitioner =
        if std::env::args().any(|a| a == "metis") { Partitioner::Metis } else { Partitioner::Bisection };
    let mut params = TfetiParams::default().with_tolerance(1e-8);
    params.rho_factor = 10.0;
    for a in std::env::args() {
        if let Some(v) = a.strip_prefix("rho=").and_then(|v| v.parse().ok()) {
            params.rho_factor = v;
        }
        match a.as_str() {
            "prec=none" => params.preconditioner = Preconditioner::None,
            "prec=lumped" => params.preconditioner = Preconditioner::Lumped,
            "prec=dirichlet" => params.preconditioner = Preconditioner::Dirichlet,
            "coarse=projector" => params.coarse = CoarseConstraint::Projector,
            "coarse=penalty" => params.coarse = CoarseConstraint::Penalty,
            "exp=fixed" => params.expansion = Expansion::Fixed,
            "exp=projcg" => params.expansion = Expansion::ProjectedCg,
            "exp=precond" => params.expansion = Expansion::Preconditioned,
            _ => {}
        }
    }
    let mut rows = Vec::new();
    for k in 1..=kmax {
        let n = k * hh;
        let g = [Grading::Uniform; 3];
        let mut mesh = box_mesh([0.0; 3], [1.0; 3], [n; 3], g)?;
        mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
        mesh.set_part_kind("bottom", BoundaryKind::Contact)?;
        let mut model = Model::<3>::new();
        let b = model.add_body("cube", mesh, Arc::new(isotropic(1.0, 0.3)?))?;
        model.prescribe(b, "top", |_, _| Vector::<3>::new(0.004, 0.0, -0.02))?;
        let sphere = SphereObstacle::new(Point::<3>::new(0.5, 0.5, -2.0), 2.0, false)?;
        let pairs = vec![ContactPair::rigid("cube-sphere", b, "bottom", Arc::new(sphere))];
        let dec = Decomposition::new(
            &model,
            &DecompositionParams::default().with_subdomains(k * k * k).with_partitioner(partitioner),
            &SingleProcess,
        )?;
        let frictionless = ModelProblem::new(&model, &pairs, 0.0, None, None)?;
        let s0 = frictionless.solve(&dec, &SingleProcess, &params)?;
        let gc: Vec<f64> = s0.lambda_n.iter().map(|p| 0.3 * p).collect();
        let tresca = ModelProblem::new(&model, &pairs, 0.0, Some(&gc), None)?;
        let s = tresca.solve(&dec, &SingleProcess, &params)?;
        let r = &s.report;
        let row = serde_json::json!({
            "k": k, "subdomains": r.subdomains, "H_over_h": hh, "dofs": dec.n_reduced(),
            "partitioner": format!("{partitioner:?}"), "preconditioner": format!("{:?}", params.preconditioner), "coarse": format!("{:?}", params.coarse),
            "rho_factor": params.rho_factor, "dual": r.dual, "coarse": r.coarse_dim,
            "frictionless": {"outer": s0.report.outer_iterations, "inner": s0.report.inner_iterations,
                             "f_products": s0.report.f_products, "steps_cg_exp_prop": s0.report.inner_steps, "exp_fallbacks": s0.report.expansion_fallbacks},
            "tresca": {"outer": r.outer_iterations, "inner": r.inner_iterations, "f_products": r.f_products,
                       "prec_products": r.preconditioner_products, "face_factorisations": r.face_factorisations, "steps_cg_exp_prop": r.inner_steps, "exp_fallbacks": r.expansion_fallbacks, "expansion": format!("{:?}", params.expansion),
                       "active": s.lambda_n.iter().filter(|&&l| l > 0.0).count()},
            "tresca_solve_s": r.solve_s,
        });
        eprintln!("{row}");
        rows.push(row);
    }
    println!("{}", serde_json::json!({ "example": "tfeti_scalability3d", "tolerance": 1e-8, "rows": rows }));
    Ok(())
}
