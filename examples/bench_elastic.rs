//! # Stage timings and peak memory of the elastic foundation
//!
//! Measures, for two linear elastic problems of about 200k unknowns each, the stages of
//! [`ElasticSolver::new`] and of one load case:
//!
//! - `2d`: the unit square in plane strain (E = 1, ν = 0.3), `316 × 316` cells of two
//!   triangles, clamped at the bottom, a traction on the top (≈ 200k reduced DOFs, AMD ordering);
//! - `3d`: the unit cube, isotropic (E = 1, ν = 0.3), `40 × 40 × 40` cells of six tetrahedra,
//!   clamped at the bottom, a traction on the top (≈ 202k reduced DOFs, METIS ordering);
//! - `3d-amd` (only when asked for): the `3d` problem with AMD instead of METIS.
//!
//! Columns: reduced DOFs, stored entries of the lower triangle of `K̃` and of the Cholesky factor,
//! then seconds for the mesh generation (not part of the solver), setup (dof map, coercivity
//! check, pattern), stiffness assembly, ordering + symbolic analysis, numeric factorisation, the
//! triangular solves of one right-hand side, the whole load case ([`ElasticSolver::solve`]:
//! right-hand side, solves, expansion to nodal displacements), and the peak resident memory
//! (`VmHWM` of `/proc/self/status`). Every case runs in a child process of this program (the same
//! executable re-run with `--child CASE SCALE`), so each peak RSS is that case's own. The
//! relative residual `‖K̃x − F̃‖/‖F̃‖` checks the solve.
//!
//! Run (release mode is essential):
//!
//! ```text
//! cargo run --release --example bench_elastic            # both problems, ≈ 200k DOFs each
//! cargo run --release --example bench_elastic 0.25       # DOF counts scaled by 0.25
//! cargo run --release --example bench_elastic 1 3d-amd   # chosen cases: 2d, 3d, 3d-amd
//! ```
//!
//! The timings are wall-clock times on a shared machine: run it when no one else is compiling
//! (check `uptime`) and repeat it; clean runs of the 3D factorisation spread by about 20 %, and
//! a concurrent build can make a stage 2× slower. The last lines are
//! one JSON object per case, `{"problem":"bench_elastic","case":"2d",...}`. Results on the
//! project's 2-core machine are in `docs/performance.md`.

use std::sync::Arc;
use std::time::Instant;

use serde_json::{json, Value};
use synovia::fem::OrderingChoice;
use synovia::prelude::*;

mod bench_common;
use bench_common::{parse_args, peak_rss_bytes, spawn_case, Invocation, Res};

/// Cells per side for a DOF budget scaled by `scale` (`base` cells per side at scale 1).
fn cells(base: usize, dim: i32, scale: f64) -> usize {
    ((base as f64) * scale.powf(1.0 / f64::from(dim))).round().max(2.0) as usize
}

/// The 2D block: unit square, plane strain, clamped bottom, traction on top.
fn model_2d(scale: f64) -> Res<(Model<2>, String)> {
    let n = cells(316, 2, scale);
    let mut mesh = rectangle(0.0, 1.0, 0.0, 1.0, n, n, Grading::Uniform, Grading::Uniform)?;
    mesh.set_part_kind("bottom", BoundaryKind::Clamped)?;
    mesh.set_part_kind("top", BoundaryKind::Traction)?;
    let mut model = Model::<2>::new();
    let b = model.add_body("block", mesh, Arc::new(plane_strain(1.0, 0.3)?))?;
    model.traction(b, "top", |x, _n, _t| Vector::<2>::new(0.01 * x[0], -0.02))?;
    Ok((model, format!("{n}x{n} rectangle, P1 triangles")))
}

/// The 3D block: unit cube, isotropic, clamped bottom, traction on top.
fn model_3d(scale: f64) -> Res<(Model<3>, String)> {
    let n = cells(40, 3, scale);
    let mut mesh = box_mesh([0.0; 3], [1.0; 3], [n; 3], [Grading::Uniform; 3])?;
    mesh.set_part_kind("bottom", BoundaryKind::Clamped)?;
    mesh.set_part_kind("top", BoundaryKind::Traction)?;
    let mut model = Model::<3>::new();
    let b = model.add_body("block", mesh, Arc::new(isotropic(1.0, 0.3)?))?;
    model.traction(b, "top", |x, _n, _t| Vector::<3>::new(0.01 * x[0], 0.005 * x[1], -0.02))?;
    Ok((model, format!("{n}x{n}x{n} box, P1 tetrahedra")))
}

/// Builds, factorises and solves one case in this process; returns its JSON record.
fn run_case<const D: usize>(
    case: &str,
    scale: f64,
    build: fn(f64) -> Res<(Model<D>, String)>,
    ordering: OrderingChoice,
) -> Res<Value> {
    let t0 = Instant::now();
    let (model, mesh) = build(scale)?;
    let mesh_s = t0.elapsed().as_secs_f64();
    let mut solver = ElasticSolver::new(&model, ElasticParams::default().with_ordering(ordering))?;
    // the triangular solves alone, on the load case's right-hand side
    let (rhs, _) = solver.rhs(&model, 0.0)?;
    let mut x = rhs.clone();
    let t1 = Instant::now();
    solver.cholesky().solve_in_place(&mut x)?;
    let triangular_s = t1.elapsed().as_secs_f64();
    let mut kx = vec![0.0; x.len()];
    solver.stiffness().mul_vec(&x, &mut kx);
    let norm = |v: &mut dyn Iterator<Item = f64>| v.map(|a| a * a).sum::<f64>().sqrt();
    let residual = norm(&mut kx.iter().zip(&rhs).map(|(a, b)| a - b))
        / norm(&mut rhs.iter().copied()).max(f64::MIN_POSITIVE);
    // the whole load case: right-hand side, solves, nodal displacements
    solver.solve(&model, 0.0)?;
    let info = solver.info();
    let ordering = match (ordering, D) {
        (OrderingChoice::Amd, _) | (OrderingChoice::Auto, 2) => "AMD",
        _ => "METIS",
    };
    Ok(json!({
        "problem": "bench_elastic",
        "case": case,
        "scale": scale,
        "mesh": mesh,
        "ordering": ordering,
        "dofs": info.n_dofs,
        "matrix_nnz": info.matrix_nnz,
        "factor_nnz": info.factor_nnz,
        "mesh_s": mesh_s,
        "setup_s": info.setup_s,
        "assembly_s": info.assembly_s,
        "symbolic_s": info.symbolic_s,
        "numeric_s": info.numeric_s,
        "solve_s": triangular_s,
        "load_case_s": info.solve_s,
        "residual": residual,
        "peak_rss_bytes": peak_rss_bytes()?,
    }))
}

/// Child mode: run one case and print its JSON record on stdout.
fn child(case: &str, scale: f64) -> Res<()> {
    let record = match case {
        "2d" => run_case::<2>(case, scale, model_2d, OrderingChoice::Auto)?,
        "3d" => run_case::<3>(case, scale, model_3d, OrderingChoice::Auto)?,
        "3d-amd" => run_case::<3>(case, scale, model_3d, OrderingChoice::Amd)?,
        other => return Err(format!("unknown case `{other}` (2d, 3d, 3d-amd)").into()),
    };
    println!("{record}");
    Ok(())
}

fn main() -> Res<()> {
    let (scale, cases) = match parse_args(&["2d", "3d"])? {
        Invocation::Child { case, scale } => return child(&case, scale),
        Invocation::Parent { scale, cases } => (scale, cases),
    };

    println!("elastic foundation: stage timings (s) and peak RSS, scale {scale}");
    println!(
        "{:<7} {:>5} {:>8} {:>10} {:>11} {:>6} {:>6} {:>8} {:>8} {:>8} {:>7} {:>9} {:>8} {:>8}",
        "case",
        "order",
        "dofs",
        "matrix nnz",
        "factor nnz",
        "mesh",
        "setup",
        "assembly",
        "symbolic",
        "numeric",
        "solve",
        "load case",
        "peak MB",
        "residual"
    );
    let mut records = Vec::new();
    for case in &cases {
        let r = spawn_case(case, scale)?;
        let f = |k: &str| r[k].as_f64().unwrap_or(f64::NAN);
        println!(
            "{:<7} {:>5} {:>8} {:>10} {:>11} {:>6.3} {:>6.3} {:>8.3} {:>8.3} {:>8.3} {:>7.3} {:>9.3} {:>8.0} {:>8.1e}",
            case,
            r["ordering"].as_str().unwrap_or("?"),
            f("dofs"),
            f("matrix_nnz"),
            f("factor_nnz"),
            f("mesh_s"),
            f("setup_s"),
            f("assembly_s"),
            f("symbolic_s"),
            f("numeric_s"),
            f("solve_s"),
            f("load_case_s"),
            f("peak_rss_bytes") / 1.0e6,
            f("residual"),
        );
        records.push(r);
    }
    println!();
    for r in &records {
        println!("{r}");
    }
    Ok(())
}
