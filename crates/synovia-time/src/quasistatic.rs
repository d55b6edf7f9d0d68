//! Quasi-static time stepping (docs/model.md §7, Part I of the report): inertia is neglected and every
//! time level `t_i` is a static contact problem with Tresca friction whose slip bound is frozen
//! from the previous level (docs/model.md §3).
//!
//! # The scheme
//!
//! For the times `t_0 < t_1 < … < t_m` ([`QuasiStaticStepper::run`]):
//!
//! * **Step 0** (the initial state `u₀`, docs/model.md §7): the frictionless contact problem at `t_0`
//!   (loads `F(t_0)`, `P(t_0)`, prescribed `u₂(t_0)`). With
//!   [`QuasiStaticParams::initial_friction`] it is followed by a Tresca solve at `t_0` with
//!   `g_c = F_c |λ_n|` of that frictionless pre-solve and slip measured from the reference
//!   (undeformed) state, i.e. friction acting while the initial load is applied in one step.
//! * **Step i ≥ 1**: the Tresca problem of docs/model.md §5 at `t_i`,
//!
//!   ```text
//!   A U + B_hnᵀ diag(κ) Λ_n + B_Htᵀ Λ_t − F(t_i) = 0
//!   Λ_n − (Λ_n + ρ (B_hn U − d(t_i)))⁺         = 0
//!   Λ_t − π(Λ_t + ρ B_Ht (U − U(t_{i−1})))     = 0
//!   ```
//!
//!   with `B_Ht` built on the cells of `supp g_c`, `g_c,r = F_c(v_r) |Λ_n,r(t_{i−1})|`
//!   (docs/model.md §3, `r = 1`) with the friction law `F_c` of the pair
//!   ([`QuasiStaticStepper::set_friction_law`], default its constant coefficient, then exactly
//!   [`ContactGeometry::slip_bounds_from_pressure`] of the previous level) and the slip rate
//!   `v_r = ‖Δ[u_t]_r‖ / Δt` of the previous level ([`QuasiStaticStepper::slip_rate`]),
//!   and slip measured from the previous level `U(t_{i−1})` (incremental slip, docs/model.md §3; with
//!   [`QuasiStaticParams::incremental_slip`] `= false` the report's total-displacement form
//!   `Λ_t − π(Λ_t + ρ B_Ht U)` is used instead, slip measured from the reference state).
//!   The solve is warm-started from the previous level: `U` and `Λ_n` (the normal rows are the
//!   same at every level) are copied, and `Λ_t` is mapped cell by cell through the contact
//!   node of each cell ([`StaticContactResult::cell_node`]), since the friction cells
//!   `supp g_c` change from level to level; new cells start from `Λ_t = 0`.
//! * **Coulomb fixed point** ([`QuasiStaticParams::coulomb_fixed_point`], docs/model.md §3): the level
//!   is re-solved with `g_c^{k+1} = F_c(v^k) |Λ_n^k|` (pressure and slip rate of the current iterate) until
//!   `max_r |g^{k+1}_r − g^k_r| / max_r |g^{k+1}_r| ≤ fixed_point_tolerance`; the accepted
//!   solution is the last one (computed with `g^k`). After `max_fixed_point` solves without
//!   convergence the run stops with [`TimeError::FixedPoint`].
//!
//! * **Bodies held by friction** (docs/model.md §7.1, (7.2a)–(7.2b)): for a model with bodies
//!   that only contact holds, a level whose Tresca solve fails (the bound frozen from `t_{i−1}`
//!   cannot hold the load at `t_i`), and a step 0 whose frictionless problem is unbalanced
//!   while the pairs have friction, are solved as the Coulomb fixed point at that level,
//!   started from the normal problem with the unbalanced rigid-body load withheld
//!   ([`synovia_contact::floating::withhold_unbalanced`]). When the tangential load exceeds the
//!   Coulomb capacity `μ·P` the run stops with [`TimeError::Slides`] (both forces given).
//!
//! The factorisation of `A` is done once, in [`QuasiStaticStepper::new`], and reused at every
//! level and fixed-point iteration (docs/model.md §7).
//!
//! # One level at a time
//!
//! [`QuasiStaticStepper::step`] advances the scheme by one level (step 0 if no sequence is
//! under way) and keeps the friction state (`Λ_n` for `g_c`, the slip origin, the warm start)
//! for the next call; [`QuasiStaticStepper::run`] is `step` over a list of times, so both give
//! the same results. [`QuasiStaticStepper::restart`] starts a new sequence with step 0 at a
//! given time, optionally warm-started from the last solution (re-solve with new loads, e.g.
//! `synovia::session::JointSession`), and [`QuasiStaticStepper::reset`] forgets the sequence.
//!
//! # Re-pairing at every level (sliding contact)
//!
//! With [`QuasiStaticStepper::set_repairing`] the contact geometry is rebuilt before every level
//! `i ≥ 1` from the configuration `x + u(t_{i−1})` of the previous level
//! ([`StaticContact::update_geometry`], [`ContactGeometry::new_deformed`]): node-to-segment
//! pairs are re-projected onto the master facets, normals, tangents and weights are those of
//! that configuration (small-deformation kinematics per pose). The contact state of level
//! `i − 1` is carried to the new pairing node by node ([`transfer_result`]: `Λ_n` and the
//! friction cells of the slave nodes that stay in their pair; new nodes start from 0), so
//! `g_c = F_c |Λ_n(t_{i−1})|` and the warm start are defined on the new rows. Slip stays
//! incremental: `B_Ht` of the new pairing applied to `U − U(t_{i−1})`, the relative tangential
//! displacement of a slave node and the master point it is over now.
//!
//! # Per-step figures ([`StepRecord`])
//!
//! * pair resultants, areas, pressures, stick/slip areas: [`pair_records`];
//! * friction dissipation of step `i`: the discrete friction functional of the slip increment,
//!   `D_i = Σ_c g_c κ_c ‖T_cᵀ([u](s_c, t_i) − [u](s_c, t_{i−1}))‖` over the friction cells `c`
//!   of the step (`T_c` the tangent basis, `[u] = u^k − u^l` or `u^k` for a rigid obstacle);
//!   this is `Σ_c ‖(B_Ht (U_i − U_{i−1}))_c‖ = Λ_t · B_Ht ΔU`, the work of the friction
//!   forces on the slip increment, ≥ 0. It is always measured on the increment (also with
//!   total-displacement slip), and for step 0 from the reference state;
//! * strain energy: the full `½ ∫ C e(u) : e(u) dx` summed over the bodies
//!   ([`synovia_fem::post::body_fields`]), including the part due to the lifts of prescribed
//!   displacements (the reduced `½ Ũᵀ K̃ Ũ` would miss it);
//! * iterations: contact solver iterations (plus nested-iteration coarse iterations) summed
//!   over the pre-solve and the Coulomb fixed-point iterations; the wall time of the step.
//!
//! # Output
//!
//! [`QuasiStaticOutput`] writes a ParaView time series (`DIR/NAME.pvd` + one `.vtu` per step,
//! one piece per body with the displacement, contact pressure, friction traction, stick flag
//! and von Mises stress) and the records as CSV ([`crate::results::write_csv`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use synovia_contact::operators::{ContactGeometry, ContactPair};
use synovia_contact::{
    slip_speeds, ContactError, ContactSolution, ContactSolver, FrictionLaw, PairFrictionLaws, StaticContact,
    StaticContactResult,
};

use synovia_fem::{BodyId, ElasticParams, Model};
use synovia_io::{Encoding, Field, TimeSeriesWriter, VtuWriter};
use synovia_mesh::math::{Real, Vector};

use crate::error::TimeError;
use crate::results::{pair_records, write_csv_with_units, StepRecord, Units};

/// Parameters of the quasi-static stepper.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct QuasiStaticParams {
    /// Re-solve each level with `g_c = F_c |Λ_n|` of the current iterate until `g_c` stops
    /// changing (true Coulomb friction, docs/model.md §3). Default `false` (Tresca with `g_c` frozen
    /// from the previous level).
    pub coulomb_fixed_point: bool,
    /// Maximum contact solves per level in the Coulomb fixed point (default 50, ≥ 1).
    pub max_fixed_point: usize,
    /// Stopping tolerance of the fixed point on the relative change
    /// `max |Δg_c| / max |g_c|` (default `1e-8`, > 0).
    pub fixed_point_tolerance: Real,
    /// Slip measured from the previous level (default `true`, docs/model.md §3); `false`: the report's
    /// total-displacement form, slip measured from the reference state.
    pub incremental_slip: bool,
    /// Step 0 with friction: after the frictionless solve at `t_0`, solve the Tresca problem at
    /// `t_0` with `g_c` from it (slip from the reference state). Default `false` (step 0 is
    /// frictionless).
    pub initial_friction: bool,
}

impl Default for QuasiStaticParams {
    fn default() -> Self {
        Self {
            coulomb_fixed_point: false,
            max_fixed_point: 50,
            fixed_point_tolerance: 1e-8,
            incremental_slip: true,
            initial_friction: false,
        }
    }
}

impl QuasiStaticParams {
    /// Sets [`Self::coulomb_fixed_point`].
    pub fn with_coulomb_fixed_point(mut self, coulomb_fixed_point: bool) -> Self {
        self.coulomb_fixed_point = coulomb_fixed_point;
        self
    }
    /// Sets [`Self::max_fixed_point`].
    pub fn with_max_fixed_point(mut self, max_fixed_point: usize) -> Self {
        self.max_fixed_point = max_fixed_point;
        self
    }
    /// Sets [`Self::fixed_point_tolerance`].
    pub fn with_fixed_point_tolerance(mut self, fixed_point_tolerance: Real) -> Self {
        self.fixed_point_tolerance = fixed_point_tolerance;
        self
    }
    /// Sets [`Self::incremental_slip`].
    pub fn with_incremental_slip(mut self, incremental_slip: bool) -> Self {
        self.incremental_slip = incremental_slip;
        self
    }
    /// Sets [`Self::initial_friction`].
    pub fn with_initial_friction(mut self, initial_friction: bool) -> Self {
        self.initial_friction = initial_friction;
        self
    }
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] if `max_fixed_point = 0` or the tolerance is not finite
    /// and positive.
    pub fn validate(&self) -> Result<(), TimeError> {
        if self.max_fixed_point == 0 {
            return Err(TimeError::InvalidParameter("max_fixed_point must be ≥ 1".into()));
        }
        if !(self.fixed_point_tolerance.is_finite() && self.fixed_point_tolerance > 0.0) {
            return Err(TimeError::InvalidParameter(format!(
                "fixed_point_tolerance must be finite and > 0, got {}",
                self.fixed_point_tolerance
            )));
        }
        Ok(())
    }
}

/// A saved state of a [`QuasiStaticStepper`] sequence ([`QuasiStaticStepper::checkpoint`]).
#[derive(Debug, Clone)]
pub struct StepperCheckpoint<const D: usize> {
    last: Option<StaticContactResult<D>>,
    slip_rate: Vec<Real>,
    next_step: usize,
    last_time: Option<Real>,
    cumulative: Real,
}

/// The quasi-static stepper of docs/model.md §7: owns a [`StaticContact`] (one factorisation of `A`,
/// reused at every level) and solves one Tresca contact problem per time level with `g_c`
/// frozen from the previous level (see the [module documentation](self)).
#[derive(Debug)]
pub struct QuasiStaticStepper<const D: usize> {
    contact: StaticContact<D>,
    params: QuasiStaticParams,
    body_nodes: Vec<usize>,
    last: Option<StaticContactResult<D>>,
    repair: Option<Vec<ContactPair<D>>>,
    /// Index of the next level of the current sequence (0: none solved yet).
    next_step: usize,
    /// Time of the last level of the current sequence.
    last_time: Option<Real>,
    /// Friction dissipation summed over the current sequence.
    cumulative: Real,
    /// The friction law `F_c` of every pair (default: its constant coefficient).
    laws: PairFrictionLaws,
    /// Slip rate `|[u'_t]|` per contact node of the last level (0 at step 0).
    slip_rate: Vec<Real>,
    /// Whether each level's record carries the strain energy (an element loop per level).
    record_strain_energy: bool,
}

impl<const D: usize> QuasiStaticStepper<D> {
    /// Factorises `model` and builds the contact geometry of `pairs` (friction coefficients
    /// `F_c` from [`ContactPair::friction`]).
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for invalid `params`; [`TimeError::ContactSetup`] from
    /// [`StaticContact::new`] (invalid pairs, semi-coercive model, …).
    pub fn new(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        elastic: ElasticParams,
        params: QuasiStaticParams,
    ) -> Result<Self, TimeError> {
        params.validate()?;
        let contact = StaticContact::new(model, pairs, elastic)?;
        Ok(Self::assemble(contact, params, body_nodes(model)))
    }

    /// Wraps an existing [`StaticContact`] of `model` (e.g. with nested iteration switched off).
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for invalid `params`.
    pub fn from_contact(
        model: &Model<D>,
        contact: StaticContact<D>,
        params: QuasiStaticParams,
    ) -> Result<Self, TimeError> {
        params.validate()?;
        Ok(Self::assemble(contact, params, body_nodes(model)))
    }

    /// Replaces the friction law `F_c(|[u'_t]|)` of the contact pair `pair` (docs/model.md §3;
    /// default: the pair's constant coefficient [`ContactPair::friction`]); the same as
    /// [`crate::dynamic::DynamicStepper::set_friction_law`]. The slip bounds of level `i` are
    /// `g_c,r = F_c(v_r) |Λ_n,r|` with the pressure and the slip rate
    /// `v_r = ‖[u_t](s_r, t_{i−1}) − [u_t](s_r, t_{i−2})‖ / (t_{i−1} − t_{i−2})` of level `i − 1`
    /// (0 for level 0); with the Coulomb fixed point, both from the current iterate of level `i`
    /// (slip rate over `[t_{i−1}, t_i]`). A law set on a pair built frictionless gives it friction.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for an unknown pair name.
    pub fn set_friction_law(&mut self, pair: &str, law: Arc<dyn FrictionLaw>) -> Result<(), TimeError> {
        self.laws.set(pair, law).map_err(|e| TimeError::InvalidParameter(e.to_string()))
    }

    /// The friction laws of the pairs.
    pub fn friction_laws(&self) -> &PairFrictionLaws {
        &self.laws
    }

    /// Slip rate `|[u'_t]|` per contact node of the last level solved (see
    /// [`QuasiStaticStepper::set_friction_law`]; 0 at step 0).
    pub fn slip_rate(&self) -> &[Real] {
        &self.slip_rate
    }

    /// Re-pair every level `i ≥ 1` from the configuration of level `i − 1` with the contact
    /// pairs `pairs` (the pairs the stepper was built with; see the
    /// [module documentation](self)), or (`None`) keep the geometry fixed (default).
    pub fn set_repairing(&mut self, pairs: Option<&[ContactPair<D>]>) {
        self.repair = pairs.map(<[ContactPair<D>]>::to_vec);
    }

    /// The static contact problem (factorisation, geometry).
    pub fn contact(&self) -> &StaticContact<D> {
        &self.contact
    }
    /// Mutable access to the static contact problem (e.g. [`StaticContact::set_nested_iteration`]).
    pub fn contact_mut(&mut self) -> &mut StaticContact<D> {
        &mut self.contact
    }
    /// The contact nodes (with re-pairing: of the last level solved).
    pub fn geometry(&self) -> &ContactGeometry<D> {
        self.contact.geometry()
    }
    /// The parameters.
    pub fn params(&self) -> &QuasiStaticParams {
        &self.params
    }
    /// Changes the parameters.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for invalid `params` (the old ones are kept).
    pub fn set_params(&mut self, params: QuasiStaticParams) -> Result<(), TimeError> {
        params.validate()?;
        self.params = params;
        Ok(())
    }
    /// The contact solution of the last level solved ([`QuasiStaticStepper::step`],
    /// [`QuasiStaticStepper::restart`], or the last level of [`QuasiStaticStepper::run`]);
    /// `None` before any level, after [`QuasiStaticStepper::reset`] and after a run that failed.
    pub fn last_result(&self) -> Option<&StaticContactResult<D>> {
        self.last.as_ref()
    }
    /// Time of the last level of the current sequence (`None` if none was solved).
    pub fn last_time(&self) -> Option<Real> {
        self.last_time
    }
    /// Index of the level that the next [`QuasiStaticStepper::step`] solves (0: the initial
    /// state).
    pub fn next_step(&self) -> usize {
        self.next_step
    }

    /// Forgets the current sequence (friction state, last solution, cumulative dissipation):
    /// the next [`QuasiStaticStepper::step`] solves the initial state (step 0). The
    /// factorisation and the contact geometry (with re-pairing: of the last level) are kept.
    pub fn reset(&mut self) {
        self.last = None;
        self.next_step = 0;
        self.last_time = None;
        self.cumulative = 0.0;
    }

    /// Whether [`QuasiStaticStepper::restart`] with `warm = true` would be warm-started: there
    /// is a last solution and it fits the current contact geometry.
    pub fn has_warm_start(&self) -> bool {
        self.last.as_ref().is_some_and(|r| r.solution.lambda_n.len() == self.contact.geometry().len())
    }

    /// Advances the scheme by one time level to `t` (see the [module documentation](self)):
    /// without a current sequence (new stepper, after [`QuasiStaticStepper::reset`] or a failed
    /// run) the initial state at `t` (step 0), otherwise the Tresca problem at `t` with `g_c`
    /// and the slip origin of the last level, warm-started from it (with re-pairing: after
    /// rebuilding the geometry from the last level's configuration). Returns the level's
    /// record and contact solution (also [`QuasiStaticStepper::last_result`]).
    ///
    /// [`QuasiStaticStepper::run`] is this method called for every time level, so stepping
    /// one level at a time gives the same records and solutions as one run.
    ///
    /// If the solve fails, the sequence keeps its last level (with re-pairing: carried to the
    /// rebuilt geometry), so the step can be retried, e.g. with other loads.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for a `t` that is not finite or not later than the last
    /// level, or a `model` whose bodies differ from the one the stepper was built with;
    /// [`TimeError::Contact`] (with the step and time) when a contact solve fails;
    /// [`TimeError::FixedPoint`] when the Coulomb fixed point does not converge;
    /// [`TimeError::Fem`] from the post-processing.
    pub fn step(
        &mut self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
    ) -> Result<(StepRecord, &StaticContactResult<D>), TimeError> {
        self.check_model(model)?;
        if !t.is_finite() {
            return Err(TimeError::InvalidParameter(format!("time level {} is {t}", self.next_step)));
        }
        if let Some(last) = self.last_time.filter(|&l| t <= l) {
            return Err(TimeError::InvalidParameter(format!(
                "time levels must increase strictly: t_{} = {t} ≤ t_{} = {last}",
                self.next_step,
                self.next_step.saturating_sub(1)
            )));
        }
        self.level(model, t, solver, None)
    }

    /// Starts a new sequence with the initial state at `t` (step 0, as the first level of
    /// [`QuasiStaticStepper::run`]); with `warm = true` its frictionless solve is warm-started
    /// from the last solution (`U`, `Λ_n`; see [`QuasiStaticStepper::has_warm_start`])
    /// instead of the cold start (nested iteration) — the re-solve of the same model with new
    /// loads or prescribed displacements. The factorisation is reused. If the solve fails, the
    /// previous sequence is kept.
    ///
    /// # Errors
    /// As [`QuasiStaticStepper::step`] (any finite `t` is accepted).
    pub fn restart(
        &mut self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        warm: bool,
    ) -> Result<(StepRecord, &StaticContactResult<D>), TimeError> {
        self.check_model(model)?;
        if !t.is_finite() {
            return Err(TimeError::InvalidParameter(format!("time level 0 is {t}")));
        }
        let warm = match &self.last {
            Some(last) if warm && self.has_warm_start() => {
                let none = vec![0.0; self.contact.geometry().len()];
                Some(warm_start(self.contact.geometry(), last, &none))
            }
            _ => None,
        };
        self.level(model, t, solver, Some(warm))
    }

    /// Whether the records of the following levels carry the strain energy (default `true`;
    /// [`StaticContact::strain_energy`]: `½ Uᵀ A U` when no prescribed displacement is
    /// non-zero, else an element loop per level, as costly as a contact solve on a large
    /// model); trial solves whose records are discarded (force control, docs/model.md §10)
    /// switch it off and compute it once for the accepted level. Off, a record's
    /// `strain_energy` is `0`.
    pub fn set_record_strain_energy(&mut self, on: bool) {
        self.record_strain_energy = on;
    }

    /// The state of the sequence (last level's solution, slip rates, step counter, time,
    /// dissipation), to try a level and go back ([`QuasiStaticStepper::rollback`]): e.g. the
    /// trial solves of a force-controlled rigid body, each from the same previous level.
    pub fn checkpoint(&self) -> StepperCheckpoint<D> {
        StepperCheckpoint {
            last: self.last.clone(),
            slip_rate: self.slip_rate.clone(),
            next_step: self.next_step,
            last_time: self.last_time,
            cumulative: self.cumulative,
        }
    }

    /// Returns to a [`QuasiStaticStepper::checkpoint`] (the factorisation and the contact
    /// geometry are not part of it).
    pub fn rollback(&mut self, checkpoint: StepperCheckpoint<D>) {
        self.last = checkpoint.last;
        self.slip_rate = checkpoint.slip_rate;
        self.next_step = checkpoint.next_step;
        self.last_time = checkpoint.last_time;
        self.cumulative = checkpoint.cumulative;
    }

    /// Runs the levels `times` (finite, strictly increasing, at least one): step 0 is the
    /// initial state at `times[0]`, step `i` the Tresca problem at `times[i]` with `g_c` and
    /// the slip origin from step `i − 1` (see the [module documentation](self)). Starts a new
    /// sequence ([`QuasiStaticStepper::reset`]) and calls [`QuasiStaticStepper::step`] for
    /// every level.
    ///
    /// `observer` is called after every level with its record and contact solution (write
    /// output, check KKT, collect figures…); an error from it stops the run and is returned.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for bad `times` or a `model` whose bodies differ from
    /// the one the stepper was built with; [`TimeError::Contact`] (with the step and time) when
    /// a contact solve fails; [`TimeError::FixedPoint`] when the Coulomb fixed point does not
    /// converge; [`TimeError::Fem`] from the post-processing; whatever `observer` returns.
    pub fn run(
        &mut self,
        model: &Model<D>,
        times: &[Real],
        solver: &dyn ContactSolver,
        mut observer: impl FnMut(&StepRecord, &StaticContactResult<D>) -> Result<(), TimeError>,
    ) -> Result<Vec<StepRecord>, TimeError> {
        self.check_model(model)?;
        check_times(times)?;
        self.reset();
        let mut records: Vec<StepRecord> = Vec::with_capacity(times.len());
        for &t in times {
            let outcome = match self.step(model, t, solver) {
                Ok((record, result)) => observer(&record, result).map(|()| record),
                Err(e) => Err(e),
            };
            match outcome {
                Ok(record) => records.push(record),
                Err(e) => {
                    self.reset();
                    return Err(e);
                }
            }
        }
        Ok(records)
    }

    fn assemble(contact: StaticContact<D>, params: QuasiStaticParams, body_nodes: Vec<usize>) -> Self {
        let laws = PairFrictionLaws::new(contact.geometry());
        let slip_rate = vec![0.0; contact.geometry().len()];
        Self {
            laws,
            slip_rate,
            contact,
            params,
            body_nodes,
            last: None,
            repair: None,
            next_step: 0,
            last_time: None,
            cumulative: 0.0,
            record_strain_energy: true,
        }
    }

    /// One level at `t`: the next level of the current sequence (`restart = None`; step 0 if
    /// there is none), or step 0 of a new sequence warm-started from the given solution
    /// (`restart = Some(warm)`). Commits the state only on success.
    #[tracing::instrument(level = "debug", skip_all)]
    fn level(
        &mut self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        restart: Option<Option<ContactSolution>>,
    ) -> Result<(StepRecord, &StaticContactResult<D>), TimeError> {
        let start = Instant::now();
        let (step, base, initial_warm) = match restart {
            Some(warm) => (0, 0.0, warm),
            None => (self.next_step, self.cumulative, None),
        };
        if step > 0 {
            if let (Some(pairs), Some(prev)) = (&self.repair, self.last.as_mut()) {
                let old = self
                    .contact
                    .update_geometry(model, pairs, &prev.displacement)
                    .map_err(|source| TimeError::Contact { step, time: t, source })?;
                *prev = transfer_result(&old, self.contact.geometry(), prev);
                self.slip_rate = self.contact.geometry().transfer(&old, &self.slip_rate);
            }
        }
        let previous = if step > 0 { self.last.as_ref() } else { None };
        let dt = self.last_time.map_or(0.0, |l| t - l);
        let (result, iterations) = match previous {
            None => self.initial(model, t, solver, initial_warm.as_ref())?,
            Some(prev) => {
                let g =
                    self.laws.slip_bounds(self.contact.geometry(), &prev.solution.lambda_n, &self.slip_rate);
                let origin = self.params.incremental_slip.then_some(prev.displacement.as_slice());
                let rate_from = Some((prev.displacement.as_slice(), dt));
                match self.tresca_level(model, step, t, solver, g, origin, rate_from, Some(prev)) {
                    Ok(solved) => solved,
                    // the bound frozen from t_{i−1} cannot hold the load at t_i: Coulomb at t_i
                    Err(e) if self.held_by_friction(&e) => {
                        let none = vec![0.0; self.contact.geometry().len()];
                        let warm = warm_start(self.contact.geometry(), prev, &none);
                        self.coulomb_from_normal(model, step, t, solver, origin, rate_from, Some(warm))?
                    }
                    Err(e) => return Err(e),
                }
            }
        };
        let geometry = self.contact.geometry();
        let slip_rate = match previous {
            Some(prev) => slip_speeds(geometry, &result.displacement, &prev.displacement, dt),
            None => vec![0.0; geometry.len()],
        };
        let dissipation =
            friction_dissipation(geometry, &result, previous.map(|p| p.displacement.as_slice()))?;
        let cumulative = base + dissipation;
        let strain_energy = if self.record_strain_energy {
            // ½ Uᵀ A U when no prescribed displacement is non-zero, else the element loop
            self.contact.strain_energy(model, &result).map_err(|source| TimeError::Contact {
                step,
                time: t,
                source,
            })?
        } else {
            0.0
        };
        let record = StepRecord {
            step,
            time: t,
            pairs: pair_records(geometry, &result),
            friction_dissipation: dissipation,
            cumulative_friction_dissipation: cumulative,
            kinetic_energy: 0.0,
            strain_energy,
            viscous_dissipation: 0.0,
            iterations,
            step_s: start.elapsed().as_secs_f64(),
            solver: result.solution.report.solver.clone(),
            fallback: result.solution.report.fallback.clone(),
            rigid: Vec::new(),
        };
        self.cumulative = cumulative;
        self.slip_rate = slip_rate;
        self.next_step = step + 1;
        self.last_time = Some(t);
        let result = &*self.last.insert(result);
        Ok((record, result))
    }

    fn check_model(&self, model: &Model<D>) -> Result<(), TimeError> {
        let nodes = body_nodes(model);
        if nodes != self.body_nodes {
            return Err(TimeError::InvalidParameter(format!(
                "the model's bodies have {nodes:?} nodes, the stepper was built for {:?}",
                self.body_nodes
            )));
        }
        Ok(())
    }

    /// Step 0: frictionless solve at `t_0` (warm-started from `warm` if given), optionally followed by a Tresca solve with `g_c`
    /// from it (slip from the reference state).
    fn initial(
        &self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        warm: Option<&ContactSolution>,
    ) -> Result<(StaticContactResult<D>, usize), TimeError> {
        let pre = match self.contact.solve(model, t, solver, None, None, warm) {
            Ok(pre) => pre,
            Err(source) => {
                let e = TimeError::Contact { step: 0, time: t, source };
                // a body held by friction alone: the static problem with Coulomb friction
                if self.held_by_friction(&e) {
                    return self.coulomb_from_normal(model, 0, t, solver, None, None, warm.cloned());
                }
                return Err(e);
            }
        };
        let its = pre.solution.report.iterations + pre.coarse_iterations;
        let geometry = self.contact.geometry();
        if !(self.params.initial_friction && self.laws.any_friction(geometry)) {
            return Ok((pre, its));
        }
        // no previous level: the slip rate of step 0 is 0 (F_c at rest)
        let rest = vec![0.0; geometry.len()];
        let g = self.laws.slip_bounds(geometry, &pre.solution.lambda_n, &rest);
        let (res, more) = self.tresca_level(model, 0, t, solver, g, None, None, Some(&pre))?;
        Ok((res, its + more))
    }

    /// One Tresca level (with the optional Coulomb fixed point, whose slip rates are measured
    /// from `rate_from = (U(t_{i−1}), t_i − t_{i−1})`, 0 without it).
    #[allow(clippy::too_many_arguments)]
    fn tresca_level(
        &self,
        model: &Model<D>,
        step: usize,
        t: Real,
        solver: &dyn ContactSolver,
        slip_bound: Vec<Real>,
        origin: Option<&[Vec<Vector<D>>]>,
        rate_from: Option<(&[Vec<Vector<D>>], Real)>,
        warm_from: Option<&StaticContactResult<D>>,
    ) -> Result<(StaticContactResult<D>, usize), TimeError> {
        let geometry = self.contact.geometry();
        let coulomb = self.params.coulomb_fixed_point;
        let max = if coulomb { self.params.max_fixed_point } else { 1 };
        let mut g = slip_bound;
        let mut warm = warm_from.map(|w| warm_start(geometry, w, &g));
        let mut iterations = 0;
        let mut change = Real::INFINITY;
        for _ in 0..max {
            let res = self
                .contact
                .solve(model, t, solver, Some(&g), origin, warm.as_ref())
                .map_err(|source| TimeError::Contact { step, time: t, source })?;
            iterations += res.solution.report.iterations + res.coarse_iterations;
            if !coulomb {
                return Ok((res, iterations));
            }
            let rate = match rate_from {
                Some((prev, dt)) => slip_speeds(geometry, &res.displacement, prev, dt),
                None => vec![0.0; geometry.len()],
            };
            let g_new = self.laws.slip_bounds(geometry, &res.solution.lambda_n, &rate);
            change = relative_change(&g, &g_new);
            if change <= self.params.fixed_point_tolerance {
                return Ok((res, iterations));
            }
            warm = Some(warm_start(geometry, &res, &g_new));
            g = g_new;
        }
        Err(TimeError::FixedPoint { step, iterations: max, change })
    }
}

impl<const D: usize> QuasiStaticStepper<D> {
    /// Whether `e` is the failure of a model with bodies held only by contact and with friction
    /// whose load contact forces cannot balance with the slip bound given to the solve (the
    /// rigid-load check, or the proximal iteration stagnating): the case for
    /// [`QuasiStaticStepper::coulomb_from_normal`].
    fn held_by_friction(&self, e: &TimeError) -> bool {
        self.contact.elastic().stabilisation().is_some()
            && self.laws.any_friction(self.contact.geometry())
            && matches!(
                e,
                TimeError::Contact {
                    source: ContactError::Unbalanced { .. } | ContactError::NoConvergence { .. },
                    ..
                }
            )
    }

    /// The Coulomb fixed point (docs/model.md (3.8), §7.1) of the level at `t` of a model whose
    /// bodies are held by friction, started from the normal problem:
    ///
    /// ```text
    /// Λ_n⁰ = Λ_n of the frictionless problem with the load F_w (F without the rigid-body load
    ///        that no normal contact force balances, synovia_contact::floating::withhold_unbalanced),
    /// g⁰   = F_c |Λ_n⁰|,
    /// g^{m+1} = F_c(v^m) |Λ_n(g^m)|   (Tresca at t with the full load F and g^m, slip from `origin`),
    /// stop when max_r |g^{m+1}_r − g^m_r| ≤ ε max_r |g^{m+1}_r|,
    /// ```
    ///
    /// each solve warm-started from the last (`ε` = [`QuasiStaticParams::fixed_point_tolerance`],
    /// at most [`QuasiStaticParams::max_fixed_point`] Tresca solves). `warm` warm-starts the
    /// normal problem (`U`, `Λ_n`).
    ///
    /// # Errors
    /// [`TimeError::Slides`] when a Tresca solve fails and the tangential load on the floating
    /// bodies exceeds their friction capacity `Σ_r g^m_r κ_r = μ·P`; [`TimeError::FixedPoint`]
    /// when the iteration does not converge; [`TimeError::Contact`] for other solver failures.
    #[allow(clippy::too_many_arguments)]
    fn coulomb_from_normal(
        &self,
        model: &Model<D>,
        step: usize,
        t: Real,
        solver: &dyn ContactSolver,
        origin: Option<&[Vec<Vector<D>>]>,
        rate_from: Option<(&[Vec<Vector<D>>], Real)>,
        warm: Option<ContactSolution>,
    ) -> Result<(StaticContactResult<D>, usize), TimeError> {
        let contact_error = |source| TimeError::Contact { step, time: t, source };
        let elastic = self.contact.elastic();
        let geometry = self.contact.geometry();
        let Some(stabilisation) = elastic.stabilisation() else {
            return Err(TimeError::InvalidParameter(
                "the Coulomb start from the normal problem needs bodies held only by contact".into(),
            ));
        };
        let (load, lifts) = elastic.rhs(model, t)?;
        let normal = geometry.normal_constraints(elastic.dofs(), &lifts);
        let (withheld, _) = synovia_contact::floating::withhold_unbalanced(stabilisation, &load, &normal);
        let pre = self
            .contact
            .solve_load(&withheld, &lifts, solver, None, None, warm.as_ref())
            .map_err(contact_error)?;
        let mut iterations = pre.solution.report.iterations + pre.coarse_iterations;
        let rest = vec![0.0; geometry.len()];
        let mut pressure = pre.solution.lambda_n.clone();
        let mut g = self.laws.slip_bounds(geometry, &pressure, &rest);
        let mut warm = warm_start(geometry, &pre, &g);
        let mut change = Real::INFINITY;
        for _ in 0..self.params.max_fixed_point {
            let res = match self.contact.solve(model, t, solver, Some(&g), origin, Some(&warm)) {
                Ok(res) => res,
                Err(source) => {
                    return Err(self
                        .slides(model, step, t, &load, &g, &pressure)
                        .unwrap_or_else(|| contact_error(source)))
                }
            };
            iterations += res.solution.report.iterations + res.coarse_iterations;
            let rate = match rate_from {
                Some((prev, dt)) => slip_speeds(geometry, &res.displacement, prev, dt),
                None => rest.clone(),
            };
            let g_new = self.laws.slip_bounds(geometry, &res.solution.lambda_n, &rate);
            change = relative_change(&g, &g_new);
            if change <= self.params.fixed_point_tolerance {
                return Ok((res, iterations));
            }
            warm = warm_start(geometry, &res, &g_new);
            pressure.clone_from(&res.solution.lambda_n);
            g = g_new;
        }
        Err(TimeError::FixedPoint { step, iterations: self.params.max_fixed_point, change })
    }

    /// [`TimeError::Slides`] for the first floating component whose tangential load exceeds its
    /// friction capacity with the slip bounds `g` computed from the pressures `pressure`:
    /// the load resultant `f = (t_kᵀ F)_k` (`t_k` the reduced unknowns of a unit translation
    /// `e_k` of the component's bodies), the contact normal `n̄ = Σ_r κ_r Λ_n,r n_r / ‖·‖` over
    /// the component's contact nodes, `Q_t = ‖f − (f·n̄) n̄‖`, `P = Σ_r κ_r Λ_n,r` and the
    /// capacity `Σ_r κ_r g_r`; `None` if no component has `Q_t` above its capacity.
    fn slides(
        &self,
        model: &Model<D>,
        step: usize,
        t: Real,
        load: &[Real],
        g: &[Real],
        pressure: &[Real],
    ) -> Option<TimeError> {
        let elastic = self.contact.elastic();
        let geometry = self.contact.geometry();
        for component in &elastic.stabilisation()?.components {
            let inside = |b: BodyId| component.body_ids.contains(&b);
            let mut f = Vector::<D>::zeros();
            for k in 0..D {
                let full: Vec<Vec<Vector<D>>> = model
                    .bodies()
                    .iter()
                    .enumerate()
                    .map(|(b, body)| {
                        let mut e = Vector::<D>::zeros();
                        if inside(BodyId(b)) {
                            e[k] = 1.0;
                        }
                        vec![e; body.mesh.n_nodes()]
                    })
                    .collect();
                let translation = elastic.dofs().restrict(&full);
                f[k] = translation.iter().zip(load).map(|(a, b)| a * b).sum();
            }
            let (mut n_sum, mut normal, mut capacity) = (Vector::<D>::zeros(), 0.0, 0.0);
            for (r, node) in geometry.nodes.iter().enumerate() {
                let on_k = inside(node.node.0);
                let on_l = node.partner.is_some_and(|(b, _)| inside(b))
                    || node.master.iter().any(|&(b, _, _)| inside(b));
                if !(on_k || on_l) {
                    continue;
                }
                let force = node.weight * pressure.get(r).copied().unwrap_or(0.0).abs();
                n_sum += node.normal * if on_k { force } else { -force };
                normal += force;
                capacity += node.weight * g.get(r).copied().unwrap_or(0.0);
            }
            let n_bar = n_sum.try_normalize(0.0)?;
            let tangential = (f - n_bar * f.dot(&n_bar)).norm();
            if normal > 0.0 && tangential > capacity {
                return Some(TimeError::Slides {
                    step,
                    time: t,
                    bodies: component.bodies.clone(),
                    tangential,
                    capacity,
                    normal,
                });
            }
        }
        None
    }
}

fn body_nodes<const D: usize>(model: &Model<D>) -> Vec<usize> {
    model.bodies().iter().map(|b| b.mesh.n_nodes()).collect()
}

fn check_times(times: &[Real]) -> Result<(), TimeError> {
    if times.is_empty() {
        return Err(TimeError::InvalidParameter("no time levels".into()));
    }
    for (i, &t) in times.iter().enumerate() {
        if !t.is_finite() {
            return Err(TimeError::InvalidParameter(format!("time level {i} is {t}")));
        }
        if i > 0 && t <= times[i - 1] {
            return Err(TimeError::InvalidParameter(format!(
                "time levels must increase strictly: t_{i} = {t} ≤ t_{} = {}",
                i - 1,
                times[i - 1]
            )));
        }
    }
    Ok(())
}

/// `max_r |b_r − a_r| / max_r |b_r|` (0 if both vanish).
fn relative_change(a: &[Real], b: &[Real]) -> Real {
    let diff = a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    let scale = b.iter().fold(0.0_f64, |m, y| m.max(y.abs()));
    if diff == 0.0 {
        0.0
    } else if scale > 0.0 {
        diff / scale
    } else {
        Real::INFINITY
    }
}

pub use synovia_contact::warm::warm_start;

/// A contact result computed on the geometry `from`, carried to the nodes of the rebuilt
/// geometry `to` ([`ContactGeometry::node_map`]): `Λ_n` node by node (0 for nodes new in `to`),
/// friction cells (`cell_node`, `slip_bound`, `Λ_t`) of the nodes that are in both, in the node
/// order of `to`; displacements, `U`, report and KKT residuals unchanged. Used as the previous
/// level (slip bounds, warm start) after re-pairing.
pub fn transfer_result<const D: usize>(
    from: &ContactGeometry<D>,
    to: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
) -> StaticContactResult<D> {
    let comps = D.saturating_sub(1);
    let map = to.node_map(from);
    let lambda_n = to.transfer(from, &result.solution.lambda_n);
    let mut cell_of = vec![None; from.len()];
    for (c, &r) in result.cell_node.iter().enumerate() {
        if let Some(slot) = cell_of.get_mut(r) {
            *slot = Some(c);
        }
    }
    let (mut cell_node, mut slip_bound, mut lambda_t) = (Vec::new(), Vec::new(), Vec::new());
    for (r_to, r_from) in map.iter().enumerate() {
        let Some(c) = r_from.and_then(|r| cell_of.get(r).copied().flatten()) else {
            continue;
        };
        let (Some(&g), Some(lt)) =
            (result.slip_bound.get(c), result.solution.lambda_t.get(c * comps..(c + 1) * comps))
        else {
            continue;
        };
        cell_node.push(r_to);
        slip_bound.push(g);
        lambda_t.extend_from_slice(lt);
    }
    let mut out = result.clone();
    out.solution.lambda_n = lambda_n;
    out.solution.lambda_t = lambda_t;
    out.cell_node = cell_node;
    out.slip_bound = slip_bound;
    out
}

/// The friction work of a step, `Σ_c g_c κ_c ‖T_cᵀ([u](s_c) − [u]_prev(s_c))‖` over the
/// friction cells `c` of `result` (`g_c` = [`StaticContactResult::slip_bound`], `T_c` the
/// tangent basis of the cell's contact node), with `[u]_prev` from the nodal displacements
/// `previous` plus the partner's motion ([`ContactGeometry::slip_origin`]; `None`: the
/// reference state, `[u]_prev = 0`). Equals `Λ_t · B_Ht ΔU ≥ 0` for a
/// solution of the incremental Tresca problem.
///
/// # Errors
/// [`TimeError::InvalidParameter`] if the displacements do not fit the geometry.
pub fn friction_dissipation<const D: usize>(
    geometry: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
    previous: Option<&[Vec<Vector<D>>]>,
) -> Result<Real, TimeError> {
    let misfit = || TimeError::InvalidParameter("displacements do not fit the contact geometry".into());
    let mut total = 0.0;
    for (&r, &g) in result.cell_node.iter().zip(&result.slip_bound) {
        let node = geometry.nodes.get(r).ok_or_else(misfit)?;
        let mut du = geometry.jump(r, &result.displacement).ok_or_else(misfit)?;
        if let Some(p) = previous {
            du -= geometry.slip_origin(r, p).ok_or_else(misfit)?;
        }
        let slip: Real = node.tangents.iter().take(D - 1).map(|t| t.dot(&du).powi(2)).sum::<Real>().sqrt();
        total += g * node.weight * slip;
    }
    Ok(total)
}

/// Nodal contact fields of every body (`[body][node]`), see [`contact_fields`]. For
/// node-to-segment pairs the fields are set on the slave side (body `k`) only.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactFields<const D: usize> {
    /// Contact pressure `Λ_n,r` at the contact node of body `k` and at its partner node of
    /// body `l` (0 elsewhere).
    pub pressure: Vec<Vec<Real>>,
    /// Friction traction `−g_c Σ_j Λ_t,c,j T_c,j` on body `k`, its opposite on body `l` (0
    /// elsewhere).
    pub friction_traction: Vec<Vec<Vector<D>>>,
    /// 1 at the nodes of sticking friction cells (`‖Λ_t‖ < 1 − 1e-6`), 0 elsewhere.
    pub stick: Vec<Vec<Real>>,
}

/// The nodal contact fields of a contact solution: pressure, friction traction and stick flag
/// per node of every body ([`ContactFields`]).
///
/// # Errors
/// [`TimeError::InvalidParameter`] if the result does not fit the geometry or the model.
pub fn contact_fields<const D: usize>(
    model: &Model<D>,
    geometry: &ContactGeometry<D>,
    result: &StaticContactResult<D>,
) -> Result<ContactFields<D>, TimeError> {
    let misfit = || TimeError::InvalidParameter("contact result does not fit the model".into());
    let n: Vec<usize> = model.bodies().iter().map(|b| b.mesh.n_nodes()).collect();
    let mut pressure: Vec<Vec<Real>> = n.iter().map(|&k| vec![0.0; k]).collect();
    let mut traction: Vec<Vec<Vector<D>>> = n.iter().map(|&k| vec![Vector::<D>::zeros(); k]).collect();
    let mut stick: Vec<Vec<Real>> = n.iter().map(|&k| vec![0.0; k]).collect();
    let set = |field: &mut Vec<Vec<Real>>, (b, i): (usize, usize), v: Real| -> Result<(), TimeError> {
        *field.get_mut(b).and_then(|f| f.get_mut(i)).ok_or_else(misfit)? = v;
        Ok(())
    };
    for (r, node) in geometry.nodes.iter().enumerate() {
        let l = result.solution.lambda_n.get(r).copied().ok_or_else(misfit)?;
        set(&mut pressure, (node.node.0 .0, node.node.1), l)?;
        if let Some((b, j)) = node.partner {
            set(&mut pressure, (b.0, j), l)?;
        }
    }
    let comps = D - 1;
    for (c, (&r, &g)) in result.cell_node.iter().zip(&result.slip_bound).enumerate() {
        let node = geometry.nodes.get(r).ok_or_else(misfit)?;
        let lt = result.solution.lambda_t.get(c * comps..(c + 1) * comps).ok_or_else(misfit)?;
        let mut q = Vector::<D>::zeros();
        for (t, l) in node.tangents.iter().zip(lt) {
            q -= t * (g * l);
        }
        let norm = lt.iter().map(|v| v * v).sum::<Real>().sqrt();
        let flag = if norm < 1.0 - 1e-6 { 1.0 } else { 0.0 };
        let (b, i) = (node.node.0 .0, node.node.1);
        *traction.get_mut(b).and_then(|f| f.get_mut(i)).ok_or_else(misfit)? = q;
        set(&mut stick, (b, i), flag)?;
        if let Some((bl, j)) = node.partner {
            *traction.get_mut(bl.0).and_then(|f| f.get_mut(j)).ok_or_else(misfit)? = -q;
            set(&mut stick, (bl.0, j), flag)?;
        }
    }
    Ok(ContactFields { pressure, friction_traction: traction, stick })
}

/// Writer of quasi-static results: a ParaView time series `DIR/NAME.pvd` with one
/// `DIR/NAME_NNNN.vtu` per step and the step records as `DIR/NAME.csv`.
///
/// Each `.vtu` holds every body (one piece, told apart by the field `body`) with the point
/// fields `displacement`, `contact_pressure` (`Λ_n`, on both sides of a node-to-node pair),
/// `contact_active` (1 where `Λ_n > 0`), `friction_traction` (`−g_c Λ_t T` on body `k`,
/// opposite on body `l`), `stick` (1 on sticking friction cells) ([`contact_fields`]) and the
/// stress and strain fields of [`crate::solid_fields::solid_fields`] (point `von_mises_nodal`,
/// `stress_nodal`; cell `stress`, `strain`, `von_mises`, `principal_stress`,
/// `strain_energy_density`).
///
/// ```no_run
/// # use synovia_time::quasistatic::*;
/// # fn demo(model: &synovia_fem::Model<2>, mut stepper: QuasiStaticStepper<2>,
/// #         solver: &dyn synovia_contact::ContactSolver) -> Result<(), synovia_time::TimeError> {
/// let mut out = QuasiStaticOutput::new("out/run", "run", stepper.geometry())?;
/// let records = stepper.run(model, &[0.0, 0.5, 1.0], solver, |rec, res| {
///     out.write_step(model, rec, res).map(|_| ())
/// })?;
/// out.write_csv(&records)?;
/// # Ok(()) }
/// ```
#[derive(Debug, Clone)]
pub struct QuasiStaticOutput<const D: usize> {
    dir: PathBuf,
    name: String,
    series: TimeSeriesWriter,
    encoding: Encoding,
    geometry: ContactGeometry<D>,
    solid_fields: bool,
    kinematics: Vec<synovia_fem::Kinematics>,
}

impl<const D: usize> QuasiStaticOutput<D> {
    /// A series `name` in `dir` (created if missing), zlib-compressed, for a stepper with the
    /// contact `geometry` ([`QuasiStaticStepper::geometry`]; copied).
    ///
    /// # Errors
    /// [`TimeError::Io`] for an invalid name or a directory that cannot be created.
    pub fn new(
        dir: impl Into<PathBuf>,
        name: &str,
        geometry: &ContactGeometry<D>,
    ) -> Result<Self, TimeError> {
        Self::with_encoding(dir, name, geometry, Encoding::Zlib)
    }

    /// As [`QuasiStaticOutput::new`] with a chosen encoding.
    ///
    /// # Errors
    /// As [`QuasiStaticOutput::new`].
    pub fn with_encoding(
        dir: impl Into<PathBuf>,
        name: &str,
        geometry: &ContactGeometry<D>,
        encoding: Encoding,
    ) -> Result<Self, TimeError> {
        let dir = dir.into();
        let series = TimeSeriesWriter::new(dir.clone(), name, encoding)?;
        Ok(Self {
            dir,
            name: name.to_string(),
            series,
            encoding,
            geometry: geometry.clone(),
            solid_fields: true,
            kinematics: Vec::new(),
        })
    }

    /// The kinematics of each body (default: small strain): finite-strain bodies get the
    /// Green–Lagrange strain and the Cauchy stress in their files
    /// ([`synovia_fem::post::body_fields_with_kinematics`]).
    #[must_use]
    pub fn with_kinematics(mut self, kinematics: Vec<synovia_fem::Kinematics>) -> Self {
        self.kinematics = kinematics;
        self
    }

    /// Whether the `.vtu` files carry the stress and strain fields (default `true`; `false`:
    /// the displacement and the contact state only, 5–7× smaller files).
    #[must_use]
    pub fn with_solid_fields(mut self, on: bool) -> Self {
        self.solid_fields = on;
        self
    }

    /// Writes the step of `record` (time `record.time`, which must exceed the previous step's)
    /// with the fields of `result`; returns the `.vtu` path.
    ///
    /// # Errors
    /// [`TimeError::Io`] on write failures or a non-increasing time; [`TimeError::Fem`] /
    /// [`TimeError::InvalidParameter`] if `result` does not fit `model`.
    pub fn write_step(
        &mut self,
        model: &Model<D>,
        record: &StepRecord,
        result: &StaticContactResult<D>,
    ) -> Result<PathBuf, TimeError> {
        let ContactFields { pressure, friction_traction: traction, stick } =
            contact_fields(model, &self.geometry, result)?;
        let fields = if self.solid_fields {
            synovia_fem::post::body_fields_with_kinematics(model, &result.displacement, &self.kinematics)?
        } else {
            Vec::new()
        };
        let mut vtu = VtuWriter::new(self.encoding);
        for (bi, body) in model.bodies().iter().enumerate() {
            let Some(u) = result.displacement.get(bi) else {
                return Err(TimeError::InvalidParameter("contact result does not fit the model".into()));
            };
            let active = pressure[bi].iter().map(|&p| if p > 0.0 { 1.0 } else { 0.0 }).collect();
            let mut all = vec![
                Field::point_vectors("displacement", u),
                Field::point_scalars("contact_pressure", pressure[bi].clone()),
                Field::point_scalars("contact_active", active),
                Field::point_vectors("friction_traction", &traction[bi]),
                Field::point_scalars("stick", stick[bi].clone()),
            ];
            if let Some(f) = fields.get(bi) {
                all.extend(crate::solid_fields::solid_fields::<D>(f, |v| *v));
            }
            vtu.add_piece(&body.mesh, all)?;
        }
        Ok(self.series.write_step(record.time, &vtu)?)
    }

    /// Writes `records` to `DIR/NAME.csv` ([`crate::results::write_csv_with_units`] with the
    /// default unit labels, mm, N, s); returns the path.
    ///
    /// # Errors
    /// [`TimeError::Io`] on write failures.
    pub fn write_csv(&self, records: &[StepRecord]) -> Result<PathBuf, TimeError> {
        let path = self.csv_path();
        write_csv_with_units(&path, records, &Units::default(), D)?;
        Ok(path)
    }

    /// `DIR/NAME.csv`.
    pub fn csv_path(&self) -> PathBuf {
        self.dir.join(format!("{}.csv", self.name))
    }
    /// `DIR/NAME.pvd`.
    pub fn pvd_path(&self) -> &Path {
        self.series.pvd_path()
    }
    /// Steps written so far.
    pub fn n_steps(&self) -> usize {
        self.series.n_steps()
    }
}
