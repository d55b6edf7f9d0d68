//! Static contact problems of a [`Model`]: one elastic factorisation, the contact operators of
//! every pair, and any [`ContactSolver`] (spec §4–§6).
//!
//! [`StaticContact`] factorises `A` once; each [`StaticContact::solve`] assembles the load and
//! the lifts of prescribed displacements at the requested time, builds `B_hn` (and `B_Ht` for
//! given slip bounds `g_c`), runs the solver, and maps the result back to nodal displacements
//! per body and pressures per contact node.

use synovia_fem::{ElasticParams, ElasticSolver, LoadSubspace, Model};
use synovia_mesh::math::{Real, Vector};

use crate::error::ContactError;
use crate::kkt::{check_kkt, inf_norm, KktReport};
use crate::operators::{BodyPlacement, ContactGeometry, ContactPair};
use crate::problem::{ContactProblem, FrictionConstraints, SchurCache};
use crate::solver::{ContactSolution, ContactSolver};

/// A factorised model with its contact geometry.
#[derive(Debug)]
pub struct StaticContact<const D: usize> {
    elastic: ElasticSolver<D>,
    geometry: ContactGeometry<D>,
    nested_min_rows: Option<usize>,
    /// Columns of `S` kept between solves on the same geometry ([`SchurCache`]).
    schur_cache: SchurCache,
    /// Solved loads `A⁻¹ F` kept for loads in their span ([`LoadSubspace`]).
    load_subspace: std::sync::Mutex<LoadSubspace>,
}

/// The result of one static contact solve.
#[derive(Debug, Clone)]
pub struct StaticContactResult<const D: usize> {
    /// Nodal displacements per body.
    pub displacement: Vec<Vec<Vector<D>>>,
    /// The solver's solution (reduced `U`, `Λ_n` per contact node, `Λ_t` per friction cell).
    pub solution: ContactSolution,
    /// Contact node of each friction cell (index into the geometry's nodes).
    pub cell_node: Vec<usize>,
    /// `g_c` of each friction cell.
    pub slip_bound: Vec<Real>,
    /// The KKT residuals of the returned solution (spec §5).
    pub kkt: KktReport,
    /// Solver iterations spent on the coarse levels of the nested iteration (0 if none).
    pub coarse_iterations: usize,
    /// Proximal-point iterations of a semi-coercive model ([`crate::floating`]); 0 for a
    /// coercive one.
    pub proximal_iterations: usize,
}

impl<const D: usize> StaticContact<D> {
    /// Factorises the model's stiffness and builds the contact nodes of `pairs`.
    ///
    /// Bodies that no Dirichlet or symmetry data hold (semi-coercive, spec §4) are accepted:
    /// the factorisation is then of `A + S` ([`ElasticSolver::new_semi_coercive`]) and
    /// [`StaticContact::solve`] runs the proximal-point iteration of [`crate::floating`].
    pub fn new(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        params: ElasticParams,
    ) -> Result<Self, ContactError> {
        let geometry = ContactGeometry::new(model, pairs)?;
        let elastic = ElasticSolver::new_for_contact(model, params, &interface_nodes(model, pairs)?)?;
        Ok(Self {
            elastic,
            geometry,
            nested_min_rows: Some(32),
            schur_cache: SchurCache::new(),
            load_subspace: std::sync::Mutex::new(LoadSubspace::new(LOAD_SUBSPACE_CAPACITY)),
        })
    }

    /// Rebuilds the contact geometry of `pairs` at the pose `x + u⁰`, `u⁰ = displacement[body][node]`
    /// ([`ContactGeometry::new_deformed`]: re-pairing of node-to-segment pairs, normals and
    /// weights of the pose, gaps in total form), keeping the factorisation of `A`. Returns the
    /// previous geometry, e.g. to carry contact data over with [`ContactGeometry::transfer`].
    pub fn update_geometry(
        &mut self,
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        displacement: &[Vec<Vector<D>>],
    ) -> Result<ContactGeometry<D>, ContactError> {
        let geometry = ContactGeometry::new_deformed(model, pairs, displacement)?;
        self.schur_cache.clear();
        Ok(std::mem::replace(&mut self.geometry, geometry))
    }

    /// Places the bodies rigidly ([`ContactGeometry::new_placed`], one [`BodyPlacement`] per
    /// body) and rebuilds the contact geometry of `pairs` there, keeping the factorisation of
    /// `A`: the bodies' stiffness in their own frames does not change with the placement, so a
    /// sequence of poses (a gait cycle) needs one factorisation. The contact parts' dofs stay
    /// the interface dofs ordered last, so Schur columns of the new rows still use the dense
    /// trailing block. Loads, prescribed displacements and results are in the bodies' frames.
    /// Returns the previous geometry.
    ///
    /// # Errors
    /// From [`ContactGeometry::new_placed`].
    pub fn place_bodies(
        &mut self,
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        placements: &[BodyPlacement<D>],
    ) -> Result<ContactGeometry<D>, ContactError> {
        let geometry = ContactGeometry::new_placed(model, pairs, placements)?;
        self.schur_cache.clear();
        Ok(std::mem::replace(&mut self.geometry, geometry))
    }

    /// Nested iteration for cold starts ([`crate::nested`]): coarsen the contact rows
    /// down to `min_rows` and use the coarse solutions as the warm start (default `Some(32)`);
    /// `None` starts every solve from `Λ = 0`.
    pub fn set_nested_iteration(&mut self, min_rows: Option<usize>) {
        self.nested_min_rows = min_rows;
    }

    /// `(reused, solved)`: solves whose `A⁻¹ F` came from the recycled load subspace and
    /// those that needed a solve with the factor ([`LoadSubspace::counts`]).
    pub fn load_solves(&self) -> (usize, usize) {
        self.load_subspace.lock().unwrap_or_else(|e| e.into_inner()).counts()
    }

    /// The elastic solver (dofs, stiffness, factorisation, timings).
    pub fn elastic(&self) -> &ElasticSolver<D> {
        &self.elastic
    }
    /// The contact nodes.
    pub fn geometry(&self) -> &ContactGeometry<D> {
        &self.geometry
    }

    /// Solves the contact problem at time `t` with slip bounds `slip_bound` (one per contact
    /// node; `None` = frictionless) and slip measured from `previous` nodal displacements (if
    /// given).
    pub fn solve(
        &self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        warm_start: Option<&ContactSolution>,
    ) -> Result<StaticContactResult<D>, ContactError> {
        match self.solve_with(model, t, solver, slip_bound, previous, warm_start, false)? {
            Solved::Full(result) => Ok(*result),
            Solved::Multipliers(..) => {
                Err(ContactError::InvalidParameter("internal: multipliers without displacement".into()))
            }
        }
    }

    /// [`StaticContact::solve`] without the final displacement: the multipliers `Λ_n`, `Λ_t`
    /// and the solver report (the solution's `u` is empty, [`ContactProblem::multipliers_only`]),
    /// and the coarse-level iterations of the nested warm start. Saves one solve with the
    /// factor (half a solve on a condensed interface) and the KKT check per call: for the
    /// iterates of a search over loads (e.g. the approach that balances a given force,
    /// [`crate::StaticContact::complete`] for the accepted one). For a semi-coercive model
    /// (proximal iteration) the displacement is needed inside the iteration and is returned.
    ///
    /// # Errors
    /// As [`StaticContact::solve`].
    pub fn solve_multipliers(
        &self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        warm_start: Option<&ContactSolution>,
    ) -> Result<(ContactSolution, usize), ContactError> {
        Ok(match self.solve_with(model, t, solver, slip_bound, previous, warm_start, true)? {
            Solved::Full(result) => (result.solution, result.coarse_iterations),
            Solved::Multipliers(solution, coarse) => (*solution, coarse),
        })
    }

    /// Completes a solution of [`StaticContact::solve_multipliers`] (same `t`, `slip_bound`,
    /// `previous`): the displacement `U = A⁻¹ F − A⁻¹ (Cᵀ ν)` (with `A⁻¹ F` recycled, half a
    /// solve on a condensed interface), the KKT check and the nodal fields — the result
    /// [`StaticContact::solve`] would have returned, to rounding. A solution that already has
    /// its `u` (semi-coercive models) is completed without a solve.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] if the solution does not fit the contact problem at
    /// `t`; the errors of the solve.
    pub fn complete(
        &self,
        model: &Model<D>,
        t: Real,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        solution: ContactSolution,
    ) -> Result<StaticContactResult<D>, ContactError> {
        let (load, lifts) = self.elastic.rhs(model, t)?;
        let dofs = self.elastic.dofs();
        let normal = self.geometry.normal_constraints(dofs, &lifts);
        let friction_op = match slip_bound {
            Some(g) => Some(self.geometry.friction_constraints(dofs, &lifts, g, previous)?),
            None => None,
        };
        let friction: Option<&FrictionConstraints> =
            friction_op.as_ref().map(|f| &f.constraints).filter(|f| f.rows.nrows() > 0);
        let n_tangential = friction.map_or(0, |f| f.rows.nrows());
        if solution.lambda_n.len() != normal.rows.nrows() || solution.lambda_t.len() != n_tangential {
            return Err(ContactError::InvalidParameter(format!(
                "a solution with {} normal and {} tangential multipliers for a problem with {} and {}",
                solution.lambda_n.len(),
                solution.lambda_t.len(),
                normal.rows.nrows(),
                n_tangential
            )));
        }
        let factor = self.elastic.cholesky();
        let load_solution = self.recycled_load_solution(&load)?;
        let problem = ContactProblem {
            matrix: self.elastic.system_matrix(),
            factor,
            load: &load,
            normal: &normal,
            friction,
            schur_cache: None,
            load_solution: load_solution.as_deref(),
            multipliers_only: false,
        };
        let mut solution = solution;
        if solution.u.is_empty() {
            let mut nu: Vec<f64> =
                solution.lambda_n.iter().zip(&normal.weights).map(|(l, k)| l * k).collect();
            nu.extend_from_slice(&solution.lambda_t);
            solution.u = crate::problem::Interface::new(problem)?.displacement(&nu)?;
        }
        let kkt = check_kkt(&problem, &solution.u, &solution.lambda_n, &solution.lambda_t);
        self.finish(solution, kkt, &lifts, friction_op, 0, 0)
    }

    #[allow(clippy::too_many_arguments)]
    fn solve_with(
        &self,
        model: &Model<D>,
        t: Real,
        solver: &dyn ContactSolver,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        warm_start: Option<&ContactSolution>,
        multipliers_only: bool,
    ) -> Result<Solved<D>, ContactError> {
        let (load, lifts) = self.elastic.rhs(model, t)?;
        let dofs = self.elastic.dofs();
        let normal = self.geometry.normal_constraints(dofs, &lifts);
        let friction_op = match slip_bound {
            Some(g) => Some(self.geometry.friction_constraints(dofs, &lifts, g, previous)?),
            None => None,
        };
        let friction: Option<&FrictionConstraints> =
            friction_op.as_ref().map(|f| &f.constraints).filter(|f| f.rows.nrows() > 0);
        let stabilisation = self.elastic.stabilisation();
        if let Some(st) = stabilisation {
            crate::floating::check_balance(st, &load, &normal, friction)?;
        }
        let (matrix, factor) = (self.elastic.system_matrix(), self.elastic.cholesky());
        // A⁻¹ F: recycled when F is a combination of loads solved before (crate docs of
        // synovia_fem::recycling); the proximal iteration's loads change every iteration
        let load_solution = self.recycled_load_solution(&load)?;
        macro_rules! problem_with {
            ($rhs:expr) => {
                ContactProblem {
                    matrix,
                    factor,
                    load: $rhs,
                    normal: &normal,
                    friction,
                    schur_cache: Some(&self.schur_cache),
                    load_solution: load_solution.as_deref(),
                    multipliers_only: multipliers_only && stabilisation.is_none(),
                }
            };
        }
        let mut coarse_iterations = 0;
        let nested = match (warm_start, self.nested_min_rows) {
            (None, Some(min_rows)) => crate::nested::nested_warm_start(
                &problem_with!(&load),
                solver,
                &self.geometry.adjacency,
                min_rows,
            )?,
            _ => None,
        };
        if let Some((_, it)) = &nested {
            coarse_iterations = *it;
        }
        let mut warm = warm_start.or(nested.as_ref().map(|(w, _)| w)).cloned();
        let Some(st) = stabilisation else {
            let problem = problem_with!(&load);
            let solution = solver.solve(&problem, warm.as_ref())?;
            if multipliers_only {
                return Ok(Solved::Multipliers(Box::new(solution), coarse_iterations));
            }
            let kkt = check_kkt(&problem, &solution.u, &solution.lambda_n, &solution.lambda_t);
            return self.finish(solution, kkt, &lifts, friction_op, coarse_iterations, 0).map(Solved::full);
        };
        // Proximal-point iteration (crate::floating): A + S with load F + S U_k.
        let mut u_k = match &warm {
            Some(w) if w.u.len() == load.len() => w.u.clone(),
            _ => vec![0.0; load.len()],
        };
        let mut history = Vec::new();
        let load_norm = inf_norm(&load);
        for iteration in 1..=PROXIMAL_MAX_ITERATIONS {
            let rhs: Vec<f64> = st.spring_mul(&u_k).iter().zip(&load).map(|(s, f)| s + f).collect();
            let problem = problem_with!(&rhs);
            let solution = solver.solve(&problem, warm.as_ref())?;
            let step: Vec<f64> = solution.u.iter().zip(&u_k).map(|(a, b)| a - b).collect();
            let residual = inf_norm(&st.spring_mul(&step));
            let mut forces = vec![0.0; load.len()];
            let nu: Vec<f64> = solution.lambda_n.iter().zip(&normal.weights).map(|(l, k)| l * k).collect();
            normal.rows.mul_transpose_add(&nu, &mut forces);
            let scale = load_norm.max(inf_norm(&forces)).max(f64::MIN_POSITIVE);
            let relative = residual / scale;
            history.push(crate::error::IterationResidual {
                iteration,
                normal: relative,
                tangential: 0.0,
                set_changes: 0,
            });
            if relative <= PROXIMAL_TOLERANCE {
                let mut kkt = check_kkt(&problem, &solution.u, &solution.lambda_n, &solution.lambda_t);
                // the equilibrium residual of the original problem is −S (U_{k+1} − U_k)
                kkt.equilibrium = kkt.equilibrium.max(relative);
                return self
                    .finish(solution, kkt, &lifts, friction_op, coarse_iterations, iteration)
                    .map(Solved::full);
            }
            // A load that contact cannot hold (e.g. a tangential load above the friction
            // capacity) makes the body move by the same amount every iteration: stop early.
            if iteration >= 8 && relative > 0.5 * history[iteration - 6].normal {
                break;
            }
            u_k = solution.u.clone();
            warm = Some(solution);
        }
        Err(ContactError::NoConvergence {
            solver: format!(
                "{} in the proximal iteration of the bodies held only by contact (stagnating: the load may exceed what contact and friction can hold)",
                solver.name()
            ),
            iterations: history.len(),
            history,
        })
    }

    /// `A⁻¹ F` through the [`LoadSubspace`] (recycled when `F` is a combination of loads
    /// solved before, [`synovia_fem::recycling`]); `None` for a semi-coercive model, whose
    /// proximal iteration changes the load every iteration.
    fn recycled_load_solution(&self, load: &[f64]) -> Result<Option<Vec<f64>>, ContactError> {
        if self.elastic.stabilisation().is_some() {
            return Ok(None);
        }
        let mut subspace = self.load_subspace.lock().unwrap_or_else(|e| e.into_inner());
        Ok(Some(subspace.solve(self.elastic.system_matrix(), self.elastic.cholesky(), load)?))
    }

    fn finish(
        &self,
        solution: ContactSolution,
        kkt: KktReport,
        lifts: &[Vector<D>],
        friction_op: Option<crate::operators::FrictionOperator>,
        coarse_iterations: usize,
        proximal_iterations: usize,
    ) -> Result<StaticContactResult<D>, ContactError> {
        let dofs = self.elastic.dofs();
        let displacement = dofs.expand(&solution.u, lifts)?;
        let has_friction = !solution.lambda_t.is_empty();
        let (cell_node, slip) = match friction_op {
            Some(op) if has_friction => (op.cell_node, op.slip_bound),
            _ => (Vec::new(), Vec::new()),
        };
        Ok(StaticContactResult {
            displacement,
            solution,
            cell_node,
            slip_bound: slip,
            kkt,
            coarse_iterations,
            proximal_iterations,
        })
    }
}

/// What [`StaticContact::solve_with`] returns: the full result, or (multipliers only) the
/// solver's solution without `u` and the coarse iterations.
enum Solved<const D: usize> {
    Full(Box<StaticContactResult<D>>),
    Multipliers(Box<ContactSolution>, usize),
}

impl<const D: usize> Solved<D> {
    fn full(result: StaticContactResult<D>) -> Self {
        Self::Full(Box::new(result))
    }
}

/// Every node of the contact parts of `pairs` (both sides), each once: the dofs that
/// [`ElasticSolver::new_for_contact`] orders last.
fn interface_nodes<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
) -> Result<Vec<(synovia_fem::BodyId, usize)>, ContactError> {
    use crate::operators::Partner;
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut add = |body: synovia_fem::BodyId, part: &str| -> Result<(), ContactError> {
        let mesh = &model.body(body)?.mesh;
        for f in mesh.boundary_part(part)?.facets() {
            for &i in f {
                if seen.insert((body.0, i)) {
                    out.push((body, i));
                }
            }
        }
        Ok(())
    };
    for pair in pairs {
        add(pair.body, &pair.part)?;
        match &pair.partner {
            Partner::Body { body, part, .. }
            | Partner::Segment { body, part, .. }
            | Partner::Mortar { body, part, .. } => add(*body, part)?,
            Partner::Rigid(_) => {}
        }
    }
    Ok(out)
}

/// Directions kept by the [`LoadSubspace`] of a [`StaticContact`].
const LOAD_SUBSPACE_CAPACITY: usize = 6;

/// Largest number of proximal-point iterations of a semi-coercive solve.
const PROXIMAL_MAX_ITERATIONS: usize = 60;
/// Relative equilibrium residual `‖S (U_{k+1} − U_k)‖_∞ / max(‖F‖_∞, ‖B_hnᵀ κ Λ_n‖_∞)` at
/// which the proximal-point iteration stops.
const PROXIMAL_TOLERANCE: f64 = 1e-12;

impl<const D: usize> StaticContactResult<D> {
    /// Total normal contact force `Σ_r κ_r Λ_n,r` of the nodes in `range`.
    pub fn normal_force(&self, geometry: &ContactGeometry<D>, range: std::ops::Range<usize>) -> Real {
        range.map(|r| geometry.nodes[r].weight * self.solution.lambda_n[r]).sum()
    }
}
