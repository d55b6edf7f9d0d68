//! The Rust side of a C handle: an [`ArrayModel`] (from `synovia-scenario`: a `JointModel`
//! with a global node numbering, integer part tags and live condition values), and the solver
//! state that carries a quasi-static sequence from one call to the next.
//!
//! Nothing here touches raw pointers; `lib.rs` turns C arguments into slices and strings first.

use std::sync::Arc;

use synovia::contact_ops::operators::ContactGeometry;
use synovia::contact_ops::{ContactSolver, StaticContact, StaticContactResult};
use synovia::fem::{ElasticParams, ElasticSolver, Kinematics, OrderingChoice};
use synovia::material::Material;
use synovia::mesh::math::{Real, Vector};
use synovia::nonlinear::{NonlinearContact, NonlinearError, NonlinearResult};
use synovia::time::quasistatic::{QuasiStaticParams, QuasiStaticStepper};
use synovia::time::results::{PairRecord, StepRecord};
use synovia::time::TimeError;
use synovia_scenario::arrays::{
    material_law, ArrayError, ArrayModel, ConditionChange, ConditionKind, ModelArrays,
};
use synovia_scenario::scenario::Scenario;

use crate::{Fail, SynStatus};

/// Contact solver nested iteration default of [`JointModel`](synovia::builder::JointModel)
/// (`Some(32)`).
const DEFAULT_NESTED: Option<usize> = Some(32);

impl From<ArrayError> for Fail {
    fn from(e: ArrayError) -> Self {
        let status = match &e {
            ArrayError::SizeMismatch(_) => SynStatus::SizeMismatch,
            ArrayError::IndexOutOfRange(_) => SynStatus::IndexOutOfRange,
            ArrayError::InvalidArgument(_) => SynStatus::InvalidArgument,
            ArrayError::Rejected(_) => SynStatus::ModelRejected,
        };
        Fail::new(status, e.to_string())
    }
}

/// The solver's parameters (those of [`JointModel`] that it does not expose).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Params {
    pub elastic: ElasticParams,
    pub quasistatic: QuasiStaticParams,
    pub nested: Option<usize>,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            elastic: ElasticParams::default(),
            quasistatic: QuasiStaticParams::default(),
            nested: DEFAULT_NESTED,
        }
    }
}

/// Factorised operator, kept while the model's structure does not change. With contact pairs
/// it is the quasi-static stepper, which also carries the friction state from one step to the
/// next.
enum Solver<const D: usize> {
    Elastic(Box<ElasticSolver<D>>),
    Contact(Box<QuasiStaticStepper<D>>),
    /// A nonlinear material or finite strain: the Newton iteration with load stepping and
    /// cut-back (docs/model.md §2.3), with or without contact pairs.
    Nonlinear(Box<NonlinearContact<D>>),
}

/// The last solution.
pub(crate) struct Solved<const D: usize> {
    pub time: Real,
    pub step: usize,
    pub iterations: usize,
    /// Nodal displacements per body.
    pub displacement: Vec<Vec<Vector<D>>>,
    /// The contact solution (`None` without contact pairs).
    pub result: Option<StaticContactResult<D>>,
    pub pairs: Vec<PairRecord>,
    /// The contact geometry of the solution when it depends on the solution (nonlinear
    /// models: the configuration of the last Newton pass); `None`: the solver's fixed one.
    pub geometry: Option<ContactGeometry<D>>,
}

/// One model behind a handle.
pub(crate) struct State<const D: usize> {
    /// The model with its global node numbering, part tags and live condition values.
    model: ArrayModel<D>,
    params: Params,
    solver: Option<Solver<D>>,
    last: Option<Solved<D>>,
}

/// Figures of the last solve.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Info {
    pub time: Real,
    pub step: usize,
    pub iterations: usize,
    pub kkt: Real,
    pub n_dofs: usize,
    pub contact_nodes: usize,
}

fn finite(v: &[Real], what: &str) -> Result<(), Fail> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Fail::new(SynStatus::InvalidArgument, format!("{what} {v:?} is not finite")))
    }
}

fn check_len(len: usize, expected: usize, what: &str) -> Result<(), Fail> {
    if len == expected {
        Ok(())
    } else {
        Err(Fail::new(SynStatus::SizeMismatch, format!("{what}: got {len} values, expected {expected}")))
    }
}

impl<const D: usize> State<D> {
    /// A model from arrays (see `syn_model_from_arrays`); `material(E, ν)` makes the material
    /// of a body.
    pub fn from_arrays(
        a: &ModelArrays<'_>,
        material: impl Fn(Real, Real) -> Result<Arc<dyn Material<D>>, synovia::material::MaterialError>,
    ) -> Result<Self, Fail> {
        Ok(Self::new(ArrayModel::from_arrays(a, material)?, Params::default()))
    }

    fn new(model: ArrayModel<D>, params: Params) -> Self {
        Self { model, params, solver: None, last: None }
    }

    /// A model from a scenario (its bodies, parts, conditions, pairs and solver; the analysis
    /// is left to the caller). Parts are tagged 0, 1, … body by body in file order; nodes are
    /// numbered body by body.
    pub fn from_scenario(sc: &Scenario) -> Result<Self, Fail> {
        let built = synovia_scenario::build::build::<D>(sc)
            .map_err(|e| Fail::new(SynStatus::Scenario, e.to_string()))?;
        let model = ArrayModel::from_joint(built.joint);
        // the solver parameters that the scenario gave the JointModel
        let mut params = Params::default();
        if let Some(s) = &sc.doc.solver {
            let s = s.get_ref();
            if let Some(n) = &s.nested_iteration {
                let v = *n.get_ref();
                params.nested = (v > 0).then_some(v);
            }
            if let Some(o) = &s.ordering {
                params.elastic.ordering = match o.get_ref().as_str() {
                    "amd" => OrderingChoice::Amd,
                    "metis" => OrderingChoice::Metis,
                    _ => OrderingChoice::Auto,
                };
            }
            if let Some(d) = &s.load_degree {
                params.elastic.load_degree = *d.get_ref();
            }
        }
        let a = sc.doc.analysis.get_ref();
        let q = &mut params.quasistatic;
        if let Some(v) = &a.coulomb_fixed_point {
            q.coulomb_fixed_point = *v.get_ref();
        }
        if let Some(v) = &a.max_fixed_point {
            q.max_fixed_point = *v.get_ref();
        }
        if let Some(v) = &a.fixed_point_tolerance {
            q.fixed_point_tolerance = *v.get_ref();
        }
        if let Some(v) = &a.incremental_slip {
            q.incremental_slip = *v.get_ref();
        }
        if let Some(v) = &a.initial_friction {
            q.initial_friction = *v.get_ref();
        }
        Ok(Self::new(model, params))
    }

    pub fn n_nodes(&self) -> usize {
        self.model.n_nodes()
    }
    pub fn n_pairs(&self) -> usize {
        self.model.joint().pairs().len()
    }

    /// The tag of `part` of body `body`.
    pub fn part_tag(&self, body: &str, part: &str) -> Result<i32, Fail> {
        Ok(self.model.part_tag(body, part)?)
    }

    /// Forgets the factorisation and the last solution (the model's structure changed).
    fn invalidate(&mut self) {
        self.solver = None;
        self.last = None;
    }

    /// Sets (first call: creates) a condition with values `v` on part `tag`.
    pub fn set_condition(&mut self, tag: i32, kind: ConditionKind, v: &[Real]) -> Result<(), Fail> {
        if self.model.set_condition(tag, kind, v)? == ConditionChange::Created {
            self.invalidate();
        }
        Ok(())
    }

    /// A body–body pair (`segment`: node-to-segment, else node-to-node); returns its index.
    pub fn add_contact(
        &mut self,
        slave: i32,
        master: i32,
        segment: bool,
        friction: Real,
    ) -> Result<usize, Fail> {
        let i = self.model.add_contact(slave, master, segment, friction)?;
        self.invalidate();
        Ok(i)
    }

    /// A pair against the rigid plane through `point` with normal `normal`.
    pub fn add_contact_plane(
        &mut self,
        tag: i32,
        point: &[Real],
        normal: &[Real],
        friction: Real,
    ) -> Result<usize, Fail> {
        let i = self.model.add_contact_plane(tag, point, normal, friction)?;
        self.invalidate();
        Ok(i)
    }

    /// Body `body` gets the law `law` with `constants` ([`material_law`]); the factorisation
    /// and the last solution are discarded.
    pub fn set_material(&mut self, body: usize, law: &str, constants: &[Real]) -> Result<(), Fail> {
        let material = material_law::<D>(law, constants)?;
        self.model.set_material(body, material)?;
        self.invalidate();
        Ok(())
    }

    /// Body `body`'s strain kinematics: `"small"` or `"finite"`; the factorisation and the
    /// last solution are discarded.
    pub fn set_kinematics(&mut self, body: usize, kinematics: &str) -> Result<(), Fail> {
        let k = match kinematics {
            "small" => Kinematics::SmallStrain,
            "finite" => Kinematics::FiniteStrain,
            other => {
                return Err(Fail::new(
                    SynStatus::InvalidArgument,
                    format!("kinematics is `small` or `finite`, got `{other}`"),
                ))
            }
        };
        self.model.set_kinematics(body, k)?;
        self.invalidate();
        Ok(())
    }

    pub fn set_solver(&mut self, name: &str) -> Result<(), Fail> {
        Ok(self.model.set_solver(name)?)
    }

    fn build(&mut self) -> Result<(), Fail> {
        if self.solver.is_some() {
            return Ok(());
        }
        let model = self.model.joint().model();
        model.validate().map_err(|e| Fail::new(SynStatus::ModelRejected, e.to_string()))?;
        let joint = self.model.joint();
        let solver = if joint.is_nonlinear() {
            Solver::Nonlinear(Box::new(
                NonlinearContact::new(
                    model,
                    joint.pairs(),
                    joint.kinematics(),
                    self.params.elastic,
                    joint.newton_parameters(),
                )
                .map_err(|e| Fail::new(SynStatus::ModelRejected, e.to_string()))?,
            ))
        } else if joint.pairs().is_empty() {
            Solver::Elastic(Box::new(
                ElasticSolver::new(model, self.params.elastic)
                    .map_err(|e| Fail::new(SynStatus::ModelRejected, e.to_string()))?,
            ))
        } else {
            let mut c = StaticContact::new(model, self.model.joint().pairs(), self.params.elastic)
                .map_err(|e| Fail::new(SynStatus::ModelRejected, e.to_string()))?;
            c.set_nested_iteration(self.params.nested);
            let stepper = QuasiStaticStepper::from_contact(model, c, self.params.quasistatic)
                .map_err(|e| Fail::new(SynStatus::InvalidArgument, e.to_string()))?;
            Solver::Contact(Box::new(stepper))
        };
        self.solver = Some(solver);
        Ok(())
    }

    fn contact_solver(&self) -> Result<Box<dyn ContactSolver>, Fail> {
        self.model.joint().build_solver().map_err(|e| Fail::new(SynStatus::InvalidArgument, e.to_string()))
    }

    /// The static problem at `t` (step 0 of the quasi-static scheme); starts a new sequence.
    pub fn solve_static(&mut self, t: Real) -> Result<(), Fail> {
        finite(&[t], "time")?;
        self.build()?;
        let cs = self.contact_solver()?;
        let model = self.model.joint().model();
        let solved = match &mut self.solver {
            Some(Solver::Elastic(e)) => {
                let sol = e.solve(model, t).map_err(|e| Fail::new(SynStatus::SolveFailed, e.to_string()))?;
                Solved {
                    time: t,
                    step: 0,
                    iterations: 0,
                    displacement: sol.displacement,
                    result: None,
                    pairs: Vec::new(),
                    geometry: None,
                }
            }
            Some(Solver::Contact(stepper)) => {
                // a new sequence, cold-started; a failure keeps the previous one
                let (record, result) = stepper.restart(model, t, cs.as_ref(), false).map_err(solve_failed)?;
                solved_from(record, result)
            }
            Some(Solver::Nonlinear(nl)) => {
                // from the unloaded reference, the load ramped to its value at `t`; a failure
                // restores the state of the previous solution
                let kept = nl.checkpoint();
                nl.reset(t);
                match nl.step_to(model, t, cs.as_ref()) {
                    Ok(level) => solved_nonlinear(nl, &level, 0),
                    Err(e) => {
                        nl.restore(kept).map_err(nonlinear_failed)?;
                        return Err(nonlinear_failed(e));
                    }
                }
            }
            None => return Err(Fail::new(SynStatus::Panic, "no solver after build")),
        };
        self.last = Some(solved);
        Ok(())
    }

    /// One quasi-static step to `t` from the last solution (or the static problem if there is
    /// none).
    pub fn solve_step(&mut self, t: Real) -> Result<(), Fail> {
        finite(&[t], "time")?;
        let Some(prev) = self.last.take() else {
            return self.solve_static(t);
        };
        if t <= prev.time {
            let msg = format!("time {t} must be later than the last solution's time {}", prev.time);
            self.last = Some(prev);
            return Err(Fail::new(SynStatus::InvalidArgument, msg));
        }
        let r = self.step_from(&prev, t);
        match r {
            Ok(s) => {
                self.last = Some(s);
                Ok(())
            }
            Err(e) => {
                self.last = Some(prev);
                Err(e)
            }
        }
    }

    fn step_from(&mut self, prev: &Solved<D>, t: Real) -> Result<Solved<D>, Fail> {
        self.build()?;
        let cs = self.contact_solver()?;
        let model = self.model.joint().model();
        match &mut self.solver {
            Some(Solver::Elastic(e)) => {
                let sol = e.solve(model, t).map_err(|e| Fail::new(SynStatus::SolveFailed, e.to_string()))?;
                Ok(Solved {
                    time: t,
                    step: prev.step + 1,
                    iterations: 0,
                    displacement: sol.displacement,
                    result: None,
                    pairs: Vec::new(),
                    geometry: None,
                })
            }
            Some(Solver::Contact(stepper)) => {
                if prev.result.is_none() || stepper.last_result().is_none() {
                    return Err(Fail::new(SynStatus::NoSolution, "the last solution has no contact state"));
                }
                let (record, result) = stepper.step(model, t, cs.as_ref()).map_err(solve_failed)?;
                Ok(solved_from(record, result))
            }
            Some(Solver::Nonlinear(nl)) => {
                // from the last solution; cut-backs that end part-way leave a converged
                // sub-level, so a failure restores the last solution's state
                let kept = nl.checkpoint();
                match nl.step_to(model, t, cs.as_ref()) {
                    Ok(level) => Ok(solved_nonlinear(nl, &level, prev.step + 1)),
                    Err(e) => {
                        nl.restore(kept).map_err(nonlinear_failed)?;
                        Err(nonlinear_failed(e))
                    }
                }
            }
            None => Err(Fail::new(SynStatus::Panic, "no solver after build")),
        }
    }

    fn solved(&self) -> Result<&Solved<D>, Fail> {
        self.last.as_ref().ok_or_else(|| {
            Fail::new(
                SynStatus::NoSolution,
                "no solution: solve first (changing the model's conditions or pairs discards it)",
            )
        })
    }

    /// Nodal displacements in global numbering (`n_nodes × D`; nodes in no element: 0).
    pub fn displacements(&self, out: &mut [Real]) -> Result<(), Fail> {
        check_len(out.len(), self.n_nodes() * D, "displacement buffer (n_nodes * dimension)")?;
        let s = self.solved()?;
        Ok(self.model.scatter_displacements(&s.displacement, out)?)
    }

    fn contact(&self) -> Option<&StaticContact<D>> {
        match &self.solver {
            Some(Solver::Contact(c)) => Some(c.contact()),
            Some(Solver::Nonlinear(nl)) => Some(nl.contact()),
            _ => None,
        }
    }

    /// The contact geometry of the last solution (a nonlinear model's is kept with it: the
    /// solver's may have moved on to a failed iterate).
    fn geometry(&self) -> Option<&ContactGeometry<D>> {
        match self.last.as_ref().and_then(|s| s.geometry.as_ref()) {
            Some(g) => Some(g),
            None => self.contact().map(|c| c.geometry()),
        }
    }

    pub fn n_contact_nodes(&self) -> Result<usize, Fail> {
        self.solved()?;
        Ok(self.geometry().map_or(0, |g| g.len()))
    }

    /// Per contact node: pair index, global node id, reference coordinates, pressure.
    pub fn contact_nodes(
        &self,
        n: usize,
        mut pair: Option<&mut [i32]>,
        mut node: Option<&mut [i32]>,
        mut coords: Option<&mut [Real]>,
        mut pressure: Option<&mut [Real]>,
    ) -> Result<(), Fail> {
        let total = self.n_contact_nodes()?;
        check_len(n, total, "contact node count")?;
        let s = self.solved()?;
        let Some(geometry) = self.geometry() else { return Ok(()) };
        for (r, cn) in geometry.nodes.iter().enumerate() {
            if let Some(p) = pair.as_deref_mut() {
                p[r] = i32::try_from(cn.pair).unwrap_or(-1);
            }
            if let Some(p) = node.as_deref_mut() {
                let g = self.model.global_node(cn.node.0, cn.node.1);
                p[r] = g.and_then(|g| i32::try_from(g).ok()).unwrap_or(-1);
            }
            if let Some(p) = coords.as_deref_mut() {
                for k in 0..D {
                    p[r * D + k] = cn.position[k];
                }
            }
            if let Some(p) = pressure.as_deref_mut() {
                p[r] = s.result.as_ref().and_then(|x| x.solution.lambda_n.get(r)).copied().unwrap_or(0.0);
            }
        }
        Ok(())
    }

    /// Normal force and resultant (3 components) of pair `i`.
    pub fn pair_force(&self, i: usize) -> Result<(Real, [Real; 3]), Fail> {
        let n = self.n_pairs();
        let name = self.model.joint().pairs().get(i).map(|p| p.name.clone()).ok_or_else(|| {
            Fail::new(SynStatus::IndexOutOfRange, format!("pair {i} is out of range 0..{n}"))
        })?;
        let s = self.solved()?;
        let rec = s
            .pairs
            .iter()
            .find(|p| p.name == name)
            .ok_or_else(|| Fail::new(SynStatus::NoSolution, format!("pair `{name}` has no result")))?;
        Ok((rec.normal_force, rec.force))
    }

    pub fn info(&self) -> Result<Info, Fail> {
        let s = self.solved()?;
        let n_dofs = match &self.solver {
            Some(Solver::Elastic(e)) => e.info().n_dofs,
            Some(Solver::Contact(c)) => c.contact().elastic().info().n_dofs,
            Some(Solver::Nonlinear(nl)) => nl.dofs().n_dofs(),
            None => 0,
        };
        Ok(Info {
            time: s.time,
            step: s.step,
            iterations: s.iterations,
            kkt: s.result.as_ref().map_or(0.0, |x| x.kkt.max()),
            n_dofs,
            contact_nodes: self.geometry().map_or(0, |g| g.len()),
        })
    }
}

/// A failure of the Newton iteration: no convergence within the cut-backs (or a state that
/// cannot be restored) is a failed solve; invalid input is an invalid argument.
fn nonlinear_failed(e: NonlinearError) -> Fail {
    let status = match &e {
        NonlinearError::InvalidParameter(_) => SynStatus::InvalidArgument,
        _ => SynStatus::SolveFailed,
    };
    Fail::new(status, e.to_string())
}

/// The last solution from a level of the Newton iteration.
fn solved_nonlinear<const D: usize>(
    nl: &NonlinearContact<D>,
    level: &NonlinearResult<D>,
    step: usize,
) -> Solved<D> {
    let geometry = nl.geometry().clone();
    Solved {
        time: level.time,
        step,
        iterations: level.report.total_iterations,
        displacement: level.contact.displacement.clone(),
        result: Some(level.contact.clone()),
        pairs: synovia::time::results::pair_records(&geometry, &level.contact),
        geometry: Some(geometry),
    }
}

/// A solve failure of the quasi-static stepper.
fn solve_failed(e: TimeError) -> Fail {
    Fail::new(SynStatus::SolveFailed, e.to_string())
}

/// The last solution from a level of the quasi-static stepper.
fn solved_from<const D: usize>(record: StepRecord, result: &StaticContactResult<D>) -> Solved<D> {
    Solved {
        time: record.time,
        step: record.step,
        iterations: record.iterations,
        displacement: result.displacement.clone(),
        result: Some(result.clone()),
        pairs: record.pairs,
        geometry: None,
    }
}
