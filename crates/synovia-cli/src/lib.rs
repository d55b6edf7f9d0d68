//! # synovia-cli
//!
//! The library behind the `synovia` command: running a scenario with ParaView, CSV and JSON
//! output ([`run`]). The TOML scenario format ([`scenario`]) and its translation into a
//! [`JointModel`](synovia::builder::JointModel) ([`build`]) live in the crate
//! `synovia-scenario` (shared with the C API) and are re-exported here. The format is
//! documented with a complete example in `docs/scenario.md`.
//!
//! ```no_run
//! use synovia_cli::{run, scenario::Scenario};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let sc = Scenario::from_file("examples/scenarios/hertz2d.toml")?;
//! let report = run::run(&sc, Some("out/hertz2d".as_ref()), &mut |_| {})?;
//! println!("{} steps, peak pressure {}", report.summary.steps.len(),
//!          report.summary.steps[0].pairs[0].peak_pressure);
//! # Ok(())
//! # }
//! ```
//!
//! Errors in a scenario are [`ScenarioError`]s: they name the key path (e.g.
//! `body[0].material.E`) and the line and column in the file, for syntax errors, unknown keys
//! and wrong types (from toml's spans) as well as for semantic errors found while building the
//! model (unknown body or part names, missing data, invalid materials or histories).
#![warn(missing_docs)]

pub mod compare;
pub mod gather;
pub mod outdir;
pub mod run;

pub use synovia_scenario::{build, scenario};
pub use synovia_scenario::{Scenario, ScenarioError, Source};
