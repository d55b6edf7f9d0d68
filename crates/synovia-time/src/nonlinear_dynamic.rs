//! The semi-implicit Kelvin–Voigt scheme with a nonlinear elastic part (docs/model.md §12.1,
//! (12.2); docs/dynamics.md §8).
//!
//! ## The scheme
//!
//! The linear scheme of docs/model.md (7.3) with the elastic force `A⁽⁰⁾ U^{i+1}` replaced
//! by the internal force `F_int(U^{i+1})` of the bodies' materials and kinematics (any
//! [`synovia_material::Material`], small strain or total Lagrangian finite strain): with
//! `h = t_{i+1} − t_i`, the velocity `V^{i+1} = (U^{i+1} − U^i)/h` and
//! `V^i = (U^i − U^{i−1})/h_i` (the previous step `h_i`),
//!
//! ```text
//! M_ρ (V^{i+1} − V^i)/h + (M_α + A⁽¹⁾) V^{i+1} + F_int(U^{i+1}) + (contact, friction) = F(t_{i+1}).
//! ```
//!
//! For a constant step `h = h_i = Δt` the first term is `M_ρ (U^{i+1} − 2U^i + U^{i−1})/Δt²`,
//! so with a linear material (`F_int(U) = A⁽⁰⁾ U`) the scheme is (7.3) exactly. In the
//! reduced unknowns `U^{i+1} = u_p(t_{i+1}) + P ũ` a step is the nonlinear contact problem
//!
//! ```text
//! B ũ + Pᵀ F_int(U^{i+1}) + c = Pᵀ F(t_{i+1}) + g,        B = (M̃_ρ + h (M̃_α + Ã⁽¹⁾))/h²,
//! g = M̃_ρ (ũ^i + r (ũ^i − ũ^{i−1}))/h² + (M̃_α + Ã⁽¹⁾) ũ^i/h
//!     − Pᵀ [ M_ρ (u_p^{i+1} − u_p^i − r (u_p^i − u_p^{i−1}))/h² + (M_α + A⁽¹⁾)(u_p^{i+1} − u_p^i)/h ],
//! ```
//!
//! `r = h/h_i` (docs/model.md (12.2)), solved by the Newton iteration of
//! [`NonlinearContact::step_with_terms`] on the tangent `K_T(U) + B`: the contact semismooth
//! Newton inside, line search, predictor for moving prescribed displacements, the contact
//! geometry on the deformed configuration for finite strain. The problem is not multiplied by
//! `h²`, so its multipliers are the physical pressures and the Tresca slip bounds are
//! `g_c = F_c(v^i) |λ_n^i|` of level `i` (the pair's [`FrictionLaw`]), slip measured from
//! `U^i` — (7.4), (7.7) divided by `Δt²`.
//!
//! **Viscosity.** The Kelvin–Voigt term is the report's linear one, `C⁽¹⁾ ε(u')`, in both
//! kinematics (docs/model.md §12.1, *Choice*).
//!
//! **Cut-back.** A step whose Newton iteration fails (no convergence, an inverted element, a
//! failed contact solve) is replaced by two steps of `h/2`, recursively up to
//! [`NonlinearDynamicStepper::set_max_cutbacks`] halvings; the variable-step form above keeps
//! the scheme consistent across the change of step.
//!
//! ## Energy (docs/dynamics.md §8)
//!
//! With `E^i = ½ ‖V^i‖²_{M_ρ} + Π(U^i)`, `Π` the stored energy `Σ_T |T| Φ(e)`, and no
//! prescribed motion, the exact step solution satisfies
//!
//! ```text
//! E^{i+1} − E^i = W_ext − W_c − W_f − D_visc − D_kin − D_Π,
//! D_kin = ½ ‖V^{i+1} − V^i‖²_{M_ρ},   D_visc = h ‖V^{i+1}‖²_{M_α + A⁽¹⁾},
//! D_Π = δᵀ F_int(U^{i+1}) − (Π(U^{i+1}) − Π(U^i)) = ∫₀¹ τ δᵀ K_T(U^i + τ δ) δ dτ,   δ = U^{i+1} − U^i,
//! ```
//!
//! with `D_Π ≥ 0` wherever the tangent is positive semi-definite along the step (it is
//! `½ ‖δ‖²_{A⁽⁰⁾}` for a linear material).

use std::sync::Arc;
use std::time::Instant;

use synovia_contact::operators::{ContactGeometry, ContactPair};
use synovia_contact::{slip_speeds, ContactSolver, FrictionLaw, PairFrictionLaws, StaticContactResult};
use synovia_fem::assembly::{add_loads, assemble_matrix, subtract_lift};
use synovia_fem::element::mass_into;
use synovia_fem::{DofMap, ElasticParams, FemError, Kinematics, Model, SymmetricMatrix};
use synovia_material::voigt_len;
use synovia_mesh::math::{Real, Vector};
use synovia_nonlinear::{LevelTerms, NewtonParams, NewtonReport, NonlinearContact, NonlinearError};

use crate::dynamic::{
    all_zero, check_nodal, damping_into, full_form, initial_levels, nodal_diff, DynamicBody, DynamicParams,
    EnergyBalance, InitialLevels, MassKind,
};
use crate::error::TimeError;
use crate::quasistatic::friction_dissipation;
use crate::results::{empty_pair_records, pair_records, StepRecord};

/// What a step of [`NonlinearDynamicStepper`] did besides its [`StepRecord`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NonlinearStepReport {
    /// Sub-steps solved (1 without cut-back).
    pub substeps: usize,
    /// Halvings of the step (0 without cut-back).
    pub cutbacks: usize,
    /// Newton iterations over all sub-steps and failed trials.
    pub newton_iterations: usize,
    /// Numeric factorisations of the tangent.
    pub factorisations: usize,
    /// The Newton report of the last sub-step.
    pub last: NewtonReport,
    /// `D_Π = δᵀ F_int(U^{i+1}) − (Π(U^{i+1}) − Π(U^i))`, summed over the sub-steps
    /// (module docs; exact only without prescribed motion).
    pub elastic_dissipation: Real,
    /// `D_kin = ½ ‖V^{i+1} − V^i‖²_{M_ρ}`, summed over the sub-steps.
    pub kinetic_dissipation: Real,
}

/// The dynamic scheme of docs/model.md (12.2) for nonlinear materials and finite strain (see
/// the module docs): each step one nonlinear contact problem solved by the Newton iteration
/// of [`NonlinearContact`] with the inertia and damping terms as its constant matrix.
///
/// The [`Model`] passed to [`Self::step`] must be the one given to [`Self::new`].
#[derive(Debug)]
pub struct NonlinearDynamicStepper<const D: usize> {
    nl: NonlinearContact<D>,
    params: DynamicParams,
    bodies: Vec<DynamicBody>,
    laws: PairFrictionLaws,
    /// `M̃_ρ`.
    mass: SymmetricMatrix,
    /// `M̃_α + Ã⁽¹⁾`.
    damping: SymmetricMatrix,
    has_damping: bool,
    n_nodes: usize,
    max_cutbacks: usize,
    /// The step `h` of the constant matrix `B` currently set in `nl`.
    b_step: Real,
    // level i (and i − 1)
    step: usize,
    time: Real,
    /// `t_i − t_{i−1}`.
    h_prev: Real,
    u: Vec<Real>,
    u_prev: Vec<Real>,
    lifts: Vec<Vector<D>>,
    lifts_prev: Vec<Vector<D>>,
    disp: Vec<Vec<Vector<D>>>,
    disp_prev: Vec<Vec<Vector<D>>>,
    /// Physical pressure `λ_n` per contact node at level i.
    pressure: Vec<Real>,
    /// Slip speed per contact node at level i.
    slip_speed: Vec<Real>,
    /// `Π(U^i)`.
    stored_energy: Real,
    last: Option<StaticContactResult<D>>,
    balance: EnergyBalance,
    report: NonlinearStepReport,
    cumulative_friction: Real,
}

/// Contact partners that move by a prescribed motion during a dynamic run (rigid bodies whose
/// coordinates are all prescribed, docs/dynamics.md §9), for
/// [`NonlinearDynamicStepper::step_posing`].
pub trait MovingPartners<const D: usize> {
    /// Poses the partners at `t`, the end of the next (sub-)step (their shapes read the pose
    /// when the contact rows are built).
    ///
    /// # Errors
    /// Whatever keeps them from being posed (e.g. a history value that is not finite).
    fn pose(&mut self, t: Real) -> Result<(), TimeError>;
    /// Their motion `w_r` at the contact nodes of `geometry` from the last committed (sub-)step
    /// to the pose set last, at the nodes' positions `x_r + [u](previous)` (one vector per
    /// node; the slip of friction is measured relative to it, docs/model.md (10.5)).
    fn motion(&self, geometry: &ContactGeometry<D>, previous: &[Vec<Vector<D>>]) -> Vec<Vector<D>>;
    /// The (sub-)step to the pose set last was committed: the origin of the next motion.
    fn commit(&mut self);
}

/// The result of one (sub-)step before it is committed.
struct SubStep<const D: usize> {
    u: Vec<Real>,
    lifts: Vec<Vector<D>>,
    disp: Vec<Vec<Vector<D>>>,
    result: StaticContactResult<D>,
    stored_energy: Real,
    report: NewtonReport,
    contact_force: Vec<Real>,
}

impl<const D: usize> NonlinearDynamicStepper<D> {
    /// Validates the data, assembles `M̃_ρ` and `M̃_α + Ã⁽¹⁾` on the tangent's pattern, sets up
    /// the Newton iteration ([`NonlinearContact::with_constant_matrix`] with
    /// `B = (M̃_ρ + Δt (M̃_α + Ã⁽¹⁾))/Δt²`) and starts at rest at the lifts of `t_0`
    /// ([`Self::set_initial_state`]). One [`Kinematics`] per body. Of the
    /// [`DynamicParams`], `dt`, `t0`, `mass`, `ordering` and `load_degree` apply (the Newton
    /// iteration always warm-starts its contact solves).
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for invalid parameters or body data (a density that is
    /// not positive, a viscosity that is not symmetric positive semi-definite, wrong counts,
    /// `coulomb_iterations > 0`);
    /// [`TimeError::Nonlinear`] for the set-up of the Newton iteration (invalid
    /// [`NewtonParams`], contact pairs).
    pub fn new(
        model: &Model<D>,
        bodies: &[DynamicBody],
        pairs: &[ContactPair<D>],
        kinematics: &[Kinematics],
        params: DynamicParams,
        newton: NewtonParams,
    ) -> Result<Self, TimeError> {
        params.check()?;
        model.validate()?;
        let nb = model.bodies().len();
        if bodies.len() != nb || kinematics.len() != nb {
            return Err(TimeError::InvalidParameter(format!(
                "{} dynamic body data and {} kinematics for {nb} bodies (one each per body)",
                bodies.len(),
                kinematics.len()
            )));
        }
        let nv = voigt_len(D);
        for (b, data) in model.bodies().iter().zip(bodies) {
            data.check(&b.name, nv)?;
        }
        if params.coulomb_iterations > 0 {
            return Err(TimeError::InvalidParameter(
                "the Coulomb fixed point per step (coulomb_iterations > 0) is not available with a nonlinear \
                 elastic part: friction is Tresca with the slip bound of the previous level"
                    .into(),
            ));
        }
        // the loads of the Newton iteration with the stepper's quadrature
        let newton = newton.with_load_degree(params.load_degree);
        let rho: Vec<Real> = bodies.iter().map(|b| b.density).collect();
        let alpha: Vec<Real> = bodies.iter().map(|b| b.damping).collect();
        let lumped = params.mass == MassKind::Lumped;
        let dt = params.dt;
        let has_alpha = alpha.iter().any(|&a| a > 0.0);
        let has_c1 = bodies.iter().any(|b| b.viscous.as_ref().is_some_and(|c| c.iter().any(|v| *v != 0.0)));
        let mut parts = None;
        let assemble = |dofs: &DofMap<D>, b: &mut SymmetricMatrix| -> Result<(), FemError> {
            let mut mass = b.clone();
            let mut damping = b.clone();
            assemble_matrix(model, dofs, &mut mass, |bi, _, geo, out| mass_into(geo, rho[bi], lumped, out))?;
            if has_alpha || has_c1 {
                assemble_matrix(model, dofs, &mut damping, |bi, _, geo, out| {
                    damping_into(geo, alpha[bi], bodies[bi].viscous.as_ref(), lumped, out);
                })?;
            }
            *b = combined(&mass, &damping, dt)?;
            parts = Some((mass, damping));
            Ok(())
        };
        let elastic = ElasticParams::default().with_ordering(params.ordering);
        let nl = NonlinearContact::with_constant_matrix(model, pairs, kinematics, elastic, newton, assemble)?;
        let (mass, damping) = parts.ok_or_else(|| {
            TimeError::InvalidParameter("internal: the inertia matrices were not assembled".into())
        })?;
        let laws = PairFrictionLaws::new(nl.geometry());
        let n = nl.dofs().n_dofs();
        let nc = nl.geometry().len();
        let lifts = nl.dofs().lifts(model, params.t0)?;
        let zero_nodal: Vec<Vec<Vector<D>>> =
            model.bodies().iter().map(|b| vec![Vector::<D>::zeros(); b.mesh.n_nodes()]).collect();
        let mut s = Self {
            nl,
            time: params.t0,
            h_prev: dt,
            b_step: dt,
            params,
            bodies: bodies.to_vec(),
            laws,
            mass,
            damping,
            has_damping: has_alpha || has_c1,
            n_nodes: model.n_nodes(),
            max_cutbacks: 6,
            step: 0,
            u: vec![0.0; n],
            u_prev: vec![0.0; n],
            lifts: lifts.clone(),
            lifts_prev: lifts,
            disp: zero_nodal.clone(),
            disp_prev: zero_nodal,
            pressure: vec![0.0; nc],
            slip_speed: vec![0.0; nc],
            stored_energy: 0.0,
            last: None,
            balance: EnergyBalance::default(),
            report: NonlinearStepReport::default(),
            cumulative_friction: 0.0,
        };
        s.set_initial_state(model, None, None)?;
        Ok(s)
    }

    /// Halvings of a failing step (default 6; 0 turns the cut-back off).
    pub fn set_max_cutbacks(&mut self, cutbacks: usize) -> &mut Self {
        self.max_cutbacks = cutbacks;
        self
    }

    /// Replaces the friction law of the contact pair `pair` (default: its constant
    /// coefficient), as [`crate::dynamic::DynamicStepper::set_friction_law`].
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for an unknown pair.
    pub fn set_friction_law(&mut self, pair: &str, law: Arc<dyn FrictionLaw>) -> Result<(), TimeError> {
        self.laws.set(pair, law).map_err(|e| TimeError::InvalidParameter(e.to_string()))
    }

    /// Sets the initial data `u(t_0) = u₀`, `u'(t_0) = u₁` (nodal values per body; `None` = 0)
    /// and resets the stepper to step 0: `U^0 = u_p(t_0) + P Pᵀ u₀`, `U^{−1} = U^0 − Δt u₁`
    /// node by node (docs/model.md (7.9)), as the linear stepper
    /// ([`crate::dynamic::DynamicStepper::set_initial_state`]).
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for wrong sizes or non-finite values;
    /// [`TimeError::Fem`] for an initial displacement that inverts an element.
    pub fn set_initial_state(
        &mut self,
        model: &Model<D>,
        displacement: Option<&[Vec<Vector<D>>]>,
        velocity: Option<&[Vec<Vector<D>>]>,
    ) -> Result<(), TimeError> {
        for (what, field) in [("initial displacement", displacement), ("initial velocity", velocity)] {
            if let Some(f) = field {
                check_nodal(model, f, what)?;
            }
        }
        let dt = self.params.dt;
        let t0 = self.params.t0;
        let InitialLevels { u0, um1, lifts0, lifts_m1 } =
            initial_levels(model, self.dofs(), t0, dt, displacement, velocity)?;
        self.disp = self.dofs().expand(&u0, &lifts0)?;
        self.disp_prev = self.dofs().expand(&um1, &lifts_m1)?;
        let (_, energy) =
            synovia_fem::nonlinear::internal_force(model, self.dofs(), self.kinematics(), &self.disp)?;
        self.nl.set_state(t0, &u0)?;
        self.u = u0;
        self.u_prev = um1;
        self.lifts = lifts0;
        self.lifts_prev = lifts_m1;
        self.step = 0;
        self.time = t0;
        self.h_prev = dt;
        self.pressure.iter_mut().for_each(|p| *p = 0.0);
        self.slip_speed = slip_speeds(self.nl.geometry(), &self.disp, &self.disp_prev, dt);
        self.last = None;
        self.cumulative_friction = 0.0;
        self.stored_energy = energy;
        let exact = all_zero(&self.lifts) && all_zero(&self.lifts_prev);
        let v = nodal_diff(&self.disp, &self.disp_prev, 1.0 / dt);
        let kinetic = 0.5 * self.full_mass_form(model, &v);
        self.balance = EnergyBalance { kinetic, strain: energy, exact, ..Default::default() };
        self.report = NonlinearStepReport::default();
        Ok(())
    }

    /// Advances one step `t_i → t_i + Δt` (module docs): the Newton iteration on the step's
    /// nonlinear contact problem, with cut-back into sub-steps of `Δt/2^k` on failure.
    /// Returns the step's figures (physical contact forces and pressures, kinetic energy,
    /// stored energy `Π`, viscous and friction dissipation, Newton iterations).
    ///
    /// # Errors
    /// [`TimeError::Nonlinear`] when the step fails after the cut-backs (the stepper stays at
    /// the last converged sub-step); [`TimeError::Fem`] for load or lift evaluation errors;
    /// [`TimeError::InvalidParameter`] for another model than the stepper's.
    pub fn step(&mut self, model: &Model<D>, solver: &dyn ContactSolver) -> Result<StepRecord, TimeError> {
        self.step_posing(model, solver, None)
    }

    /// As [`Self::step`], with contact partners that move: before every (sub-)step to `t`,
    /// [`MovingPartners::pose`] poses them (e.g. rigid bodies at their prescribed coordinates,
    /// docs/model.md §10) and the contact rows are rebuilt
    /// ([`NonlinearContact::rebuild_geometry`]; the level's pressures and slip speeds carried
    /// node by node to the new rows), so a cut-back step poses the partners at its sub-step
    /// times; friction measures the slip relative to [`MovingPartners::motion`]
    /// ([`NonlinearContact::step_with_terms_and_partner_motion`]), and the slip speeds and
    /// friction work of the step use the same relative slip.
    ///
    /// # Errors
    /// As [`Self::step`]; whatever `pose` returns; [`TimeError::NonlinearSetup`] from the
    /// rebuild of the rows.
    pub fn step_posing(
        &mut self,
        model: &Model<D>,
        solver: &dyn ContactSolver,
        mut partners: Option<&mut dyn MovingPartners<D>>,
    ) -> Result<StepRecord, TimeError> {
        let t_start = Instant::now();
        if model.n_nodes() != self.n_nodes {
            return Err(TimeError::InvalidParameter(
                "the model passed to step() is not the one the stepper was built for".into(),
            ));
        }
        let dt = self.params.dt;
        let step = self.step + 1;
        let t_end = self.params.t0 + step as Real * dt;
        let mut report = NonlinearStepReport::default();
        let mut sum = EnergyBalance { exact: true, ..Default::default() };
        let mut halvings = 0usize;
        let mut done = 0usize; // sub-steps of Δt/2^halvings done
        loop {
            let parts = 1usize << halvings;
            let h = dt / parts as Real;
            let t_new = if done + 1 == parts { t_end } else { self.time + h };
            if let Some(partners) = partners.as_deref_mut() {
                partners.pose(t_new)?;
                let old = self.nl.rebuild_geometry(model)?;
                let new = self.nl.geometry();
                if !new.same_rows(&old) {
                    self.pressure = new.transfer(&old, &self.pressure);
                    self.slip_speed = new.transfer(&old, &self.slip_speed);
                }
            }
            match self.substep(model, h, t_new, solver, partners.as_deref()) {
                Ok(sub) => {
                    report.newton_iterations += sub.report.total_iterations;
                    report.factorisations += sub.report.factorisations;
                    self.commit(model, h, t_new, sub, &mut sum, &mut report)?;
                    if let Some(partners) = partners.as_deref_mut() {
                        partners.commit();
                    }
                    report.substeps += 1;
                    done += 1;
                    if done == parts {
                        break;
                    }
                }
                Err(e) => {
                    let recoverable = matches!(
                        e,
                        NonlinearError::NoConvergence { .. }
                            | NonlinearError::Fem(FemError::InvertedElement { .. })
                            | NonlinearError::Fem(FemError::Linalg(_))
                            | NonlinearError::Contact(_)
                    );
                    if !recoverable || halvings >= self.max_cutbacks {
                        return Err(TimeError::Nonlinear { step, time: t_new, source: e });
                    }
                    halvings += 1;
                    report.cutbacks += 1;
                    done *= 2;
                    tracing::debug!(step, h = h / 2.0, "dynamic step cut back");
                }
            }
        }
        self.step = step;
        self.time = t_end;
        sum.kinetic = self.balance.kinetic;
        sum.strain = self.stored_energy;
        self.balance = sum;
        self.report = report;
        let mut record = StepRecord {
            step,
            time: t_end,
            iterations: self.report.newton_iterations,
            kinetic_energy: sum.kinetic,
            strain_energy: sum.strain,
            viscous_dissipation: sum.viscous_dissipation,
            friction_dissipation: sum.friction_work,
            cumulative_friction_dissipation: self.cumulative_friction,
            ..Default::default()
        };
        if let Some(res) = &self.last {
            record.pairs = pair_records(self.nl.geometry(), res);
            record.solver.clone_from(&res.solution.report.solver);
            record.fallback.clone_from(&res.solution.report.fallback);
        }
        record.step_s = t_start.elapsed().as_secs_f64();
        Ok(record)
    }

    /// `B = (M̃_ρ + h (M̃_α + Ã⁽¹⁾))/h²` into the Newton iteration.
    fn set_step_matrix(&mut self, h: Real) -> Result<(), NonlinearError> {
        let b = combined(&self.mass, &self.damping, h)?;
        self.nl.set_constant_matrix(b)?;
        self.b_step = h;
        Ok(())
    }

    /// Solves one (sub-)step of length `h` from the current level to `t_new` without
    /// committing it.
    fn substep(
        &mut self,
        model: &Model<D>,
        h: Real,
        t_new: Real,
        solver: &dyn ContactSolver,
        partners: Option<&dyn MovingPartners<D>>,
    ) -> Result<SubStep<D>, NonlinearError> {
        if self.b_step != h {
            self.set_step_matrix(h)?;
        }
        let n = self.dofs().n_dofs();
        let r = h / self.h_prev;
        let lifts_new = self.dofs().lifts(model, t_new)?;
        // g = M̃ (ũ^i + r(ũ^i − ũ^{i−1}))/h² + (M̃_α + Ã⁽¹⁾) ũ^i/h − lift terms
        let x: Vec<Real> = self.u.iter().zip(&self.u_prev).map(|(a, b)| a + r * (a - b)).collect();
        let mut g = vec![0.0; n];
        self.mass.mul_vec(&x, &mut g);
        g.iter_mut().for_each(|v| *v /= h * h);
        if self.has_damping {
            let mut tmp = vec![0.0; n];
            self.damping.mul_vec(&self.u, &mut tmp);
            g.iter_mut().zip(&tmp).for_each(|(a, b)| *a += b / h);
        }
        let second: Vec<Vector<D>> = lifts_new
            .iter()
            .zip(self.lifts.iter().zip(&self.lifts_prev))
            .map(|(a, (b, c))| a - b - (b - c) * r)
            .collect();
        let lumped = self.params.mass == MassKind::Lumped;
        if !all_zero(&second) {
            let rho: Vec<Real> = self.bodies.iter().map(|b| b.density).collect();
            subtract_lift(model, self.dofs(), &second, &mut g, |b, _, geo, out| {
                mass_into(geo, rho[b], lumped, out);
                out.iter_mut().for_each(|v| *v /= h * h);
            })?;
        }
        if self.has_damping {
            let first: Vec<Vector<D>> = lifts_new.iter().zip(&self.lifts).map(|(a, b)| a - b).collect();
            if !all_zero(&first) {
                let bodies = &self.bodies;
                subtract_lift(model, self.dofs(), &first, &mut g, |b, _, geo, out| {
                    damping_into(geo, bodies[b].damping, bodies[b].viscous.as_ref(), lumped, out);
                    out.iter_mut().for_each(|v| *v /= h);
                })?;
            }
        }
        let bounds = self.laws.slip_bounds(self.nl.geometry(), &self.pressure, &self.slip_speed);
        let slip_bound = bounds.iter().any(|v| *v > 0.0).then_some(&bounds[..]);
        let terms = LevelTerms { load: &g, slip_bound };
        let level = match partners.filter(|_| slip_bound.is_some()) {
            // friction against moving partners: the slip measured relative to their motion
            Some(p) => {
                let motion =
                    |geometry: &ContactGeometry<D>, previous: &[Vec<Vector<D>>]| p.motion(geometry, previous);
                self.nl.step_with_terms_and_partner_motion(model, t_new, &terms, solver, &motion)?
            }
            None => self.nl.step_with_terms(model, t_new, &terms, solver)?,
        };
        let u = self.nl.reduced().to_vec();
        let disp = level.contact.displacement.clone();
        Ok(SubStep {
            u,
            lifts: lifts_new,
            disp,
            contact_force: self.nl.contact_force().to_vec(),
            stored_energy: level.strain_energy,
            report: level.report,
            result: level.contact,
        })
    }

    /// Commits a converged sub-step: energies (added to `sum`), pressures, slip speeds, levels.
    fn commit(
        &mut self,
        model: &Model<D>,
        h: Real,
        t_new: Real,
        sub: SubStep<D>,
        sum: &mut EnergyBalance,
        report: &mut NonlinearStepReport,
    ) -> Result<(), TimeError> {
        let n = self.dofs().n_dofs();
        let lifts_zero = all_zero(&sub.lifts) && all_zero(&self.lifts) && all_zero(&self.lifts_prev);
        // V^{i+1}, V^i (full nodal fields), and their reduced parts when the lifts vanish
        let v_new = nodal_diff(&sub.disp, &self.disp, 1.0 / h);
        let v_old = nodal_diff(&self.disp, &self.disp_prev, 1.0 / self.h_prev);
        let kinetic = 0.5 * self.full_mass_form(model, &v_new);
        let dv = nodal_diff(&v_new, &v_old, 1.0);
        let kinetic_dissipation = 0.5 * self.full_mass_form(model, &dv);
        let viscous = if self.has_damping { h * self.full_damping_form(model, &v_new) } else { 0.0 };
        let delta: Vec<Real> = sub.u.iter().zip(&self.u).map(|(a, b)| a - b).collect();
        let mut load = vec![0.0; n];
        add_loads(model, self.dofs(), t_new, self.params.load_degree, &mut load)?;
        let external_work: Real = delta.iter().zip(&load).map(|(d, f)| d * f).sum();
        let (f_int, _) =
            synovia_fem::nonlinear::internal_force(model, self.dofs(), self.kinematics(), &sub.disp)?;
        let elastic_dissipation = delta.iter().zip(&f_int).map(|(d, f)| d * f).sum::<Real>()
            - (sub.stored_energy - self.stored_energy);
        let total_contact: Real = delta.iter().zip(&sub.contact_force).map(|(d, c)| d * c).sum();
        let friction_work = if sub.result.cell_node.is_empty() {
            0.0
        } else {
            friction_dissipation(self.nl.geometry(), &sub.result, Some(&self.disp))?
        };
        sum.kinetic = kinetic;
        sum.strain = sub.stored_energy;
        sum.numerical_dissipation += kinetic_dissipation + elastic_dissipation;
        sum.viscous_dissipation += viscous;
        sum.external_work += external_work;
        sum.contact_work += total_contact - friction_work;
        sum.friction_work += friction_work;
        sum.exact &= lifts_zero;
        report.kinetic_dissipation += kinetic_dissipation;
        report.elastic_dissipation += elastic_dissipation;
        report.last = sub.report;
        self.cumulative_friction += friction_work;
        // shift the levels
        self.slip_speed = slip_speeds(self.nl.geometry(), &sub.disp, &self.disp, h);
        self.pressure.clone_from(&sub.result.solution.lambda_n);
        if self.pressure.len() != self.slip_speed.len() {
            self.pressure.resize(self.slip_speed.len(), 0.0);
        }
        self.u_prev = std::mem::replace(&mut self.u, sub.u);
        self.lifts_prev = std::mem::replace(&mut self.lifts, sub.lifts);
        self.disp_prev = std::mem::replace(&mut self.disp, sub.disp);
        self.stored_energy = sub.stored_energy;
        self.h_prev = h;
        self.time = t_new;
        self.balance.kinetic = kinetic;
        self.last = Some(sub.result);
        Ok(())
    }

    /// Runs `n_steps` steps ([`Self::step`]).
    ///
    /// # Errors
    /// The first error of a step.
    pub fn run(
        &mut self,
        model: &Model<D>,
        solver: &dyn ContactSolver,
        n_steps: usize,
    ) -> Result<Vec<StepRecord>, TimeError> {
        (0..n_steps).map(|_| self.step(model, solver)).collect()
    }

    /// The record of the current level (energies, zero contact figures): row 0 of a results
    /// table.
    pub fn initial_record(&self) -> StepRecord {
        StepRecord {
            step: self.step,
            time: self.time,
            pairs: empty_pair_records(self.nl.geometry()),
            kinetic_energy: self.balance.kinetic,
            strain_energy: self.stored_energy,
            cumulative_friction_dissipation: self.cumulative_friction,
            ..Default::default()
        }
    }

    /// `Σ_T v_Tᵀ M_T v_T` for a full nodal field.
    fn full_mass_form(&self, model: &Model<D>, v: &[Vec<Vector<D>>]) -> Real {
        let lumped = self.params.mass == MassKind::Lumped;
        full_form(model, v, |b, geo, out| mass_into(geo, self.bodies[b].density, lumped, out))
    }

    /// `Σ_T v_Tᵀ (M_α + A⁽¹⁾)_T v_T` for a full nodal field.
    fn full_damping_form(&self, model: &Model<D>, v: &[Vec<Vector<D>>]) -> Real {
        let lumped = self.params.mass == MassKind::Lumped;
        full_form(model, v, |b, geo, out| {
            let data = &self.bodies[b];
            damping_into(geo, data.damping, data.viscous.as_ref(), lumped, out);
        })
    }

    /// Current step index `i`.
    pub fn step_index(&self) -> usize {
        self.step
    }
    /// Current time `t_i`.
    pub fn time(&self) -> Real {
        self.time
    }
    /// The time step `Δt`.
    pub fn dt(&self) -> Real {
        self.params.dt
    }
    /// The parameters.
    pub fn params(&self) -> &DynamicParams {
        &self.params
    }
    /// The kinematics of the bodies.
    pub fn kinematics(&self) -> &[Kinematics] {
        self.nl.kinematics()
    }
    /// Nodal displacements `U^i` per body.
    pub fn displacement(&self) -> &[Vec<Vector<D>>] {
        &self.disp
    }
    /// Reduced unknowns `ũ^i`.
    pub fn reduced_displacement(&self) -> &[Real] {
        &self.u
    }
    /// Nodal velocities `V^i = (U^i − U^{i−1})/h_i` per body.
    pub fn velocity(&self) -> Vec<Vec<Vector<D>>> {
        nodal_diff(&self.disp, &self.disp_prev, 1.0 / self.h_prev)
    }
    /// The discrete energy `E^i = ½ ‖V^i‖²_{M_ρ} + Π(U^i)` of the current level.
    pub fn energy(&self) -> Real {
        self.balance.kinetic + self.stored_energy
    }
    /// The stored energy `Π(U^i) = Σ_T |T| Φ(e)`.
    pub fn stored_energy(&self) -> Real {
        self.stored_energy
    }
    /// The terms of the energy identity of the last step (module docs), summed over its
    /// sub-steps: `strain` is `Π`, `numerical_dissipation` is `D_kin + D_Π`,
    /// `contact_work` the work of the normal contact forces.
    pub fn energy_balance(&self) -> &EnergyBalance {
        &self.balance
    }
    /// What the last step did (sub-steps, cut-backs, Newton iterations, `D_kin`, `D_Π`).
    pub fn last_report(&self) -> &NonlinearStepReport {
        &self.report
    }
    /// The contact result of the last sub-step (physical multipliers, KKT residuals of its
    /// last linearised contact problem, nodal displacements); `None` before the first step.
    pub fn last_contact(&self) -> Option<&StaticContactResult<D>> {
        self.last.as_ref()
    }
    /// Physical contact pressure `λ_n` per contact node at the current level.
    pub fn pressure(&self) -> &[Real] {
        &self.pressure
    }
    /// The contact geometry of the last Newton iteration.
    pub fn geometry(&self) -> &ContactGeometry<D> {
        self.nl.geometry()
    }
    /// The dof map.
    pub fn dofs(&self) -> &DofMap<D> {
        self.nl.dofs()
    }
    /// `M̃_ρ`.
    pub fn mass_matrix(&self) -> &SymmetricMatrix {
        &self.mass
    }
    /// `M̃_α + Ã⁽¹⁾`.
    pub fn damping_matrix(&self) -> &SymmetricMatrix {
        &self.damping
    }
    /// The Newton iteration (its geometry, factorisation and state).
    pub fn nonlinear(&self) -> &NonlinearContact<D> {
        &self.nl
    }
}

/// `(M + h C)/h²` on one pattern.
fn combined(mass: &SymmetricMatrix, damping: &SymmetricMatrix, h: Real) -> Result<SymmetricMatrix, FemError> {
    let mut b = mass.clone();
    b.add_scaled(h, damping)?;
    b.values_mut().iter_mut().for_each(|v| *v /= h * h);
    Ok(b)
}
