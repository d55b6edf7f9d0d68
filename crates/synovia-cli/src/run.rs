//! Running a scenario: build the model, step through the analysis, write the ParaView series,
//! the per-step CSV and `summary.json`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;
use synovia::builder::JointError;
use synovia::feti::{Communicator, SingleProcess};
use synovia::time::quasistatic::QuasiStaticOutput;
use synovia::time::results::{write_csv_with_units, PairRecord, StepRecord, Units};

use crate::build::{build, Built};
use crate::outdir::{OutDir, MANIFEST, SUMMARY};
use crate::scenario::{Scenario, ScenarioError};

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The scenario is broken (with its key and position).
    #[error("{0}")]
    Scenario(#[from] ScenarioError),
    /// The output directory holds files no earlier run wrote and `force` was not given
    /// ([`crate::outdir`]).
    #[error("{0}")]
    Refused(String),
    /// The model is valid but solving or writing failed.
    #[error("{0}")]
    Failed(#[from] anyhow::Error),
}

/// Progress of a run, for a progress bar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Progress {
    /// The model is built; `steps` records will follow.
    Start {
        /// Number of steps (records).
        steps: usize,
    },
    /// A step is done.
    Step {
        /// Its index (0-based).
        index: usize,
        /// Its time.
        time: f64,
    },
}

/// The figures of one contact pair at one step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairSummary {
    /// Pair name.
    pub name: String,
    /// Resultant contact force on body `k` (normal + friction), `[x, y, z]` (`z = 0` in 2D;
    /// per unit thickness in 2D).
    pub force: [f64; 3],
    /// Normal force.
    pub normal_force: f64,
    /// Magnitude of the friction force.
    pub tangential_force: f64,
    /// Contact area (length in 2D).
    pub contact_area: f64,
    /// Peak contact pressure.
    pub peak_pressure: f64,
    /// Sticking area.
    pub stick_area: f64,
    /// Slipping area.
    pub slip_area: f64,
    /// Moment of the contact forces on body `k` about the origin, `[x, y, z]` (2D: `z` only).
    pub moment: [f64; 3],
    /// Centre of pressure (normal-force-weighted position of the contact nodes); `null`
    /// without contact.
    pub centre_of_pressure: Option<[f64; 3]>,
    /// Mean contact pressure (normal force / contact area).
    pub mean_pressure: f64,
    /// The two sides of a pair split by a plane (`split` in `[[contact]]`), positive side
    /// first, each with the figures above (`name` = the side's name, `sides` empty); empty
    /// for a pair without a split.
    pub sides: Vec<PairSummary>,
}

impl PairSummary {
    fn of(p: &PairRecord) -> Self {
        Self {
            name: p.name.clone(),
            force: p.force,
            normal_force: p.normal_force,
            tangential_force: p.tangential_force,
            contact_area: p.contact_area,
            peak_pressure: p.peak_pressure,
            stick_area: p.stick_area,
            slip_area: p.slip_area,
            moment: p.moment,
            centre_of_pressure: p.centre_of_pressure,
            mean_pressure: p.mean_pressure,
            sides: p.sides.iter().map(Self::of).collect(),
        }
    }
}

/// The unit labels of the outputs (`[units]` of the scenario; synovia computes in any
/// consistent units, these only name them).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnitsSummary {
    /// Length unit of the meshes (positions, displacements, centres of pressure).
    pub length: String,
    /// Force unit (forces; in 2D forces are per unit thickness, `force/length`).
    pub force: String,
    /// Time unit of the time levels.
    pub time: String,
    /// Pressure and modulus unit, `force/length²` (`MPa` for N and mm).
    pub pressure: String,
    /// Area unit (3D `length^2`; 2D: contact length per unit thickness, `length^2/length`).
    pub area: String,
    /// Moment and energy unit (`force*length`; 2D per unit thickness).
    pub moment: String,
}

impl UnitsSummary {
    fn of(u: &Units, dimension: usize) -> Self {
        use synovia::time::results::Quantity;
        Self {
            length: u.length.clone(),
            force: u.label(Quantity::Force, dimension),
            time: u.time.clone(),
            pressure: u.pressure(),
            area: u.label(Quantity::Area, dimension),
            moment: u.label(Quantity::Moment, dimension),
        }
    }
}

/// The state of one rigid body with mixed control at one step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RigidSummary {
    /// Rigid body name.
    pub name: String,
    /// Coordinates `[t_x, t_y, t_z, θ_x, θ_y, θ_z]` (2D: `[t_x, t_y, θ]`): length unit, radians.
    pub dofs: Vec<f64>,
    /// Generalised forces the elastic bodies exert on it, per coordinate (force; moment about
    /// the angle's axis through the moved reference point).
    pub reaction: Vec<f64>,
    /// Applied generalised force per coordinate, `null` for a prescribed one.
    pub applied: Vec<Option<f64>>,
    /// Resultant force on it from the elastic bodies, `[x, y, z]`.
    pub force: [f64; 3],
    /// Moment of those forces about the moved reference point, `[x, y, z]`.
    pub moment: [f64; 3],
    /// Largest relative equilibrium error `|Q_k + F_k| / scale` of the force-controlled
    /// coordinates (0 if none).
    pub balance_error: f64,
    /// Contact solves spent on the step.
    pub solves: usize,
}

/// The figures of one step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepSummary {
    /// Step index (0 = first level / initial state).
    pub step: usize,
    /// Time.
    pub time: f64,
    /// Contact solver iterations.
    pub iterations: usize,
    /// Wall time of the step, s.
    pub step_s: f64,
    /// Sum of the pairs' normal forces.
    pub contact_force: f64,
    /// Per contact pair.
    pub pairs: Vec<PairSummary>,
    /// Per rigid body (empty without rigid bodies).
    pub rigid_bodies: Vec<RigidSummary>,
    /// Strain energy.
    pub strain_energy: f64,
    /// Kinetic energy (dynamic runs).
    pub kinetic_energy: f64,
    /// Friction work of the step.
    pub friction_dissipation: f64,
    /// The largest relative KKT residual of the step's contact solution (equilibrium,
    /// penetration, complementarity, friction; 0 without contact).
    pub kkt: f64,
    /// The contact solver that produced the step's solution (e.g. `dual-mprgp` when
    /// `pdas-fallback` fell back; the step record's `solver`), the configured one for a step
    /// without contact solve.
    pub solver: String,
    /// `true` when a body held only by contact carries no contact force at this step: its
    /// position is then not determined by the equations (any rigid motion of it is a
    /// solution; the one reported is the solver's).
    pub position_undetermined: bool,
    /// The step's `.vtu` file (relative to the output directory), if written.
    pub vtu: Option<String>,
}

/// One body of the model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BodySummary {
    /// Name.
    pub name: String,
    /// Nodes.
    pub nodes: usize,
    /// Cells.
    pub cells: usize,
}

/// The files written, relative to the output directory.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FilesSummary {
    /// The ParaView time series (`None` with `vtu_every = 0`).
    pub pvd: Option<String>,
    /// The per-step CSV.
    pub csv: String,
    /// Number of `.vtu` files.
    pub vtu: usize,
    /// The manifest of every file written (`manifest.json`, written last).
    pub manifest: String,
}

/// `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// The scenario file.
    pub scenario: String,
    /// Its name (base name of the outputs).
    pub name: String,
    /// Its title.
    pub title: Option<String>,
    /// 2 or 3.
    pub dimension: usize,
    /// `static`, `quasistatic` or `dynamic`.
    pub analysis: String,
    /// Contact solver (as configured; each step's [`StepSummary::solver`] names the one that
    /// ran).
    pub solver: String,
    /// Reduced unknowns.
    pub dofs: usize,
    /// Contact nodes.
    pub contact_nodes: usize,
    /// Bodies.
    pub bodies: Vec<BodySummary>,
    /// Contact pair names.
    pub pairs: Vec<String>,
    /// Set-up time (assembly, factorisation, contact geometry), s.
    pub setup_s: f64,
    /// Wall time of the solve (set-up and steps, without writing the summary), s.
    pub total_s: f64,
    /// One entry per step.
    pub steps: Vec<StepSummary>,
    /// Files written.
    pub files: FilesSummary,
    /// `true` when the run was interrupted (Ctrl-C, SIGTERM, [`RunOptions::interrupt`]):
    /// `steps` holds the steps done, and the files are those of these steps.
    pub interrupted: bool,
    /// Steps the analysis would have produced (`steps.len()` unless interrupted).
    pub steps_planned: usize,
    /// The KKT residual of the last step (`steps.last().kkt`; 0 without steps).
    pub final_kkt: f64,
    /// Warnings of the build and the run (initial penetration, unused duplicate nodes,
    /// undetermined positions, large strains of the unit check), also printed by the CLI.
    pub warnings: Vec<String>,
    /// The unit labels of every figure (`[units]` of the scenario; default mm, N, s).
    pub units: UnitsSummary,
    /// The sweep case this run is (runs of a `[sweep]` scenario only; `synovia gather` reads
    /// it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep: Option<SweepSummary>,
}

/// One case of a parameter study (`[sweep]`, docs/scenario.md), as recorded in `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct SweepSummary {
    /// 0-based case index.
    pub case: usize,
    /// Number of cases of the sweep.
    pub cases: usize,
    /// The swept keys and this case's values, in the order of `[sweep.values]`.
    pub parameters: Vec<SweepParameter>,
}

/// One swept key and its value in a case.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct SweepParameter {
    /// Key path, e.g. `body[0].material.E`.
    pub key: String,
    /// The value (TOML value as JSON).
    pub value: serde_json::Value,
}

impl SweepSummary {
    /// The record of `case` of a sweep of `cases` cases.
    pub fn of(case: &synovia_scenario::sweep::Case, cases: usize) -> Self {
        let parameters = case
            .parameters
            .iter()
            .map(|(k, v)| SweepParameter {
                key: k.clone(),
                value: serde_json::to_value(v).unwrap_or(serde_json::Value::Null),
            })
            .collect();
        Self { case: case.index, cases, parameters }
    }
    /// The case's folder name inside the sweep's output directory: `case-NNNN`.
    pub fn folder(&self) -> String {
        format!("case-{:04}", self.case)
    }
}

/// Options of [`run_with_options`].
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Write into an output directory that holds files no earlier run wrote (they are kept);
    /// without it the run is refused ([`RunError::Refused`]).
    pub force: bool,
    /// Checked after every step: once `true`, the run stops there and writes a consistent
    /// folder (`summary.json` with `"interrupted": true`).
    pub interrupt: Option<Arc<AtomicBool>>,
    /// The sweep case the scenario is (from [`synovia_scenario::sweep::case_scenario`]): the
    /// run then writes into the subfolder [`SweepSummary::folder`] of the output directory and
    /// records the case in `summary.json`.
    pub sweep: Option<SweepSummary>,
}

/// What a successful run wrote.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// The summary (also in `summary.json`).
    pub summary: Summary,
    /// The output directory.
    pub out_dir: PathBuf,
}

/// A short description of a built and checked model (`synovia check`).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelInfo {
    /// Dimension.
    pub dimension: usize,
    /// Bodies `(name, nodes, cells)`.
    pub bodies: Vec<(String, usize, usize)>,
    /// Contact pair names.
    pub pairs: Vec<String>,
    /// Analysis kind.
    pub analysis: String,
    /// Steps the analysis will produce.
    pub steps: usize,
    /// Reduced unknowns.
    pub dofs: usize,
    /// Contact candidates (contact nodes) per pair `(name, count)`.
    pub contact_nodes: Vec<(String, usize)>,
    /// The memory estimate of the factorisation, bytes.
    pub memory_bytes: u64,
    /// The contact solver.
    pub solver: String,
    /// Warnings (initial penetration, unused duplicate nodes, floating bodies).
    pub warnings: Vec<String>,
}

fn dimension(sc: &Scenario) -> Result<usize, ScenarioError> {
    match *sc.doc.dimension.get_ref() {
        2 => Ok(2),
        3 => Ok(3),
        d => Err(sc.source.error(
            "dimension",
            Some(sc.doc.dimension.span()),
            format!("must be 2 or 3, got {d}"),
        )),
    }
}

/// Builds everything [`run`] builds before solving (meshes, every name and value, dofs and
/// ties, contact geometry and pair conflicts, the symbolic factorisation and its memory
/// estimate, initial penetration) without solving.
///
/// # Errors
/// The scenario's first problem; a set-up error a run would meet (initial penetration
/// refused, memory, ties, pairs) is a [`ScenarioError`] about the whole file with the same
/// message as the run's.
pub fn check(sc: &Scenario) -> Result<ModelInfo, ScenarioError> {
    fn info<const D: usize>(sc: &Scenario, b: &Built<D>) -> Result<ModelInfo, ScenarioError> {
        let setup = b.joint.check().map_err(|e| sc.source.file_error(error_message(&e)))?;
        let mut warnings = b.warnings.clone();
        warnings.extend(setup.penetration.iter().map(ToString::to_string));
        if !setup.floating_bodies.is_empty() {
            warnings.push(floating_note(&setup.floating_bodies));
        }
        Ok(ModelInfo {
            dimension: D,
            bodies: b
                .joint
                .model()
                .bodies()
                .iter()
                .map(|x| (x.name.clone(), x.mesh.n_nodes(), x.mesh.n_cells()))
                .collect(),
            pairs: b.joint.pairs().iter().map(|p| p.name.clone()).collect(),
            analysis: b.analysis.kind().to_string(),
            steps: b.analysis.n_records(),
            dofs: setup.n_dofs,
            contact_nodes: setup.contact_nodes,
            memory_bytes: setup.memory.total_bytes(),
            solver: b.joint.solver_name().to_string(),
            warnings,
        })
    }
    match dimension(sc)? {
        2 => info(sc, &build::<2>(sc)?),
        _ => info(sc, &build::<3>(sc)?),
    }
}

fn floating_note(bodies: &[String]) -> String {
    format!(
        "bodies {} are held only by contact: at a step where no contact force acts on them their position is undetermined (summary.json: `position_undetermined`)",
        bodies.iter().map(|b| format!("`{b}`")).collect::<Vec<_>>().join(", ")
    )
}

/// An error and its causes as one line, each cause once: a cause whose text the message
/// already holds (errors that print their source) is not repeated.
pub fn error_message(e: &(dyn std::error::Error + 'static)) -> String {
    let mut out = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !out.contains(&text) {
            out.push_str(": ");
            out.push_str(&text);
        }
        cause = c.source();
    }
    out
}

/// Runs a scenario and writes its results to `out` (default: `output.dir` of the scenario, or
/// `out/NAME`), calling `progress` as it goes; [`run_with_options`] with the default options
/// (no `force`, no interrupt flag).
///
/// # Errors
/// As [`run_with_options`].
pub fn run(
    sc: &Scenario,
    out: Option<&Path>,
    progress: &mut dyn FnMut(Progress),
) -> Result<RunReport, RunError> {
    run_with_options(sc, out, &RunOptions::default(), progress)
}

/// Runs a scenario and writes its results to `out` (default: `output.dir` of the scenario, or
/// `out/NAME`), calling `progress` as it goes.
///
/// The folder is first cleared of what an earlier run wrote ([`crate::outdir`]); every file
/// is written under a temporary name and renamed into place; `manifest.json`, written last,
/// lists every file with its size. When `options.interrupt` becomes `true` the run stops after
/// the current step and returns `Ok` with [`Summary::interrupted`] set.
///
/// # Errors
/// [`RunError::Scenario`] for a broken scenario, [`RunError::Refused`] for an output folder
/// with foreign files (without `force`), [`RunError::Failed`] when solving or writing fails.
pub fn run_with_options(
    sc: &Scenario,
    out: Option<&Path>,
    options: &RunOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<RunReport, RunError> {
    run_on(sc, out, options, &SingleProcess, progress)
}

/// [`run_with_options`] on the ranks of `comm` (e.g. MPI ranks: `synovia` built with the
/// feature `mpi` under `mpirun`). Collective: every rank calls it with the same scenario. With
/// the solver `tfeti` the subdomains are shared among the ranks
/// ([`JointModel::run_on`](synovia::builder::JointModel::run_on)), and every rank computes the
/// same results; only rank 0 touches the output folder (clears it, writes the files, the
/// summary and the manifest). The other ranks write nothing and return the same summary
/// (with `files` naming what rank 0 wrote). Other solvers run on one rank only.
///
/// # Errors
/// As [`run_with_options`]; a solver other than `tfeti` on more than one rank is refused
/// ([`RunError::Failed`]).
pub fn run_on(
    sc: &Scenario,
    out: Option<&Path>,
    options: &RunOptions,
    comm: &dyn Communicator,
    progress: &mut dyn FnMut(Progress),
) -> Result<RunReport, RunError> {
    match dimension(sc)? {
        2 => run_dim::<2>(sc, out, options, comm, progress),
        _ => run_dim::<3>(sc, out, options, comm, progress),
    }
}
fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned())
}

fn step_summary(record: &StepRecord, vtu: Option<String>, kkt: f64, solver: String) -> StepSummary {
    StepSummary {
        step: record.step,
        time: record.time,
        iterations: record.iterations,
        step_s: record.step_s,
        contact_force: record.pairs.iter().map(|p| p.normal_force).sum(),
        pairs: record.pairs.iter().map(PairSummary::of).collect(),
        rigid_bodies: record
            .rigid
            .iter()
            .map(|r| RigidSummary {
                name: r.name.clone(),
                dofs: r.dofs.clone(),
                reaction: r.reaction.clone(),
                applied: r.applied.clone(),
                force: r.force,
                moment: r.moment,
                balance_error: r.balance_error,
                solves: r.solves,
            })
            .collect(),
        strain_energy: record.strain_energy,
        kinetic_energy: record.kinetic_energy,
        friction_dissipation: record.friction_dissipation,
        kkt,
        solver,
        position_undetermined: false,
        vtu,
    }
}

/// The observer's error when the interrupt flag is seen.
#[derive(Debug, thiserror::Error)]
#[error("interrupted")]
struct Interrupted;

fn run_dim<const D: usize>(
    sc: &Scenario,
    out: Option<&Path>,
    options: &RunOptions,
    comm: &dyn Communicator,
    progress: &mut dyn FnMut(Progress),
) -> Result<RunReport, RunError> {
    let start = Instant::now();
    let built = build::<D>(sc)?;
    let name = built.name.clone();
    let mut warnings = built.warnings.clone();
    // initial penetration (refused by the run itself when the scenario says so)
    if let Ok(found) = built.joint.initial_penetration() {
        // (a refused one is the run's error, not a warning)
        warnings.extend(
            found
                .iter()
                .filter(|p| !built.joint.refuses_initial_penetration(&p.pair))
                .map(ToString::to_string),
        );
    }
    // bodies held only by contact, and the pairs that hold them (not in dynamic runs: the
    // mass holds them)
    let floating: Vec<String> = if built.analysis.kind() == "dynamic" {
        Vec::new()
    } else {
        synovia::fem::dofs::DofMap::new(built.joint.model())
            .map(|m| m.floating_components(built.joint.model()).into_iter().flat_map(|c| c.bodies).collect())
            .unwrap_or_default()
    };
    let holding: Vec<String> = built
        .joint
        .pairs()
        .iter()
        .filter(|p| {
            let body = |id: synovia::fem::BodyId| {
                built.joint.model().body(id).is_ok_and(|b| floating.contains(&b.name))
            };
            body(p.body) || p.partner_part().is_some_and(|(b, _)| body(b))
        })
        .map(|p| p.name.clone())
        .collect();
    for w in &warnings {
        tracing::warn!("{w}");
    }
    let configured_solver = built.joint.solver_name().to_string();
    let mut undetermined_steps = 0usize;
    let out_dir = match (out, &built.output.dir) {
        (Some(o), _) => o.to_path_buf(),
        (None, Some(d)) => d.clone(),
        (None, None) => PathBuf::from("out").join(&name),
    };
    let out_dir = match &options.sweep {
        Some(case) => out_dir.join(case.folder()),
        None => out_dir,
    };
    // only rank 0 writes (the other ranks of a distributed run compute the same results)
    let mut folder = match comm.rank() {
        0 => Some(OutDir::prepare(&out_dir, &sc.source.file, &name, options.force)?),
        _ => None,
    };
    let plan = built.output.clone();
    let n_steps = built.analysis.n_records();
    progress(Progress::Start { steps: n_steps });
    let mut writer: Option<QuasiStaticOutput<D>> = None;
    let mut steps: Vec<StepSummary> = Vec::with_capacity(n_steps);
    let mut records: Vec<StepRecord> = Vec::with_capacity(n_steps);
    let mut contact_nodes = 0;
    let mut first_step_at: Option<f64> = None;
    let mut interrupted = false;
    let kinematics = built.joint.kinematics().to_vec();
    let result = built.joint.run_on(comm, |view| {
        let index = steps.len();
        if first_step_at.is_none() {
            first_step_at = Some(start.elapsed().as_secs_f64() - view.record.step_s);
            contact_nodes = view.geometry.len();
        }
        let due = plan.vtu_every > 0 && (index % plan.vtu_every == 0 || index + 1 == view.n_steps);
        let vtu = if let (true, Some(folder)) = (due, folder.as_mut()) {
            if writer.is_none() {
                writer = Some(
                    QuasiStaticOutput::with_encoding(folder.dir(), &name, view.geometry, plan.encoding)?
                        .with_solid_fields(plan.stress)
                        .with_kinematics(kinematics.clone()),
                );
            }
            match writer.as_mut() {
                Some(w) => {
                    // the .vtu first, then the .pvd that lists it (both atomic), then the
                    // manifest that explains both
                    let file = file_name(&w.write_step(view.model, view.record, view.result)?);
                    folder.record(&file);
                    folder.record(&file_name(w.pvd_path()));
                    folder.write_manifest("running").map_err(|e| JointError::Observer(e.into()))?;
                    Some(file)
                }
                None => None,
            }
        } else if due {
            // the file rank 0 writes for this step (numbered by the files written before)
            let written = steps.iter().filter(|s| s.vtu.is_some()).count();
            Some(format!("{name}_{written:04}.vtu"))
        } else {
            None
        };
        let has_contact = !view.geometry.is_empty();
        let kkt = if has_contact { view.result.kkt.max() } else { 0.0 };
        let ran = if view.record.solver.is_empty() { &configured_solver } else { &view.record.solver };
        let mut summary = step_summary(view.record, vtu, kkt, ran.clone());
        summary.position_undetermined = !floating.is_empty()
            && summary.pairs.iter().filter(|p| holding.contains(&p.name)).all(|p| p.normal_force == 0.0);
        if summary.position_undetermined {
            undetermined_steps += 1;
        }
        steps.push(summary);
        records.push(view.record.clone());
        progress(Progress::Step { index, time: view.record.time });
        let stop = options.interrupt.as_ref().is_some_and(|f| f.load(Ordering::SeqCst));
        if stop && index + 1 < view.n_steps {
            interrupted = true;
            return Err(JointError::Observer(Box::new(Interrupted)));
        }
        Ok::<(), JointError>(())
    });
    let (solver, dofs, setup_s, total_s) = match result {
        Ok(r) => {
            records = r.records;
            contact_nodes = r.contact_nodes;
            (r.solver, r.n_dofs, r.setup_s, r.total_s)
        }
        Err(_) if interrupted => {
            let dofs = synovia::fem::dofs::DofMap::new(built.joint.model()).map_or(0, |m| m.n_dofs());
            let setup = first_step_at.unwrap_or(0.0).max(0.0);
            (built.joint.solver_name().to_string(), dofs, setup, start.elapsed().as_secs_f64())
        }
        Err(e) => {
            // keep the folder explained: what was written before the failure
            if let Some(folder) = &folder {
                let _ = folder.write_manifest("failed");
            }
            return Err(RunError::Failed(anyhow::Error::new(e)));
        }
    };
    if undetermined_steps > 0 {
        let w = format!(
            "bodies {} are held only by contact, and at {undetermined_steps} step(s) no contact force acts on them: their position there is undetermined (`position_undetermined` in summary.json)",
            floating.iter().map(|b| format!("`{b}`")).collect::<Vec<_>>().join(", ")
        );
        tracing::warn!("{w}");
        warnings.push(w);
    }
    let final_kkt = steps.last().map_or(0.0, |s| s.kkt);
    let csv = format!("{name}.csv");
    if let Some(folder) = folder.as_mut() {
        let csv_tmp = out_dir.join(format!("{csv}.tmp"));
        write_csv_with_units(&csv_tmp, &records, &built.units, D).map_err(anyhow::Error::new)?;
        std::fs::rename(&csv_tmp, out_dir.join(&csv)).map_err(|e| {
            let _ = std::fs::remove_file(&csv_tmp);
            anyhow::anyhow!("cannot write `{}`: {e}", out_dir.join(&csv).display())
        })?;
        folder.record(&csv);
    }
    let summary = Summary {
        scenario: sc.source.file.clone(),
        name: name.clone(),
        title: sc.doc.title.clone(),
        dimension: D,
        analysis: built.analysis.kind().to_string(),
        solver,
        dofs,
        contact_nodes,
        bodies: built
            .joint
            .model()
            .bodies()
            .iter()
            .map(|b| BodySummary { name: b.name.clone(), nodes: b.mesh.n_nodes(), cells: b.mesh.n_cells() })
            .collect(),
        pairs: built.joint.pairs().iter().map(|p| p.name.clone()).collect(),
        setup_s,
        total_s,
        files: FilesSummary {
            pvd: steps.iter().any(|s| s.vtu.is_some()).then(|| format!("{name}.pvd")),
            csv,
            vtu: steps.iter().filter(|s| s.vtu.is_some()).count(),
            manifest: MANIFEST.to_string(),
        },
        steps,
        interrupted,
        steps_planned: n_steps,
        final_kkt,
        warnings,
        units: UnitsSummary::of(&built.units, D),
        sweep: options.sweep.clone(),
    };
    if let Some(folder) = folder.as_mut() {
        let json = serde_json::to_string_pretty(&summary).map_err(anyhow::Error::new)?;
        folder.write(SUMMARY, (json + "\n").as_bytes())?;
        folder.write_manifest(if interrupted { "interrupted" } else { "complete" })?;
    }
    Ok(RunReport { summary, out_dir })
}
