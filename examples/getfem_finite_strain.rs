//! # Large-deformation indentation: the problem handed to GetFEM (issue 20)
//!
//! A compressible neo-Hookean indenter (`W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²`, the law
//! GetFEM calls `Compressible_Neo_Hookean_Bonet`) is pushed onto a rigid flat `y ≥ 0` (2D, plane
//! strain: a half-disc) or `z ≥ 0` (3D: a hemisphere) by a prescribed displacement of its flat
//! top, far enough for Green–Lagrange strains beyond 20 % under the contact. The example
//!
//! 1. builds the model and writes the discrete problem — nodes, P1 cells, the facets of the
//!    contact part and of the prescribed top, the material constants, the obstacle and the
//!    push — to `out/getfem_finite_strain/problem{2,3}d.json`;
//! 2. solves it with `NonlinearContact` in total Lagrangian finite strain (node-to-obstacle
//!    rows, the condition `x_n + u_n ≥ 0` of every contact node, exact for a flat obstacle)
//!    and, for contrast, the small-strain linear model (`StaticContact`, plane strain / 3D
//!    isotropic with the same `λ`, `μ`) on the same mesh;
//! 3. writes both solutions into the same file: nodal displacements, the contact nodes with
//!    their weights `κ`, multipliers `Λ_n` and nodal forces `κ Λ_n`, the total contact force,
//!    the Newton history and the strain reached (largest principal Green–Lagrange strain
//!    `max |eig E|`, largest `‖∇u‖₂`, smallest `det F`).
//!
//! `benches/getfem_finite_strain.py` reads the file, solves the same discrete problem with
//! GetFEM (`python3-getfem`) and compares (docs/nonlinear.md).
//!
//! Run: `cargo run --release --example getfem_finite_strain [2d|3d|both]` (default `both`),
//! then `/usr/bin/python3 benches/getfem_finite_strain.py`.

use std::path::Path;
use std::sync::Arc;

use nalgebra::DMatrix;
use serde_json::{json, Value};
use synovia::contact_ops::obstacle::PlaneObstacle;
use synovia::contact_ops::operators::{ContactGeometry, ContactPair};
use synovia::contact_ops::StaticContact;
use synovia::fem::{ElasticParams, Kinematics, Model};
use synovia::material::{isotropic, neo_hookean, plane_strain, Material};
use synovia::mesh::generators::{half_disc_refined, hemisphere_refined};
use synovia::mesh::math::{Point, Vector};
use synovia::mesh::{BoundaryKind, Mesh};
use synovia::nonlinear::{NewtonParams, NonlinearContact};
use synovia::pdas::Pdas;

type Error = Box<dyn std::error::Error>;

/// Young's modulus and Poisson ratio (λ, μ of the 3D law; plane strain in 2D).
const E: f64 = 10.0;
const NU: f64 = 0.3;
/// Newton tolerance (relative equilibrium residual).
const TOLERANCE: f64 = 1e-12;

/// One indentation problem: the mesh with its `contact` and prescribed `top` parts, and the push.
struct Problem<const D: usize> {
    mesh: Mesh<D>,
    push: f64,
    levels: usize,
}

fn problem_2d() -> Result<Problem<2>, Error> {
    // half-disc of radius 1 touching y = 0 at the origin, refined toward the contact zone
    let mut mesh = half_disc_refined(Point::<2>::new(0.0, 1.0), 1.0, 8, Point::<2>::new(0.0, 0.0), 0.45, 6)?;
    mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[1] < 0.5 && n[1] < 0.0)?;
    Ok(Problem { mesh, push: 0.25, levels: 10 })
}

fn problem_3d() -> Result<Problem<3>, Error> {
    // hemisphere of radius 1 touching z = 0 at the origin, coarse, refined toward the contact
    let mut mesh = hemisphere_refined(Point::<3>::new(0.0, 0.0, 1.0), 1.0, 4, Point::<3>::zeros(), 0.45, 6)?;
    mesh.set_part_kind("top", BoundaryKind::Prescribed)?;
    mesh.add_boundary_part("contact", BoundaryKind::Contact, |x, n| x[2] < 0.5 && n[2] < 0.0)?;
    Ok(Problem { mesh, push: 0.2, levels: 10 })
}

fn model<const D: usize>(
    p: &Problem<D>,
    material: Arc<dyn Material<D>>,
) -> Result<(Model<D>, Vec<ContactPair<D>>), Error> {
    let mut model = Model::new();
    let b = model.add_body("indenter", p.mesh.clone(), material)?;
    let push = p.push;
    model.prescribe(b, "top", move |_, t| {
        let mut v = Vector::<D>::zeros();
        v[D - 1] = -push * t;
        v
    })?;
    let mut normal = Vector::<D>::zeros();
    normal[D - 1] = 1.0;
    let flat = PlaneObstacle::new(Point::<D>::zeros(), normal)?;
    Ok((model, vec![ContactPair::rigid("indenter-flat", b, "contact", Arc::new(flat))]))
}

/// Largest `|eig E|` (Green–Lagrange), largest `‖∇u‖₂` and smallest `det F` over the cells.
fn strain_measures<const D: usize>(mesh: &Mesh<D>, u: &[Vector<D>]) -> Result<(f64, f64, f64), Error> {
    let (mut e_max, mut h_max, mut j_min) = (0.0_f64, 0.0_f64, f64::INFINITY);
    for cell in mesh.cells() {
        let x0 = mesh.node(cell[0]);
        let dm = DMatrix::from_fn(D, D, |i, j| mesh.node(cell[j + 1])[i] - x0[i]);
        let du = DMatrix::from_fn(D, D, |i, j| u[cell[j + 1]][i] - u[cell[0]][i]);
        let dm_inv = dm.try_inverse().ok_or("degenerate cell")?;
        let h = du * dm_inv;
        let f = DMatrix::<f64>::identity(D, D) + &h;
        let green = (f.transpose() * &f - DMatrix::<f64>::identity(D, D)) * 0.5;
        let eig = green.symmetric_eigenvalues();
        e_max = eig.iter().fold(e_max, |m, v| m.max(v.abs()));
        h_max = h.singular_values().iter().fold(h_max, |m, &v| m.max(v));
        j_min = j_min.min(f.determinant());
    }
    Ok((e_max, h_max, j_min))
}

fn vectors<const D: usize>(u: &[Vector<D>]) -> Value {
    Value::Array(u.iter().map(|v| json!(v.iter().copied().collect::<Vec<f64>>())).collect())
}

/// The contact nodes of a geometry with their weights, multipliers and nodal forces.
fn contact_json<const D: usize>(geo: &ContactGeometry<D>, lambda: &[f64]) -> Value {
    let nodes: Vec<usize> = geo.nodes.iter().map(|n| n.node.1).collect();
    let weights: Vec<f64> = geo.nodes.iter().map(|n| n.weight).collect();
    let forces: Vec<f64> = weights.iter().zip(lambda).map(|(w, l)| w * l).collect();
    json!({ "nodes": nodes, "weights": weights, "lambda_n": lambda, "nodal_force": forces,
            "force": forces.iter().sum::<f64>() })
}

fn part_facets<const D: usize>(mesh: &Mesh<D>, name: &str) -> Result<Value, Error> {
    let part = mesh.boundary_part(name)?;
    Ok(Value::Array(part.facets().map(|f| json!(f)).collect()))
}

/// Solves one problem both ways, writes `problem{D}d.json`, returns the summary.
fn run<const D: usize>(
    p: &Problem<D>,
    nh: Arc<dyn Material<D>>,
    lin: Arc<dyn Material<D>>,
    dir: &Path,
) -> Result<Value, Error> {
    let material = synovia::material::NeoHookean::from_young_poisson(E, NU)?;
    let (lambda, mu) = (material.lambda(), material.mu());
    // finite strain, neo-Hookean
    let (m_nh, pairs) = model(p, nh)?;
    let params = NewtonParams::default().with_tolerance(TOLERANCE);
    let mut nl =
        NonlinearContact::new(&m_nh, &pairs, &[Kinematics::FiniteStrain], ElasticParams::default(), params)?;
    let times: Vec<f64> = (1..=p.levels).map(|k| k as f64 / p.levels as f64).collect();
    let start = std::time::Instant::now();
    // level by level, with the contact force of each (the force–indentation curve)
    let (mut newton, mut curve, mut last) = (Vec::new(), Vec::new(), None);
    let (mut total_newton, mut cutbacks) = (0, 0);
    for &t in &times {
        let r = nl.step_to(&m_nh, t, &Pdas::default())?;
        let geo = nl.geometry();
        curve.push(json!([t * p.push, r.contact.normal_force(geo, 0..geo.len())]));
        newton.push(r.report.iterations.len());
        total_newton += r.report.total_iterations;
        cutbacks += r.report.cutbacks;
        last = Some(r);
    }
    let nl_time = start.elapsed().as_secs_f64();
    let last = last.ok_or("no level")?;
    let geo = nl.geometry();
    let u_nh = &last.contact.displacement[0];
    let (e_max, h_max, j_min) = strain_measures(&p.mesh, u_nh)?;
    let residual = last.report.residual();
    let kkt = last.contact.kkt.max();
    let finite = json!({
        "displacement": vectors(u_nh),
        "contact": contact_json(geo, &last.contact.solution.lambda_n),
        "strain_energy": last.strain_energy,
        "newton_iterations": newton,
        "force_indentation": curve,
        "newton_iterations_total": total_newton,
        "cutbacks": cutbacks,
        "residual": residual,
        "kkt": kkt,
        "max_green_lagrange": e_max,
        "max_grad_u": h_max,
        "min_det_f": j_min,
        "time_s": nl_time,
    });
    // small strain, linear
    let (m_lin, pairs_lin) = model(p, lin)?;
    let sc = StaticContact::new(&m_lin, &pairs_lin, ElasticParams::default())?;
    let res = sc.solve(&m_lin, 1.0, &Pdas::default(), None, None, None)?;
    let u_lin = &res.displacement[0];
    let (e_lin, h_lin, _) = strain_measures(&p.mesh, u_lin)?;
    let linear = json!({
        "displacement": vectors(u_lin),
        "contact": contact_json(sc.geometry(), &res.solution.lambda_n),
        "kkt": res.kkt.max(),
        "max_green_lagrange": e_lin,
        "max_grad_u": h_lin,
    });
    let prescribed: Vec<usize> = p.mesh.boundary_part("top")?.nodes();
    let contact_nodes: Vec<usize> = p.mesh.boundary_part("contact")?.nodes();
    let mut normal = vec![0.0; D];
    normal[D - 1] = 1.0;
    let mut push = vec![0.0; D];
    push[D - 1] = -p.push;
    let problem = json!({
        "dim": D,
        "law": "compressible neo-Hookean (Bonet & Wood), plane strain in 2D",
        "youngs_modulus": E, "poisson_ratio": NU, "lambda": lambda, "mu": mu,
        "nodes": p.mesh.nodes().iter().map(|x| x.iter().copied().collect::<Vec<f64>>()).collect::<Vec<_>>(),
        "cells": p.mesh.cells().map(|c| c.to_vec()).collect::<Vec<_>>(),
        "contact_facets": part_facets(&p.mesh, "contact")?,
        "prescribed_facets": part_facets(&p.mesh, "top")?,
        "contact_nodes": contact_nodes,
        "prescribed_nodes": prescribed,
        "prescribed_displacement": push,
        "obstacle": { "point": vec![0.0; D], "normal": normal },
        "levels": p.levels,
        "newton_tolerance": TOLERANCE,
        "synovia": { "finite_strain": finite, "linear": linear },
    });
    std::fs::create_dir_all(dir)?;
    let file = dir.join(format!("problem{D}d.json"));
    std::fs::write(&file, serde_json::to_string(&problem)?)?;
    let f_nh = geo.nodes.iter().zip(&last.contact.solution.lambda_n).map(|(n, l)| n.weight * l).sum::<f64>();
    let f_lin = res.normal_force(sc.geometry(), 0..sc.geometry().len());
    let active = last.contact.solution.lambda_n.iter().filter(|&&l| l > 0.0).count();
    println!(
        "{D}D: {} nodes, {} cells, {} contact nodes ({active} active), push {}: neo-Hookean force {f_nh:.10e} \
         (Newton {newton:?}, {total_newton} in all with {cutbacks} cut-backs, residual {residual:.1e}, KKT {kkt:.1e}, {nl_time:.2} s), linear force {f_lin:.10e}; \
         max |eig E| {e_max:.3} (linear {e_lin:.3}), max ‖∇u‖ {h_max:.3}, min det F {j_min:.3}",
        p.mesh.n_nodes(),
        p.mesh.n_cells(),
        geo.len(),
        p.push,
    );
    println!("wrote {}", file.display());
    Ok(json!({
        "dim": D, "nodes": p.mesh.n_nodes(), "cells": p.mesh.n_cells(), "contact_nodes": geo.len(),
        "active": active, "push": p.push, "force_finite_strain": f_nh, "force_linear": f_lin,
        "max_green_lagrange": e_max, "max_grad_u": h_max, "min_det_f": j_min,
        "newton_iterations": newton, "newton_iterations_total": total_newton, "cutbacks": cutbacks,
        "residual": residual, "kkt": kkt,
        "file": file.display().to_string(),
    }))
}

fn main() -> Result<(), Error> {
    let which = std::env::args().nth(1).unwrap_or_else(|| "both".to_string());
    if !matches!(which.as_str(), "2d" | "3d" | "both") {
        return Err(format!("unknown argument {which:?}: expected 2d, 3d or both").into());
    }
    let dir = Path::new("out/getfem_finite_strain");
    let mut summary = Vec::new();
    if which != "3d" {
        let p = problem_2d()?;
        summary.push(run(&p, Arc::new(neo_hookean(E, NU)?), Arc::new(plane_strain(E, NU)?), dir)?);
    }
    if which != "2d" {
        let p = problem_3d()?;
        summary.push(run(&p, Arc::new(neo_hookean(E, NU)?), Arc::new(isotropic(E, NU)?), dir)?);
    }
    println!("{}", json!({ "example": "getfem_finite_strain", "runs": summary }));
    Ok(())
}
