//! The dynamic semi-implicit Kelvin–Voigt stepper with contact and friction (docs/model.md §2, §3, §7).
//!
//! ## The scheme (docs/model.md §7, report Part II (2.16)–(2.22))
//!
//! With `Δt` the step, `U^i ≈ u(t_i)`, `t_i = t_0 + iΔt`, the mass matrices
//! `M_ρ = (ρ φ_a, φ_b)`, `M_α = (α φ_a, φ_b)` (consistent or row-sum lumped), the stiffness
//! `A⁽⁰⁾` of `C⁽⁰⁾` and the viscosity matrix `A⁽¹⁾` of `C⁽¹⁾`, every step solves the contact
//! problem of docs/model.md §5 with
//!
//! ```text
//! A = M_ρ + Δt M_α + Δt² A⁽⁰⁾ + Δt A⁽¹⁾
//! F̄ = Δt² F(t_{i+1}) + M_ρ (2U^i − U^{i−1}) + Δt M_α U^i + Δt A⁽¹⁾ U^i
//! ```
//!
//! i.e. the time-discrete Kelvin–Voigt equation multiplied by `Δt²`:
//!
//! ```text
//! M_ρ (U^{i+1} − 2U^i + U^{i−1})/Δt² + M_α (U^{i+1} − U^i)/Δt + A⁽⁰⁾ U^{i+1}
//!     + A⁽¹⁾ (U^{i+1} − U^i)/Δt = F(t_{i+1}) − (contact and friction forces).
//! ```
//!
//! `A` is symmetric positive definite even for bodies without any Dirichlet data (the mass
//! term), so no coercivity check is needed; it is assembled on one sparsity pattern and
//! factorised once (symbolic and numeric) for the whole run.
//!
//! **One pipeline**: the step problem is solved by the static contact machinery,
//! [`StaticContact::with_system_matrix`] on `A` and [`StaticContact::solve_load`] with `F̄` per
//! step (contact rows, row screening, Schur-column cache, KKT check), the same code as a static
//! or quasi-static solve; this module only adds what is dynamic (mass and damping, `F̄`, the
//! levels, slip speeds, the `Δt²` scaling, energies).
//!
//! **Contact in displacements**: `[U^{i+1}_n] ≤ d` with the initial gap `d` (minus the normal
//! part of the lift at `t_{i+1}`). Because the equation was multiplied by `Δt²`, the contact
//! multipliers of the step problem are `Λ̄_n = Δt² λ_n`: the physical contact pressure is
//! `λ_n = Λ̄_n / Δt²` and the nodal contact forces are `−B_hnᵀ κ Λ̄_n / Δt²`.
//!
//! **Friction on the slip rate** (docs/model.md §3): the rate form `j(w) = ∫ g_c |[w_t]| ds` in the
//! velocity `w = (v − U^i)/Δt`, tested with `(v − U^{i+1})/Δt` and multiplied by `Δt²`
//! (`j` is positively homogeneous), becomes `Δt² ∫ g_c |[v_t − U^i_t]| ds` in the step problem
//! with the *physical* slip bound `g_c = F_c(|[u'_t]|) |λ_n|` (force per area). The report's
//! Part II (2.16), (2.19) carries the same `Δt²`; a single `Δt` would be one power too few for
//! a `g_c` in force per area (check the units: every term of the step problem is `kg·m²`;
//! docs/model.md (7.7)). synovia uses the slip
//! bound `ḡ_c = Δt² g_c = F_c(|[u'_t]|^i) |Λ̄_n^i|` in the step problem, i.e. the Coulomb law with the scaled pressure of level `i`. The deceleration of a
//! sliding block (`μ g`, see the tests) confirms the scaling. The slip speed `|[u'_t]|^i` is
//! `|[U^i_t] − [U^{i−1}_t]| / Δt` at each contact node ([`slip_speeds`]) and the law `F_c` is any
//! [`FrictionLaw`] per pair ([`DynamicStepper::set_friction_law`], [`PairFrictionLaws`], shared
//! with the quasi-static stepper; default: the pair's constant coefficient). Optionally a Coulomb fixed point per step recomputes
//! `ḡ_c` from the new level until it stops changing ([`DynamicParams::coulomb_iterations`]).
//!
//! ## Reduced unknowns and moving lifts
//!
//! All matrices act on full nodal vectors; the unknowns are the reduced ones of
//! [`DofMap`], `U^j = u_p(t_j) + P ũ^j`. Testing with `P` (i.e. multiplying by `Pᵀ`) gives
//! `Ã ũ^{i+1} = F̃` with `Ã = Pᵀ A P` and
//!
//! ```text
//! F̃ = Δt² Pᵀ F(t_{i+1}) + M̃_ρ (2ũ^i − ũ^{i−1}) + Δt (M̃_α + Ã⁽¹⁾) ũ^i
//!     − Pᵀ [ M_ρ (u_p^{i+1} − 2u_p^i + u_p^{i−1}) + Δt (M_α + A⁽¹⁾)(u_p^{i+1} − u_p^i)
//!            + Δt² A⁽⁰⁾ u_p^{i+1} ]
//! ```
//!
//! (`M̃ = Pᵀ M P` etc.). The three lift terms are evaluated element by element with
//! [`subtract_lift`] and the element kernels of `M_ρ`, `Δt (M_α + A⁽¹⁾)` (a composite
//! kernel) and `Δt² A⁽⁰⁾`; each is skipped when its lift combination vanishes (no prescribed
//! motion, or a lift constant in time leaves only the last one).
//!
//! ## Energies (see `docs/dynamics.md`)
//!
//! With `δ^i = U^{i+1} − U^i` and `V^{i+1} = δ^i/Δt`, the stepper reports after each step the
//! kinetic energy `½ V^{i+1}ᵀ M_ρ V^{i+1}`, the strain energy `½ U^{i+1}ᵀ A⁽⁰⁾ U^{i+1}` and the
//! terms of the discrete energy identity ([`EnergyBalance`]):
//!
//! ```text
//! E^{i+1} − E^i = W_ext − W_c − W_f − D_visc − D_num,
//! E^i = ½ ‖δ^{i−1}‖²_{M_ρ}/Δt² + ½ ‖U^i‖²_{A⁽⁰⁾},
//! D_num = ½ ‖δ^i − δ^{i−1}‖²_{M_ρ}/Δt² + ½ ‖δ^i‖²_{A⁽⁰⁾},
//! D_visc = Δt (V^{i+1}ᵀ M_α V^{i+1} + V^{i+1}ᵀ A⁽¹⁾ V^{i+1}),
//! W_ext = δ^iᵀ F(t_{i+1}),  W_c = δ^iᵀ B_hnᵀ κ Λ̄_n / Δt²,  W_f = δ^iᵀ B_Htᵀ Λ_t / Δt²,
//! ```
//!
//! exact (to round-off) when there is no prescribed motion.

use std::sync::Arc;
use std::time::Instant;

use nalgebra::DMatrix;
use synovia_contact::operators::{ContactGeometry, ContactPair};
use synovia_contact::{
    slip_speeds, ContactSolution, ContactSolver, FrictionLaw, PairFrictionLaws, StaticContact,
    StaticContactResult,
};
use synovia_fem::assembly::{add_loads, assemble_matrix, body_stiffnesses, subtract_lift};
use synovia_fem::element::{mass_into, stiffness_into, SimplexGeometry};
use synovia_fem::{CholeskySolver, DofMap, ElasticParams, FemError, Model, OrderingChoice, SymmetricMatrix};
use synovia_material::{voigt_len, KelvinVoigt, VoigtMatrix};
use synovia_mesh::math::{Point, Real, Vector};

use crate::error::TimeError;
use crate::quasistatic::{friction_dissipation, transfer_result, warm_start};
use crate::results::{empty_pair_records, pair_records, StepRecord};

/// Largest element matrix size `(D(D+1))²` for `D ≤ 3`.
const KE_MAX: usize = 144;

/// The inertia and viscosity data of one body for dynamics (docs/model.md §2): density `ρ`, damping `α`
/// and the viscosity `C⁽¹⁾` of `τ = C⁽⁰⁾ e(u) + C⁽¹⁾ e(u')`. The elasticity `C⁽⁰⁾` is the
/// body's material in the [`Model`].
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicBody {
    /// Mass density `ρ > 0` (mass per volume; per area in 2D plane strain per unit thickness).
    pub density: Real,
    /// Damping coefficient `α ≥ 0` of the damping force `α u'` per volume, i.e. the bilinear
    /// form `(α u', v) = ∫ α u'·v dx` of docs/model.md §2 (`M_α`). A mass-proportional damping
    /// `c ρ u'` is `α = c ρ`.
    pub damping: Real,
    /// The viscosity `C⁽¹⁾` (Voigt, `voigt_len(D)` square, symmetric positive semi-definite);
    /// `None` means `C⁽¹⁾ = 0`.
    pub viscous: Option<VoigtMatrix>,
}

impl DynamicBody {
    /// An elastic body (no damping, no viscosity) of density `ρ`.
    pub fn elastic(density: Real) -> Self {
        Self { density, damping: 0.0, viscous: None }
    }

    /// The data of a [`KelvinVoigt`] material: `ρ`, `α` and its linear `C⁽¹⁾`.
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] if the viscosity is nonlinear (no constant `C⁽¹⁾`).
    pub fn from_kelvin_voigt<const D: usize>(material: &KelvinVoigt<D>) -> Result<Self, TimeError> {
        let viscous = match material.viscous() {
            None => None,
            Some(_) => Some(material.viscous_stiffness().ok_or_else(|| {
                TimeError::InvalidParameter(
                    "the Kelvin-Voigt viscosity C(1) is nonlinear; the dynamic stepper needs a constant C(1)"
                        .into(),
                )
            })?),
        };
        Ok(Self { density: material.density(), damping: material.damping(), viscous })
    }

    pub(crate) fn check(&self, body: &str, nv: usize) -> Result<(), TimeError> {
        let bad = |m: String| Err(TimeError::InvalidParameter(format!("body `{body}`: {m}")));
        if !(self.density.is_finite() && self.density > 0.0) {
            return bad(format!("density ρ = {} must be positive and finite", self.density));
        }
        if !(self.damping.is_finite() && self.damping >= 0.0) {
            return bad(format!("damping α = {} must be finite and ≥ 0", self.damping));
        }
        if let Some(c) = &self.viscous {
            if c.nrows() != nv || c.ncols() != nv {
                return bad(format!("viscosity C(1) is {}×{}, expected {nv}×{nv}", c.nrows(), c.ncols()));
            }
            if c.iter().any(|v| !v.is_finite()) {
                return bad("viscosity C(1) is not finite".into());
            }
            let scale = c.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            if (c - c.transpose()).iter().any(|v| v.abs() > 1e-10 * scale) {
                return bad("viscosity C(1) is not symmetric".into());
            }
            let min = c.clone().symmetric_eigen().eigenvalues.iter().fold(Real::INFINITY, |a, &v| a.min(v));
            if min < -1e-12 * scale.max(Real::MIN_POSITIVE) * nv as Real {
                return bad(format!("viscosity C(1) is not positive semi-definite (λ_min = {min:e})"));
            }
        }
        Ok(())
    }
}

/// Consistent or row-sum lumped mass matrices `M_ρ`, `M_α`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum MassKind {
    /// The consistent mass `∫ ρ φ_a φ_b dx` (default).
    #[default]
    Consistent,
    /// Row-sum lumped (diagonal) mass `ρ |T| / (D + 1)` per node and cell.
    Lumped,
}

/// Parameters of the dynamic stepper (docs/model.md §7).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct DynamicParams {
    /// Time step `Δt > 0`.
    pub dt: Real,
    /// Initial time `t_0` (default 0).
    pub t0: Real,
    /// Consistent or lumped mass (default consistent).
    pub mass: MassKind,
    /// Fill-reducing ordering of the factorisation of `A` (default: AMD in 2D, METIS in 3D).
    pub ordering: OrderingChoice,
    /// Quadrature degree of the load integrals (default 2).
    pub load_degree: usize,
    /// Coulomb fixed-point iterations per step: 0 (default) freezes `g_c` from level `i`
    /// (docs/model.md §7); `k > 0` re-solves up to `k` times with `g_c` from the new level (true Coulomb
    /// friction at `t_{i+1}`, docs/model.md §3) until the relative change of `g_c` is at most
    /// [`DynamicParams::coulomb_tolerance`].
    pub coulomb_iterations: usize,
    /// Tolerance of the Coulomb fixed point (default `1e-8`).
    pub coulomb_tolerance: Real,
    /// Warm-start each contact solve from the multipliers of the previous step (default true).
    pub warm_start: bool,
}

impl Default for DynamicParams {
    /// The defaults with `Δt = 10⁻³` (set the time step of the problem with
    /// [`DynamicParams::with_dt`] or use [`DynamicParams::new`]).
    fn default() -> Self {
        Self::new(1e-3)
    }
}

impl DynamicParams {
    /// Sets [`Self::dt`].
    pub fn with_dt(mut self, dt: Real) -> Self {
        self.dt = dt;
        self
    }
    /// Sets [`Self::t0`].
    pub fn with_t0(mut self, t0: Real) -> Self {
        self.t0 = t0;
        self
    }
    /// Sets [`Self::mass`].
    pub fn with_mass(mut self, mass: MassKind) -> Self {
        self.mass = mass;
        self
    }
    /// Sets [`Self::ordering`].
    pub fn with_ordering(mut self, ordering: OrderingChoice) -> Self {
        self.ordering = ordering;
        self
    }
    /// Sets [`Self::load_degree`].
    pub fn with_load_degree(mut self, load_degree: usize) -> Self {
        self.load_degree = load_degree;
        self
    }
    /// Sets [`Self::coulomb_iterations`].
    pub fn with_coulomb_iterations(mut self, coulomb_iterations: usize) -> Self {
        self.coulomb_iterations = coulomb_iterations;
        self
    }
    /// Sets [`Self::coulomb_tolerance`].
    pub fn with_coulomb_tolerance(mut self, coulomb_tolerance: Real) -> Self {
        self.coulomb_tolerance = coulomb_tolerance;
        self
    }
    /// Sets [`Self::warm_start`].
    pub fn with_warm_start(mut self, warm_start: bool) -> Self {
        self.warm_start = warm_start;
        self
    }
    /// Defaults with the time step `dt`.
    pub fn new(dt: Real) -> Self {
        Self {
            dt,
            t0: 0.0,
            mass: MassKind::Consistent,
            ordering: OrderingChoice::Auto,
            load_degree: 2,
            coulomb_iterations: 0,
            coulomb_tolerance: 1e-8,
            warm_start: true,
        }
    }

    pub(crate) fn check(&self) -> Result<(), TimeError> {
        let bad = |m: String| Err(TimeError::InvalidParameter(m));
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return bad(format!("time step Δt = {} must be positive and finite", self.dt));
        }
        if !self.t0.is_finite() {
            return bad(format!("initial time t0 = {} must be finite", self.t0));
        }
        if !(self.coulomb_tolerance.is_finite() && self.coulomb_tolerance > 0.0) {
            return bad(format!("Coulomb tolerance {} must be positive", self.coulomb_tolerance));
        }
        if self.load_degree == 0 {
            return bad("load quadrature degree must be at least 1".into());
        }
        Ok(())
    }
}

/// The terms of the discrete energy identity of one step `i → i+1` (see the module docs and
/// `docs/dynamics.md`):
/// `E^{i+1} − E^i = W_ext − W_c − W_f − D_visc − D_num`, exact when there is no prescribed
/// motion ([`EnergyBalance::exact`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EnergyBalance {
    /// Kinetic energy `½ Vᵀ M_ρ V`, `V = (U^{i+1} − U^i)/Δt`.
    pub kinetic: Real,
    /// Strain energy `½ U^{i+1}ᵀ A⁽⁰⁾ U^{i+1}`.
    pub strain: Real,
    /// Numerical dissipation `½ ‖δ^i − δ^{i−1}‖²_{M_ρ}/Δt² + ½ ‖δ^i‖²_{A⁽⁰⁾}` (≥ 0).
    pub numerical_dissipation: Real,
    /// Damping and viscous dissipation `Δt (Vᵀ M_α V + Vᵀ A⁽¹⁾ V)` (≥ 0).
    pub viscous_dissipation: Real,
    /// Work of the loads `δ^iᵀ F(t_{i+1})` (reduced loads: without reactions of prescribed
    /// displacements).
    pub external_work: Real,
    /// Work of the normal contact forces `δ^iᵀ B_hnᵀ κ Λ̄_n / Δt²` (≥ 0 for a fixed gap: the
    /// contact dissipates).
    pub contact_work: Real,
    /// Work of the friction forces `δ^iᵀ B_Htᵀ Λ_t / Δt² = Σ_c g_c κ_c ‖Δ[u_t]_c‖` (≥ 0).
    pub friction_work: Real,
    /// `true` when no lift (prescribed displacement) is non-zero at the three levels involved:
    /// then the identity holds to round-off.
    pub exact: bool,
}

impl EnergyBalance {
    /// The discrete energy `E = kinetic + strain`.
    pub fn energy(&self) -> Real {
        self.kinetic + self.strain
    }
    /// `W_ext − W_c − W_f − D_visc − D_num`: the predicted change `E^{i+1} − E^i`.
    pub fn predicted_change(&self) -> Real {
        self.external_work
            - self.contact_work
            - self.friction_work
            - self.viscous_dissipation
            - self.numerical_dissipation
    }
}

/// Sizes and set-up timings of a [`DynamicStepper`], in seconds.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DynamicInfo {
    /// Reduced unknowns.
    pub n_dofs: usize,
    /// Stored entries of the lower triangle of `A`.
    pub matrix_nnz: usize,
    /// Stored entries of the Cholesky factor.
    pub factor_nnz: usize,
    /// Dof map, pattern and assembly of the four matrices.
    pub assembly_s: f64,
    /// Ordering + symbolic analysis.
    pub symbolic_s: f64,
    /// Numeric factorisation of `A` (done once).
    pub numeric_s: f64,
}

/// The dynamic semi-implicit stepper of docs/model.md §7 (see the module docs): assembles
/// `A = M_ρ + Δt M_α + Δt² A⁽⁰⁾ + Δt A⁽¹⁾` and hands it to the static contact machinery
/// ([`StaticContact::with_system_matrix`]: one factorisation, contact rows, Schur-column cache,
/// KKT check), which solves one contact problem of docs/model.md §5 per step with any
/// [`ContactSolver`] for the right-hand side `F̄` of the step ([`StaticContact::solve_load`]).
/// The stepper keeps only what is dynamic: the mass, damping and viscosity matrices, `F̄`, the
/// levels `U^i`, `U^{i−1}`, the slip speeds and the energies.
///
/// The [`Model`] passed to [`DynamicStepper::step`] must be the one given to
/// [`DynamicStepper::new`] (its loads and prescribed displacements are evaluated at every step).
#[derive(Debug)]
pub struct DynamicStepper<const D: usize> {
    /// The contact machinery on `Ã` (dofs, geometry, factorisation).
    contact: StaticContact<D>,
    params: DynamicParams,
    bodies: Vec<DynamicBody>,
    c0: Vec<DMatrix<Real>>,
    laws: PairFrictionLaws,
    mass: SymmetricMatrix,
    mass_alpha: SymmetricMatrix,
    stiffness: SymmetricMatrix,
    viscous: SymmetricMatrix,
    /// `Δt (M̃_α + Ã⁽¹⁾)`.
    damping_dt: SymmetricMatrix,
    has_damping: bool,
    nodal_mass: Vec<Vec<Real>>,
    info: DynamicInfo,
    // state at level i (and i − 1)
    step: usize,
    u: Vec<Real>,
    u_prev: Vec<Real>,
    lifts: Vec<Vector<D>>,
    lifts_prev: Vec<Vector<D>>,
    disp: Vec<Vec<Vector<D>>>,
    disp_prev: Vec<Vec<Vector<D>>>,
    /// Scaled pressure `Λ̄_n = Δt² λ_n` per contact node at level i.
    pressure: Vec<Real>,
    /// Slip speed `|[u'_t]|` per contact node at level i.
    slip_speed: Vec<Real>,
    /// The step problem's solution of level i (scaled multipliers), for the warm start.
    warm: Option<StaticContactResult<D>>,
    last: Option<StaticContactResult<D>>,
    balance: EnergyBalance,
    cumulative_friction: Real,
}

impl<const D: usize> DynamicStepper<D> {
    /// Validates the data, builds the dofs and contact nodes, assembles `M_ρ`, `M_α`, `A⁽⁰⁾`,
    /// `A⁽¹⁾` on one pattern, forms `A` and factorises it. The initial state is rest at the
    /// lifts of `t_0` (`u₀ = u_p(t_0)`, `u₁ = 0`); see [`DynamicStepper::set_initial_state`].
    ///
    /// `bodies[ι]` holds the dynamic data of body `ι` of the model; `pairs` the contact pairs
    /// (possibly none).
    ///
    /// # Errors
    /// Invalid parameters or body data ([`TimeError::InvalidParameter`]), model and assembly
    /// errors ([`TimeError::Fem`]), contact set-up errors ([`TimeError::ContactSetup`]).
    pub fn new(
        model: &Model<D>,
        bodies: &[DynamicBody],
        pairs: &[ContactPair<D>],
        params: DynamicParams,
    ) -> Result<Self, TimeError> {
        params.check()?;
        model.validate()?;
        if bodies.len() != model.bodies().len() {
            return Err(TimeError::InvalidParameter(format!(
                "{} dynamic body data for {} bodies",
                bodies.len(),
                model.bodies().len()
            )));
        }
        let nv = voigt_len(D);
        for (b, data) in model.bodies().iter().zip(bodies) {
            data.check(&b.name, nv)?;
        }
        let c0 = body_stiffnesses(model)?;
        let zero_c = DMatrix::<Real>::zeros(nv, nv);
        let c1: Vec<DMatrix<Real>> =
            bodies.iter().map(|b| b.viscous.clone().unwrap_or_else(|| zero_c.clone())).collect();
        let rho: Vec<Real> = bodies.iter().map(|b| b.density).collect();
        let alpha: Vec<Real> = bodies.iter().map(|b| b.damping).collect();
        let lumped = params.mass == MassKind::Lumped;
        let dt = params.dt;
        let has_alpha = alpha.iter().any(|&a| a > 0.0);
        let has_c1 = bodies.iter().any(|b| b.viscous.as_ref().is_some_and(|c| c.iter().any(|v| *v != 0.0)));

        // M̃_ρ, M̃_α, Ã⁽⁰⁾, Ã⁽¹⁾ on the model's pattern; Ã is handed to the contact machinery
        let mut parts = None;
        let assemble = |dofs: &DofMap<D>, matrix: &mut SymmetricMatrix| -> Result<(), FemError> {
            let mut mass = matrix.clone();
            let mut mass_alpha = matrix.clone();
            let mut stiffness = matrix.clone();
            let mut viscous = matrix.clone();
            assemble_matrix(model, dofs, &mut mass, |b, _, geo, out| mass_into(geo, rho[b], lumped, out))?;
            if has_alpha {
                assemble_matrix(model, dofs, &mut mass_alpha, |b, _, geo, out| {
                    mass_into(geo, alpha[b], lumped, out)
                })?;
            }
            assemble_matrix(model, dofs, &mut stiffness, |b, _, geo, out| stiffness_into(geo, &c0[b], out))?;
            if has_c1 {
                assemble_matrix(model, dofs, &mut viscous, |b, _, geo, out| {
                    stiffness_into(geo, &c1[b], out)
                })?;
            }
            let mut damping_dt = mass_alpha.clone();
            damping_dt.values_mut().iter_mut().for_each(|v| *v *= dt);
            damping_dt.add_scaled(dt, &viscous)?;
            *matrix = mass.clone();
            matrix.add_scaled(1.0, &damping_dt)?;
            matrix.add_scaled(dt * dt, &stiffness)?;
            parts = Some((mass, mass_alpha, stiffness, viscous, damping_dt));
            Ok(())
        };
        let elastic = ElasticParams::default().with_ordering(params.ordering);
        let mut contact = StaticContact::with_system_matrix(model, pairs, elastic, assemble)?;
        // every step is warm-started from the previous one (or cold, as chosen): no nested iteration
        contact.set_nested_iteration(None);
        let (mass, mass_alpha, stiffness, viscous, damping_dt) = parts.ok_or_else(|| {
            TimeError::InvalidParameter("internal: the time-step matrix was not assembled".into())
        })?;
        let ei = contact.elastic().info();
        let info = DynamicInfo {
            n_dofs: ei.n_dofs,
            matrix_nnz: ei.matrix_nnz,
            factor_nnz: ei.factor_nnz,
            assembly_s: ei.setup_s + ei.assembly_s,
            symbolic_s: ei.symbolic_s,
            numeric_s: ei.numeric_s,
        };
        // lumped nodal masses (eᵀ M_ρ for a translation e, the same for consistent mass)
        let mut nodal_mass = Vec::with_capacity(model.bodies().len());
        for (bi, body) in model.bodies().iter().enumerate() {
            let mut m = vec![0.0; body.mesh.n_nodes()];
            for c in 0..body.mesh.n_cells() {
                let share = rho[bi] * body.mesh.cell_measure(c) / (D + 1) as Real;
                for &a in body.mesh.cell(c) {
                    m[a] += share;
                }
            }
            nodal_mass.push(m);
        }

        let laws = PairFrictionLaws::new(contact.geometry());
        let n = contact.elastic().dofs().n_dofs();
        let nc = contact.geometry().len();
        let lifts = contact.elastic().dofs().lifts(model, params.t0)?;
        let zero_nodal: Vec<Vec<Vector<D>>> =
            model.bodies().iter().map(|b| vec![Vector::<D>::zeros(); b.mesh.n_nodes()]).collect();
        let mut s = Self {
            contact,
            params,
            bodies: bodies.to_vec(),
            c0,
            laws,
            mass,
            mass_alpha,
            stiffness,
            viscous,
            damping_dt,
            has_damping: has_alpha || has_c1,
            nodal_mass,
            info,
            step: 0,
            u: vec![0.0; n],
            u_prev: vec![0.0; n],
            lifts: lifts.clone(),
            lifts_prev: lifts,
            disp: zero_nodal.clone(),
            disp_prev: zero_nodal,
            pressure: vec![0.0; nc],
            slip_speed: vec![0.0; nc],
            warm: None,
            last: None,
            balance: EnergyBalance::default(),
            cumulative_friction: 0.0,
        };
        s.set_initial_state(model, None, None)?;
        Ok(s)
    }

    /// Sets the initial data `u(t_0) = u₀`, `u'(t_0) = u₁` (nodal values per body; `None` = 0)
    /// and resets the stepper to step 0 (docs/model.md §7: `U^{−1} = U^0 − Δt u₁`).
    ///
    /// The constrained components of `U^0` are taken from the prescribed displacements at
    /// `t_0` (the lift `u_p(t_0)`), the free ones from `u₀`; `U^{−1} = U^0 − Δt u₁` is formed
    /// node by node, so `u₁` should agree with `u₂'(t_0)` on prescribed components. Bonded
    /// nodes take the values of the first node of their group. The contact pressure of level 0
    /// is reset to zero (no friction in the first step unless
    /// [`DynamicStepper::set_initial_pressure`] is called or the Coulomb fixed point is on).
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for wrong sizes or non-finite values.
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
        let InitialLevels { u0, um1, lifts0, lifts_m1 } =
            initial_levels(model, self.dofs(), self.params.t0, dt, displacement, velocity)?;
        self.disp = self.dofs().expand(&u0, &lifts0)?;
        self.disp_prev = self.dofs().expand(&um1, &lifts_m1)?;
        self.u = u0;
        self.u_prev = um1;
        self.lifts = lifts0;
        self.lifts_prev = lifts_m1;
        self.step = 0;
        self.pressure.iter_mut().for_each(|p| *p = 0.0);
        self.slip_speed = self.nodal_slip_speeds(&self.disp, &self.disp_prev);
        self.warm = None;
        self.last = None;
        self.cumulative_friction = 0.0;
        let dt2 = dt * dt;
        let (kinetic, strain) = if all_zero(&self.lifts) && all_zero(&self.lifts_prev) {
            let d: Vec<Real> = self.u.iter().zip(&self.u_prev).map(|(a, b)| a - b).collect();
            (0.5 * self.mass.quadratic_form(&d) / dt2, 0.5 * self.stiffness.quadratic_form(&self.u))
        } else {
            let d = nodal_diff(&self.disp, &self.disp_prev, 1.0);
            (
                0.5 * self.full_form(model, &d, Kernel::Mass) / dt2,
                0.5 * self.full_form(model, &self.disp, Kernel::Stiffness),
            )
        };
        let exact = all_zero(&self.lifts) && all_zero(&self.lifts_prev);
        self.balance = EnergyBalance { kinetic, strain, exact, ..Default::default() };
        Ok(())
    }

    /// Sets the contact pressure `λ_n` (physical, one per contact node) of level 0, from which
    /// the slip bounds of the first step are computed (e.g. the pressure of the static contact
    /// problem that gave `u₀`).
    ///
    /// # Errors
    /// [`TimeError::InvalidParameter`] for a wrong length or non-finite values.
    pub fn set_initial_pressure(&mut self, pressure: &[Real]) -> Result<(), TimeError> {
        if pressure.len() != self.geometry().len() || pressure.iter().any(|p| !p.is_finite()) {
            return Err(TimeError::InvalidParameter(format!(
                "initial pressure: {} finite values needed (one per contact node), got {}",
                self.geometry().len(),
                pressure.len()
            )));
        }
        let dt2 = self.params.dt * self.params.dt;
        self.pressure = pressure.iter().map(|p| p * dt2).collect();
        Ok(())
    }

    /// Replaces the friction law `F_c(|[u'_t]|)` of the contact pair `pair` (docs/model.md §3; default
    /// `ConstantFriction(pair.friction)`, none for a frictionless pair).
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

    /// The physical slip bounds `g_c = F_c(|[u'_t]|) |λ_n|` per contact node scaled by `Δt²`
    /// (`ḡ_c = F_c |Λ̄_n|`), from the given scaled pressures and slip speeds
    /// ([`PairFrictionLaws::slip_bounds`]).
    fn slip_bounds(&self, pressure: &[Real], speed: &[Real]) -> Vec<Real> {
        self.laws.slip_bounds(self.geometry(), pressure, speed)
    }

    /// Rebuilds the contact rows from the model's current data before the next step — e.g. a
    /// rigid partner posed at `t_{i+1}` (docs/model.md §10: its posed shape is read when the
    /// rows are built; the step's constraints are then those of the partner's position at the
    /// end of the step). The level's pressures, slip speeds and warm start are carried node by
    /// node to the new rows ([`ContactGeometry::node_map`]; nodes new in the rows start at
    /// zero). The factorisation of `Ã` is kept. The partner motion of the new rows is none
    /// until [`DynamicStepper::set_partner_motion`].
    ///
    /// # Errors
    /// [`TimeError::ContactSetup`] from [`StaticContact::rebuild_geometry`].
    pub fn rebuild_geometry(&mut self, model: &Model<D>, pairs: &[ContactPair<D>]) -> Result<(), TimeError> {
        let old = self.contact.rebuild_geometry(model, pairs)?;
        let new = self.contact.geometry();
        if !new.same_rows(&old) {
            self.pressure = new.transfer(&old, &self.pressure);
            self.slip_speed = new.transfer(&old, &self.slip_speed);
            self.warm = self.warm.take().map(|w| transfer_result(&old, new, &w));
            self.last = self.last.take().map(|l| transfer_result(&old, new, &l));
        }
        Ok(())
    }

    /// Sets the motion `w_r` of the contact partners' material points at the contact nodes
    /// over the next step (one vector per contact node, or empty for none;
    /// [`ContactGeometry::set_partner_motion`]): friction against a moving rigid partner
    /// measures the slip `[U^{i+1}_t] − ([U^i_t] + w_{r,t})` relative to it, in the step
    /// problem, the friction work and the slip speeds of the friction law.
    ///
    /// # Errors
    /// [`TimeError::ContactSetup`] for a wrong length or non-finite values.
    pub fn set_partner_motion(&mut self, motion: Vec<Vector<D>>) -> Result<(), TimeError> {
        Ok(self.contact.set_partner_motion(motion)?)
    }

    /// `|[u'_t]|` per contact node from two nodal displacement levels ([`slip_speeds`]).
    fn nodal_slip_speeds(&self, new: &[Vec<Vector<D>>], old: &[Vec<Vector<D>>]) -> Vec<Real> {
        slip_speeds(self.geometry(), new, old, self.params.dt)
    }

    /// Advances one step `t_i → t_{i+1}`: assembles `F̃` (see the module docs), builds the
    /// normal constraints at `t_{i+1}` and the friction constraints with `ḡ_c` from level `i`
    /// (and slip measured from `U^i`), solves the contact problem with `solver` (reusing the
    /// factorisation of `A`), and returns the step's figures (physical contact forces and
    /// pressures, energies, friction dissipation).
    ///
    /// # Errors
    /// [`TimeError::Contact`] when the solver fails, [`TimeError::FixedPoint`] when the Coulomb
    /// fixed point does not converge, [`TimeError::Fem`] for load or lift evaluation errors.
    pub fn step(&mut self, model: &Model<D>, solver: &dyn ContactSolver) -> Result<StepRecord, TimeError> {
        let t_start = Instant::now();
        let step = self.step + 1;
        let dt = self.params.dt;
        let dt2 = dt * dt;
        let time = self.params.t0 + step as Real * dt;
        if model.n_nodes() != self.nodal_mass.iter().map(Vec::len).sum::<usize>() {
            return Err(TimeError::InvalidParameter(
                "the model passed to step() is not the one the stepper was built for".into(),
            ));
        }
        let n = self.dofs().n_dofs();
        let lifts_new = self.dofs().lifts(model, time)?;

        // loads: F̃_load = Pᵀ F(t_{i+1})
        let mut load = vec![0.0; n];
        add_loads(model, self.dofs(), time, self.params.load_degree, &mut load)?;
        // F̄ = Δt² F̃_load + M̃ (2ũ^i − ũ^{i−1}) + Δt (M̃_α + Ã⁽¹⁾) ũ^i − lift terms
        let mut rhs: Vec<Real> = load.iter().map(|f| dt2 * f).collect();
        let two_u: Vec<Real> = self.u.iter().zip(&self.u_prev).map(|(a, b)| 2.0 * a - b).collect();
        let mut tmp = vec![0.0; n];
        self.mass.mul_vec(&two_u, &mut tmp);
        add_into(&mut rhs, &tmp);
        if self.has_damping {
            self.damping_dt.mul_vec(&self.u, &mut tmp);
            add_into(&mut rhs, &tmp);
        }
        self.subtract_lift_terms(model, &lifts_new, &mut rhs)?;

        // contact
        let nc = self.geometry().len();
        let (u_new, result, iterations) = if nc == 0 {
            let mut x = rhs.clone();
            self.cholesky().solve_in_place(&mut x)?;
            (x, None, 0)
        } else {
            let cs = self.solve_contact(step, time, &lifts_new, &rhs, solver)?;
            let iterations = cs.iterations;
            (cs.result.solution.u.clone(), Some(cs), iterations)
        };

        // energies (before shifting the levels)
        let lifts_zero = all_zero(&lifts_new) && all_zero(&self.lifts) && all_zero(&self.lifts_prev);
        let disp_new = self.dofs().expand(&u_new, &lifts_new)?;
        let delta: Vec<Real> = u_new.iter().zip(&self.u).map(|(a, b)| a - b).collect();
        let (kinetic, strain, numerical, viscous) = if lifts_zero {
            let d2: Vec<Real> =
                delta.iter().zip(self.u.iter().zip(&self.u_prev)).map(|(d, (a, b))| d - (a - b)).collect();
            let kinetic = 0.5 * self.mass.quadratic_form(&delta) / dt2;
            let strain = 0.5 * self.stiffness.quadratic_form(&u_new);
            let numerical =
                0.5 * self.mass.quadratic_form(&d2) / dt2 + 0.5 * self.stiffness.quadratic_form(&delta);
            let viscous = if self.has_damping { self.damping_dt.quadratic_form(&delta) / dt2 } else { 0.0 };
            (kinetic, strain, numerical, viscous)
        } else {
            let dfull = nodal_diff(&disp_new, &self.disp, 1.0);
            let dprev = nodal_diff(&self.disp, &self.disp_prev, 1.0);
            let d2 = nodal_diff(&dfull, &dprev, 1.0);
            let kinetic = 0.5 * self.full_form(model, &dfull, Kernel::Mass) / dt2;
            let strain = 0.5 * self.full_form(model, &disp_new, Kernel::Stiffness);
            let numerical = 0.5 * self.full_form(model, &d2, Kernel::Mass) / dt2
                + 0.5 * self.full_form(model, &dfull, Kernel::Stiffness);
            let viscous =
                if self.has_damping { self.full_form(model, &dfull, Kernel::DampingDt) / dt2 } else { 0.0 };
            (kinetic, strain, numerical, viscous)
        };
        let external_work: Real = delta.iter().zip(&load).map(|(d, f)| d * f).sum();

        let mut record = StepRecord { step, time, iterations, ..Default::default() };
        let (mut contact_work, mut friction_work) = (0.0, 0.0);
        let mut warm = None;
        let mut new_pressure = vec![0.0; nc];
        if let Some(ContactStep { result: scaled, friction_work: fwork, .. }) = result {
            // W_c = δᵀ B_hnᵀ κ Λ̄_n / Δt² with the normal rows of the step
            let normal = self.geometry().normal_constraints(self.dofs(), &lifts_new);
            let bn_delta = normal.rows.mul(&delta);
            contact_work = bn_delta
                .iter()
                .zip(&normal.weights)
                .zip(&scaled.solution.lambda_n)
                .map(|((y, k), l)| y * k * l)
                .sum::<Real>()
                / dt2;
            friction_work = fwork / dt2;
            new_pressure.clone_from(&scaled.solution.lambda_n);
            record.solver.clone_from(&scaled.solution.report.solver);
            record.fallback.clone_from(&scaled.solution.report.fallback);
            let physical = ContactSolution {
                u: scaled.solution.u.clone(),
                lambda_n: scaled.solution.lambda_n.iter().map(|l| l / dt2).collect(),
                lambda_t: scaled.solution.lambda_t.clone(),
                report: scaled.solution.report.clone(),
            };
            let res = StaticContactResult {
                displacement: disp_new.clone(),
                solution: physical,
                cell_node: scaled.cell_node.clone(),
                slip_bound: scaled.slip_bound.iter().map(|g| g / dt2).collect(),
                kkt: scaled.kkt,
                coarse_iterations: scaled.coarse_iterations,
                proximal_iterations: scaled.proximal_iterations,
            };
            record.pairs = pair_records(self.geometry(), &res);
            self.last = Some(res);
            warm = Some(scaled);
        }
        self.cumulative_friction += friction_work;
        record.friction_dissipation = friction_work;
        record.cumulative_friction_dissipation = self.cumulative_friction;
        record.kinetic_energy = kinetic;
        record.strain_energy = strain;
        record.viscous_dissipation = viscous;
        self.balance = EnergyBalance {
            kinetic,
            strain,
            numerical_dissipation: numerical,
            viscous_dissipation: viscous,
            external_work,
            contact_work,
            friction_work,
            exact: lifts_zero,
        };

        // shift the levels
        self.slip_speed = self.nodal_slip_speeds(&disp_new, &self.disp);
        self.pressure = new_pressure;
        self.u_prev = std::mem::replace(&mut self.u, u_new);
        self.lifts_prev = std::mem::replace(&mut self.lifts, lifts_new);
        self.disp_prev = std::mem::replace(&mut self.disp, disp_new);
        self.warm = warm;
        self.step = step;
        record.step_s = t_start.elapsed().as_secs_f64();
        Ok(record)
    }

    /// Solves the contact problem of one step (with the optional Coulomb fixed point) on the
    /// static contact machinery ([`StaticContact::solve_load`] with `F̄`, the lifts of
    /// `t_{i+1}`, `ḡ_c` and slip measured from `U^i`).
    fn solve_contact(
        &self,
        step: usize,
        time: Real,
        lifts_new: &[Vector<D>],
        rhs: &[Real],
        solver: &dyn ContactSolver,
    ) -> Result<ContactStep<D>, TimeError> {
        let contact_err = |source| TimeError::Contact { step, time, source };
        let geometry = self.geometry();
        let mut bounds = self.slip_bounds(&self.pressure, &self.slip_speed);
        let mut iterations = 0;
        let mut fp_iter = 0;
        loop {
            let slip_bound = bounds.iter().any(|g| *g > 0.0).then_some(&bounds[..]);
            let warm = match (&self.warm, self.params.warm_start) {
                (Some(prev), true) => Some(warm_start(geometry, prev, &bounds)),
                _ => None,
            };
            let result = self
                .contact
                .solve_load(rhs, lifts_new, solver, slip_bound, Some(&self.disp), warm.as_ref())
                .map_err(contact_err)?;
            iterations += result.solution.report.iterations + result.coarse_iterations;
            // Σ_c ‖B_Ht U − s‖_c = Σ_c ḡ_c κ_c ‖T_cᵀ([U^{i+1}] − [U^i])‖ (scaled friction work)
            let friction_work = friction_dissipation(geometry, &result, Some(&self.disp))?;
            if self.params.coulomb_iterations > 0 {
                let speed = self.nodal_slip_speeds(&result.displacement, &self.disp);
                let new_bounds = self.slip_bounds(&result.solution.lambda_n, &speed);
                let scale = new_bounds.iter().chain(&bounds).fold(0.0_f64, |a, &b| a.max(b));
                let change = if scale > 0.0 {
                    new_bounds.iter().zip(&bounds).fold(0.0_f64, |a, (x, y)| a.max((x - y).abs())) / scale
                } else {
                    0.0
                };
                if change > self.params.coulomb_tolerance {
                    if fp_iter >= self.params.coulomb_iterations {
                        return Err(TimeError::FixedPoint { step, iterations: fp_iter, change });
                    }
                    bounds = new_bounds;
                    fp_iter += 1;
                    continue;
                }
            }
            return Ok(ContactStep { result, friction_work, iterations });
        }
    }

    /// Runs `n_steps` steps and returns their records (see [`DynamicStepper::step`];
    /// [`DynamicStepper::initial_record`] gives the record of the current level).
    ///
    /// # Errors
    /// The first error of a step.
    pub fn run(
        &mut self,
        model: &Model<D>,
        solver: &dyn ContactSolver,
        n_steps: usize,
    ) -> Result<Vec<StepRecord>, TimeError> {
        let mut out = Vec::with_capacity(n_steps);
        for _ in 0..n_steps {
            out.push(self.step(model, solver)?);
        }
        Ok(out)
    }

    /// A record of the current level with its energies (kinetic energy of
    /// `(U^i − U^{i−1})/Δt`, strain energy of `U^i`) and zero contact figures (one
    /// [`PairRecord`](crate::results::PairRecord) per pair, so CSV columns line up): the row of step 0 of a results table.
    pub fn initial_record(&self) -> StepRecord {
        let pairs = empty_pair_records(self.geometry());
        StepRecord {
            step: self.step,
            time: self.time(),
            pairs,
            kinetic_energy: self.balance.kinetic,
            strain_energy: self.balance.strain,
            cumulative_friction_dissipation: self.cumulative_friction,
            ..Default::default()
        }
    }

    /// `rhs −= Pᵀ [M_ρ (u_p^{i+1} − 2u_p^i + u_p^{i−1}) + Δt (M_α + A⁽¹⁾)(u_p^{i+1} − u_p^i)
    /// + Δt² A⁽⁰⁾ u_p^{i+1}]`, element by element.
    fn subtract_lift_terms(
        &self,
        model: &Model<D>,
        lifts_new: &[Vector<D>],
        rhs: &mut [Real],
    ) -> Result<(), FemError> {
        let dt = self.params.dt;
        let lumped = self.params.mass == MassKind::Lumped;
        let rho: Vec<Real> = self.bodies.iter().map(|b| b.density).collect();
        let second: Vec<Vector<D>> = lifts_new
            .iter()
            .zip(self.lifts.iter().zip(&self.lifts_prev))
            .map(|(a, (b, c))| a - b * 2.0 + c)
            .collect();
        if !all_zero(&second) {
            subtract_lift(model, self.dofs(), &second, rhs, |b, _, geo, out| {
                mass_into(geo, rho[b], lumped, out)
            })?;
        }
        if self.has_damping {
            let first: Vec<Vector<D>> = lifts_new.iter().zip(&self.lifts).map(|(a, b)| a - b).collect();
            if !all_zero(&first) {
                subtract_lift(model, self.dofs(), &first, rhs, |b, _, geo, out| {
                    self.element_kernel(Kernel::DampingDt, b, geo, out)
                })?;
            }
        }
        if !all_zero(lifts_new) {
            let c0 = &self.c0;
            subtract_lift(model, self.dofs(), lifts_new, rhs, |b, _, geo, out| {
                stiffness_into(geo, &c0[b], out);
                out.iter_mut().for_each(|v| *v *= dt * dt);
            })?;
        }
        Ok(())
    }

    /// Element matrix of `M_ρ`, `A⁽⁰⁾` or `Δt (M_α + A⁽¹⁾)` (composite kernel).
    fn element_kernel(&self, kernel: Kernel, b: usize, geo: &SimplexGeometry<D>, out: &mut [Real]) {
        let lumped = self.params.mass == MassKind::Lumped;
        let data = &self.bodies[b];
        match kernel {
            Kernel::Mass => mass_into(geo, data.density, lumped, out),
            Kernel::Stiffness => stiffness_into(geo, &self.c0[b], out),
            Kernel::DampingDt => {
                let nn = (D * (D + 1)) * (D * (D + 1));
                damping_into(geo, data.damping, data.viscous.as_ref(), lumped, out);
                out[..nn].iter_mut().for_each(|v| *v *= self.params.dt);
            }
        }
    }

    /// `Σ_T v_Tᵀ K_T v_T` over all cells for a full nodal field.
    fn full_form(&self, model: &Model<D>, v: &[Vec<Vector<D>>], kernel: Kernel) -> Real {
        full_form(model, v, |bi, geo, out| self.element_kernel(kernel, bi, geo, out))
    }

    /// Current step index `i` (0 = initial state).
    pub fn step_index(&self) -> usize {
        self.step
    }
    /// Current time `t_i = t_0 + iΔt`.
    pub fn time(&self) -> Real {
        self.params.t0 + self.step as Real * self.params.dt
    }
    /// The time step `Δt`.
    pub fn dt(&self) -> Real {
        self.params.dt
    }
    /// The parameters.
    pub fn params(&self) -> &DynamicParams {
        &self.params
    }
    /// Nodal displacements `U^i` per body.
    pub fn displacement(&self) -> &[Vec<Vector<D>>] {
        &self.disp
    }
    /// Nodal displacements `U^{i−1}` per body.
    pub fn previous_displacement(&self) -> &[Vec<Vector<D>>] {
        &self.disp_prev
    }
    /// Reduced unknowns `ũ^i`.
    pub fn reduced_displacement(&self) -> &[Real] {
        &self.u
    }
    /// Reduced unknowns `ũ^{i−1}`.
    pub fn previous_reduced_displacement(&self) -> &[Real] {
        &self.u_prev
    }
    /// Nodal velocities `V^i = (U^i − U^{i−1})/Δt` per body (at step 0: `u₁`).
    pub fn velocity(&self) -> Vec<Vec<Vector<D>>> {
        nodal_diff(&self.disp, &self.disp_prev, 1.0 / self.params.dt)
    }
    /// Kinetic energy `½ V^iᵀ M_ρ V^i` of the current level, `V^i = (U^i − U^{i−1})/Δt`.
    pub fn kinetic_energy(&self) -> Real {
        self.balance.kinetic
    }
    /// Strain energy `½ U^iᵀ A⁽⁰⁾ U^i` of the current level.
    pub fn strain_energy(&self) -> Real {
        self.balance.strain
    }
    /// The discrete energy `E^i = ½ ‖U^i − U^{i−1}‖²_{M_ρ}/Δt² + ½ ‖U^i‖²_{A⁽⁰⁾}` of the
    /// current level.
    pub fn energy(&self) -> Real {
        self.balance.energy()
    }
    /// The terms of the discrete energy identity of the last step.
    pub fn energy_balance(&self) -> &EnergyBalance {
        &self.balance
    }
    /// Total momentum `Σ_ι ∫ ρ V^i dx = Σ_nodes m_a V_a` (`m_a` the row sums of `M_ρ`, the same
    /// for consistent and lumped mass).
    pub fn momentum(&self) -> Vector<D> {
        let dt = self.params.dt;
        let mut p = Vector::<D>::zeros();
        for ((new, old), m) in self.disp.iter().zip(&self.disp_prev).zip(&self.nodal_mass) {
            for ((a, b), mi) in new.iter().zip(old).zip(m) {
                p += (a - b) * (mi / dt);
            }
        }
        p
    }
    /// Row sums of `M_ρ` per body node (nodal masses).
    pub fn nodal_masses(&self) -> &[Vec<Real>] {
        &self.nodal_mass
    }
    /// Centre of mass of the deformed bodies `Σ m_a (x_a + U_a^i) / Σ m_a`.
    pub fn centre_of_mass(&self, model: &Model<D>) -> Point<D> {
        let mut c = Point::<D>::zeros();
        let mut total = 0.0;
        for ((body, u), m) in model.bodies().iter().zip(&self.disp).zip(&self.nodal_mass) {
            for ((x, ui), mi) in body.mesh.nodes().iter().zip(u).zip(m) {
                c += (x + ui) * *mi;
                total += mi;
            }
        }
        if total > 0.0 {
            c / total
        } else {
            c
        }
    }
    /// The contact result of the last step with *physical* multipliers (`λ_n = Λ̄_n/Δt²`,
    /// slip bounds `g_c = ḡ_c/Δt²`), its KKT residuals (of the step problem) and nodal
    /// displacements; `None` before the first step or without contact pairs.
    pub fn last_contact(&self) -> Option<&StaticContactResult<D>> {
        self.last.as_ref()
    }
    /// Total physical contact force (normal and friction) acting on the bodies `k` of all
    /// pairs at the current level, `−(B_hnᵀ κ Λ̄_n + B_Htᵀ Λ_t)/Δt²` summed per component.
    pub fn contact_force(&self) -> Vector<D> {
        let mut f = Vector::<D>::zeros();
        if let Some(res) = &self.last {
            for rec in pair_records(self.geometry(), res) {
                for k in 0..D {
                    f[k] += rec.force[k];
                }
            }
        }
        f
    }
    /// Contact pressure `λ_n` (physical) per contact node at the current level.
    pub fn pressure(&self) -> Vec<Real> {
        let dt2 = self.params.dt * self.params.dt;
        self.pressure.iter().map(|p| p / dt2).collect()
    }
    /// Slip speed `|[u'_t]|` per contact node at the current level.
    pub fn slip_speed(&self) -> &[Real] {
        &self.slip_speed
    }
    /// The dof map.
    pub fn dofs(&self) -> &DofMap<D> {
        self.contact.elastic().dofs()
    }
    /// The contact nodes.
    pub fn geometry(&self) -> &ContactGeometry<D> {
        self.contact.geometry()
    }
    /// `M̃_ρ = Pᵀ M_ρ P`.
    pub fn mass_matrix(&self) -> &SymmetricMatrix {
        &self.mass
    }
    /// `M̃_α = Pᵀ M_α P`.
    pub fn damping_matrix(&self) -> &SymmetricMatrix {
        &self.mass_alpha
    }
    /// `Ã⁽⁰⁾ = Pᵀ A⁽⁰⁾ P`.
    pub fn stiffness_matrix(&self) -> &SymmetricMatrix {
        &self.stiffness
    }
    /// `Ã⁽¹⁾ = Pᵀ A⁽¹⁾ P`.
    pub fn viscous_matrix(&self) -> &SymmetricMatrix {
        &self.viscous
    }
    /// `Ã = M̃_ρ + Δt M̃_α + Δt² Ã⁽⁰⁾ + Δt Ã⁽¹⁾`.
    pub fn system_matrix(&self) -> &SymmetricMatrix {
        self.contact.elastic().system_matrix()
    }
    /// The factorisation of `Ã` (computed once in [`DynamicStepper::new`]).
    pub fn cholesky(&self) -> &CholeskySolver {
        self.contact.elastic().cholesky()
    }
    /// Sizes and set-up timings.
    pub fn info(&self) -> DynamicInfo {
        self.info
    }
}

/// Which element matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kernel {
    Mass,
    Stiffness,
    DampingDt,
}

/// The solution of one step's contact problem (scaled multipliers `Λ̄_n`, `ḡ_c`) with what
/// the record needs.
struct ContactStep<const D: usize> {
    result: StaticContactResult<D>,
    /// `Σ_c ‖B_Ht U − s‖_c` (scaled by `Δt²`).
    friction_work: Real,
    iterations: usize,
}

fn add_into(a: &mut [Real], b: &[Real]) {
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
}

/// Element matrix of `M_α + A⁽¹⁾` of a body (docs/model.md §7): the mass-proportional damping
/// `α` plus, when given and not zero, the Kelvin–Voigt viscosity `C⁽¹⁾`. Shared by the linear
/// and the nonlinear dynamic steppers.
pub(crate) fn damping_into<const D: usize>(
    geo: &SimplexGeometry<D>,
    alpha: Real,
    viscous: Option<&DMatrix<Real>>,
    lumped: bool,
    out: &mut [Real],
) {
    let nn = (D * (D + 1)) * (D * (D + 1));
    mass_into(geo, alpha, lumped, out);
    if let Some(c1) = viscous.filter(|c| c.iter().any(|v| *v != 0.0)) {
        let mut k1 = [0.0; KE_MAX];
        stiffness_into(geo, c1, &mut k1[..nn]);
        out[..nn].iter_mut().zip(&k1[..nn]).for_each(|(o, k)| *o += k);
    }
}

/// The two starting levels of the scheme from an initial displacement `u₀` and velocity `u₁`
/// (docs/model.md (7.9)), node by node: `U⁰ = u_p(t₀) + N Nᵀ u₀` and `U⁻¹ = U⁰ − Δt u₁`, the
/// latter split into its reduced part `N Nᵀ U⁻¹` and the rest (the lift of level −1). Shared by
/// the linear [`DynamicStepper`] and [`crate::nonlinear_dynamic::NonlinearDynamicStepper`].
pub(crate) struct InitialLevels<const D: usize> {
    /// Reduced `U⁰`.
    pub u0: Vec<Real>,
    /// Reduced `U⁻¹`.
    pub um1: Vec<Real>,
    /// Lifts of level 0, `u_p(t₀)` per dof group.
    pub lifts0: Vec<Vector<D>>,
    /// Lifts of level −1, `U⁻¹ − N Nᵀ U⁻¹` per dof group.
    pub lifts_m1: Vec<Vector<D>>,
}

/// [`InitialLevels`] of `dofs` at `t0` with the step `dt` (zero fields where `None`).
///
/// # Errors
/// [`TimeError::Fem`] when the prescribed displacements cannot be evaluated at `t0`.
pub(crate) fn initial_levels<const D: usize>(
    model: &Model<D>,
    dofs: &DofMap<D>,
    t0: Real,
    dt: Real,
    displacement: Option<&[Vec<Vector<D>>]>,
    velocity: Option<&[Vec<Vector<D>>]>,
) -> Result<InitialLevels<D>, TimeError> {
    let lifts0 = dofs.lifts(model, t0)?;
    let n = dofs.n_dofs();
    let mut u0 = vec![0.0; n];
    let mut um1 = vec![0.0; n];
    let mut lifts_m1 = vec![Vector::<D>::zeros(); dofs.groups().len()];
    for (gi, grp) in dofs.groups().iter().enumerate() {
        let (body, node) = grp.origin;
        let x0 = displacement.map_or(Vector::<D>::zeros(), |f| f[body.0][node]);
        let v0 = velocity.map_or(Vector::<D>::zeros(), |f| f[body.0][node]);
        // U^0 = u_p(t0) + N Nᵀ u₀
        let mut full0 = lifts0[gi];
        for k in 0..grp.n_dofs {
            let c = grp.basis[k].dot(&x0);
            u0[grp.first_dof + k] = c;
            full0 += grp.basis[k] * c;
        }
        // U^{-1} = U^0 − Δt u₁, split into N Nᵀ part and the rest (the lift of level −1)
        let wm1 = full0 - v0 * dt;
        let mut free = Vector::<D>::zeros();
        for k in 0..grp.n_dofs {
            let c = grp.basis[k].dot(&wm1);
            um1[grp.first_dof + k] = c;
            free += grp.basis[k] * c;
        }
        lifts_m1[gi] = wm1 - free;
    }
    Ok(InitialLevels { u0, um1, lifts0, lifts_m1 })
}
/// `Σ_T v_Tᵀ K_T v_T` over all cells of a full nodal field with the element kernel `kernel`.
pub(crate) fn full_form<const D: usize>(
    model: &Model<D>,
    v: &[Vec<Vector<D>>],
    kernel: impl Fn(usize, &SimplexGeometry<D>, &mut [Real]),
) -> Real {
    let nl = D * (D + 1);
    let mut ke = [0.0; KE_MAX];
    let mut total = 0.0;
    for (bi, body) in model.bodies().iter().enumerate() {
        for c in 0..body.mesh.n_cells() {
            let cell = body.mesh.cell(c);
            let mut x = [0.0; 12];
            let mut nz = false;
            for (a, &i) in cell.iter().enumerate() {
                for k in 0..D {
                    x[D * a + k] = v[bi][i][k];
                    nz |= v[bi][i][k] != 0.0;
                }
            }
            if !nz {
                continue;
            }
            let Some(geo) = SimplexGeometry::new(&body.mesh.cell_points(c)) else { continue };
            kernel(bi, &geo, &mut ke[..nl * nl]);
            for p in 0..nl {
                let row: Real = (0..nl).map(|q| ke[p * nl + q] * x[q]).sum();
                total += x[p] * row;
            }
        }
    }
    total
}

pub(crate) fn all_zero<const D: usize>(v: &[Vector<D>]) -> bool {
    v.iter().all(|x| x.iter().all(|c| *c == 0.0))
}

/// `(a − b) · s` node by node.
pub(crate) fn nodal_diff<const D: usize>(
    a: &[Vec<Vector<D>>],
    b: &[Vec<Vector<D>>],
    s: Real,
) -> Vec<Vec<Vector<D>>> {
    a.iter().zip(b).map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q) * s).collect()).collect()
}

pub(crate) fn check_nodal<const D: usize>(
    model: &Model<D>,
    field: &[Vec<Vector<D>>],
    what: &str,
) -> Result<(), TimeError> {
    if field.len() != model.bodies().len()
        || field.iter().zip(model.bodies()).any(|(f, b)| f.len() != b.mesh.n_nodes())
    {
        return Err(TimeError::InvalidParameter(format!(
            "{what}: one value per node of every body needed ({} bodies)",
            model.bodies().len()
        )));
    }
    if field.iter().flatten().any(|v| v.iter().any(|c| !c.is_finite())) {
        return Err(TimeError::InvalidParameter(format!("{what} is not finite")));
    }
    Ok(())
}
