//! Reference figures from the Rust API, printed as one JSON object per line at full
//! precision (`serde_json` writes the shortest representation that round-trips), for the
//! Python tests to compare against:
//!
//! ```sh
//! synovia-python-reference hertz2d LEVELS SOLVER [rigid|cold|pair]
//! synovia-python-reference hertz3d LEVELS SOLVER
//! synovia-python-reference scenario FILE
//! synovia-python-reference session FILE T0 T1 …   # prepare, solve_static(T0), step(T1), …
//! ```

use serde_json::{json, Value};
use synovia_models::hertz::{hertz2d, hertz3d, ContactRun, Hertz2d, Hertz3d};

type Error = Box<dyn std::error::Error>;

fn run_json(r: &ContactRun) -> Value {
    json!({
        "problem": r.problem, "level": r.level, "h": r.h, "dofs": r.dofs,
        "contact_nodes": r.contact_nodes, "active_nodes": r.active_nodes, "solver": r.solver,
        "iterations": r.iterations, "coarse_iterations": r.coarse_iterations,
        "force": r.force, "a": r.a, "a_exact": r.a_exact, "a_rel_err": r.a_rel_err(),
        "p0": r.p0, "p0_exact": r.p0_exact, "p0_rel_err": r.p0_rel_err(),
        "pressure_l2_err": r.pressure_l2_err, "kkt": r.kkt,
        "profile": r.profile.iter().map(|&(x, p)| vec![x, p]).collect::<Vec<_>>(),
        "json": r.json(),
    })
}

fn scenario<const D: usize>(sc: &synovia_scenario::Scenario) -> Result<Value, Error> {
    let built = synovia_scenario::build::build::<D>(sc)?;
    let run = built.joint.run()?;
    let records: Vec<Value> = run
        .records
        .iter()
        .map(|r| {
            json!({
                "time": r.time,
                "strain_energy": r.strain_energy,
                "pairs": r.pairs.iter().map(|p| json!({
                    "name": p.name, "normal_force": p.normal_force, "contact_area": p.contact_area,
                    "peak_pressure": p.peak_pressure, "force": p.force.to_vec(),
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let displacement: Vec<Vec<f64>> = run
        .displacement
        .iter()
        .map(|u| u.iter().flat_map(|v| v.iter().copied().collect::<Vec<_>>()).collect())
        .collect();
    Ok(json!({ "n_dofs": run.n_dofs, "records": records, "displacement": displacement }))
}

fn session<const D: usize>(sc: &synovia_scenario::Scenario, times: &[f64]) -> Result<Value, Error> {
    let built = synovia_scenario::build::build::<D>(sc)?;
    let mut session = built.joint.prepare()?;
    let mut solves = Vec::new();
    for (i, &t) in times.iter().enumerate() {
        if i == 0 {
            session.solve_static(t)?;
        } else {
            session.step(t)?;
        }
        let record = session.record().ok_or("no record")?;
        let u = session.displacement().ok_or("no displacement")?;
        solves.push(json!({
            "time": record.time,
            "pairs": record.pairs.iter().map(|p| json!({
                "name": p.name, "normal_force": p.normal_force, "tangential_force": p.tangential_force,
                "contact_area": p.contact_area, "force": p.force.to_vec(),
            })).collect::<Vec<_>>(),
            "rigid_dofs": record.rigid.iter().map(|r| r.dofs.clone()).collect::<Vec<_>>(),
            "displacement": u.iter().map(|b| b.iter().flat_map(|v| v.iter().copied().collect::<Vec<_>>()).collect::<Vec<_>>()).collect::<Vec<_>>(),
        }));
    }
    Ok(json!({ "solves": solves }))
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg =
        |i: usize| args.get(i).cloned().ok_or_else(|| format!("missing argument {i}; usage: see the source"));
    match arg(0)?.as_str() {
        "hertz2d" => {
            let levels: usize = arg(1)?.parse()?;
            let solver = synovia::solvers::by_name(&arg(2)?)?;
            let p = match args.get(3).map(String::as_str).unwrap_or("rigid") {
                "rigid" => Hertz2d { levels, ..Default::default() },
                "cold" => Hertz2d { levels, nested: false, ..Default::default() },
                "pair" => Hertz2d { levels, e2: Some(3.0), ..Default::default() },
                other => return Err(format!("unknown hertz2d case `{other}`").into()),
            };
            println!("{}", run_json(&hertz2d(&p, solver.as_ref())?));
        }
        "hertz3d" => {
            let levels: usize = arg(1)?.parse()?;
            let solver = synovia::solvers::by_name(&arg(2)?)?;
            println!("{}", run_json(&hertz3d(&Hertz3d { levels, ..Default::default() }, solver.as_ref())?));
        }
        "scenario" => {
            let sc = synovia_scenario::Scenario::from_file(arg(1)?)?;
            let v = match *sc.doc.dimension.get_ref() {
                2 => scenario::<2>(&sc)?,
                3 => scenario::<3>(&sc)?,
                d => return Err(format!("dimension {d}").into()),
            };
            println!("{v}");
        }
        "session" => {
            let sc = synovia_scenario::Scenario::from_file(arg(1)?)?;
            let times: Vec<f64> = args[2..].iter().map(|t| t.parse()).collect::<Result<_, _>>()?;
            let v = match *sc.doc.dimension.get_ref() {
                2 => session::<2>(&sc, &times)?,
                3 => session::<3>(&sc, &times)?,
                d => return Err(format!("dimension {d}").into()),
            };
            println!("{v}");
        }
        other => return Err(format!("unknown command `{other}`").into()),
    }
    Ok(())
}
