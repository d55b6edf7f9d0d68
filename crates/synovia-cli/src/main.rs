//! `synovia`: run joint-contact scenarios described in TOML files (`docs/scenario.md`).
//!
//! ```text
//! synovia run SCENARIO.toml --out DIR    # solve; write DIR/NAME.pvd, NAME_*.vtu, NAME.csv, summary.json, manifest.json
//! synovia check SCENARIO.toml            # read and build the model without solving
//! ```
//!
//! Exit codes: 0 success, 1 the solve or the output failed, 2 a broken scenario (the message on
//! stderr names the key and the line:column), bad command-line arguments, or an output
//! directory holding files no earlier run wrote (without `--force`), 130 interrupted (Ctrl-C,
//! SIGTERM: the folder then holds the steps done, with `"interrupted": true` in summary.json).
//!
//! For tests, the environment variable `SYNOVIA_STOP_AFTER_STEPS=N` raises the interrupt flag
//! once `N` steps are done, exactly as Ctrl-C would then.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use synovia_cli::run::{self, Progress, RunError, RunOptions};
use synovia_cli::Scenario;

#[derive(Parser)]
#[command(name = "synovia", version, about = "Finite-element contact mechanics of human joints")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scenario and write ParaView (PVD/VTU), CSV and summary.json results.
    Run {
        /// The scenario file (TOML, see docs/scenario.md).
        scenario: PathBuf,
        /// Output directory (default: `output.dir` of the scenario, or out/NAME).
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// No progress bar and no closing report.
        #[arg(long, short)]
        quiet: bool,
        /// Write into an output directory that holds files no earlier run wrote (they are
        /// kept; the outputs of earlier runs are always replaced).
        #[arg(long)]
        force: bool,
    },
    /// Read a scenario and build its model (meshes, materials, conditions) without solving.
    Check {
        /// The scenario file.
        scenario: PathBuf,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { scenario } => {
            let checked = Scenario::from_file(&scenario).and_then(|sc| run::check(&sc));
            match checked {
                Ok(info) => {
                    println!(
                        "{}: {}D, {} steps ({})",
                        scenario.display(),
                        info.dimension,
                        info.steps,
                        info.analysis
                    );
                    for (name, nodes, cells) in &info.bodies {
                        println!("  body {name}: {nodes} nodes, {cells} cells");
                    }
                    for p in &info.pairs {
                        println!("  contact pair {p}");
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
            }
        }
        Command::Run { scenario, out, quiet, force } => {
            let sc = match Scenario::from_file(&scenario) {
                Ok(sc) => sc,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            let target = if !quiet && std::io::stderr().is_terminal() {
                ProgressDrawTarget::stderr()
            } else {
                ProgressDrawTarget::hidden()
            };
            let bar = ProgressBar::with_draw_target(None, target);
            if let Ok(style) = ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} steps  {msg}",
            ) {
                bar.set_style(style);
            }
            // Ctrl-C / SIGTERM: stop after the current step with a consistent folder; a second
            // signal exits at once
            let interrupt = Arc::new(AtomicBool::new(false));
            let flag = Arc::clone(&interrupt);
            if let Err(e) = ctrlc::set_handler(move || {
                if flag.swap(true, Ordering::SeqCst) {
                    std::process::exit(130);
                }
            }) {
                eprintln!("warning: cannot catch Ctrl-C ({e}); an interrupted run leaves partial results");
            }
            let stop_after =
                std::env::var("SYNOVIA_STOP_AFTER_STEPS").ok().and_then(|v| v.parse::<usize>().ok());
            let options = RunOptions { force, interrupt: Some(Arc::clone(&interrupt)) };
            let result = run::run_with_options(&sc, out.as_deref(), &options, &mut |p| match p {
                Progress::Start { steps } => bar.set_length(steps as u64),
                Progress::Step { index, time } => {
                    bar.set_message(format!("t = {time:.4e}"));
                    bar.set_position(index as u64 + 1);
                    if stop_after.is_some_and(|n| index + 1 >= n) {
                        interrupt.store(true, Ordering::SeqCst);
                    }
                }
            });
            bar.finish_and_clear();
            match result {
                Ok(report) if report.summary.interrupted => {
                    let s = &report.summary;
                    eprintln!(
                        "interrupted after {} of {} steps; {} holds their results (summary.json has \"interrupted\": true)",
                        s.steps.len(),
                        s.steps_planned,
                        report.out_dir.display()
                    );
                    ExitCode::from(130)
                }
                Ok(report) => {
                    if !quiet {
                        let s = &report.summary;
                        let dir = report.out_dir.display();
                        println!(
                            "{}: {} analysis, {} steps, {} dofs, {} contact nodes, solver {}, {:.2} s",
                            s.name,
                            s.analysis,
                            s.steps.len(),
                            s.dofs,
                            s.contact_nodes,
                            s.solver,
                            s.total_s
                        );
                        if let Some(last) = s.steps.last() {
                            for p in &last.pairs {
                                println!(
                                    "  last step (t = {}): pair {}: normal force {:.5e}, contact area {:.5e}, peak pressure {:.5e}",
                                    last.time, p.name, p.normal_force, p.contact_area, p.peak_pressure
                                );
                            }
                        }
                        println!("results in {dir}/:");
                        if let Some(pvd) = &s.files.pvd {
                            println!("  {pvd}  (ParaView: File > Open, Apply, colour by contact_pressure)");
                        }
                        println!("  {}  (one row per step)", s.files.csv);
                        println!("  summary.json");
                        println!("  {}  (every file written, with its size)", s.files.manifest);
                    }
                    ExitCode::SUCCESS
                }
                Err(RunError::Refused(e)) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
                Err(RunError::Scenario(e)) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
                Err(RunError::Failed(e)) => {
                    eprintln!("error: {e:#}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}
