//! # Node-to-segment: which side should be the slave?
//!
//! The 2D Hertz problem of [`synovia_models::hertz::HertzBlock2d`] with a **stiff, finely meshed
//! indenter** (`E₁ = 100`, cells `h`) on a **soft, coarsely meshed block** (`E₂ = 1`, cells
//! `2.5 h`), over three refinements (`h` halved each time), with node-to-segment contact and
//! either side as the slave, and with dual mortar. Prints the pressure L² error against Hertz
//! (for the computed force) and ends with one JSON line.
//!
//! Run: `cargo run --release --example nts_slave_choice`

use synovia_models::hertz::{hertz2d_block, HertzBlock2d};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let solver = synovia::solvers::by_name(synovia::solvers::DEFAULT_SOLVER)?;
    println!("| E indenter / block | operator | slave | indenter h | block h | active | a err | p₀ err | L² err of p |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut json = Vec::new();
    let cases = [
        (100.0, false, true, "stiff-fine-slave"),
        (100.0, false, false, "soft-coarse-slave"),
        (100.0, true, true, "mortar-stiff-fine-slave"),
        (100.0, true, false, "mortar-soft-coarse-slave"),
        (0.01, false, true, "soft-fine-slave"),
        (0.01, false, false, "stiff-coarse-slave"),
    ];
    for (e1, mortar, slave_indenter, label) in cases {
        let mut errors = Vec::new();
        for (levels, h) in [(10usize, 7.5e-3), (11, 3.77e-3), (12, 1.88e-3)] {
            let p = HertzBlock2d {
                e1,
                e2: 1.0,
                levels,
                block_h: 2.5 * h,
                slave_indenter,
                mortar,
                ..Default::default()
            };
            let run = hertz2d_block(&p, solver.as_ref())?;
            println!(
                "| {e1} / 1 | {} | {} | {h:.2e} | {:.2e} | {} | {:.1e} | {:.1e} | {:.2e} |",
                if mortar { "mortar" } else { "node-to-segment" },
                if slave_indenter { "indenter (fine)" } else { "block (coarse)" },
                2.5 * h,
                run.active_nodes,
                run.a_rel_err(),
                run.p0_rel_err(),
                run.pressure_l2_err
            );
            errors.push(run.pressure_l2_err);
        }
        json.push(format!("\"{label}\":[{:.4e},{:.4e},{:.4e}]", errors[0], errors[1], errors[2]));
    }
    println!("{{\"example\":\"nts_slave_choice\",{}}}", json.join(","));
    Ok(())
}
