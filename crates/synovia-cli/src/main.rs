//! `synovia`: run joint-contact scenarios described in TOML files (`docs/scenario.md`).
//!
//! ```text
//! synovia run SCENARIO.toml --out DIR    # solve; write DIR/NAME.pvd, NAME_*.vtu, NAME.csv, summary.json, manifest.json
//! synovia check SCENARIO.toml            # build everything up to the solve, report sizes
//! synovia run STUDY.toml --task-index I --tasks N   # task I of N of a [sweep] study: cases c ≡ I (mod N), each into DIR/case-NNNN
//! synovia gather DIR… [--out table.csv]  # merge the summary.json of the cases into one CSV
//! synovia -v run …                       # one log line per step; -vv: everything; -q: errors only
//! ```
//!
//! Exit codes: 0 success, 1 the solve or the output failed, 2 a broken scenario (the message on
//! stderr names the key and the line:column), bad command-line arguments, or an output
//! directory holding files no earlier run wrote (without `--force`), 130 interrupted (Ctrl-C,
//! SIGTERM: the folder then holds the steps done, with `"interrupted": true` in summary.json).
//!
//! For tests, the environment variable `SYNOVIA_STOP_AFTER_STEPS=N` raises the interrupt flag
//! once `N` steps are done, exactly as Ctrl-C would then.
//!
//! Built with the feature `mpi`, `synovia run` initialises MPI and runs on the ranks it is
//! launched on (`mpirun -np N synovia run s.toml --out D`): with the solver `tfeti` each rank
//! owns a share of the subdomains, every rank computes the same results, and only rank 0
//! prints and writes the output folder. A failure on any rank aborts all of them
//! (`MPI_Abort` with the exit code).

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::{ArgAction, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use synovia::feti::Communicator;
use synovia_cli::run::{self, Progress, RunError, RunOptions, SweepSummary};
use synovia_cli::Scenario;
use synovia_scenario::sweep;
use tracing::Level;
use tracing_subscriber::fmt::format::{self, FormatEvent, FormatFields};
use tracing_subscriber::fmt::FmtContext;
use tracing_subscriber::registry::LookupSpan;

#[derive(Parser)]
#[command(name = "synovia", version, about = "Finite-element contact mechanics of human joints")]
struct Cli {
    /// More output on stderr: `-v` one line per step (time, iterations, KKT residual, step
    /// time, solver) instead of the progress bar, `-vv` everything the library logs.
    #[arg(long, short, action = ArgAction::Count, global = true)]
    verbose: u8,
    /// Errors only: no progress bar, no report, no warnings.
    #[arg(long, short, global = true, conflicts_with = "verbose")]
    quiet: bool,
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
        /// Write into an output directory that holds files no earlier run wrote (they are
        /// kept; the outputs of earlier runs are always replaced).
        #[arg(long)]
        force: bool,
        /// For a scenario with `[sweep]`: this task's 0-based index among `--tasks` (default:
        /// `SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN`; without either, all cases run here).
        /// The task runs the cases `c` with `c mod tasks = index`, each into the subfolder
        /// `case-NNNN` of the output directory.
        #[arg(long, requires = "tasks")]
        task_index: Option<usize>,
        /// For a scenario with `[sweep]`: the number of tasks (default:
        /// `SLURM_ARRAY_TASK_COUNT`).
        #[arg(long, requires = "task_index")]
        tasks: Option<usize>,
    },
    /// Merge the summary.json of the case folders of a `[sweep]` study into one CSV (one row
    /// per case, the swept values as columns); refuses missing or incomplete cases.
    Gather {
        /// Case folders, or folders holding them (e.g. the study's output directory).
        #[arg(required = true)]
        folders: Vec<PathBuf>,
        /// Write the CSV here (default: standard output).
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// Gather the cases present even when some are missing.
        #[arg(long)]
        allow_missing: bool,
    },
    /// Build everything `run` builds before solving (model, ties, contact geometry, symbolic
    /// factorisation and its memory estimate) and report it, without solving.
    Check {
        /// The scenario file.
        scenario: PathBuf,
    },
}

/// Log lines as `warning: message key=value …` on stderr.
struct Plain;

impl<S, N> FormatEvent<S, N> for Plain
where
    S: tracing::Subscriber + for<'a> LookupSpan<'a>,
    N: for<'a> FormatFields<'a> + 'static,
{
    fn format_event(
        &self,
        ctx: &FmtContext<'_, S, N>,
        mut writer: format::Writer<'_>,
        event: &tracing::Event<'_>,
    ) -> std::fmt::Result {
        let level = match *event.metadata().level() {
            Level::ERROR => "error",
            Level::WARN => "warning",
            Level::INFO => "info",
            Level::DEBUG => "debug",
            Level::TRACE => "trace",
        };
        write!(writer, "{level}: ")?;
        ctx.field_format().format_fields(writer.by_ref(), event)?;
        writeln!(writer)
    }
}

/// Installs the log subscriber: errors only with `-q`, warnings by default, debug with `-v`,
/// trace with `-vv`.
fn init_logging(verbose: u8, quiet: bool) {
    let level = match (quiet, verbose) {
        (true, _) => Level::ERROR,
        (false, 0) => Level::WARN,
        (false, 1) => Level::DEBUG,
        _ => Level::TRACE,
    };
    let _ = tracing_subscriber::fmt()
        .with_max_level(level)
        .with_writer(std::io::stderr)
        .with_ansi(false)
        .event_format(Plain)
        .try_init();
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let quiet = cli.quiet;
    // `run` installs the logger once it knows its MPI rank (the other ranks log errors only)
    if !matches!(cli.command, Command::Run { .. }) {
        init_logging(cli.verbose, quiet);
    }
    match cli.command {
        Command::Check { scenario } => {
            let checked =
                Scenario::from_file(&scenario).and_then(|sc| run::check(&sc)).map_err(RunError::from);
            match checked {
                Ok(info) => {
                    for w in &info.warnings {
                        tracing::warn!("{w}");
                    }
                    if !quiet {
                        println!(
                            "{}: {}D, {} steps ({}), {} dofs, solver {}",
                            scenario.display(),
                            info.dimension,
                            info.steps,
                            info.analysis,
                            info.dofs,
                            info.solver
                        );
                        for (name, nodes, cells) in &info.bodies {
                            println!("  body {name}: {nodes} nodes, {cells} cells");
                        }
                        for (p, n) in &info.contact_nodes {
                            println!("  contact pair {p}: {n} contact candidates");
                        }
                        if info.solver == synovia::builder::TFETI {
                            println!("  factorisation: subdomains only (solver tfeti: the whole model is never factorised)");
                        } else {
                            println!(
                                "  factorisation: ≈ {} of memory",
                                synovia::linalg::error::fmt_bytes(info.memory_bytes)
                            );
                        }
                        println!("  ok: {} warning(s)", info.warnings.len());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    report_error(&scenario, &e);
                    ExitCode::from(2)
                }
            }
        }
        Command::Gather { folders, out, allow_missing } => {
            match synovia_cli::gather::gather(&folders, allow_missing) {
                Ok(csv) => match &out {
                    Some(path) => match std::fs::write(path, csv) {
                        Ok(()) => ExitCode::SUCCESS,
                        Err(e) => {
                            eprintln!("error: cannot write `{}`: {e}", path.display());
                            ExitCode::FAILURE
                        }
                    },
                    None => {
                        print!("{csv}");
                        ExitCode::SUCCESS
                    }
                },
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Run { scenario, out, force, task_index, tasks } => {
            #[cfg(feature = "mpi")]
            let Some(universe) = mpi::initialize() else {
                eprintln!("error: MPI could not be initialised");
                return ExitCode::FAILURE;
            };
            #[cfg(feature = "mpi")]
            let ranks = Ranks {
                comm: synovia::feti::MpiCommunicator::new(universe.world()),
                world: universe.world(),
            };
            #[cfg(not(feature = "mpi"))]
            let ranks = Ranks { comm: synovia::feti::SingleProcess };
            // only rank 0 reports (every rank computes the same results)
            let quiet = quiet || ranks.comm.rank() != 0;
            init_logging(cli.verbose, quiet);
            let sc = match Scenario::from_file(&scenario) {
                Ok(sc) => sc,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
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
            let cases = match sweep::cases(&sc) {
                Ok(c) => c,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            let Some(cases) = cases else {
                if task_index.is_some() {
                    eprintln!(
                        "error: {}: --task-index/--tasks need a scenario with a [sweep] table (docs/scenario.md)",
                        scenario.display()
                    );
                    return ExitCode::from(2);
                }
                let options = RunOptions { force, interrupt: Some(Arc::clone(&interrupt)), sweep: None };
                return run_one(&sc, &scenario, out.as_deref(), &options, quiet, cli.verbose, &ranks);
            };
            let (index, count) = match task_of(task_index, tasks) {
                Ok(t) => t,
                Err(m) => {
                    eprintln!("error: {m}");
                    return ExitCode::from(2);
                }
            };
            let mine = match sweep::task_cases(cases.len(), index, count) {
                Ok(m) => m,
                Err(e) => {
                    eprintln!("error: {}: {e}", scenario.display());
                    return ExitCode::from(2);
                }
            };
            let mut code = ExitCode::SUCCESS;
            for c in mine {
                let Some(case) = cases.get(c) else { continue };
                let case_sc = match sweep::case_scenario(&sc, case) {
                    Ok(s) => s,
                    Err(e) => {
                        eprintln!("error: {e}");
                        return ExitCode::from(2);
                    }
                };
                if !quiet {
                    println!("case {} of {}: {}", c, cases.len(), sweep::describe(case));
                }
                let record = SweepSummary::of(case, cases.len());
                let options =
                    RunOptions { force, interrupt: Some(Arc::clone(&interrupt)), sweep: Some(record) };
                let r = run_one(&case_sc, &scenario, out.as_deref(), &options, quiet, cli.verbose, &ranks);
                if r == ExitCode::from(130) {
                    return r;
                }
                if r != ExitCode::SUCCESS {
                    code = r;
                }
            }
            code
        }
    }
}

/// This task's `(index, count)`: from the flags, else from Slurm's array variables
/// (`SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN`, `SLURM_ARRAY_TASK_COUNT`), else `(0, 1)`
/// (all cases in this process).
fn task_of(index: Option<usize>, tasks: Option<usize>) -> Result<(usize, usize), String> {
    if let (Some(i), Some(n)) = (index, tasks) {
        return Ok((i, n));
    }
    let var = |name: &str| -> Result<Option<usize>, String> {
        match std::env::var(name) {
            Err(_) => Ok(None),
            Ok(v) => v
                .trim()
                .parse::<usize>()
                .map(Some)
                .map_err(|_| format!("{name}=`{v}` is not a non-negative integer")),
        }
    };
    match (var("SLURM_ARRAY_TASK_ID")?, var("SLURM_ARRAY_TASK_COUNT")?) {
        (Some(id), Some(count)) => {
            let min = var("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let i = id
                .checked_sub(min)
                .ok_or_else(|| format!("SLURM_ARRAY_TASK_ID={id} is below SLURM_ARRAY_TASK_MIN={min}"))?;
            Ok((i, count))
        }
        (Some(_), None) => {
            Err("SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not; pass --task-index and --tasks"
                .into())
        }
        _ => Ok((0, 1)),
    }
}

/// The processes a run is shared among: one ([`synovia::feti::SingleProcess`]) or the MPI
/// ranks (feature `mpi`).
struct Ranks {
    #[cfg(feature = "mpi")]
    comm: synovia::feti::MpiCommunicator,
    #[cfg(feature = "mpi")]
    world: mpi::topology::SimpleCommunicator,
    #[cfg(not(feature = "mpi"))]
    comm: synovia::feti::SingleProcess,
}

impl Ranks {
    /// Ends a run that failed with exit code `code`: on more than one rank, every rank is
    /// stopped (`MPI_Abort`: the others may be waiting for this one in a collective);
    /// otherwise `code` is returned.
    fn fail(&self, code: u8) -> ExitCode {
        #[cfg(feature = "mpi")]
        if self.comm.size() > 1 {
            mpi::topology::Communicator::abort(&self.world, i32::from(code));
        }
        ExitCode::from(code)
    }
}

/// Runs one scenario (a plain one, or one case of a sweep) with the progress bar and the
/// report; returns the exit code.
fn run_one(
    sc: &Scenario,
    scenario: &std::path::Path,
    out: Option<&std::path::Path>,
    options: &RunOptions,
    quiet: bool,
    verbose: u8,
    ranks: &Ranks,
) -> ExitCode {
    let Some(interrupt) = options.interrupt.as_ref() else { return ExitCode::FAILURE };
    {
        {
            let target = if !quiet && verbose == 0 && std::io::stderr().is_terminal() {
                ProgressDrawTarget::stderr()
            } else {
                ProgressDrawTarget::hidden()
            };
            let bar = ProgressBar::with_draw_target(None, target);
            if let Ok(style) = ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} steps, ETA {eta}  {msg}",
            ) {
                bar.set_style(style);
            }
            let stop_after =
                std::env::var("SYNOVIA_STOP_AFTER_STEPS").ok().and_then(|v| v.parse::<usize>().ok());
            let result = run::run_on(sc, out, options, &ranks.comm, &mut |p| match p {
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
                    // printed also with -q: it explains the exit code 130
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
                            if !last.pairs.is_empty() {
                                println!(
                                    "  last step (t = {}): KKT residual {:.3e} (solver {})",
                                    last.time, last.kkt, last.solver
                                );
                            }
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
                Err(e @ RunError::Failed(_)) => {
                    report_error(scenario, &e);
                    ranks.fail(1)
                }
                Err(e) => {
                    report_error(scenario, &e);
                    ranks.fail(2)
                }
            }
        }
    }
}

/// Prints an error once on stderr: a scenario error (it names the file, key and position), or
/// a set-up / solve failure prefixed with the scenario file.
fn report_error(scenario: &std::path::Path, e: &RunError) {
    match e {
        RunError::Scenario(e) => eprintln!("error: {e}"),
        RunError::Refused(e) => eprintln!("error: {e}"),
        RunError::Failed(e) => {
            let inner: &(dyn std::error::Error + 'static) = e.as_ref();
            eprintln!("error: {}: {}", scenario.display(), run::error_message(inner));
        }
    }
}
