//! Numerical scalability of TFETI (docs/scale-out.md): a plane-strain block pressed onto a
//! rigid cylinder and sheared, Tresca friction, cut into `k²` METIS subdomains with the mesh
//! refined with `k`, so that `H/h` (cells per subdomain edge) stays fixed. Prints one JSON line
//! with a row per `k`: subdomains, dofs, dual size, SMALBE outer and MPRGP inner iterations,
//! `F` products and times.
//!
//! `cargo run --release -p synovia-feti --example scalability [-- H/h k_max [star]]` (defaults
//! 8, 8; `star` glues from the owner copy instead of by orthonormal rows).

use std::sync::Arc;
use std::time::Instant;

use synovia_contact::obstacle::SphereObstacle;
use synovia_contact::operators::ContactPair;
use synovia_fem::model::Model;
use synovia_feti::{
    CoarseConstraint, Decomposition, DecompositionParams, Expansion, Gluing, ModelProblem, Partitioner,
    Preconditioner, SingleProcess, TfetiParams,
};
use synovia_material::plane_strain;
use synovia_mesh::generators::{rectangle, Grading};
use synovia_mesh::math::{Point, Vector};
use synovia_mesh::BoundaryKind;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let hh = args.first().copied().unwrap_or(8);
    let kmax = args.get(1).copied().unwrap_or(8);
    let linear = std::env::args().any(|a| a == "linear");
    let gluing = if std::env::args().any(|a| a == "star") { Gluing::Star } else { Gluing::Orthonormal };
    let partitioner =
        if std::env::args().any(|a| a == "bisection") { Partitioner::Bisection } else { Partitioner::Metis };
    let mut rows = Vec::new();
    for k in (2..=kmax).step_by(2) {
        let n = k * hh;
        let mut mesh = rectangle(0.0, 1.0, 0.0, 1.0, n, n, Grading::Uniform, Grading::Uniform)?;
        mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
        let mut model = Model::<2>::new();
        let pairs = if linear {
            // diagnostic: both ends prescribed, contact with a far cylinder (inactive rows)
            mesh.set_part_kind("bottom", BoundaryKind::Prescribed)?;
            mesh.set_part_kind("right", BoundaryKind::Contact)?;
            let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3)?))?;
            model.prescribe(b, "top", |_, _| Vector::<2>::new(0.004, -0.02))?;
            model.prescribe(b, "bottom", |_, _| Vector::<2>::zeros())?;
            let far = SphereObstacle::new(Point::<2>::new(4.0, 0.5), 2.0, false)?;
            vec![ContactPair::rigid("block-far", b, "right", Arc::new(far))]
        } else {
            mesh.set_part_kind("bottom", BoundaryKind::Contact)?;
            let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3)?))?;
            model.prescribe(b, "top", |_, _| Vector::<2>::new(0.004, -0.02))?;
            let cylinder = SphereObstacle::new(Point::<2>::new(0.5, -2.0), 2.0, false)?;
            vec![ContactPair::rigid("block-cylinder", b, "bottom", Arc::new(cylinder))]
        };
        let t0 = Instant::now();
        let dec = Decomposition::new(
            &model,
            &DecompositionParams::default()
                .with_subdomains(k * k)
                .with_gluing(gluing)
                .with_partitioner(partitioner),
            &SingleProcess,
        )?;
        let decompose_s = t0.elapsed().as_secs_f64();
        let frictionless = ModelProblem::new(&model, &pairs, 0.0, None, None)?;
        let mut params = TfetiParams::default().with_tolerance(1e-8);
        for a in std::env::args() {
            if let Some(v) = a.strip_prefix("rho=").and_then(|v| v.parse().ok()) {
                params.rho_factor = v;
            }
            if let Some(v) = a.strip_prefix("eta=").and_then(|v| v.parse().ok()) {
                params.eta_factor = v;
            }
            if let Some(v) = a.strip_prefix("m=").and_then(|v| v.parse().ok()) {
                params.m_factor = v;
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
        let s0 = frictionless.solve(&dec, &SingleProcess, &params)?;
        let spectrum = if std::env::args().any(|a| a == "spectrum") {
            // on the equality rows alone, and on the face of the frictionless solution
            let spectrum_on = |face: Option<&[bool]>| {
                synovia_feti::face_spectrum(
                    &dec,
                    &SingleProcess,
                    &frictionless.load,
                    &frictionless.normal,
                    None,
                    &params,
                    face,
                    2000,
                )
            };
            let eq = spectrum_on(None)?;
            let active: Vec<bool> = s0.lambda_n.iter().map(|&l| l > 0.0).collect();
            let sol = spectrum_on(Some(&active))?;
            serde_json::json!({"equality": {"rows": eq.rows, "pfp": eq.norm_pfp, "extreme": eq.extreme, "condition": eq.condition, "cg": eq.cg_steps},
                "solution_face": {"rows": sol.rows, "extreme": sol.extreme, "condition": sol.condition, "cg": sol.cg_steps}})
        } else {
            serde_json::Value::Null
        };
        // Tresca bounds g_c = 0.3 κ-weighted pressure of the frictionless solution
        let gc: Vec<f64> = s0.lambda_n.iter().map(|p| 0.3 * p + if linear { 1.0 } else { 0.0 }).collect();
        let tresca = ModelProblem::new(&model, &pairs, 0.0, Some(&gc), None)?;
        let s = tresca.solve(&dec, &SingleProcess, &params)?;
        let r = &s.report;
        let row = serde_json::json!({
            "k": k, "gluing": format!("{gluing:?}"), "preconditioner": format!("{:?}", params.preconditioner), "coarse": format!("{:?}", params.coarse), "partitioner": format!("{partitioner:?}"), "subdomains": r.subdomains, "H_over_h": hh, "dofs": dec.n_reduced(),
            "primal": dec.n_primal(), "dual": r.dual, "coarse": r.coarse_dim,
            "frictionless": {"outer": s0.report.outer_iterations, "inner": s0.report.inner_iterations, "f_products": s0.report.f_products,
                "per_outer": s0.report.inner_per_outer, "steps_cg_exp_prop": s0.report.inner_steps, "exp_fallbacks": s0.report.expansion_fallbacks},
            "spectrum": spectrum,
            "tresca": {"outer": r.outer_iterations, "inner": r.inner_iterations, "f_products": r.f_products, "prec_products": r.preconditioner_products, "face_factorisations": r.face_factorisations,
                        "per_outer": r.inner_per_outer, "steps_cg_exp_prop": r.inner_steps, "exp_fallbacks": r.expansion_fallbacks, "expansion": format!("{:?}", params.expansion),
                        "active": s.lambda_n.iter().filter(|&&l| l > 0.0).count(),
                        "slip": s.lambda_t.iter().filter(|l| l.abs() >= 1.0 - 1e-8).count()},
            "decompose_s": decompose_s, "tresca_setup_s": r.setup_s, "tresca_solve_s": r.solve_s,
        });
        eprintln!("{row}");
        rows.push(row);
    }
    println!("{}", serde_json::json!({ "example": "tfeti_scalability", "tolerance": 1e-8, "rows": rows }));
    Ok(())
}
