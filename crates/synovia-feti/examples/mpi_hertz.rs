//! TFETI on MPI ranks (feature `mpi`; docs/scale-out.md): the 2D Hertz problem with Tresca
//! friction, decomposed into 8 subdomains shared among the ranks.
//!
//! * `mpirun -np N target/release/examples/mpi_hertz solve OUT.json` — solves (every rank
//!   factorises only its own subdomains) and rank 0 writes `U`, `Λ_n`, `Λ_t` and the report to
//!   `OUT.json`;
//! * `mpi_hertz compare A.json B.json …` — (one process) checks that all the files agree with
//!   the first to 1e-10 relative (max norm) and prints `N passed, M failed`.

use std::process::ExitCode;

use synovia_feti::{
    Communicator as _, Decomposition, DecompositionParams, ModelProblem, MpiCommunicator, TfetiParams,
};
use synovia_models::hertz::{hertz2d_model, Hertz2d};

fn solve(out: &str) -> Result<(), Box<dyn std::error::Error>> {
    let universe = mpi::initialize().ok_or("MPI could not be initialised")?;
    let comm = MpiCommunicator::new(universe.world());
    let p = Hertz2d { levels: 8, e2: Some(1.0), push: 0.02, ..Default::default() };
    let (model, mut pairs) = hertz2d_model(&p)?;
    pairs[0].friction = 0.3;
    let dec = Decomposition::new(&model, &DecompositionParams::default().with_subdomains(8), &comm)?;
    let params = TfetiParams::default();
    let normal = ModelProblem::new(&model, &pairs, 0.0, None, None)?;
    let s0 = normal.solve(&dec, &comm, &params)?;
    let gc = normal.geometry.slip_bounds_from_pressure(&s0.lambda_n);
    let previous = normal.dofs.expand(&s0.u, &normal.lifts)?;
    let tresca = ModelProblem::new(&model, &pairs, 0.004, Some(&gc), Some(&previous))?;
    let s = tresca.solve(&dec, &comm, &params)?;
    if comm.rank() == 0 {
        let r = &s.report;
        let json = serde_json::json!({
            "ranks": r.ranks, "subdomains": r.subdomains, "owned_by_rank0": dec.owned().len(),
            "outer": r.outer_iterations, "inner": r.inner_iterations, "f_products": r.f_products,
            "solve_s": r.solve_s, "u": s.u, "lambda_n": s.lambda_n, "lambda_t": s.lambda_t,
        });
        std::fs::write(out, json.to_string())?;
        println!(
            "ranks {}: {} subdomains ({} on rank 0), SMALBE {} outer / {} inner, {:.3} s",
            r.ranks,
            r.subdomains,
            dec.owned().len(),
            r.outer_iterations,
            r.inner_iterations,
            r.solve_s
        );
    }
    Ok(())
}

fn compare(files: &[String]) -> Result<bool, Box<dyn std::error::Error>> {
    let read = |f: &String| -> Result<serde_json::Value, Box<dyn std::error::Error>> {
        Ok(serde_json::from_str(&std::fs::read_to_string(f)?)?)
    };
    let vec = |v: &serde_json::Value, k: &str| -> Vec<f64> {
        v[k].as_array().map(|a| a.iter().filter_map(|x| x.as_f64()).collect()).unwrap_or_default()
    };
    let first = read(&files[0])?;
    let (mut passed, mut failed) = (0, 0);
    for f in &files[1..] {
        let other = read(f)?;
        let mut worst: f64 = 0.0;
        for key in ["u", "lambda_n", "lambda_t"] {
            let (a, b) = (vec(&first, key), vec(&other, key));
            if a.len() != b.len() || a.is_empty() {
                worst = f64::INFINITY;
                continue;
            }
            let scale = a.iter().fold(0.0_f64, |m, x| m.max(x.abs())).max(1e-300);
            worst = worst.max(a.iter().zip(&b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / scale);
        }
        let ok = worst <= 1e-10;
        println!(
            "{} vs {}: max relative difference {worst:.3e} ({})",
            files[0],
            f,
            if ok { "ok" } else { "FAILED" }
        );
        if ok {
            passed += 1;
        } else {
            failed += 1;
        }
    }
    println!("{passed} passed, {failed} failed");
    Ok(failed == 0)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("solve") if args.len() == 2 => solve(&args[1]).map(|_| true),
        Some("compare") if args.len() >= 3 => compare(&args[1..]),
        _ => Err("usage: mpi_hertz solve OUT.json | mpi_hertz compare A.json B.json …".into()),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("mpi_hertz: {e}");
            ExitCode::FAILURE
        }
    }
}
