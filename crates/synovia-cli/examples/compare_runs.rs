//! Compares the output folders of runs of one scenario with the first
//! ([`synovia_cli::compare`]: the nodal displacement, contact pressure and friction traction of
//! every `.vtu` file, the per-pair forces of `summary.json`):
//!
//! ```text
//! cargo run --release -p synovia-cli --example compare_runs -- [--tolerance 1e-10] A B [C …]
//! ```
//!
//! Prints the largest relative difference of each quantity for every folder against `A` and
//! exits with status 1 if one exceeds the tolerance (default `1e-10`), 2 for bad arguments or
//! folders that cannot be compared. `.ci/run` uses it on the runs of
//! `examples/scenarios/hertz2d_tfeti.toml` on 1, 2 and 4 MPI ranks.

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let mut tolerance = 1e-10;
    let mut folders: Vec<PathBuf> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--tolerance" {
            match args.next().and_then(|v| v.parse::<f64>().ok()) {
                Some(t) if t >= 0.0 => tolerance = t,
                _ => {
                    eprintln!("compare_runs: --tolerance needs a number ≥ 0");
                    return ExitCode::from(2);
                }
            }
        } else {
            folders.push(a.into());
        }
    }
    if folders.len() < 2 {
        eprintln!("usage: compare_runs [--tolerance T] A B [C …]");
        return ExitCode::from(2);
    }
    let mut failed = 0;
    for other in &folders[1..] {
        match synovia_cli::compare::compare(&folders[0], other) {
            Ok(c) => {
                let ok = c.max() <= tolerance;
                println!(
                    "{} vs {}: {} steps, {} .vtu files, max relative difference {:.3e} ({})",
                    folders[0].display(),
                    other.display(),
                    c.steps,
                    c.files,
                    c.max(),
                    if ok { "ok" } else { "FAILED" }
                );
                for (q, d) in &c.differences {
                    println!("  {q}: {d:.3e}");
                }
                if !ok {
                    failed += 1;
                }
            }
            Err(e) => {
                eprintln!("compare_runs: {e}");
                return ExitCode::from(2);
            }
        }
    }
    println!("{} passed, {failed} failed (tolerance {tolerance:e})", folders.len() - 1 - failed);
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
