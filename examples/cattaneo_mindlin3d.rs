//! # 3D Cattaneo–Mindlin partial slip
//!
//! Two identical elastic hemispheres (Dundurs `β = 0`: normal and tangential problems decouple)
//! are pressed together by a prescribed displacement, then sheared by a tangential displacement
//! of the upper one's top with Tresca friction `g_c = μ p` frozen from the normal state (the
//! Coulomb problem, since `β = 0` leaves the pressure unchanged; docs/model.md §3, §9). For
//! `Q/(μP) = 0.3, 0.6, 0.9` the stick zone is the disc `r ≤ c = a (1 − Q/(μP))^{1/3}` (Mindlin,
//! exact for `ν = 0`, which is used here), `a` the Hertz radius. The stick radius of the finite
//! element solution is `sqrt(A_stick/π)`, `A_stick` the area of the dual cells of the sticking
//! contact nodes (`synovia_models::hertz::cattaneo_mindlin_3d`). Three refinements of the
//! hemispheres toward the contact point; the table is the one in docs/contact.md.
//!
//! Run: `cargo run --release --example cattaneo_mindlin3d [pdas|…] [levels…]` (default
//! `pdas 12 14 16`; the finest level, 309 492 dofs, takes about 2 minutes and 2.5 GB on 2 shared cores).

use synovia_models::hertz::{cattaneo_mindlin_3d, ContactRun, Hertz3d};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "pdas".to_string());
    let mut levels: Vec<usize> = args.map(|a| a.parse()).collect::<Result<_, _>>()?;
    if levels.is_empty() {
        levels = vec![12, 14, 16];
    }
    let solver = synovia::solvers::by_name(&name)?;
    let mu = 0.3;
    let ratios = [0.3, 0.6, 0.9];
    let mut all: Vec<Vec<ContactRun>> = Vec::new();
    for &level in &levels {
        let p = Hertz3d { levels: level, push: 0.02, nu: 0.0, ..Default::default() };
        let runs = cattaneo_mindlin_3d(&p, mu, &ratios, solver.as_ref())?;
        all.push(runs);
    }
    println!(
        "{:>6} {:>6} {:>10} {:>7} {:>7} {:>9} {:>9} {:>8} {:>9} {:>9} {:>8} {:>9} {:>9} {:>8}",
        "Q/μP",
        "level",
        "h",
        "dofs",
        "active",
        "a FE",
        "a Hertz",
        "a err",
        "c FE",
        "c exact",
        "c err",
        "q L2 err",
        "max|q|-μp",
        "solve s"
    );
    for (k, _) in ratios.iter().enumerate() {
        for runs in &all {
            let r = &runs[k];
            println!(
                "{:>6.4} {:>6} {:>10.3e} {:>7} {:>7} {:>9.5} {:>9.5} {:>9.5} {:>8.2e} {:>9.5} {:>9.5} {:>9.5} {:>8.2e} {:>9.2e} {:>9.1e} {:>8.2}",
                r.q_ratio,
                r.level,
                r.h,
                r.dofs,
                r.active_nodes,
                r.a,
                r.a_contact_area,
                r.a_exact,
                (r.a_contact_area - r.a_exact).abs() / r.a_exact,
                r.c,
                r.c_stick_area,
                r.c_exact,
                r.c_rel_err(),
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
        "{{\"example\":\"cattaneo_mindlin3d\",\"solver\":\"{}\",\"mu\":{mu},\"levels\":{:?},\"h\":[{}],\"dofs\":[{}],\"q_ratio\":{},\"a_area_rel_err\":{},\"c\":{},\"c_stick_area\":{},\"c_exact\":{},\"c_rel_err\":{},\"traction_l2_err\":{},\"kkt\":{}}}",
        solver.name(),
        levels,
        all.iter().map(|r| format!("{:.4e}", r[0].h)).collect::<Vec<_>>().join(","),
        all.iter().map(|r| r[0].dofs.to_string()).collect::<Vec<_>>().join(","),
        list(&|r| format!("{:.4}", r.q_ratio)),
        list(&|r| format!("{:.3e}", (r.a_contact_area - r.a_exact).abs() / r.a_exact)),
        list(&|r| format!("{:.5e}", r.c)),
        list(&|r| format!("{:.5e}", r.c_stick_area)),
        list(&|r| format!("{:.5e}", r.c_exact)),
        list(&|r| format!("{:.3e}", r.c_rel_err())),
        list(&|r| format!("{:.3e}", r.traction_l2_err)),
        list(&|r| format!("{:.1e}", r.kkt)),
    );
    Ok(())
}
