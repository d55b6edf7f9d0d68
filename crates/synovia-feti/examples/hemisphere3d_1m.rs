//! The `bench_report` case `hemisphere3d_1m` (issue 19; docs/performance.md,
//! *`hemisphere3d_1m` (TFETI)*): the 3D Hertz hemisphere of `synovia_models::hertz::Hertz3d` on a
//! rigid flat at a refinement giving ≈ 1M DOFs, with friction μ = 0.3 as in `bench_report`'s
//! `hemisphere3d_friction` — a frictionless normal solve, then a Tresca step with `g_c = μ Λ_n`
//! and a tangential shift of the top of `2e-4 R` — solved by TFETI without ever factorising the
//! undecomposed stiffness (the direct factorisation of a 3D model needs 4 GB at 340k DOFs).
//!
//! It lives here and not in `examples/bench_report.rs` because `synovia-feti` is not a
//! dependency of the facade (and its MPI ranks need this crate's `mpi` feature); it prints one
//! JSON line with the keys of `bench_report` (`problem`, `case`, `dofs`, `time_s`,
//! `peak_rss_mb`, `kkt`) and the TFETI figures (`subdomains`, `ranks`, outer and inner
//! iterations of both solves, per-rank peak RSS).
//!
//! ```text
//! cargo run --release -p synovia-feti --example hemisphere3d_1m -- [levels=19] [subdomains=N]
//!     [tol=1e-8] [bisection] [prec=lumped|dirichlet|none] [coarse=penalty|projector] [exp=fixed|projcg|precond] [rho=F]
//!     [dry | direct]
//! cargo build --release -p synovia-feti --features mpi --example hemisphere3d_1m
//! mpirun --oversubscribe -np 2 target/release/examples/hemisphere3d_1m levels=19 mpi
//! ```
//!
//! `subdomains` defaults to one per 10 000 DOFs (METIS, `ρ = ‖PFP‖`, tolerance `1e-8`); the
//! preconditioner defaults to the lumped one, which needs no second factorisation per subdomain
//! (the Dirichlet one adds one of `K_ii` per subdomain and solve, more memory and more time per
//! iteration for 15–25 % fewer iterations at 46k DOFs); `dry` builds the model and prints its
//! size only; `direct` prints the memory the direct route would need (symbolic analysis of the
//! undecomposed stiffness with the METIS ordering, no numeric factorisation). `time_s` is the whole run up to the Tresca solution (model, decomposition with the
//! subdomain factorisations, both solves); the KKT residuals are evaluated afterwards on rank 0
//! with the assembled (never factorised) stiffness, after the subdomain factors are freed, and
//! `peak_rss_mb` is each process' `VmHWM` at the very end (`peak_rss_mb` of rank 0,
//! `rank_peak_rss_mb` of all ranks, `total_peak_rss_mb` their sum).

#![recursion_limit = "256"]

use std::time::Instant;

use synovia_contact::{check_kkt, ContactProblem, KktReport};
use synovia_fem::assembly::{assemble_matrix, body_stiffnesses, pattern};
use synovia_fem::element::stiffness_into;
use synovia_fem::model::Model;
use synovia_feti::{
    CoarseConstraint, Communicator, Decomposition, DecompositionParams, Expansion, ModelProblem, Partitioner,
    Preconditioner, SingleProcess, TfetiParams, TfetiSolution,
};
use synovia_linalg::{CholeskySolver, FactorisedOperator, LinalgError, SymmetricMatrix};
use synovia_models::hertz::{hertz3d_model, Hertz3d};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

const MU: f64 = 0.3;

/// The assembled reduced stiffness, for the equilibrium residual of the KKT check only (never
/// factorised).
#[derive(Debug)]
struct Assembled(SymmetricMatrix);

impl FactorisedOperator for Assembled {
    fn n(&self) -> usize {
        self.0.n()
    }
    fn apply(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.0.n()];
        self.0.mul_vec(x, &mut y);
        y
    }
    fn diagonal(&self) -> Vec<f64> {
        self.0.diagonal()
    }
    fn key(&self) -> u64 {
        self.0.n() as u64
    }
    fn solve_in_place(&self, _b: &mut [f64]) -> Result<(), LinalgError> {
        Err(LinalgError::InvalidParameter(
            "the assembled stiffness of the KKT check is not factorised".into(),
        ))
    }
}

/// `VmHWM` of this process in MB.
fn peak_rss_mb() -> Res<f64> {
    let status = std::fs::read_to_string("/proc/self/status")?;
    let line =
        status.lines().find(|l| l.starts_with("VmHWM:")).ok_or("no VmHWM line in /proc/self/status")?;
    let kb: f64 = line.trim_start_matches("VmHWM:").trim().trim_end_matches("kB").trim().parse()?;
    Ok(kb * 1024.0 / 1.0e6)
}

struct Options {
    levels: usize,
    subdomains: Option<usize>,
    tol: f64,
    partitioner: Partitioner,
    preconditioner: Preconditioner,
    coarse: CoarseConstraint,
    expansion: Expansion,
    rho: f64,
    dry: bool,
    direct: bool,
    mpi: bool,
}

fn options() -> Res<Options> {
    let mut o = Options {
        levels: 19,
        subdomains: None,
        tol: 1e-8,
        partitioner: Partitioner::Metis,
        preconditioner: Preconditioner::Lumped,
        coarse: CoarseConstraint::default(),
        expansion: Expansion::Fixed,
        rho: 1.0,
        dry: false,
        direct: false,
        mpi: false,
    };
    for a in std::env::args().skip(1) {
        let (k, v) = a.split_once('=').unwrap_or((a.as_str(), ""));
        match k {
            "levels" => o.levels = v.parse()?,
            "subdomains" => o.subdomains = Some(v.parse()?),
            "tol" => o.tol = v.parse()?,
            "rho" => o.rho = v.parse()?,
            "bisection" => o.partitioner = Partitioner::Bisection,
            "metis" => o.partitioner = Partitioner::Metis,
            "prec" => {
                o.preconditioner = match v {
                    "none" => Preconditioner::None,
                    "lumped" => Preconditioner::Lumped,
                    "dirichlet" => Preconditioner::Dirichlet,
                    _ => return Err(format!("unknown preconditioner `{v}`").into()),
                }
            }
            "coarse" => {
                o.coarse = match v {
                    "penalty" => CoarseConstraint::Penalty,
                    "projector" => CoarseConstraint::Projector,
                    _ => return Err(format!("unknown coarse constraint `{v}`").into()),
                }
            }
            "exp" => {
                o.expansion = match v {
                    "fixed" => Expansion::Fixed,
                    "projcg" => Expansion::ProjectedCg,
                    "precond" => Expansion::Preconditioned,
                    _ => return Err(format!("unknown expansion step `{v}`").into()),
                }
            }
            "dry" => o.dry = true,
            "direct" => o.direct = true,
            "mpi" => o.mpi = true,
            _ => return Err(format!("unknown argument `{a}`").into()),
        }
    }
    Ok(o)
}

fn kkt(model: &Model<3>, problem: &ModelProblem<3>, s: &TfetiSolution) -> Res<KktReport> {
    let (mut a, _) = pattern(model, &problem.dofs)?;
    let c = body_stiffnesses(model)?;
    assemble_matrix(model, &problem.dofs, &mut a, |b, _, geo, out| stiffness_into(geo, &c[b], out))?;
    let op = Assembled(a);
    let cp = ContactProblem {
        operator: &op,
        load: &problem.load,
        normal: &problem.normal,
        friction: problem.friction.as_ref(),
        border: None,
    };
    Ok(check_kkt(&cp, &s.u, &s.lambda_n, &s.lambda_t))
}

fn run(o: &Options, comm: &dyn Communicator) -> Res<()> {
    let rank = comm.rank();
    let say = |m: String| {
        if rank == 0 {
            eprintln!("hemisphere3d_1m: {m}");
        }
    };
    let t0 = Instant::now();
    let p = Hertz3d { levels: o.levels, ..Default::default() };
    let (model, mut pairs) = hertz3d_model(&p)?;
    pairs[0].friction = MU;
    let model_s = t0.elapsed().as_secs_f64();
    let normal = ModelProblem::new(&model, &pairs, 0.0, None, None)?;
    let dofs = normal.dofs.n_dofs();
    let subdomains = o.subdomains.unwrap_or_else(|| dofs.div_ceil(10_000).max(1));
    say(format!(
        "level {}: {dofs} DOFs, {} contact nodes, {subdomains} subdomains asked, model {model_s:.1} s",
        o.levels,
        normal.geometry.len()
    ));
    if o.direct {
        // what the direct route would need: the symbolic analysis (METIS, the 3D default of the
        // elastic solve) of the undecomposed stiffness, no numeric factorisation
        let t = Instant::now();
        let (a, ordering) = pattern(&model, &normal.dofs)?;
        let est = CholeskySolver::analyse(&a, &ordering)?.memory_estimate();
        println!(
            "{}",
            serde_json::json!({"problem": "bench_report", "case": "hemisphere3d_1m_direct_estimate",
                "levels": o.levels, "dofs": dofs, "factor_entries": est.factor_entries,
                "factor_gb": est.factor_bytes as f64 / 1e9, "workspace_gb": est.workspace_bytes as f64 / 1e9,
                "total_gb": est.total_bytes() as f64 / 1e9, "analyse_s": t.elapsed().as_secs_f64(),
                "peak_rss_mb": peak_rss_mb()?})
        );
        return Ok(());
    }
    if o.dry {
        if rank == 0 {
            println!(
                "{}",
                serde_json::json!({"problem": "bench_report", "case": "hemisphere3d_1m", "levels": o.levels,
                    "dofs": dofs, "contact_nodes": normal.geometry.len(), "peak_rss_mb": peak_rss_mb()?})
            );
        }
        return Ok(());
    }
    let t1 = Instant::now();
    let dp = DecompositionParams::default().with_subdomains(subdomains).with_partitioner(o.partitioner);
    let dec = Decomposition::new(&model, &dp, comm)?;
    let decomposition_s = t1.elapsed().as_secs_f64();
    say(format!(
        "{} subdomains ({} on rank 0), decomposition {decomposition_s:.1} s",
        dec.n_subdomains(),
        dec.owned().len()
    ));
    let mut params = TfetiParams::default()
        .with_tolerance(o.tol)
        .with_preconditioner(o.preconditioner)
        .with_coarse(o.coarse)
        .with_expansion(o.expansion);
    params.rho_factor = o.rho;
    let t2 = Instant::now();
    let s0 = normal.solve(&dec, comm, &params)?;
    let normal_s = t2.elapsed().as_secs_f64();
    say(format!(
        "normal: {} outer / {} inner, {normal_s:.1} s",
        s0.report.outer_iterations, s0.report.inner_iterations
    ));
    let gc = normal.geometry.slip_bounds_from_pressure(&s0.lambda_n);
    let previous = normal.dofs.expand(&s0.u, &normal.lifts)?;
    let t3 = Instant::now();
    let tresca = ModelProblem::new(&model, &pairs, 2e-4 * p.radius, Some(&gc), Some(&previous))?;
    let s = tresca.solve(&dec, comm, &params)?;
    let tresca_s = t3.elapsed().as_secs_f64();
    let time_s = t0.elapsed().as_secs_f64();
    say(format!(
        "tresca: {} outer / {} inner, {tresca_s:.1} s",
        s.report.outer_iterations, s.report.inner_iterations
    ));
    let owned = dec.owned().len();
    let primal = dec.n_primal();
    drop(dec);
    let t4 = Instant::now();
    let (k0, k1) = if rank == 0 {
        (Some(kkt(&model, &normal, &s0)?), Some(kkt(&model, &tresca, &s)?))
    } else {
        (None, None)
    };
    let kkt_s = t4.elapsed().as_secs_f64();
    let rss = peak_rss_mb()?;
    let ranks = comm.size();
    let all = comm.all_gather(&[rss, owned as f64, normal_s + tresca_s], &vec![3; ranks])?;
    if let (Some(k0), Some(k1)) = (k0, k1) {
        let r = &s.report;
        let active = s.lambda_n.iter().filter(|&&l| l > 0.0).count();
        let (mut stick, mut slip) = (0, 0);
        for c in s.lambda_t.chunks(2) {
            if c.iter().map(|v| v * v).sum::<f64>().sqrt() < 1.0 - 1e-8 {
                stick += 1;
            } else {
                slip += 1;
            }
        }
        let per_rank: Vec<f64> = all.chunks(3).map(|c| c[0]).collect();
        let v = serde_json::json!({
            "problem": "bench_report", "case": "hemisphere3d_1m", "solver": "tfeti",
            "levels": o.levels, "dofs": dofs, "primal_dofs": primal, "contact_nodes": normal.geometry.len(),
            "mu": MU, "subdomains": r.subdomains, "ranks": r.ranks,
            "threads_per_rank": rayon::current_num_threads(),
            "subdomains_per_rank": all.chunks(3).map(|c| c[1] as usize).collect::<Vec<_>>(),
            "partitioner": format!("{:?}", o.partitioner), "preconditioner": format!("{:?}", o.preconditioner), "coarse": format!("{:?}", o.coarse), "expansion": format!("{:?}", o.expansion),
            "rho_factor": o.rho, "tolerance": o.tol,
            "dual": r.dual, "coarse": r.coarse_dim,
            "time_s": time_s, "model_s": model_s, "decomposition_s": decomposition_s,
            "normal_s": normal_s, "tresca_s": tresca_s, "kkt_s": kkt_s,
            "normal_outer": s0.report.outer_iterations, "normal_inner": s0.report.inner_iterations, "normal_steps_cg_exp_prop": s0.report.inner_steps,
            "tresca_outer": r.outer_iterations, "tresca_inner": r.inner_iterations, "tresca_steps_cg_exp_prop": r.inner_steps,
            "exp_fallbacks": [s0.report.expansion_fallbacks, r.expansion_fallbacks],
            "outer_iterations": s0.report.outer_iterations + r.outer_iterations,
            "inner_iterations": s0.report.inner_iterations + r.inner_iterations,
            "f_products": s0.report.f_products + r.f_products,
            "normal_active": s0.lambda_n.iter().filter(|&&l| l > 0.0).count(),
            "active": active, "stick": stick, "slip": slip,
            "kkt_normal": k0.max(), "kkt": k1.max().max(k0.max()),
            "kkt_equilibrium": k1.equilibrium, "gradient": r.gradient, "feasibility": r.feasibility,
            "peak_rss_mb": rss, "rank_peak_rss_mb": per_rank,
            "total_peak_rss_mb": per_rank.iter().sum::<f64>(),
        });
        println!("{v}");
    }
    Ok(())
}

fn main() -> Res<()> {
    let o = options()?;
    if o.mpi {
        #[cfg(feature = "mpi")]
        {
            let universe = mpi::initialize().ok_or("MPI could not be initialised")?;
            let comm = synovia_feti::MpiCommunicator::new(universe.world());
            return run(&o, &comm);
        }
        #[cfg(not(feature = "mpi"))]
        return Err("`mpi` needs the build with `--features mpi`".into());
    }
    run(&o, &SingleProcess)
}
