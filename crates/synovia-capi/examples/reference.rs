//! Reference values for the C example (`examples/c/run.sh`): solves the rounded punch of
//! `tests/common/mod.rs` through the Rust API (`JointModel::run_quasistatic`) and prints the
//! normal contact force after each step with 17 significant digits, on one line.
//!
//! ```sh
//! cargo run --release -p synovia-capi --example reference
//! ```

#[path = "../tests/common/mod.rs"]
mod common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let forces = common::reference_forces()?;
    let line: Vec<String> = forces.iter().map(|f| format!("{f:.16e}")).collect();
    println!("{}", line.join(" "));
    Ok(())
}
