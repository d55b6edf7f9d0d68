//! # 2D Hertz on non-matching meshes (node-to-segment and dual mortar)
//!
//! The half-disc indenter (R = 1, E = 1, ν = 0.3, plane strain) pressed onto an elastic block
//! (E = 1, ν = 0.3, 2 × 1, clamped at its base) whose mesh is refined toward the contact point
//! to another mesh size ([`synovia_models::hertz::HertzBlock2d`]); the interface is node-to-segment
//! with the R*-tree contact search, or dual mortar. Both ways (a finer indenter than the block
//! and the reverse, mesh-size ratio 2.5), both choices of the slave side, both operators;
//! prints `a`, `p₀` and the pressure L² error against the Hertz line contact for the computed
//! force, and ends with one JSON line of the key figures.
//!
//! Run: `cargo run --release --example hertz2d_nonmatching [pdas|au-pdas|uzawa-mprgp|dual-mprgp]`

use synovia_models::hertz::{hertz2d_block, HertzBlock2d};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args().nth(1).unwrap_or_else(|| "pdas".into());
    let solver = synovia::solvers::by_name(&name)?;
    println!(
        "| operator | finer side | slave side | indenter h | block h | dofs | active | iterations (final + coarse) | a err | p₀ err | L² err of p | solve s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut lines = Vec::new();
    for mortar in [false, true] {
        for (finer, levels, block_h) in [("indenter", 12, 4.7e-3), ("block", 10, 1.5e-3)] {
            for slave_indenter in [true, false] {
                let p = HertzBlock2d { levels, block_h, slave_indenter, mortar, ..Default::default() };
                let run = hertz2d_block(&p, solver.as_ref())?;
                let h_ind = if levels == 12 { 1.88e-3 } else { 3.77e-3 };
                println!(
                    "| {} | {finer} | {} | {h_ind:.2e} | {block_h:.2e} | {} | {} | {} + {} | {:.1e} | {:.1e} | {:.1e} | {:.3} |",
                    if mortar { "mortar" } else { "node-to-segment" },
                    if slave_indenter { "indenter" } else { "block" },
                    run.dofs,
                    run.active_nodes,
                    run.iterations,
                    run.coarse_iterations,
                    run.a_rel_err(),
                    run.p0_rel_err(),
                    run.pressure_l2_err,
                    run.solve_s
                );
                lines.push(run.json());
            }
        }
    }
    println!("{{\"example\":\"hertz2d_nonmatching\",\"solver\":\"{name}\",\"runs\":[{}]}}", lines.join(","));
    Ok(())
}
