//! # 3D Cattaneo–Mindlin partial slip
//!
//! Two identical elastic hemispheres (Dundurs `β = 0`: normal and tangential problems decouple)
//! are pressed together by a prescribed displacement, then sheared by a tangential displacement
//! of the upper one's top with Tresca friction `g_c = μ p` frozen from the normal state (the
//! Coulomb problem, since `β = 0` leaves the pressure unchanged; docs/model.md §3, §9). For
//! `Q/(μP) = 0.3, 0.6, 0.9` the stick zone is the disc `r ≤ c = a (1 − Q/(μP))^{1/3}` (Mindlin,
//! exact for `ν = 0`, which is used here), `a` the Hertz radius of the computed force. The stick
//! radius of the finite element solution is measured from the moments of the stick deficit
//! `μ p − |q|` (nodal forces; `synovia_models::hertz::stick_radius_from_moments`), with the fit
//! of Mindlin's traction ratio to the nodal `‖Λ_t‖` and the area of the sticking dual cells
//! beside it (`synovia_models::hertz::cattaneo_mindlin_3d`). Three refinements of the
//! hemispheres toward the contact point; the table is the one in docs/contact.md.
//!
//! Run: `cargo run --release --example cattaneo_mindlin3d [pdas|…] [levels…] [--push d]
//! [--refine-radius r]` (default `pdas 15 17 19 --push 0.005 --refine-radius 0.075`: contact
//! radius `a ≈ 0.05 R`; the three levels take about 35 s and 2.3 GB after the build on 2 shared
//! cores).

use synovia_models::hertz::{cattaneo_mindlin_3d, ContactRun, Hertz3d};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut name = None;
    let mut levels: Vec<usize> = Vec::new();
    let (mut push, mut refine_radius) = (0.005, 0.075);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--push" => push = args.next().ok_or("--push needs a value")?.parse()?,
            "--refine-radius" => {
                refine_radius = args.next().ok_or("--refine-radius needs a value")?.parse()?
            }
            _ if name.is_none() && arg.parse::<usize>().is_err() => name = Some(arg),
            _ => levels.push(arg.parse()?),
        }
    }
    let name = name.unwrap_or_else(|| "pdas".to_string());
    if levels.is_empty() {
        levels = vec![15, 17, 19];
    }
    let solver = synovia::solvers::by_name(&name)?;
    let mu = 0.3;
    let ratios = [0.3, 0.6, 0.9];
    let mut all: Vec<Vec<ContactRun>> = Vec::new();
    for &level in &levels {
        let p = Hertz3d { levels: level, push, refine_radius, nu: 0.0, ..Default::default() };
        let runs = cattaneo_mindlin_3d(&p, mu, &ratios, solver.as_ref())?;
        all.push(runs);
    }
    println!("push {push}, refine radius {refine_radius}");
    println!(
        "{:>6} {:>5} {:>9} {:>7} {:>6} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9} {:>9} {:>9} {:>8} {:>8} {:>7}",
        "Q/μP",
        "level",
        "h",
        "dofs",
        "active",
        "a area",
        "a Hertz",
        "c",
        "c fit",
        "c area",
        "c exact",
        "c err",
        "c_fit err",
        "c_area err",
        "q L2 err",
        "|q|-μp",
        "solve s"
    );
    for (k, _) in ratios.iter().enumerate() {
        for runs in &all {
            let r = &runs[k];
            println!(
                "{:>6.4} {:>5} {:>9.3e} {:>7} {:>6} {:>8.5} {:>8.5} {:>8.5} {:>8.5} {:>8.5} {:>8.5} {:>+9.2e} {:>+9.2e} {:>+9.2e} {:>8.2e} {:>8.1e} {:>7.2}",
                r.q_ratio,
                r.level,
                r.h,
                r.dofs,
                r.active_nodes,
                r.a_contact_area,
                r.a_exact,
                r.c,
                r.c_fit,
                r.c_stick_area,
                r.c_exact,
                r.c / r.c_exact - 1.0,
                r.c_fit / r.c_exact - 1.0,
                r.c_stick_area / r.c_exact - 1.0,
                r.traction_l2_err,
                r.coulomb_excess,
                r.solve_s
            );
        }
    }
    let list = |f: &dyn Fn(&ContactRun) -> String| -> String {
        let rows: Vec<String> = all
            .iter()
            .map(|runs| format!("[{}]", runs.iter().map(f).collect::<Vec<_>>().join(",")))
            .collect();
        format!("[{}]", rows.join(","))
    };
    println!(
        "{{\"example\":\"cattaneo_mindlin3d\",\"solver\":\"{}\",\"mu\":{mu},\"push\":{push},\"refine_radius\":{refine_radius},\"levels\":{:?},\"h\":[{}],\"dofs\":[{}],\"q_ratio\":{},\"a_area_rel_err\":{},\"c\":{},\"c_fit\":{},\"c_stick_area\":{},\"c_exact\":{},\"c_rel_err\":{},\"c_fit_rel_err\":{},\"traction_l2_err\":{},\"kkt\":{}}}",
        solver.name(),
        levels,
        all.iter().map(|r| format!("{:.4e}", r[0].h)).collect::<Vec<_>>().join(","),
        all.iter().map(|r| r[0].dofs.to_string()).collect::<Vec<_>>().join(","),
        list(&|r| format!("{:.4}", r.q_ratio)),
        list(&|r| format!("{:.3e}", (r.a_contact_area - r.a_exact).abs() / r.a_exact)),
        list(&|r| format!("{:.5e}", r.c)),
        list(&|r| format!("{:.5e}", r.c_fit)),
        list(&|r| format!("{:.5e}", r.c_stick_area)),
        list(&|r| format!("{:.5e}", r.c_exact)),
        list(&|r| format!("{:.3e}", r.c_rel_err())),
        list(&|r| format!("{:.3e}", (r.c_fit - r.c_exact).abs() / r.c_exact)),
        list(&|r| format!("{:.3e}", r.traction_l2_err)),
        list(&|r| format!("{:.1e}", r.kkt)),
    );
    Ok(())
}
