//! # 3D Hertz on non-matching meshes (dual mortar and node-to-facet)
//!
//! A hemisphere indenter (R = 1, E = 1, ν = 0.3, refined toward its pole) pressed 0.01 onto an
//! elastic block `[−1, 1]² × [−1, 0]` (E = 1, ν = 0.3, clamped at its base) whose Kuhn mesh is
//! refined by bisection toward the contact point to another mesh size
//! ([`synovia_models::hertz::HertzBlock3d`]). Two meshings — a finer indenter than the block (ratio
//! 2.7) and a finer block than the indenter (ratio 2.1) — each with dual mortar (finer side
//! slave, then coarser side slave) and with node-to-facet (finer side slave). Prints a table of
//! `a`, `p₀` and the pressure L² error against the Hertz point contact for the computed force
//! (`1/E* = Σ (1 − ν²)/E`, `R* = R`), and ends with one JSON line of the key figures.
//!
//! Run: `cargo run --release --example hertz3d_nonmatching [pdas|au-pdas|uzawa-mprgp|dual-mprgp]`

use synovia_models::hertz::{hertz3d_block, HertzBlock3d};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "pdas".into());
    let solver = synovia::solvers::by_name(&name)?;
    let fine_indenter =
        HertzBlock3d { levels: 13, block_levels: 12, block_refine_radius: 0.25, ..Default::default() };
    let fine_block =
        HertzBlock3d { levels: 10, block_levels: 16, block_refine_radius: 0.13, ..Default::default() };
    println!(
        "| finer side | operator | slave | indenter h | block h | dofs | contact nodes | active | iterations (final + coarse) | a err | p₀ err | L² err of p | contact solve s | factorise + solve A s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut json = Vec::new();
    for (finer, base) in [("indenter", fine_indenter), ("block", fine_block)] {
        let finer_is_indenter = finer == "indenter";
        for (mortar, slave_indenter) in
            [(true, finer_is_indenter), (true, !finer_is_indenter), (false, finer_is_indenter)]
        {
            let p = HertzBlock3d { mortar, slave_indenter, ..base };
            let (run, (h_ind, h_block)) = hertz3d_block(&p, solver.as_ref())?;
            println!(
                "| {finer} | {} | {} | {h_ind:.2e} | {h_block:.2e} | {} | {} | {} | {} + {} | {:.1e} | {:.1e} | {:.1e} | {:.2} | {:.2} |",
                if mortar { "mortar" } else { "node-to-facet" },
                if slave_indenter { "indenter" } else { "block" },
                run.dofs,
                run.contact_nodes,
                run.active_nodes,
                run.iterations,
                run.coarse_iterations,
                run.a_rel_err(),
                run.p0_rel_err(),
                run.pressure_l2_err,
                run.solve_s,
                run.linear_solve_s
            );
            json.push(format!(
                "{{\"finer\":\"{finer}\",\"h_indenter\":{h_ind:.4e},\"h_block\":{h_block:.4e},\"run\":{}}}",
                run.json()
            ));
        }
    }
    println!("{{\"example\":\"hertz3d_nonmatching\",\"solver\":\"{name}\",\"runs\":[{}]}}", json.join(","));
    Ok(())
}
