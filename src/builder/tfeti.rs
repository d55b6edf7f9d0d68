//! The contact solver `"tfeti"` behind the builder: static and quasi-static analyses of the
//! model decomposed into subdomains ([`synovia_feti`], docs/scale-out.md), without ever
//! factorising the undecomposed stiffness.
//!
//! The other solvers sit behind the [`ContactSolver`](synovia_contact::ContactSolver) seam,
//! which hands them the factorised operator `A` of the whole model. TFETI needs the subdomain
//! stiffnesses instead, so [`JointModel`] runs it through its own level loop
//! ([`JointModel::run_on`]): a [`Decomposition`] of the model (each rank of the
//! [`Communicator`] factorises the subdomains it owns), then at every time level the load `F`,
//! the normal rows and — from the pressures of the previous level — the Tresca rows, solved by
//! [`synovia_feti::solve`]. The scheme is the quasi-static one of docs/model.md §7
//! ([`synovia_time::quasistatic`]): step 0 frictionless (with
//! [`QuasiStaticParams::initial_friction`](synovia_time::quasistatic::QuasiStaticParams) a
//! Tresca solve at `t_0` with `g_c` from it), step `i ≥ 1` Tresca with
//! `g_c = F_c(v) |Λ_n(t_{i−1})|` (the pairs' friction laws) and slip measured from
//! `U(t_{i−1})`, optionally the Coulomb fixed point per level. The observer sees the same
//! [`StepView`] as with the other solvers (nodal displacements, `Λ_n`, `Λ_t`, friction cells,
//! and the KKT residuals evaluated with the stiffness applied cell by cell), so output and
//! records are those of a direct run.
//!
//! What TFETI does not treat is refused with [`JointError::Unsupported`] naming the feature
//! ([`JointModel::tfeti_support`]): dynamic analyses, nonlinear materials and finite strain,
//! rigid bodies with mixed control, bodies held only by contact (semi-coercive), and the
//! re-solve sessions and contact-solver uses that need the assembled operator.

use std::sync::Arc;
use std::time::Instant;

use nalgebra::DMatrix;
use synovia_contact::operators::{ContactGeometry, FrictionOperator};
use synovia_contact::{
    check_kkt, slip_speeds, ContactProblem, ContactSolution, FrictionConstraints, PairFrictionLaws,
    SolverReport, StaticContactResult,
};
use synovia_fem::assembly::{add_loads, body_stiffnesses, subtract_lift};
use synovia_fem::element::{stiffness_into, SimplexGeometry};
use synovia_fem::{DofMap, Model};
use synovia_feti::{Communicator, Decomposition, DecompositionParams, TfetiParams};
use synovia_linalg::{FactorisedOperator, LinalgError};
use synovia_mesh::math::{Real, Vector};
use synovia_time::results::{pair_records, StepRecord};

use super::{check_levels, Analysis, JointError, JointModel, RunResult, StepView};

/// The name of the TFETI solver ([`JointModel::solver`], scenario `solver.name`).
pub const TFETI: &str = "tfeti";

/// The parameters of the `"tfeti"` solver: how the model is cut and how the dual problem is
/// solved ([`JointModel::tfeti`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct TfetiSettings {
    /// Subdomains, partitioner, gluing.
    pub decomposition: DecompositionParams,
    /// Tolerance, penalty `ρ`, preconditioner, iteration limits of SMALBE and MPRGP/MPGP.
    pub params: TfetiParams,
}

impl TfetiSettings {
    /// The settings with `decomposition` and `params`.
    pub fn new(decomposition: DecompositionParams, params: TfetiParams) -> Self {
        Self { decomposition, params }
    }
}

/// `A x` of the reduced stiffness `A = Pᵀ K P` of a linear model, applied cell by cell (no
/// matrix is stored): for the KKT check of a TFETI solution. It cannot solve.
#[derive(Debug)]
struct CellStiffness<'a, const D: usize> {
    model: &'a Model<D>,
    dofs: &'a DofMap<D>,
    stiffness: Vec<DMatrix<Real>>,
    zero_lifts: Vec<Vector<D>>,
}

impl<const D: usize> CellStiffness<'_, D> {
    /// `Σ_T K_T u_T` per node, for the nodal displacements `u` (`diagonal`: only the diagonal
    /// of each `K_T`, with `u` all ones).
    fn nodal_forces(&self, u: &[Vec<Vector<D>>], diagonal: bool) -> Vec<Vec<Vector<D>>> {
        let n = D * (D + 1);
        let mut ke = vec![0.0; n * n];
        let mut out: Vec<Vec<Vector<D>>> = Vec::with_capacity(u.len());
        for (b, body) in self.model.bodies().iter().enumerate() {
            let mut f = vec![Vector::<D>::zeros(); body.mesh.n_nodes()];
            for c in 0..body.mesh.n_cells() {
                let Some(geo) = SimplexGeometry::new(&body.mesh.cell_points(c)) else { continue };
                stiffness_into(&geo, &self.stiffness[b], &mut ke);
                let cell = body.mesh.cell(c);
                for (a, &na) in cell.iter().enumerate() {
                    for i in 0..D {
                        let row = (D * a + i) * n;
                        let mut s = 0.0;
                        if diagonal {
                            s = ke[row + D * a + i];
                        } else {
                            for (bb, &nb) in cell.iter().enumerate() {
                                for j in 0..D {
                                    s += ke[row + D * bb + j] * u[b][nb][j];
                                }
                            }
                        }
                        f[na][i] += s;
                    }
                }
            }
            out.push(f);
        }
        out
    }
}

impl<const D: usize> FactorisedOperator for CellStiffness<'_, D> {
    fn n(&self) -> usize {
        self.dofs.n_dofs()
    }
    fn apply(&self, x: &[f64]) -> Vec<f64> {
        match self.dofs.expand(x, &self.zero_lifts) {
            Ok(u) => self.dofs.restrict(&self.nodal_forces(&u, false)),
            Err(_) => vec![f64::NAN; self.n()],
        }
    }
    fn diagonal(&self) -> Vec<f64> {
        // diag(Pᵀ K P)_k = Σ_nodes of the group N_kᵀ diag(K) N_k (the off-diagonal couplings
        // between the nodes of a tied group are left out: an estimate, not used by the check)
        let ones: Vec<Vec<Vector<D>>> =
            self.model.bodies().iter().map(|b| vec![Vector::<D>::repeat(1.0); b.mesh.n_nodes()]).collect();
        let d = self.nodal_forces(&ones, true);
        let mut out = vec![0.0; self.n()];
        for (b, body) in d.iter().enumerate() {
            for (node, v) in body.iter().enumerate() {
                let g = &self.dofs.groups()[self.dofs.group_of(synovia_fem::BodyId(b), node)];
                for k in 0..g.n_dofs {
                    out[g.first_dof + k] +=
                        g.basis[k].iter().zip(v.iter()).map(|(n, a)| n * n * a).sum::<f64>();
                }
            }
        }
        out
    }
    fn key(&self) -> u64 {
        0
    }
    fn solve_in_place(&self, _b: &mut [f64]) -> Result<(), LinalgError> {
        Err(LinalgError::Sparse("the TFETI KKT operator applies the stiffness only; it cannot solve".into()))
    }
}

/// One level's problem in the model's reduced unknowns: `F`, the lifts, the normal rows and the
/// Tresca rows (with their cells).
struct Level<const D: usize> {
    load: Vec<f64>,
    lifts: Vec<Vector<D>>,
    normal: synovia_contact::NormalConstraints,
    friction: Option<FrictionOperator>,
}

impl<const D: usize> Level<D> {
    fn friction(&self) -> Option<&FrictionConstraints> {
        self.friction.as_ref().map(|f| &f.constraints).filter(|f| f.rows.nrows() > 0)
    }
}

/// What the TFETI level loop keeps between levels.
struct Runner<'a, const D: usize> {
    joint: &'a JointModel<D>,
    comm: &'a dyn Communicator,
    decomposition: Decomposition,
    dofs: DofMap<D>,
    geometry: ContactGeometry<D>,
    laws: PairFrictionLaws,
    stiffness: Vec<DMatrix<Real>>,
    settings: TfetiSettings,
}

impl<const D: usize> Runner<'_, D> {
    fn level(
        &self,
        t: Real,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
    ) -> Result<Level<D>, JointError> {
        let model = self.joint.model();
        let lifts = self.dofs.lifts(model, t)?;
        let mut load = vec![0.0; self.dofs.n_dofs()];
        add_loads(model, &self.dofs, t, self.joint.elastic_params.load_degree, &mut load)?;
        let c = &self.stiffness;
        subtract_lift(model, &self.dofs, &lifts, &mut load, |b, _, geo, out| {
            stiffness_into(geo, &c[b], out)
        })?;
        let normal = self.geometry.normal_constraints(&self.dofs, &lifts);
        let friction = match slip_bound {
            Some(g) => Some(self.geometry.friction_constraints(&self.dofs, &lifts, g, previous)?),
            None => None,
        };
        Ok(Level { load, lifts, normal, friction })
    }

    /// The contact problem at `t` with the slip bounds `slip_bound` (frictionless: `None`),
    /// slip measured from `previous`, solved by TFETI; the result as a direct solve returns it.
    fn solve(
        &self,
        t: Real,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
    ) -> Result<StaticContactResult<D>, JointError> {
        let level = self.level(t, slip_bound, previous)?;
        let friction = level.friction();
        let s = synovia_feti::solve(
            &self.decomposition,
            self.comm,
            &level.load,
            &level.normal,
            friction,
            &self.settings.params,
        )?;
        let model = self.joint.model();
        let operator = CellStiffness {
            model,
            dofs: &self.dofs,
            stiffness: self.stiffness.clone(),
            zero_lifts: vec![Vector::<D>::zeros(); self.dofs.groups().len()],
        };
        let problem = ContactProblem {
            operator: &operator,
            load: &level.load,
            normal: &level.normal,
            friction,
            border: None,
        };
        let kkt = check_kkt(&problem, &s.u, &s.lambda_n, &s.lambda_t);
        let components = friction.map_or(1, |f| f.components.max(1));
        let (active, stick, slip) = contact_counts(&s.lambda_n, &s.lambda_t, components);
        let displacement = self.dofs.expand(&s.u, &level.lifts)?;
        let (cell_node, slip_bound) = match level.friction {
            Some(op) if !s.lambda_t.is_empty() => (op.cell_node, op.slip_bound),
            _ => (Vec::new(), Vec::new()),
        };
        let r = &s.report;
        Ok(StaticContactResult {
            displacement,
            solution: ContactSolution {
                u: s.u,
                lambda_n: s.lambda_n,
                lambda_t: s.lambda_t,
                report: SolverReport {
                    solver: TFETI.into(),
                    iterations: r.outer_iterations,
                    inner_iterations: r.inner_iterations,
                    linear_solves: r.f_products,
                    active,
                    stick,
                    slip,
                    time_s: r.setup_s + r.solve_s,
                    ..Default::default()
                },
            },
            cell_node,
            slip_bound,
            kkt,
            coarse_iterations: 0,
            proximal_iterations: 0,
        })
    }

    /// One Tresca level with `g`, or with the Coulomb fixed point (slip rates from
    /// `rate_from = (U(t_{i−1}), Δt)`): as `QuasiStaticStepper`.
    fn tresca(
        &self,
        step: usize,
        t: Real,
        mut g: Vec<Real>,
        origin: Option<&[Vec<Vector<D>>]>,
        rate_from: Option<(&[Vec<Vector<D>>], Real)>,
    ) -> Result<(StaticContactResult<D>, usize), JointError> {
        let qs = &self.joint.quasistatic_params;
        let max = if qs.coulomb_fixed_point { qs.max_fixed_point } else { 1 };
        let mut iterations = 0;
        let mut change = Real::INFINITY;
        for _ in 0..max {
            let res = self.solve(t, Some(&g), origin)?;
            iterations += res.solution.report.iterations;
            if !qs.coulomb_fixed_point {
                return Ok((res, iterations));
            }
            let rate = match rate_from {
                Some((prev, dt)) => slip_speeds(&self.geometry, &res.displacement, prev, dt),
                None => vec![0.0; self.geometry.len()],
            };
            let g_new = self.laws.slip_bounds(&self.geometry, &res.solution.lambda_n, &rate);
            let scale = g_new.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            let diff = g.iter().zip(&g_new).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            change = if scale > 0.0 { diff / scale } else { diff };
            if change <= qs.fixed_point_tolerance {
                return Ok((res, iterations));
            }
            g = g_new;
        }
        Err(JointError::Time(synovia_time::TimeError::FixedPoint { step, iterations: max, change }))
    }
}

/// The refusal of a dynamic analysis by `"tfeti"`.
fn dynamic_unsupported() -> JointError {
    JointError::Unsupported {
        solver: TFETI.into(),
        feature:
            "dynamic analyses (it solves static and quasi-static ones; choose another solver for `dynamic`)"
                .into(),
    }
}

/// `(active normal rows, sticking cells, slipping cells)` of a solution.
fn contact_counts(lambda_n: &[f64], lambda_t: &[f64], components: usize) -> (usize, usize, usize) {
    let active = lambda_n.iter().filter(|&&l| l > 0.0).count();
    let (mut stick, mut slip) = (0, 0);
    for c in lambda_t.chunks(components) {
        if c.iter().map(|v| v * v).sum::<f64>().sqrt() < 1.0 - 1e-8 {
            stick += 1;
        } else {
            slip += 1;
        }
    }
    (active, stick, slip)
}

impl<const D: usize> JointModel<D> {
    /// Sets the parameters of the `"tfeti"` solver (subdomains, partitioner, preconditioner,
    /// tolerance, penalty); they take effect when the solver is `"tfeti"`
    /// ([`JointModel::solver`]).
    pub fn tfeti(&mut self, settings: TfetiSettings) -> &mut Self {
        self.tfeti = settings;
        self
    }

    /// The parameters of the `"tfeti"` solver.
    pub fn tfeti_settings(&self) -> TfetiSettings {
        self.tfeti
    }

    /// `true` when the contact solver is `"tfeti"` (the model is solved decomposed).
    pub fn uses_tfeti(&self) -> bool {
        self.solver == TFETI
    }

    /// Checks that the `"tfeti"` solver can run this model with its analysis (the one set with
    /// [`JointModel::set_analysis`], if any).
    ///
    /// # Errors
    /// [`JointError::Unsupported`] naming the first feature TFETI does not treat: a dynamic
    /// analysis, a nonlinear material or finite strain, rigid bodies with mixed control, bodies
    /// held only by contact; the dof map's errors.
    pub fn tfeti_support(&self) -> Result<(), JointError> {
        let unsupported = |feature: String| Err(JointError::Unsupported { solver: TFETI.into(), feature });
        if matches!(self.analysis, Some(Analysis::Dynamic { .. })) {
            return Err(dynamic_unsupported());
        }
        if let Some(b) = self.model.bodies().iter().find(|b| b.material.linear_stiffness().is_none()) {
            return unsupported(format!(
                "nonlinear materials (body `{}`: `{}`); it solves linear elasticity",
                b.name,
                b.material.name()
            ));
        }
        if let Some(i) = self.kinematics.iter().position(|k| *k == synovia_fem::Kinematics::FiniteStrain) {
            let name = self.model.bodies().get(i).map_or("?", |b| b.name.as_str());
            return unsupported(format!("finite strain (body `{name}`); it solves small-strain elasticity"));
        }
        if let Some(r) = self.rigid_bodies.first() {
            return unsupported(format!(
                "rigid bodies with mixed control (rigid body `{}`); prescribe the partner as a rigid obstacle or choose another solver",
                r.name
            ));
        }
        let floating: Vec<String> = DofMap::new(&self.model)?
            .floating_components(&self.model)
            .into_iter()
            .flat_map(|c| c.bodies)
            .collect();
        if !floating.is_empty() {
            return unsupported(format!(
                "bodies held only by contact (semi-coercive: {}); its subdomains' rigid-body modes must be fixed by Dirichlet or symmetry conditions",
                floating.iter().map(|b| format!("`{b}`")).collect::<Vec<_>>().join(", ")
            ));
        }
        Ok(())
    }

    /// Runs the analysis set with [`JointModel::set_analysis`] with the subdomains of the
    /// `"tfeti"` solver shared among the ranks of `comm` (each rank factorises only the
    /// subdomains it owns; only interface data travel). Collective: every rank builds the same
    /// model and calls it; every rank gets the same result (bitwise, for any number of ranks:
    /// docs/scale-out.md) and its observer is called after every step — a program writes
    /// output on one rank only. With one process ([`SingleProcess`](synovia_feti::SingleProcess)) it is
    /// [`JointModel::run_with`].
    ///
    /// # Errors
    /// As [`JointModel::run_with`]; [`JointError::Unsupported`] for more than one rank with a
    /// solver other than `"tfeti"`, and for what TFETI does not treat
    /// ([`JointModel::tfeti_support`]); TFETI's errors ([`JointError::Feti`]).
    pub fn run_on(
        &self,
        comm: &dyn Communicator,
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        if !self.uses_tfeti() {
            if comm.size() > 1 {
                return Err(JointError::Unsupported {
                    solver: self.solver.clone(),
                    feature: format!(
                        "runs on {} MPI ranks (only `{TFETI}` distributes its work; run it in one process)",
                        comm.size()
                    ),
                });
            }
            return self.run_with(observer);
        }
        self.check_penetration_policy()?;
        let times = match self.analysis.clone() {
            None => return Err(JointError::Invalid("no analysis set (use set_analysis)".into())),
            Some(Analysis::Static { time }) => vec![time],
            Some(Analysis::QuasiStatic { times }) => times,
            Some(Analysis::Dynamic { .. }) => return Err(dynamic_unsupported()),
        };
        let log = |v: &StepView<'_, D>| {
            tracing::debug!(
                step = v.record.step,
                time = v.record.time,
                iterations = v.record.iterations,
                kkt = if v.geometry.is_empty() { 0.0 } else { v.result.kkt.max() },
                step_s = v.record.step_s,
                solver = TFETI,
                "step {} of {} done",
                v.record.step + 1,
                v.n_steps
            );
        };
        self.run_tfeti_levels(&times, comm, |v| {
            log(v);
            observer(v)
        })
    }

    /// The static or quasi-static levels `times` by TFETI (module docs).
    pub(super) fn run_tfeti_levels(
        &self,
        times: &[Real],
        comm: &dyn Communicator,
        mut observer: impl FnMut(&StepView<'_, D>) -> Result<(), JointError>,
    ) -> Result<RunResult<D>, JointError> {
        let start = Instant::now();
        check_levels(times)?;
        self.model.validate()?;
        self.tfeti_support()?;
        let decomposition = Decomposition::new(&self.model, &self.tfeti.decomposition, comm)?;
        let dofs = DofMap::new(&self.model)?;
        let geometry = ContactGeometry::new(&self.model, &self.pairs)?;
        let mut laws = PairFrictionLaws::new(&geometry);
        for (pair, law) in &self.friction_laws {
            laws.set(pair, Arc::clone(law))?;
        }
        let runner = Runner {
            joint: self,
            comm,
            decomposition,
            dofs,
            geometry,
            laws,
            stiffness: body_stiffnesses(&self.model)?,
            settings: self.tfeti,
        };
        let setup_s = start.elapsed().as_secs_f64();
        let geometry = &runner.geometry;
        let qs = self.quasistatic_params;
        let n_steps = times.len();
        let mut records = Vec::with_capacity(n_steps);
        let mut last: Option<StaticContactResult<D>> = None;
        let mut slip_rate = vec![0.0; geometry.len()];
        let mut cumulative = 0.0;
        let mut last_time: Option<Real> = None;
        for (step, &t) in times.iter().enumerate() {
            let t_step = Instant::now();
            let dt = last_time.map_or(0.0, |l| t - l);
            let previous = last.as_ref();
            let (result, iterations) = match previous {
                None => {
                    let pre = runner.solve(t, None, None)?;
                    let its = pre.solution.report.iterations;
                    if qs.initial_friction && runner.laws.any_friction(geometry) {
                        let rest = vec![0.0; geometry.len()];
                        let g = runner.laws.slip_bounds(geometry, &pre.solution.lambda_n, &rest);
                        let (res, more) = runner.tresca(0, t, g, None, None)?;
                        (res, its + more)
                    } else {
                        (pre, its)
                    }
                }
                Some(prev) => {
                    let g = runner.laws.slip_bounds(geometry, &prev.solution.lambda_n, &slip_rate);
                    let origin = qs.incremental_slip.then_some(prev.displacement.as_slice());
                    runner.tresca(step, t, g, origin, Some((prev.displacement.as_slice(), dt)))?
                }
            };
            let prev_u = previous.map(|p| p.displacement.as_slice());
            slip_rate = match prev_u {
                Some(p) => slip_speeds(geometry, &result.displacement, p, dt),
                None => vec![0.0; geometry.len()],
            };
            let dissipation = synovia_time::quasistatic::friction_dissipation(geometry, &result, prev_u)?;
            cumulative += dissipation;
            let record = StepRecord {
                step,
                time: t,
                pairs: pair_records(geometry, &result),
                friction_dissipation: dissipation,
                cumulative_friction_dissipation: cumulative,
                strain_energy: synovia_fem::post::total_strain_energy(&self.model, &result.displacement)?,
                iterations,
                step_s: t_step.elapsed().as_secs_f64(),
                solver: TFETI.into(),
                ..Default::default()
            };
            observer(&StepView { model: &self.model, geometry, record: &record, result: &result, n_steps })?;
            records.push(record);
            last_time = Some(t);
            last = Some(result);
        }
        Ok(RunResult {
            records,
            displacement: last.as_ref().map(|r| r.displacement.clone()).unwrap_or_default(),
            contact: if self.pairs.is_empty() { None } else { last },
            n_dofs: runner.dofs.n_dofs(),
            contact_nodes: geometry.len(),
            solver: TFETI.into(),
            setup_s,
            total_s: start.elapsed().as_secs_f64(),
        })
    }

    /// [`JointModel::check`] for the `"tfeti"` solver: the support check, the dofs and the
    /// contact geometry (no factorisation of the whole model, so no memory estimate: the
    /// estimate's `dofs` only).
    pub(super) fn check_tfeti(&self) -> Result<super::SetupInfo, JointError> {
        self.model.validate()?;
        self.tfeti_support()?;
        let dofs = DofMap::new(&self.model)?;
        let geometry = ContactGeometry::new(&self.model, &self.pairs)?;
        let penetration = self.penetration_in(&geometry);
        self.refused(&penetration)?;
        Ok(super::SetupInfo {
            n_dofs: dofs.n_dofs(),
            memory: synovia_linalg::cholesky::MemoryEstimate {
                dofs: dofs.n_dofs(),
                factor_entries: 0,
                factor_bytes: 0,
                workspace_bytes: 0,
                trailing_bytes: 0,
            },
            contact_nodes: geometry.pairs.iter().map(|(n, r)| (n.clone(), r.len())).collect(),
            penetration,
            floating_bodies: Vec::new(),
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use synovia_contact::operators::PlaneObstacle;
    use synovia_contact::ExponentialFriction;
    use synovia_material::plane_strain;
    use synovia_mesh::generators::{rectangle, Grading};
    use synovia_mesh::math::Point;
    use synovia_time::history::PiecewiseLinear;
    use synovia_time::quasistatic::QuasiStaticParams;

    /// Two blocks tied on top of each other, the lower one pressed onto a rigid flat and sheared
    /// through the upper one's top (friction 0.4): ties, friction, three quasi-static levels.
    fn stack(solver: &str, params: QuasiStaticParams, law: bool) -> JointModel<2> {
        let mut jm = JointModel::<2>::new();
        let lo = rectangle(-1.0, 1.0, 0.0, 0.5, 12, 3, Grading::Uniform, Grading::Uniform).unwrap();
        let hi = rectangle(-1.0, 1.0, 0.5, 1.0, 12, 3, Grading::Uniform, Grading::Uniform).unwrap();
        let a = jm.add_body("lower", lo, plane_strain(1.0, 0.3).unwrap()).unwrap();
        let b = jm.add_body("upper", hi, plane_strain(3.0, 0.25).unwrap()).unwrap();
        jm.tie(a, "top", b, "bottom").unwrap();
        let h = PiecewiseLinear::new(&[(0.0, 0.4), (1.0, 1.0)]).unwrap();
        jm.prescribe(b, "top", Vector::<2>::new(0.01, -0.02), h).unwrap();
        let floor = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::y()).unwrap();
        jm.contact_rigid("floor", a, "bottom", floor, 0.4).unwrap();
        if law {
            let exp = ExponentialFriction {
                static_coefficient: 0.4,
                kinetic_coefficient: 0.2,
                characteristic_speed: 0.01,
            };
            jm.friction_law("floor", Arc::new(exp)).unwrap();
        }
        jm.quasistatic_params(params);
        jm.solver(solver).unwrap();
        jm.tfeti(TfetiSettings::new(
            DecompositionParams::default().with_subdomains(6),
            TfetiParams::default().with_tolerance(1e-12),
        ));
        jm
    }

    fn max_rel(a: &[Vec<Vector<2>>], b: &[Vec<Vector<2>>]) -> f64 {
        let (mut d, mut s) = (0.0_f64, 0.0_f64);
        for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
            d = d.max((x - y).amax());
            s = s.max(x.amax());
        }
        d / s
    }

    #[test]
    fn tfeti_levels_equal_the_direct_ones() {
        let times = [0.0, 0.5, 1.0];
        for (params, law) in [
            (QuasiStaticParams::default(), false),
            (QuasiStaticParams::default().with_initial_friction(true), true),
            (QuasiStaticParams::default().with_coulomb_fixed_point(true), false),
        ] {
            let direct = stack("pdas", params, law).run_quasistatic(&times).unwrap();
            let feti = stack(TFETI, params, law).run_quasistatic(&times).unwrap();
            assert_eq!(feti.solver, TFETI);
            assert_eq!(feti.n_dofs, direct.n_dofs);
            let du = max_rel(&direct.displacement, &feti.displacement);
            assert!(du < 1e-8, "{params:?} {law}: U differs by {du:e}");
            for (r, s) in direct.records.iter().zip(&feti.records) {
                let (p, q) = (&r.pairs[0], &s.pairs[0]);
                assert!((p.normal_force - q.normal_force).abs() <= 1e-8 * p.normal_force.abs());
                assert!((p.tangential_force - q.tangential_force).abs() <= 1e-8 * p.normal_force.abs());
                assert!(p.tangential_force > 0.0 || r.step == 0);
                assert_eq!(s.solver, TFETI);
            }
            let kkt = feti.contact.as_ref().unwrap().kkt.max();
            assert!(kkt < 1e-8, "{kkt}");
        }
    }

    #[test]
    fn unsupported_features_are_named() {
        // a body held only by contact (no Dirichlet data)
        let mut jm = JointModel::<2>::new();
        let m = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4, Grading::Uniform, Grading::Uniform).unwrap();
        let b = jm.add_body("puck", m, plane_strain(1.0, 0.3).unwrap()).unwrap();
        jm.pressure(b, "top", 0.01, synovia_time::history::Constant(1.0)).unwrap();
        let floor = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::y()).unwrap();
        jm.contact_rigid("floor", b, "bottom", floor, 0.0).unwrap();
        jm.solver(TFETI).unwrap();
        let e = jm.run_static(0.0).unwrap_err();
        assert!(matches!(e, JointError::Unsupported { .. }), "{e}");
        assert!(
            e.to_string().contains("bodies held only by contact") && e.to_string().contains("`puck`"),
            "{e}"
        );
        // dynamic analyses, and uses as a ContactSolver
        let mut jm = stack(TFETI, QuasiStaticParams::default(), false);
        jm.set_analysis(Analysis::Dynamic { dt: 0.1, steps: 1 });
        let e = jm.run().unwrap_err();
        assert!(e.to_string().contains("does not support dynamic analyses"), "{e}");
        let e = jm.run_dynamic(0.1, 1).unwrap_err();
        assert!(matches!(e, JointError::Unsupported { .. }), "{e}");
        assert!(jm.build_solver().is_err() && jm.prepare().is_err());
        // other solvers do not run on several ranks
        struct TwoRanks;
        impl Communicator for TwoRanks {
            fn rank(&self) -> usize {
                0
            }
            fn size(&self) -> usize {
                2
            }
            fn all_gather(&self, _: &[f64], _: &[usize]) -> Result<Vec<f64>, synovia_feti::FetiError> {
                Err(synovia_feti::FetiError::Communication("test".into()))
            }
        }
        let mut jm = stack("pdas", QuasiStaticParams::default(), false);
        jm.set_analysis(Analysis::Static { time: 0.0 });
        let e = jm.run_on(&TwoRanks, |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("the `pdas` solver does not support runs on 2 MPI ranks"), "{e}");
    }
}
