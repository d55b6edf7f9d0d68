//! Static contact problems of a [`Model`]: one elastic factorisation, the contact operators of
//! every pair, and any [`ContactSolver`] (docs/model.md §4–§6).
//!
//! [`StaticContact`] factorises `A` once; each [`StaticContact::solve`] assembles the load and
//! the lifts of prescribed displacements at the requested time, builds `B_hn` (and `B_Ht` for
//! given slip bounds `g_c`), runs the solver, and maps the result back to nodal displacements
//! per body and pressures per contact node.

use synovia_fem::{DofMap, ElasticParams, ElasticSolver, FemError, Model};
use synovia_linalg::{CholeskyOperator, InterfaceBlockParams, SymmetricMatrix};
use synovia_mesh::math::{Real, Vector};

use crate::context::SolveContext;
use crate::error::ContactError;
use crate::kkt::{check_kkt, check_kkt_at_border, inf_norm, KktReport};
use crate::operators::{BodyPlacement, ContactGeometry, ContactPair, GeometryCache};
use crate::problem::{ContactProblem, FrictionConstraints, NormalConstraints, RigidBorder};
use crate::solver::{ContactSolution, ContactSolver, SolverReport};
use synovia_linalg::SparseRows;

/// A factorised model with its contact geometry.
///
/// The dofs of the contact interface are ordered last in the factorisation (a dense trailing
/// block for the interface Schur complement, [`InterfaceBlockParams`],
/// [`synovia_linalg::Ordering::Trailing`]). An interface with more than
/// [`InterfaceBlockParams::max_dofs`] dofs keeps only the contact nodes of smallest initial gap
/// (with their partner and master nodes) in the block, up to
/// [`InterfaceBlockParams::screened_dofs`]; each solve then screens the contact rows: it
/// solves on the rows in the block, checks the others with the computed displacement and adds
/// those that penetrate until none does, so the result is the one of the full problem.
#[derive(Debug)]
pub struct StaticContact<const D: usize> {
    elastic: ElasticSolver<D>,
    geometry: ContactGeometry<D>,
    nested_min_rows: Option<usize>,
    /// Gap screening of whole-factor solves ([`StaticContact::set_screening_band`]).
    screening_band: Option<Real>,
    /// What the solves reuse: columns of `S` kept between solves on the same geometry, the
    /// recycled load solves `A⁻¹ F` ([`SolveContext`], with its memory budget).
    context: SolveContext,
    /// Built on a caller's matrix ([`StaticContact::with_system_matrix`]): the loads come from
    /// the caller ([`StaticContact::solve_load`]), not from the model.
    caller_matrix: bool,
    /// The pose-independent geometry data kept by [`StaticContact::rebuild_geometry`].
    geometry_cache: GeometryCache<D>,
    /// Rigid partners' force-controlled coordinates solved with the contact conditions
    /// ([`StaticContact::set_coordinate_borders`]); dropped when the geometry changes.
    borders: Vec<CoordinateBorder<D>>,
}

/// A rigid partner's force-controlled coordinate `z` solved together with the contact
/// conditions (docs/model.md §10, "The coordinate in the contact solve";
/// [`crate::RigidBorder`]): per contact node `r` of the geometry the rate `∂d_r/∂z` of its
/// gap and the rate `∂w_r/∂z` of the partner's motion there (the slip origin of friction), and
/// the equilibrium `Q(ν) = Σ_r (∂d_r/∂z) κ_r Λ_n,r + Σ_c (∂s_c/∂z) Λ_t,c = target`
/// (`target = −F` for the force `F` applied along `z`). The gaps and shifts are taken at
/// `z₀` (the coordinate they were built or set at); the solve returns `ζ = z − z₀` in
/// [`crate::SolverReport::border_values`], and its solution is that of the gaps `d + (∂d/∂z) ζ`.
#[derive(Debug, Clone, PartialEq)]
pub struct CoordinateBorder<const D: usize> {
    /// `∂d_r/∂z` per contact node.
    pub gap_rate: Vec<Real>,
    /// `∂w_r/∂z` per contact node (zero where the partner is not the moving body).
    pub motion_rate: Vec<Vector<D>>,
    /// The right-hand side of the equilibrium.
    pub target: Real,
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
    /// The KKT residuals of the returned solution (docs/model.md §5).
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
    /// Bodies that no Dirichlet or symmetry data hold (semi-coercive, docs/model.md §4) are accepted:
    /// the factorisation is then of `A + S` ([`ElasticSolver::new_semi_coercive`]) and
    /// [`StaticContact::solve`] runs the proximal-point iteration of [`crate::floating`].
    pub fn new(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        params: ElasticParams,
    ) -> Result<Self, ContactError> {
        Self::with_interface_block(model, pairs, params, InterfaceBlockParams::default())
    }

    /// [`StaticContact::new`] with the given choice of the interface dofs ordered last
    /// ([`InterfaceBlockParams`]: the size of the dense interface block, and of the screened
    /// block of a larger interface).
    ///
    /// # Errors
    /// As [`StaticContact::new`].
    pub fn with_interface_block(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        params: ElasticParams,
        block: InterfaceBlockParams,
    ) -> Result<Self, ContactError> {
        let geometry = ContactGeometry::new(model, pairs)?;
        let interface = interface_nodes(model, pairs, &geometry)?;
        let elastic =
            ElasticSolver::new_with_ordering(model, params, true, &interface_ordering(&interface, block))?;
        Ok(Self {
            elastic,
            geometry,
            nested_min_rows: Some(32),
            screening_band: None,
            context: SolveContext::new(),
            caller_matrix: false,
            geometry_cache: GeometryCache::default(),
            borders: Vec::new(),
        })
    }

    /// Everything [`StaticContact::new`] does before the numeric factorisation: the contact
    /// geometry of `pairs` (nodes, normals, initial gaps; invalid pairs are errors), the dofs,
    /// the interface ordering and the symbolic analysis with the memory check of the
    /// factorisation ([`ElasticSolver::estimate_with_ordering`]). For checking a model
    /// without solving it.
    ///
    /// # Errors
    /// As [`StaticContact::new`] up to the factorisation (including
    /// [`synovia_linalg::LinalgError::OutOfMemory`]).
    pub fn estimate(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        params: ElasticParams,
    ) -> Result<(ContactGeometry<D>, synovia_fem::ElasticEstimate), ContactError> {
        let geometry = ContactGeometry::new(model, pairs)?;
        let interface = interface_nodes(model, pairs, &geometry)?;
        let estimate = ElasticSolver::estimate_with_ordering(
            model,
            params,
            true,
            &interface_ordering(&interface, InterfaceBlockParams::default()),
        )?;
        Ok((geometry, estimate))
    }

    /// The context of the solves (kept columns, recycled load solves, memory budget).
    pub fn context(&self) -> &SolveContext {
        &self.context
    }

    /// Replaces the context (e.g. one with another memory budget,
    /// [`SolveContext::with_memory_budget`]).
    pub fn set_context(&mut self, context: SolveContext) {
        self.context = context;
    }

    /// The contact machinery on a caller-assembled symmetric positive definite matrix `A` of the
    /// model's reduced dofs ([`ElasticSolver::with_system_matrix`], interface dofs ordered
    /// last): e.g. the time-step matrix `A = M_ρ + Δt M_α + Δt² A⁽⁰⁾ + Δt A⁽¹⁾` of the dynamic
    /// scheme (docs/model.md §7), whose every step is the contact problem of docs/model.md §5
    /// `A U + B_hnᵀ κ Λ_n + B_Htᵀ Λ_t = F̄` with the caller's right-hand side `F̄`, solved by
    /// [`StaticContact::solve_load`]. `assemble` fills the zero matrix on the model's pattern.
    /// Solves of the model's own load case ([`StaticContact::solve`] and its relatives) are
    /// refused, and loads are not recycled (each right-hand side is new).
    ///
    /// # Errors
    /// Invalid pairs, the errors of `assemble` and of the factorisation.
    pub fn with_system_matrix(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        params: ElasticParams,
        assemble: impl FnOnce(&DofMap<D>, &mut SymmetricMatrix) -> Result<(), FemError>,
    ) -> Result<Self, ContactError> {
        Self::with_system_matrix_block(model, pairs, params, InterfaceBlockParams::default(), assemble)
    }

    /// [`StaticContact::with_system_matrix`] with the given choice of the interface dofs
    /// ordered last ([`InterfaceBlockParams`], as [`StaticContact::with_interface_block`]).
    ///
    /// # Errors
    /// As [`StaticContact::with_system_matrix`].
    pub fn with_system_matrix_block(
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        params: ElasticParams,
        block: InterfaceBlockParams,
        assemble: impl FnOnce(&DofMap<D>, &mut SymmetricMatrix) -> Result<(), FemError>,
    ) -> Result<Self, ContactError> {
        let geometry = ContactGeometry::new(model, pairs)?;
        let interface = interface_nodes(model, pairs, &geometry)?;
        let ordering = interface_ordering(&interface, block);
        let elastic = ElasticSolver::with_system_matrix(model, params, &ordering, assemble)?;
        Ok(Self {
            elastic,
            geometry,
            nested_min_rows: Some(32),
            screening_band: None,
            context: SolveContext::new(),
            caller_matrix: true,
            geometry_cache: GeometryCache::default(),
            borders: Vec::new(),
        })
    }

    /// A new numeric factorisation of a caller-assembled matrix on the same pattern and interface
    /// ordering ([`ElasticSolver::refactorise`]; the symbolic analysis and the contact geometry
    /// are kept, the kept Schur columns and load solves are dropped): e.g. the tangent stiffness
    /// `K_T(u_k)` of each Newton iteration of a nonlinear solve (`synovia-nonlinear`), whose
    /// linearised contact problem is then solved by [`StaticContact::solve_load`].
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] unless built by [`StaticContact::with_system_matrix`];
    /// the errors of `assemble` and of the factorisation.
    pub fn refactorise(
        &mut self,
        assemble: impl FnOnce(&DofMap<D>, &mut SymmetricMatrix) -> Result<(), FemError>,
    ) -> Result<(), ContactError> {
        if !self.caller_matrix {
            return Err(ContactError::InvalidParameter(
                "refactorise needs a StaticContact built on a caller-assembled matrix (with_system_matrix)"
                    .into(),
            ));
        }
        self.context.clear();
        self.elastic.refactorise(assemble)?;
        Ok(())
    }

    /// Solves the contact problem of docs/model.md §5 with the caller's reduced right-hand side
    /// `load` (`F̄`, one entry per reduced dof) and lifts of prescribed displacements `lifts`
    /// (one per dof group, [`DofMap::lifts`]; they enter the gaps and the slip shifts) on the
    /// factorised matrix: `A U + B_hnᵀ κ Λ_n + B_Htᵀ Λ_t = F̄`, `Λ_n ≥ 0 ⟂ B_hn U ≤ d`, and
    /// Tresca friction with the slip bounds `slip_bound` (one per contact node; `None` =
    /// frictionless) and slip measured from `previous` nodal displacements (if given). The
    /// same solve as [`StaticContact::solve`] (row screening, Schur-column cache, KKT check,
    /// nested iteration for cold starts) with the load given instead of assembled.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] for a `load` or `lifts` of the wrong length or a
    /// non-finite `load`; the errors of the solve.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_load(
        &self,
        load: &[f64],
        lifts: &[Vector<D>],
        solver: &dyn ContactSolver,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        warm_start: Option<&ContactSolution>,
    ) -> Result<StaticContactResult<D>, ContactError> {
        let source = self.given(load, lifts)?;
        match self.solve_with(source, solver, slip_bound, previous, warm_start, false)? {
            Solved::Full(result) => Ok(*result),
            Solved::Multipliers(..) => {
                Err(ContactError::InvalidParameter("internal: multipliers without displacement".into()))
            }
        }
    }

    /// [`StaticContact::solve_load`] without the final displacement, as
    /// [`StaticContact::solve_multipliers`] for a caller's load: the multipliers `Λ_n`, `Λ_t` of
    /// `A U + B_hnᵀ κ Λ_n + B_Htᵀ Λ_t = F̄` with the complementarity and friction conditions of
    /// [`StaticContact::solve_load`], the solver report (the solution's `u` is empty) and the
    /// coarse-level iterations. Saves the displacement's back-substitution
    /// `U = A⁻¹ F̄ − A⁻¹ (Cᵀ ν)` and the KKT check: for the trials of a search over loads (e.g.
    /// the load control of a Newton iteration, `synovia-nonlinear`), the accepted one completed
    /// by [`StaticContact::complete_load`].
    ///
    /// # Errors
    /// As [`StaticContact::solve_load`].
    #[allow(clippy::too_many_arguments)]
    pub fn solve_load_multipliers(
        &self,
        load: &[f64],
        lifts: &[Vector<D>],
        solver: &dyn ContactSolver,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        warm_start: Option<&ContactSolution>,
    ) -> Result<(ContactSolution, usize), ContactError> {
        let source = self.given(load, lifts)?;
        Ok(match self.solve_with(source, solver, slip_bound, previous, warm_start, true)? {
            Solved::Full(result) => (result.solution, result.coarse_iterations),
            Solved::Multipliers(solution, coarse) => (*solution, coarse),
        })
    }

    /// Completes a solution of [`StaticContact::solve_load_multipliers`] (same `load`, `lifts`,
    /// `slip_bound`, `previous`): the displacement `U = A⁻¹ F̄ − A⁻¹ (Cᵀ ν)`, `ν = (κ Λ_n, Λ_t)`
    /// (with `A⁻¹ F̄` kept from the solve of the same load when it was the last one, so half a
    /// solve on a condensed interface), the KKT check and the nodal fields — the result
    /// [`StaticContact::solve_load`] would have returned, to rounding.
    ///
    /// # Errors
    /// As [`StaticContact::complete`], and [`StaticContact::solve_load`]'s checks of `load`
    /// and `lifts`.
    pub fn complete_load(
        &self,
        load: &[f64],
        lifts: &[Vector<D>],
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        solution: ContactSolution,
    ) -> Result<StaticContactResult<D>, ContactError> {
        let source = self.given(load, lifts)?;
        self.complete_with(source, slip_bound, previous, solution)
    }

    /// The source of a caller's `load` and `lifts` ([`StaticContact::solve_load`]), checked.
    fn given<'a>(&self, load: &'a [f64], lifts: &'a [Vector<D>]) -> Result<Source<'a, D>, ContactError> {
        let dofs = self.elastic.dofs();
        if load.len() != dofs.n_dofs() || lifts.len() != dofs.groups().len() {
            return Err(ContactError::InvalidParameter(format!(
                "a load of {} entries and {} lifts for {} reduced dofs and {} dof groups",
                load.len(),
                lifts.len(),
                dofs.n_dofs(),
                dofs.groups().len()
            )));
        }
        if load.iter().any(|v| !v.is_finite()) {
            return Err(ContactError::InvalidParameter("the load is not finite".into()));
        }
        Ok(Source::Given(load, lifts))
    }

    /// Rebuilds the contact geometry of `pairs` at the pose `x + u⁰`, `u⁰ = displacement[body][node]`
    /// ([`ContactGeometry::updated`]: each discretisation's re-pairing hook, as
    /// [`ContactGeometry::new_deformed`] by default: re-pairing of node-to-segment pairs, normals
    /// and weights of the pose, gaps in total form), keeping the factorisation of `A`. Returns the
    /// previous geometry, e.g. to carry contact data over with [`ContactGeometry::transfer`].
    /// The kept Schur columns are dropped (the rows changed); the unit solves of the contact
    /// nodes' dofs on this factorisation are kept ([`SolveContext::clear_deformed_rows`]), so
    /// a rebuild without a refactorisation in between (the geometry passes of a finite-strain
    /// Newton iteration under modified Newton) costs no solve for the nodes already seen.
    pub fn update_geometry(
        &mut self,
        model: &Model<D>,
        pairs: &[ContactPair<D>],
        displacement: &[Vec<Vector<D>>],
    ) -> Result<ContactGeometry<D>, ContactError> {
        let geometry = self.geometry.updated(model, pairs, displacement)?;
        self.context.clear_deformed_rows();
        self.borders.clear();
        Ok(std::mem::replace(&mut self.geometry, geometry))
    }

    /// Places the bodies rigidly ([`ContactGeometry::new_placed`], one [`BodyPlacement`] per
    /// body) and rebuilds the contact geometry of `pairs` there, keeping the factorisation of
    /// `A`: the bodies' stiffness in their own frames does not change with the placement, so a
    /// sequence of poses (a gait cycle) needs one factorisation. The contact parts' dofs stay
    /// the interface dofs ordered last, so Schur columns of the new rows still use the dense
    /// trailing block (for an interface above [`InterfaceBlockParams::max_dofs`], the block
    /// chosen by the initial gaps at construction; rows outside it are screened as in
    /// [`StaticContact::solve`]). Loads, prescribed displacements and results are in the
    /// bodies' frames.
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
        self.context.clear_rows();
        self.borders.clear();
        Ok(std::mem::replace(&mut self.geometry, geometry))
    }

    /// Rebuilds the contact geometry of `pairs` on the reference meshes
    /// ([`ContactGeometry::new`]), keeping the factorisation of `A`: for contact partners that
    /// moved (a posed rigid body's shape reads its pose when the geometry is built). What does
    /// not depend on the partners' poses (weights, normals and adjacency of the parts) is kept
    /// between rebuilds ([`ContactGeometry::new_cached`], checked against `model` each time),
    /// so a rebuild costs the discretisations' rows. Returns the previous geometry. The kept Schur columns are dropped (the rows changed); from the
    /// first rebuild on, the columns of single-node rows come from kept unit solves
    /// ([`SolveContext::clear_moved_rows`]), so a node's rows cost no solve at later poses.
    ///
    /// # Errors
    /// From [`ContactGeometry::new`].
    #[tracing::instrument(level = "debug", skip_all)]
    pub fn rebuild_geometry(
        &mut self,
        model: &Model<D>,
        pairs: &[ContactPair<D>],
    ) -> Result<ContactGeometry<D>, ContactError> {
        let geometry = ContactGeometry::new_cached(model, pairs, &mut self.geometry_cache)?;
        self.context.clear_moved_rows();
        self.borders.clear();
        Ok(std::mem::replace(&mut self.geometry, geometry))
    }

    /// Replaces the gaps `d_r` of the contact nodes (one per node), keeping the rows and the
    /// kept Schur columns: a partner that moves by a small rigid motion changes the gaps to
    /// first order and not the normals (`synovia::rigid`, the force-control iteration).
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] for a wrong length or a gap that is not finite.
    pub fn set_gaps(&mut self, gaps: &[Real]) -> Result<(), ContactError> {
        if gaps.len() != self.geometry.nodes.len() || gaps.iter().any(|g| !g.is_finite()) {
            return Err(ContactError::InvalidParameter(format!(
                "{} gaps (all finite) needed for {} contact nodes, {} given",
                self.geometry.nodes.len(),
                self.geometry.nodes.len(),
                gaps.len()
            )));
        }
        for (node, &g) in self.geometry.nodes.iter_mut().zip(gaps) {
            node.gap = g;
        }
        Ok(())
    }

    /// Sets the partner motion of the contact nodes since the slip origin
    /// ([`ContactGeometry::set_partner_motion`]: friction against a moving rigid partner).
    ///
    /// # Errors
    /// As [`ContactGeometry::set_partner_motion`].
    pub fn set_partner_motion(&mut self, motion: Vec<Vector<D>>) -> Result<(), ContactError> {
        self.geometry.set_partner_motion(motion)
    }

    /// Solves the next contact problems with rigid partners' force-controlled coordinates as
    /// unknowns, one [`CoordinateBorder`] each (empty: the gaps as given). Kept until the
    /// geometry changes (a rebuild, update or placement drops them). Only solvers that take a
    /// border ([`ContactSolver::solves_border`]) solve such a problem; a semi-coercive model
    /// refuses it.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] for rates that do not fit the contact nodes or are
    /// not finite.
    pub fn set_coordinate_borders(&mut self, borders: Vec<CoordinateBorder<D>>) -> Result<(), ContactError> {
        for b in &borders {
            let n = self.geometry.nodes.len();
            if b.gap_rate.len() != n || b.motion_rate.len() != n {
                return Err(ContactError::InvalidParameter(format!(
                    "a coordinate border needs one gap rate and one motion rate per contact node ({n}), got {} and {}",
                    b.gap_rate.len(),
                    b.motion_rate.len()
                )));
            }
            let finite = b.gap_rate.iter().all(|v| v.is_finite())
                && b.motion_rate.iter().all(|v| v.iter().all(|x| x.is_finite()))
                && b.target.is_finite();
            if !finite {
                return Err(ContactError::InvalidParameter(
                    "a coordinate border's rates and target must be finite".into(),
                ));
            }
        }
        self.borders = borders;
        Ok(())
    }

    /// Nested iteration for cold starts ([`crate::nested`]): coarsen the contact rows
    /// down to `min_rows` and use the coarse solutions as the warm start (default `Some(32)`);
    /// `None` starts every solve from `Λ = 0`.
    pub fn set_nested_iteration(&mut self, min_rows: Option<usize>) {
        self.nested_min_rows = min_rows;
    }

    /// Gap screening of the contact rows when the factor has no dense interface block for them
    /// (e.g. [`InterfaceBlockParams::max_dofs`] = 0 on a large candidate surface): each solve
    /// runs on the rows whose gap `d_r` is at most `band` (plus the rows of friction cells and
    /// those loaded in the warm start), checks the other rows with the computed displacement
    /// and adds those that penetrate, warm-started, until none does — the result is the one
    /// of the full problem, at a cost that follows the rows near contact instead of the
    /// candidate surface. `None` (default): every row takes part in every solve.
    ///
    /// # Errors
    /// [`ContactError::InvalidParameter`] for a band that is negative or not finite.
    pub fn set_screening_band(&mut self, band: Option<Real>) -> Result<(), ContactError> {
        check_screening_band(band)?;
        self.screening_band = band;
        Ok(())
    }

    /// The strain energy `W = Σ_T |T| Φ(ε(u))` of `result`, a solution of this problem
    /// ([`synovia_fem::post::total_strain_energy`] of its nodal displacements). When the
    /// displacements are those of the reduced solution alone (no prescribed displacement is
    /// non-zero: `u = N Ũ`) and `A` is the assembled stiffness (no stabilisation of floating
    /// bodies, not a caller's matrix), `W = ½ Ũᵀ A Ũ` — `A = Σ_T |T| Nᵀ Bᵀ C B N` with the
    /// linear materials' `C` and `Φ = ½ εᵀ C ε` — one product with `A` instead of the element
    /// loop (equal to rounding); otherwise the element loop.
    ///
    /// # Errors
    /// [`ContactError::Fem`] for displacements that do not fit the model.
    pub fn strain_energy(
        &self,
        model: &Model<D>,
        result: &StaticContactResult<D>,
    ) -> Result<Real, ContactError> {
        match self.reduced_strain_energy(result) {
            Some(w) => Ok(w),
            None => Ok(synovia_fem::post::total_strain_energy(model, &result.displacement)?),
        }
    }

    /// `½ Ũᵀ A Ũ` of [`StaticContact::strain_energy`] when it is the strain energy of
    /// `result`, else `None`.
    pub(crate) fn reduced_strain_energy(&self, result: &StaticContactResult<D>) -> Option<Real> {
        let dofs = self.elastic.dofs();
        let u = &result.solution.u;
        if self.caller_matrix || self.elastic.stabilisation().is_some() || u.len() != dofs.n_dofs() {
            return None;
        }
        // without lifts the nodal displacements are N Ũ entry by entry
        let zero = vec![Vector::<D>::zeros(); dofs.groups().len()];
        if dofs.expand(u, &zero).ok()? != result.displacement {
            return None;
        }
        let w = 0.5 * self.elastic.system_matrix().quadratic_form(u);
        w.is_finite().then_some(w)
    }

    /// `(reused, solved)`: solves whose `A⁻¹ F` came from the recycled load subspace and
    /// those that needed a solve with the factor ([`SolveContext::recycled_counts`]).
    pub fn load_solves(&self) -> (usize, usize) {
        self.context.recycled_counts()
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
        match self.solve_with(Source::Model(model, t), solver, slip_bound, previous, warm_start, false)? {
            Solved::Full(result) => Ok(*result),
            Solved::Multipliers(..) => {
                Err(ContactError::InvalidParameter("internal: multipliers without displacement".into()))
            }
        }
    }

    /// [`StaticContact::solve`] without the final displacement: the multipliers `Λ_n`, `Λ_t`
    /// and the solver report (the solution's `u` is empty, [`SolveContext::multipliers_only`]),
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
        Ok(
            match self.solve_with(Source::Model(model, t), solver, slip_bound, previous, warm_start, true)? {
                Solved::Full(result) => (result.solution, result.coarse_iterations),
                Solved::Multipliers(solution, coarse) => (*solution, coarse),
            },
        )
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
        self.complete_with(Source::Model(model, t), slip_bound, previous, solution)
    }

    /// [`StaticContact::complete`] of either source: `U = A⁻¹ F − A⁻¹ (Cᵀ ν)` unless the
    /// solution has its `u`, the KKT check and the nodal fields.
    fn complete_with(
        &self,
        source: Source<'_, D>,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        solution: ContactSolution,
    ) -> Result<StaticContactResult<D>, ContactError> {
        let Assembled { load, lifts, normal, friction_op, border } =
            self.assemble(source, slip_bound, previous)?;
        let friction = active_friction(friction_op.as_ref());
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
        let operator = self.operator()?;
        // the kept caches: `A⁻¹ F` of the last solve (the accepted trial of a search over
        // loads on a caller's matrix) or from the recycled load solves
        let mut context = self.context.with_start(None, false);
        context.set_load_solution(self.recycled_load_solution(&operator, &load)?);
        let problem = ContactProblem {
            operator: &operator,
            load: &load,
            normal: &normal,
            friction,
            border: border.as_ref(),
        };
        let mut solution = solution;
        if solution.u.is_empty() {
            let mut nu: Vec<f64> =
                solution.lambda_n.iter().zip(&normal.weights).map(|(l, k)| l * k).collect();
            nu.extend_from_slice(&solution.lambda_t);
            solution.u = crate::problem::Interface::new(problem, &context)?.displacement(&nu)?;
        }
        let kkt = kkt_of(&problem, &solution);
        self.finish(solution, kkt, &lifts, friction_op, 0, 0)
    }

    #[allow(clippy::too_many_arguments)]
    #[tracing::instrument(level = "debug", skip_all)]
    fn solve_with(
        &self,
        source: Source<'_, D>,
        solver: &dyn ContactSolver,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
        warm_start: Option<&ContactSolution>,
        multipliers_only: bool,
    ) -> Result<Solved<D>, ContactError> {
        let Assembled { load, lifts, normal, friction_op, border } =
            self.assemble(source, slip_bound, previous)?;
        let friction = active_friction(friction_op.as_ref());
        let stabilisation = self.elastic.stabilisation();
        if let Some(st) = stabilisation {
            let dofs = self.elastic.dofs();
            // Σ over node groups of N_g f̃_g: the net Cartesian force of a reduced load
            let net_force = |reduced: &[f64]| -> Vec<f64> {
                let mut total = Vector::<D>::zeros();
                for g in dofs.groups() {
                    for k in 0..g.n_dofs {
                        total += g.basis[k] * reduced[g.first_dof + k];
                    }
                }
                total.iter().copied().collect()
            };
            crate::floating::check_balance(st, &load, &normal, friction, &net_force)?;
        }
        let operator = self.operator()?;
        // A⁻¹ F: recycled when F is a combination of loads solved before (crate docs of
        // synovia_linalg::recycling); the proximal iteration's loads change every iteration
        let mut context = self.context.with_start(None, multipliers_only && stabilisation.is_none());
        context.set_load_solution(self.recycled_load_solution(&operator, &load)?);
        let context = context;
        macro_rules! problem_with {
            ($rhs:expr) => {
                ContactProblem {
                    operator: &operator,
                    load: $rhs,
                    normal: &normal,
                    friction,
                    border: border.as_ref(),
                }
            };
        }
        let cell_node = friction_op.as_ref().map_or(&[][..], |f| &f.cell_node[..]);
        let mut coarse_iterations = 0;
        let mut warm = warm_start.cloned();
        if border.is_some() && !solver.solves_border() {
            return Err(ContactError::InvalidParameter(format!(
                "solver `{}` does not solve a rigid partner's force-controlled coordinate with the contact conditions; use `pdas` or `pdas-fallback`",
                solver.name()
            )));
        }
        let Some(st) = stabilisation else {
            let problem = problem_with!(&load);
            let (solution, it) = self.run(&problem, solver, &context, warm.as_ref(), cell_node)?;
            if multipliers_only {
                return Ok(Solved::Multipliers(Box::new(solution), it));
            }
            let kkt = kkt_of(&problem, &solution);
            return self.finish(solution, kkt, &lifts, friction_op, it, 0).map(Solved::full);
        };
        if border.is_some() {
            return Err(ContactError::InvalidParameter(
                "a rigid partner's force-controlled coordinate is not solved with the contact conditions of a body held only by contact (semi-coercive model)".into(),
            ));
        }
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
            let (solution, it) = self.run(&problem, solver, &context, warm.as_ref(), cell_node)?;
            coarse_iterations += it;
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

    /// The load, the lifts of prescribed displacements and the constraints at `t`.
    #[tracing::instrument(level = "debug", skip_all)]
    fn assemble(
        &self,
        source: Source<'_, D>,
        slip_bound: Option<&[Real]>,
        previous: Option<&[Vec<Vector<D>>]>,
    ) -> Result<Assembled<D>, ContactError> {
        let (load, lifts) = match source {
            Source::Model(..) if self.caller_matrix => {
                return Err(ContactError::InvalidParameter(
                    "this contact problem is built on a caller's matrix: solve it with solve_load".into(),
                ))
            }
            Source::Model(model, t) => self.elastic.rhs(model, t)?,
            Source::Given(load, lifts) => (load.to_vec(), lifts.to_vec()),
        };
        let dofs = self.elastic.dofs();
        let normal = self.geometry.normal_constraints(dofs, &lifts);
        let friction_op = match slip_bound {
            Some(g) => Some(self.geometry.friction_constraints(dofs, &lifts, g, previous)?),
            None => None,
        };
        let border = (!self.borders.is_empty()).then(|| {
            // σ_j: the gap rates of the normal rows, then `g_c κ_r t · ∂w_r/∂z_j` of each
            // friction row (its shift is `g_c κ_r t · ([u_{i−1}] + w_r) − lift`)
            let column = |b: &CoordinateBorder<D>| {
                let mut sensitivity = b.gap_rate.clone();
                if let Some(f) = active_friction(friction_op.as_ref()).and(friction_op.as_ref()) {
                    for (&r, &g) in f.cell_node.iter().zip(&f.slip_bound) {
                        let node = &self.geometry.nodes[r];
                        for t in node.tangents.iter().take(D - 1) {
                            sensitivity.push(g * node.weight * t.dot(&b.motion_rate[r]));
                        }
                    }
                }
                sensitivity
            };
            RigidBorder {
                columns: self.borders.iter().map(column).collect(),
                targets: self.borders.iter().map(|b| b.target).collect(),
            }
        });
        Ok(Assembled { load, lifts, normal, friction_op, border })
    }

    /// The factorised operator `A` (or `A + S` of a semi-coercive model).
    fn operator(&self) -> Result<CholeskyOperator<'_>, ContactError> {
        Ok(CholeskyOperator::new(self.elastic.system_matrix(), self.elastic.cholesky())?)
    }

    /// `A⁻¹ F` through the context's recycled load solves (recycled when `F` is a combination
    /// of loads solved before, [`synovia_linalg::recycling`]); `None` for a semi-coercive
    /// model, whose proximal iteration changes the load every iteration.
    #[tracing::instrument(level = "debug", skip_all)]
    fn recycled_load_solution(
        &self,
        operator: &CholeskyOperator<'_>,
        load: &[f64],
    ) -> Result<Option<Vec<f64>>, ContactError> {
        // a caller's matrix (dynamic steps): every right-hand side is new, nothing to recycle
        if self.elastic.stabilisation().is_some() || self.caller_matrix {
            return Ok(None);
        }
        Ok(Some(self.context.recycled_load_solve(operator, load)?))
    }

    /// Runs `solver` on `problem` (with the nested iteration when there is no warm start) and
    /// returns the solution with the iterations spent on coarse levels.
    ///
    /// Row screening: when the factor's trailing block holds the dofs of only some normal
    /// rows (an interface larger than [`InterfaceBlockParams::max_dofs`], of which the
    /// [`InterfaceBlockParams::screened_dofs`] of the smallest gaps are ordered last), the solver runs
    /// on the sub-problem of those *candidate* rows (plus the rows of friction cells and the
    /// rows loaded in the warm start), whose interface Schur complement comes from the dense
    /// trailing block. The excluded rows are then checked with the computed `U`: if none
    /// penetrates, `(U, Λ_n, Λ_t)` with `Λ_n = 0` on them solves the full problem (its KKT
    /// conditions hold row by row); otherwise the penetrating rows join the candidates and the
    /// sub-problem is solved again, warm-started, until no excluded row penetrates. The
    /// returned solution has one `Λ_n` per row of `problem`.
    fn run(
        &self,
        problem: &ContactProblem<'_>,
        solver: &dyn ContactSolver,
        context: &SolveContext,
        warm: Option<&ContactSolution>,
        cell_node: &[usize],
    ) -> Result<(ContactSolution, usize), ContactError> {
        // (a bordered problem is solved whole: its coarse levels would need the border too)
        let nested = |p: &ContactProblem<'_>, adjacency: &[Vec<usize>]| match (warm, self.nested_min_rows) {
            (None, Some(min_rows)) if p.border.is_none() => {
                crate::nested::nested_warm_start(p, solver, context, adjacency, min_rows)
            }
            _ => Ok(None),
        };
        let m = problem.n_normal();
        let screened = self.trailing_rows(problem.normal).or_else(|| {
            let band = self.screening_band?;
            let near: Vec<bool> = problem.normal.gap.iter().map(|&d| d <= band).collect();
            (!near.iter().all(|&b| b)).then(|| {
                // the sub-problems draw on the unit solves of all candidate rows: reserved on
                // every dof of their nodes (a row whose normal gains a component later would
                // otherwise grow the support and empty the kept solves)
                let nodes = self.geometry.node_dof_rows(self.elastic.dofs());
                problem
                    .operator
                    .reserve_interface(synovia_linalg::RowStack::new(&nodes, None), context.row_solves());
                problem.operator.reserve_interface(problem.rows(), context.row_solves());
                near
            })
        });
        let Some(mut candidate) = screened else {
            let coarse = nested(problem, &self.geometry.adjacency)?;
            let start = warm.or(coarse.as_ref().map(|(w, _)| w));
            let solution =
                solver.solve(problem, &context.with_start(start.cloned(), context.multipliers_only()))?;
            return Ok((solution, coarse.map_or(0, |(_, it)| it)));
        };
        for &r in cell_node {
            if let Some(c) = candidate.get_mut(r) {
                *c = true;
            }
        }
        if let Some(w) = warm.filter(|w| w.lambda_n.len() == m) {
            for (c, l) in candidate.iter_mut().zip(&w.lambda_n) {
                *c |= *l != 0.0;
            }
        }
        let mut coarse_iterations = 0;
        let mut current = warm.cloned();
        let mut report: Option<SolverReport> = None;
        loop {
            let rows: Vec<usize> = (0..m).filter(|&r| candidate[r]).collect();
            let normal = restrict_rows(problem.normal, &rows);
            let border = problem.border.map(|b| crate::problem::RigidBorder {
                columns: b
                    .columns
                    .iter()
                    .map(|c| rows.iter().map(|&r| c[r]).chain(c[m..].iter().copied()).collect())
                    .collect(),
                targets: b.targets.clone(),
            });
            // the screening check below needs U, whatever the caller asked for
            let sub = ContactProblem { normal: &normal, border: border.as_ref(), ..*problem };
            let start = match &current {
                Some(w) if w.lambda_n.len() == m => Some(ContactSolution {
                    u: w.u.clone(),
                    lambda_n: rows.iter().map(|&r| w.lambda_n[r]).collect(),
                    lambda_t: w.lambda_t.clone(),
                    report: SolverReport::default(),
                }),
                // a warm start that does not fit: the solver reports it
                Some(w) => Some(w.clone()),
                None => {
                    let adjacency = restrict_adjacency(&self.geometry.adjacency, &rows, m);
                    nested(&sub, &adjacency)?.map(|(w, it)| {
                        coarse_iterations += it;
                        w
                    })
                }
            };
            let solution = solver.solve(&sub, &context.with_start(start, false))?;
            let mut lambda_n = vec![0.0; m];
            for (&r, l) in rows.iter().zip(&solution.lambda_n) {
                lambda_n[r] = *l;
            }
            let merged = merge_reports(report.take(), solution.report);
            let full =
                ContactSolution { u: solution.u, lambda_n, lambda_t: solution.lambda_t, report: merged };
            let scale = inf_norm(&full.u).max(inf_norm(&problem.normal.gap)).max(f64::MIN_POSITIVE);
            // the gaps at the coordinate the bordered solve found
            let zeta = &full.report.border_values;
            let gap = |r: usize| problem.normal.gap[r] + problem.border.map_or(0.0, |b| b.shift(r, zeta));
            let penetrating: Vec<usize> = (0..m)
                .filter(|&r| {
                    !candidate[r]
                        && problem.normal.rows.row_dot(r, &full.u) - gap(r) > SCREENING_TOLERANCE * scale
                })
                .collect();
            if penetrating.is_empty() {
                return Ok((full, coarse_iterations));
            }
            for r in penetrating {
                candidate[r] = true;
            }
            report = Some(full.report.clone());
            current = Some(full);
        }
    }

    /// For each normal row, whether all its dofs lie in the trailing block of the factor;
    /// `None` when there is no trailing block or every row does (no screening needed).
    fn trailing_rows(&self, normal: &NormalConstraints) -> Option<Vec<bool>> {
        let block = self.elastic.cholesky().trailing()?;
        let inside: Vec<bool> = (0..normal.rows.nrows())
            .map(|r| normal.rows.row(r).all(|(i, _)| block.position.get(i).is_some_and(|&p| p != usize::MAX)))
            .collect();
        (!inside.iter().all(|&b| b)).then_some(inside)
    }

    #[tracing::instrument(level = "debug", skip_all)]
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

/// Where the right-hand side of a solve comes from: the model's load case at `t`, or the
/// caller ([`StaticContact::solve_load`]: reduced load and lifts).
#[derive(Clone, Copy)]
enum Source<'a, const D: usize> {
    Model(&'a Model<D>, Real),
    Given(&'a [f64], &'a [Vector<D>]),
}

/// The right-hand side and constraints of one contact problem ([`StaticContact::assemble`]).
struct Assembled<const D: usize> {
    load: Vec<f64>,
    lifts: Vec<Vector<D>>,
    normal: NormalConstraints,
    friction_op: Option<crate::operators::FrictionOperator>,
    /// The coordinate borders on these rows ([`StaticContact::set_coordinate_borders`]).
    border: Option<RigidBorder>,
}

/// The KKT residuals of `solution` for `problem`, at the offsets of the bordered coordinates it
/// found ([`check_kkt_at_border`]).
fn kkt_of(problem: &ContactProblem<'_>, solution: &ContactSolution) -> KktReport {
    check_kkt_at_border(
        problem,
        &solution.report.border_values,
        &solution.u,
        &solution.lambda_n,
        &solution.lambda_t,
    )
}

/// The friction constraints of `op`, if it has any cell.
fn active_friction(op: Option<&crate::operators::FrictionOperator>) -> Option<&FrictionConstraints> {
    op.map(|f| &f.constraints).filter(|f| f.rows.nrows() > 0)
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
/// [`StaticContact::with_interface_block`] orders last ([`InterfaceBlockParams`]). Priority order (what a trailing block too
/// small for all of them keeps): the contact nodes of `geometry` by increasing initial gap,
/// each with its partner and master nodes, then the remaining nodes of the parts.
fn interface_nodes<const D: usize>(
    model: &Model<D>,
    pairs: &[ContactPair<D>],
    geometry: &ContactGeometry<D>,
) -> Result<Vec<(synovia_fem::BodyId, usize)>, ContactError> {
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut by_gap: Vec<usize> = (0..geometry.len()).collect();
    by_gap.sort_by(|&a, &b| geometry.nodes[a].gap.total_cmp(&geometry.nodes[b].gap).then(a.cmp(&b)));
    for r in by_gap {
        let node = &geometry.nodes[r];
        let others = node.partner.iter().copied().chain(node.master.iter().map(|&(b, j, _)| (b, j)));
        for (b, i) in std::iter::once(node.node).chain(others) {
            if seen.insert((b.0, i)) {
                out.push((b, i));
            }
        }
    }
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
        if let Some((body, part)) = pair.partner_part() {
            add(body, part)?;
        }
    }
    Ok(out)
}

/// The ordering of the contact set-up, for [`ElasticSolver::new_with_ordering`]: the dofs of
/// the `interface` nodes (in priority order) last, as [`InterfaceBlockParams`] selects them.
pub fn interface_ordering<const D: usize>(
    interface: &[(synovia_fem::BodyId, usize)],
    block: InterfaceBlockParams,
) -> impl Fn(&DofMap<D>, synovia_linalg::Ordering) -> Result<synovia_linalg::Ordering, FemError> + '_ {
    move |dofs, base| {
        let groups: Vec<std::ops::Range<usize>> =
            interface.iter().map(|&(b, i)| dofs.node_dofs(b, i)).collect();
        Ok(block.ordering(base, &groups, dofs.n_dofs()))
    }
}

/// `Ok` for a screening band ([`StaticContact::set_screening_band`]) that is `None` or finite
/// and non-negative.
///
/// # Errors
/// [`ContactError::InvalidParameter`] naming the band otherwise.
pub fn check_screening_band(band: Option<Real>) -> Result<(), ContactError> {
    match band {
        Some(b) if !(b.is_finite() && b >= 0.0) => Err(ContactError::InvalidParameter(format!(
            "screening band must be finite and non-negative, got {b}"
        ))),
        _ => Ok(()),
    }
}

/// The rows `rows` of `normal` (with their weights and gaps).
fn restrict_rows(normal: &NormalConstraints, rows: &[usize]) -> NormalConstraints {
    let mut out = SparseRows::new(normal.rows.ncols());
    for &r in rows {
        out.push_row(normal.rows.row(r));
    }
    NormalConstraints {
        rows: out,
        weights: rows.iter().map(|&r| normal.weights[r]).collect(),
        gap: rows.iter().map(|&r| normal.gap[r]).collect(),
    }
}

/// The contact-node graph `adjacency` (of `m` rows) restricted to `rows`, renumbered.
fn restrict_adjacency(adjacency: &[Vec<usize>], rows: &[usize], m: usize) -> Vec<Vec<usize>> {
    let mut index = vec![usize::MAX; m];
    for (i, &r) in rows.iter().enumerate() {
        index[r] = i;
    }
    rows.iter()
        .map(|&r| {
            adjacency.get(r).map_or_else(Vec::new, |nb| {
                nb.iter().filter_map(|&j| index.get(j).copied().filter(|&i| i != usize::MAX)).collect()
            })
        })
        .collect()
}

/// The report of a screened solve: counts and times of all passes, states of the last one.
fn merge_reports(previous: Option<SolverReport>, last: SolverReport) -> SolverReport {
    let Some(p) = previous else { return last };
    let mut history = p.history;
    history.extend(last.history);
    SolverReport {
        iterations: p.iterations + last.iterations,
        inner_iterations: p.inner_iterations + last.inner_iterations,
        linear_solves: p.linear_solves + last.linear_solves,
        time_s: p.time_s + last.time_s,
        history,
        ..last
    }
}

/// Relative penetration `(B_hn U − d)_r / max(‖U‖_∞, ‖d‖_∞)` above which a row excluded by
/// the screening of [`StaticContact`] joins the solve.
const SCREENING_TOLERANCE: f64 = 1e-12;

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
