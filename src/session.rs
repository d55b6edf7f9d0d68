//! Re-solving a prepared [`JointModel`] (navigation, interactive tools): factorise once, then
//! solve the same model again and again with new loads or prescribed displacements, each solve
//! warm-started from the previous contact state.
//!
//! [`JointModel::prepare`] validates the model, assembles and factorises the stiffness and
//! builds the contact geometry once, and returns a [`JointSession`]. The solves of a linear
//! model never refactorise:
//!
//! * [`JointSession::solve_static`]`(t)`: the static problem at `t` (step 0 of the quasi-static
//!   scheme, exactly what [`JointModel::run_static`] solves), warm-started from the last
//!   solution (`U`, `Λ_n`) instead of the cold start;
//! * [`JointSession::step`]`(t)`: one level of the quasi-static scheme
//!   ([`QuasiStaticStepper::step`]): Tresca friction with `g_c = F_c |Λ_n|` and the slip origin
//!   of the previous level, warm-started from it, so a sequence of `step` calls is
//!   [`JointModel::run_quasistatic`] one frame at a time.
//!
//! # Nonlinear models
//!
//! A model with a nonlinear material or finite strain ([`JointModel::is_nonlinear`]) gets a
//! session on the Newton iteration of [`NonlinearContact`] (docs/nonlinear.md): the symbolic
//! factorisation of the tangent and the contact set-up are done once, and each solve starts
//! from the last converged state (its displacement and, for [`JointSession::step`], its
//! friction state) instead of the reference configuration; the tangent is refactorised by the
//! Newton iteration as it needs ([`JointSession::factorizations`] counts them).
//!
//! * [`JointSession::solve_static`]`(t)`: the frictionless static problem at `t` (as
//!   [`JointModel::run_static`] solves it from the reference configuration), reached from the
//!   last solution's displacement: the same solution to the Newton tolerance where it is
//!   unique;
//! * [`JointSession::step`]`(t)`: one quasi-static level from the last one (Coulomb frozen to
//!   Tresca, friction laws, rigid bodies with mixed control as in
//!   [`JointModel::run_quasistatic`]), so a sequence of `step` calls is that run one frame at
//!   a time.
//!
//! # Changing loads between solves
//!
//! The model's loads and prescribed displacements are closures of `(x, t)` that are evaluated
//! at every solve, so there are two ways to give a solve new data without rebuilding anything:
//!
//! * **settable values**: build the model with [`SharedValue`] histories (or closures that read
//!   them, e.g. one per component of a tool position or of a [`RigidMotion`] translation), keep
//!   clones, and [`SharedValue::set`] new values before the next solve — the natural choice
//!   for a navigation tool whose inputs change from frame to frame;
//! * **time**: give the loads histories in `t` (e.g. a [`PiecewiseLinear`] table of recorded
//!   poses) and solve at the frame's time.
//!
//! Only the values may change: bodies, parts, the kind of condition on a part, and contact
//! pairs are fixed by the factorisation (the session borrows the model, so the borrow checker
//! enforces it); change them on the [`JointModel`] and prepare a new session.
//!
//! [`RigidMotion`]: synovia_time::history::RigidMotion
//! [`SharedValue`]: synovia_time::history::SharedValue
//! [`SharedValue::set`]: synovia_time::history::SharedValue::set
//! [`PiecewiseLinear`]: synovia_time::history::PiecewiseLinear

use std::time::Instant;

use synovia_contact::operators::ContactGeometry;
use synovia_contact::{ContactSolver, StaticContact, StaticContactResult};
use synovia_fem::{ElasticInfo, ElasticSolver, Model};
use synovia_mesh::math::{Real, Vector};
use synovia_nonlinear::NonlinearContact;
use synovia_time::quasistatic::QuasiStaticStepper;
use synovia_time::results::StepRecord;

use crate::builder::{JointError, JointModel};
use crate::rigid::{LevelMode, RigidDriver};

/// Figures of one solve of a [`JointSession`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveReport {
    /// Level of the quasi-static sequence: 0 for [`JointSession::solve_static`], +1 per
    /// [`JointSession::step`].
    pub step: usize,
    /// Time of the solve.
    pub time: Real,
    /// Contact solver iterations (with nested-iteration coarse iterations, the frictionless
    /// pre-solve and Coulomb fixed-point solves; 0 without contact pairs).
    pub iterations: usize,
    /// Wall time of the solve including its post-processing (records), s.
    pub seconds: f64,
    /// Whether the contact solve started from the previous solution (`false`: cold start by
    /// nested iteration, or no contact pairs).
    pub warm_started: bool,
    /// Largest KKT residual of the solution ([`KktReport::max`](synovia_contact::KktReport::max);
    /// 0 without contact pairs).
    pub kkt: Real,
}

/// A factorised [`JointModel`] that solves again with new loads, warm-started, without
/// refactorising (see the [module documentation](self) and [`JointModel::prepare`]).
pub struct JointSession<'a, const D: usize> {
    joint: &'a JointModel<D>,
    solver: Box<dyn ContactSolver>,
    engine: Engine<D>,
    /// The contact nodes of a session without contact pairs (none); with pairs the stepper's.
    no_geometry: ContactGeometry<D>,
    record: Option<StepRecord>,
    report: Option<SolveReport>,
    setup_s: f64,
    rigid: RigidDriver,
}

// one per session, so the size difference of the variants does not matter
#[allow(clippy::large_enum_variant)]
enum Engine<const D: usize> {
    Contact(Box<QuasiStaticStepper<D>>),
    Elastic {
        solver: Box<ElasticSolver<D>>,
        result: Option<StaticContactResult<D>>,
        step: usize,
    },
    /// A nonlinear model: the Newton iteration, the last converged level's contact solution
    /// and index, and the tangent factorisations of the solves so far.
    Nonlinear {
        nl: Box<NonlinearContact<D>>,
        result: Option<StaticContactResult<D>>,
        step: usize,
        factorisations: usize,
    },
}

impl<const D: usize> std::fmt::Debug for JointSession<'_, D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JointSession")
            .field("solver", &self.solver.name())
            .field("contact_nodes", &self.geometry().len())
            .field("report", &self.report)
            .finish_non_exhaustive()
    }
}

impl<'a, const D: usize> JointSession<'a, D> {
    pub(crate) fn new(joint: &'a JointModel<D>) -> Result<Self, JointError> {
        let start = Instant::now();
        let model = joint.model();
        model.validate()?;
        let solver = joint.build_solver()?;
        let (elastic_params, quasistatic_params, nested) = joint.session_params();
        let engine = if joint.is_nonlinear() {
            Engine::Nonlinear {
                nl: Box::new(joint.nonlinear_contact()?),
                result: None,
                step: 0,
                factorisations: 0,
            }
        } else if joint.pairs().is_empty() {
            Engine::Elastic {
                solver: Box::new(ElasticSolver::new(model, elastic_params)?),
                result: None,
                step: 0,
            }
        } else {
            let mut contact = StaticContact::with_interface_block(
                model,
                joint.pairs(),
                elastic_params,
                joint.interface_block_params(),
            )?;
            contact.set_nested_iteration(nested);
            contact.set_screening_band(joint.screening_band_value())?;
            let mut stepper = QuasiStaticStepper::from_contact(model, contact, quasistatic_params)?;
            for (pair, law) in joint.pair_friction_laws() {
                stepper.set_friction_law(pair, law.clone())?;
            }
            Engine::Contact(Box::new(stepper))
        };
        Ok(Self {
            joint,
            solver,
            engine,
            no_geometry: ContactGeometry::default(),
            record: None,
            report: None,
            setup_s: start.elapsed().as_secs_f64(),
            rigid: RigidDriver::new(joint),
        })
    }

    /// Solves the static problem at `t` with the model's current loads and prescribed
    /// displacements (step 0 of the quasi-static scheme, as [`JointModel::run_static`]: no
    /// friction, or with [`QuasiStaticParams::initial_friction`] a Tresca solve with `g_c` from
    /// the frictionless pressure), warm-started from the last solution if there is one. Starts
    /// a new quasi-static sequence (the next [`JointSession::step`] continues from this one).
    ///
    /// The result equals that of [`JointModel::run_static`] to the contact solver's
    /// tolerance.
    ///
    /// # Errors
    /// [`JointError::Invalid`] for a `t` that is not finite; contact solver failures
    /// ([`JointError::Time`]); the last solution is kept.
    ///
    /// [`QuasiStaticParams::initial_friction`]: synovia_time::quasistatic::QuasiStaticParams::initial_friction
    pub fn solve_static(&mut self, t: Real) -> Result<SolveReport, JointError> {
        let model = self.joint.model();
        match &mut self.engine {
            Engine::Contact(stepper) if !self.joint.rigid_bodies().is_empty() => {
                let warm = stepper.has_warm_start();
                let (record, result) = self.rigid.level(
                    self.joint,
                    stepper,
                    t,
                    self.solver.as_ref(),
                    LevelMode::Restart { warm: true },
                )?;
                let report = contact_report(&record, &result, warm);
                Ok(self.commit(record, report))
            }
            Engine::Contact(stepper) => {
                let warm = stepper.has_warm_start();
                let (record, result) = stepper.restart(model, t, self.solver.as_ref(), true)?;
                let report = contact_report(&record, result, warm);
                Ok(self.commit(record, report))
            }
            Engine::Elastic { .. } => self.elastic(t, true),
            Engine::Nonlinear { .. } => self.nonlinear(t, true),
        }
    }

    /// One level of the quasi-static scheme at `t` ([`QuasiStaticStepper::step`]): the Tresca
    /// problem with `g_c` and the slip origin of the last solution, warm-started from it (with
    /// no last solution: the static problem at `t`, cold-started). `t` must be later than the
    /// last solution's time. A sequence `step(t_0)`, `step(t_1)`, … solves what
    /// [`JointModel::run_quasistatic`] solves for `[t_0, t_1, …]`.
    ///
    /// # Errors
    /// [`JointError::Time`] for a `t` that is not finite or not later than the last solve, and
    /// for contact solver failures; the last solution is kept.
    pub fn step(&mut self, t: Real) -> Result<SolveReport, JointError> {
        let model = self.joint.model();
        match &mut self.engine {
            Engine::Contact(stepper) if !self.joint.rigid_bodies().is_empty() => {
                if let Some(last) = stepper.last_time().filter(|&l| t <= l) {
                    return Err(JointError::Invalid(format!(
                        "time {t} must be later than the last solve's time {last}"
                    )));
                }
                let warm = stepper.last_result().is_some();
                let mode = if warm { LevelMode::Step } else { LevelMode::Restart { warm: false } };
                let (record, result) =
                    self.rigid.level(self.joint, stepper, t, self.solver.as_ref(), mode)?;
                let report = contact_report(&record, &result, warm);
                Ok(self.commit(record, report))
            }
            Engine::Contact(stepper) => {
                let warm = stepper.last_result().is_some();
                let (record, result) = stepper.step(model, t, self.solver.as_ref())?;
                let report = contact_report(&record, result, warm);
                Ok(self.commit(record, report))
            }
            Engine::Elastic { .. } | Engine::Nonlinear { .. } => {
                if let Some(last) = self.report.filter(|r| t <= r.time) {
                    return Err(JointError::Invalid(format!(
                        "time {t} must be later than the last solve's time {}",
                        last.time
                    )));
                }
                if matches!(self.engine, Engine::Nonlinear { .. }) {
                    self.nonlinear(t, false)
                } else {
                    self.elastic(t, false)
                }
            }
        }
    }

    /// Forgets the last solution and the friction state (the next solve is cold-started); the
    /// factorisation is kept.
    pub fn reset(&mut self) {
        self.rigid.reset(self.joint);
        match &mut self.engine {
            Engine::Contact(stepper) => stepper.reset(),
            Engine::Elastic { result, step, .. } => {
                *result = None;
                *step = 0;
            }
            Engine::Nonlinear { nl, result, step, .. } => {
                nl.reset(0.0);
                *result = None;
                *step = 0;
            }
        }
        self.record = None;
        self.report = None;
    }

    fn elastic(&mut self, t: Real, restart: bool) -> Result<SolveReport, JointError> {
        if !t.is_finite() {
            return Err(JointError::Invalid(format!("time {t} is not finite")));
        }
        let start = Instant::now();
        let model = self.joint.model();
        let Engine::Elastic { solver, result, step } = &mut self.engine else {
            return Err(JointError::Invalid("not an elastic session".into()));
        };
        let level = if restart || result.is_none() { 0 } else { *step + 1 };
        let sol = solver.solve(model, t)?;
        let strain_energy = synovia_fem::post::total_strain_energy(model, &sol.displacement)?;
        let record = StepRecord {
            step: level,
            time: t,
            strain_energy,
            step_s: start.elapsed().as_secs_f64(),
            ..Default::default()
        };
        *result = Some(crate::builder::zero_result(sol.displacement, 0));
        *step = level;
        let report = SolveReport {
            step: level,
            time: t,
            iterations: 0,
            seconds: record.step_s,
            warm_started: false,
            kkt: 0.0,
        };
        Ok(self.commit(record, report))
    }

    /// A level of a nonlinear model at `t`: `restart` the frictionless static problem from the
    /// last solution's displacement (its multipliers and friction state dropped), else the next
    /// quasi-static level from the last one; with no last solution from the reference
    /// configuration at `min(t, 0)` (as [`JointModel::run_quasistatic`]). On failure the last
    /// converged state is restored.
    fn nonlinear(&mut self, t: Real, restart: bool) -> Result<SolveReport, JointError> {
        if !t.is_finite() {
            return Err(JointError::Invalid(format!("time {t} is not finite")));
        }
        let start = Instant::now();
        let joint = self.joint;
        let driver = if joint.rigid_bodies().is_empty() { None } else { Some(&mut self.rigid) };
        let Engine::Nonlinear { nl, result, step, factorisations } = &mut self.engine else {
            return Err(JointError::Invalid("not a nonlinear session".into()));
        };
        let warm = result.is_some();
        let checkpoint = nl.checkpoint();
        let level_index = match (warm, restart) {
            (true, true) => {
                let reduced = nl.reduced().to_vec();
                nl.set_state(nl.time(), &reduced)?;
                0
            }
            (true, false) => *step + 1,
            (false, _) => {
                nl.reset(t.min(0.0));
                0
            }
        };
        let (record, level) = match joint.nonlinear_level(nl, driver, level_index, t, self.solver.as_ref()) {
            Ok(solved) => solved,
            Err(e) => {
                nl.restore(checkpoint)?;
                return Err(e);
            }
        };
        *factorisations += level.report.factorisations;
        let record = StepRecord { step_s: start.elapsed().as_secs_f64(), ..record };
        let report = contact_report(&record, &level.contact, warm);
        *result = Some(level.contact);
        *step = level_index;
        Ok(self.commit(record, report))
    }

    fn commit(&mut self, record: StepRecord, report: SolveReport) -> SolveReport {
        self.record = Some(record);
        self.report = Some(report);
        report
    }

    /// The contact solution of the last solve (nodal displacements, `Λ_n` per contact node,
    /// friction cells, KKT residuals; without contact pairs only the displacements), `None`
    /// before the first solve and after [`JointSession::reset`].
    pub fn result(&self) -> Option<&StaticContactResult<D>> {
        match &self.engine {
            Engine::Contact(stepper) => stepper.last_result(),
            Engine::Elastic { result, .. } | Engine::Nonlinear { result, .. } => result.as_ref(),
        }
    }
    /// Nodal displacements per body of the last solve.
    pub fn displacement(&self) -> Option<&[Vec<Vector<D>>]> {
        self.result().map(|r| r.displacement.as_slice())
    }
    /// The record of the last solve (pair forces and areas, energies, iterations, time).
    pub fn record(&self) -> Option<&StepRecord> {
        self.record.as_ref()
    }
    /// The figures of the last solve.
    pub fn report(&self) -> Option<SolveReport> {
        self.report
    }
    /// The model.
    pub fn model(&self) -> &Model<D> {
        self.joint.model()
    }
    /// The kinematics of the bodies (small strain, or finite strain for the stresses and
    /// strains of a nonlinear model's solution: [`JointModel::kinematics`]).
    pub fn kinematics(&self) -> &[synovia_fem::Kinematics] {
        self.joint.kinematics()
    }
    /// The contact nodes (empty without contact pairs): those of the last solve, rebuilt at
    /// every pose of a posed rigid partner — after a solve that failed, those of the pose it
    /// failed at (the nodes are the same at every pose, their normals and gaps are the pose's),
    /// while [`JointSession::result`] keeps the last solution.
    pub fn geometry(&self) -> &ContactGeometry<D> {
        match &self.engine {
            Engine::Contact(stepper) => stepper.geometry(),
            Engine::Elastic { .. } => &self.no_geometry,
            Engine::Nonlinear { nl, .. } => nl.geometry(),
        }
    }
    /// The contact solver's name.
    pub fn solver_name(&self) -> &str {
        self.solver.name()
    }
    /// The factorisation's figures (unknowns, factor size, symbolic and numeric times); they
    /// do not change over the session's solves.
    pub fn elastic_info(&self) -> ElasticInfo {
        match &self.engine {
            Engine::Contact(stepper) => stepper.contact().elastic().info(),
            Engine::Elastic { solver, .. } => solver.info(),
            Engine::Nonlinear { nl, .. } => nl.contact().elastic().info(),
        }
    }
    /// Number of numeric factorisations the session has done: for a linear model always 1 (of
    /// the stiffness, in [`JointModel::prepare`]; solves reuse it); for a nonlinear model the
    /// tangent factorisations of the Newton iterations of all solves so far.
    pub fn factorizations(&self) -> usize {
        match &self.engine {
            Engine::Nonlinear { factorisations, .. } => *factorisations,
            _ => 1,
        }
    }
    /// Set-up time of [`JointModel::prepare`] (validation, assembly, factorisation, contact
    /// geometry), s.
    pub fn setup_s(&self) -> f64 {
        self.setup_s
    }
    /// Bytes held now by the caches the contact solves reuse (kept columns of the interface
    /// operator and row solves, [`SolveContext::bytes`]); bounded by
    /// [`SolveContext::memory_budget`], and constant once a periodic loading has visited its
    /// states — the figure to watch in a long navigation loop. 0 without contact pairs.
    ///
    /// [`SolveContext::bytes`]: synovia_contact::SolveContext::bytes
    /// [`SolveContext::memory_budget`]: synovia_contact::SolveContext::memory_budget
    pub fn cache_bytes(&self) -> usize {
        match &self.engine {
            Engine::Contact(stepper) => stepper.contact().context().bytes(),
            Engine::Nonlinear { nl, .. } => nl.contact().context().bytes(),
            Engine::Elastic { .. } => 0,
        }
    }
}

fn contact_report<const D: usize>(
    record: &StepRecord,
    result: &StaticContactResult<D>,
    warm_started: bool,
) -> SolveReport {
    SolveReport {
        step: record.step,
        time: record.time,
        iterations: record.iterations,
        seconds: record.step_s,
        warm_started,
        kkt: result.kkt.max(),
    }
}
