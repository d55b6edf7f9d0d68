//! Dostál's MPRGP (bound constraints) and MPGP (separable convex constraints) for the
//! quadratic programme
//!
//! ```text
//! min q(x) = ½ xᵀ H x − bᵀ x   s.t.  x ∈ Ω = Ω_1 × … × Ω_s,
//! ```
//!
//! `H` symmetric positive (semi-)definite, given by its action ([`Hessian`]).
//!
//! **Gradient splitting.** With `g = H x − b`, a block `i` is *free* if `x_i` lies in the
//! interior of `Ω_i` and *active* if it lies on the boundary. The *free gradient* `φ` equals `g`
//! on the free blocks and `0` on the active ones; the *chopped gradient* `β` is `0` on the free
//! blocks and on an active block with outer unit normal `n_i`
//!
//! ```text
//! β_i = g_i − min(n_iᵀ g_i, 0) n_i       (interval, lower bound: min(g_i, 0); upper: max(g_i, 0))
//! ```
//!
//! The *projected gradient* is `g^P = φ + β`; `x` is a solution iff `g^P(x) = 0`. With the
//! fixed step length `ᾱ ∈ (0, 2/‖H‖]` the *reduced free gradient* is
//! `φ̃ = (x − P_Ω(x − ᾱ φ)) / ᾱ` (for a lower bound `φ̃_i = min((x_i − l_i)/ᾱ, φ_i)`), and `x` is
//! *strictly proportional* if `‖β‖² ≤ Γ² φ̃ᵀ φ`.
//!
//! **Iteration** (MPRGP: Dostál & Schöberl 2005; Dostál 2009, *Optimal Quadratic Programming
//! Algorithms*, Ch. 5; MPGP: Dostál & Kozubek 2012). From a proportional iterate,
//! a *conjugate gradient step* `x ← x − α_cg p`, `α_cg = gᵀp / pᵀHp`, is taken if it is feasible
//! (`α_cg ≤ α_f`, the largest feasible step along `−p`), followed by
//! `p ← z − (zᵀHp / pᵀHp) p` with `z = M_F⁻¹ φ` (`M_F = I`, the Jacobi preconditioner or the
//! Hessian's own [`Hessian::precondition_in_face`]
//! restricted to the free set: *preconditioning in face*, Dostál 2009, Ch. 5). Otherwise an
//! *expansion step* goes to the boundary, `x^{½} = x − α_f p`, and then takes a fixed-length
//! projected step `x ← P_Ω(x^{½} − ᾱ φ(x^{½}))`, restarting CG. A disproportional iterate gets a
//! *proportioning step*: MPRGP minimises along the chopped gradient,
//! `x ← x − min(α_cg, α_f) β` with `α_cg = βᵀg / βᵀHβ` (feasible for boxes); MPGP, whose curved
//! boundaries make `−β` infeasible, takes the projected gradient step `x ← P_Ω(x − ᾱ g)`.
//! Both are R-linearly convergent for `ᾱ ∈ (0, 2/‖H‖]` and `Γ > 0`; `Γ = 1` and
//! `ᾱ = 1.9 / ‖H‖` are used by default. The stopping test is `‖g^P‖ ≤ ε ‖b‖`.
//!
//! ## Extension in MPGP (this crate)
//!
//! On active spheres (slipping 3D friction cells) the fixed
//! step `ᾱ ≤ 2/‖H‖` turns the multipliers very slowly: a strongly coupled `H` makes `ᾱ` short
//! compared with the curvature of one block, and a step along `−β` cannot be taken without
//! leaving the sphere. The proportioning step of [`mpgp`] therefore also computes a second
//! candidate — a truncated CG solve (at most 25 steps, residual reduced 10³-fold) of the
//! second-order model `min gᵀv + ½ vᵀ (H + K) v` on the current *face* (free blocks, active
//! blocks that the gradient pushes inwards, and the tangent planes of the active spheres, where
//! `K = (λ_c / r_c) I` is the curvature of sphere `c` with multiplier `λ_c = −n_cᵀ g_c > 0`),
//! retracted onto `Ω` by the projection, `x + v ↦ P_Ω(x + v)` — and keeps whichever of the two
//! candidates has the lower cost. The cost therefore decreases at least as much as in MPGP, so its
//! convergence theory is untouched, while the iteration counts on 3D Tresca problems with many
//! slipping cells drop several-fold (e.g. from about 200 to 20).
//!
//! ## Longer expansion steps (option, [`Expansion`])
//!
//! The fixed length `ᾱ ≤ 2/‖H‖` of the expansion step is set by the largest eigenvalue of the
//! *unpreconditioned* `H`; when the CG steps are preconditioned in face and `‖H‖` is large (a
//! FETI dual whose coarse condition is eliminated by an oblique projector), one expansion step
//! adds only the few blocks near their boundary to the active set, and the expansion steps grow
//! with `‖H‖`. [`QpOptions::expansion`] offers two longer steps from the half step
//! `x^{½} = x − α_f p` (Kružík, Horák, Čermák, Pospíšil, Pecha 2020, *Active set expansion
//! strategies in MPRGP algorithm*; PERMON's `projcg` and `gf`/`opt` expansions):
//!
//! ```text
//! ProjectedCg:     x^c = P_Ω(x − α_cg p) = P_Ω(x^{½} − (α_cg − α_f) p),   α_cg = gᵀp / pᵀHp,
//! Preconditioned:  x^c = P_Ω(x^{½} − α_z z),   z = M_F⁻¹ φ(x^{½}),   α_z = φᵀz / zᵀHz,
//! ```
//!
//! (`α_z` minimises `q` along `−z` before the projection). The candidate is kept if
//! `q(x^c) ≤ q(x^{½})`; otherwise the fixed-length step is taken from `x^{½}` (a *fallback*,
//! counted in [`QpReport::expansion_fallbacks`]). The cost therefore decreases monotonically,
//! but the R-linear rate of Dostál's proof covers only the fixed step, which stays the default.
//!
//! `‖H‖` is estimated by a few steps of the power method (which converges from below; the
//! estimate is enlarged by 5 %), unless given.

use nalgebra::DMatrix;

use synovia_contact::{ContactError, IterationResidual};

/// The action `y = H x` of a symmetric positive semi-definite matrix.
///
/// Every closure `FnMut(&[f64], &mut [f64])` is a `Hessian` (annotate its argument types:
/// `|x: &[f64], y: &mut [f64]| …`). Implementors that can supply `diag H` cheaply enable the
/// Jacobi preconditioning in face of [`mprgp`] and [`mpgp`].
pub trait Hessian {
    /// `y = H x` (`y` has the length of `x`; it need not be zeroed).
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), ContactError>;
    /// `diag H`, if cheaply available (`None` by default: no preconditioning).
    fn diagonal(&mut self) -> Option<Vec<f64>> {
        None
    }
    /// A general preconditioner in face: `z = Z_F M_F⁻¹ Z_Fᵀ r`, where `Z_F` selects the
    /// entries with `free[i]` and `M⁻¹` is a symmetric positive definite approximation of `H⁻¹`
    /// (e.g. a projected Dirichlet preconditioner of a FETI dual); `z` must vanish off the face.
    /// Returns `Ok(false)` (the default) if the Hessian has none — then the Jacobi preconditioner
    /// of [`Self::diagonal`] is used, or none.
    fn precondition_in_face(
        &mut self,
        free: &[bool],
        r: &[f64],
        z: &mut [f64],
    ) -> Result<bool, ContactError> {
        let _ = (free, r, z);
        Ok(false)
    }
}

impl<F> Hessian for F
where
    F: FnMut(&[f64], &mut [f64]),
{
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), ContactError> {
        self(x, y);
        Ok(())
    }
}

/// A dense symmetric Hessian `H` (a [`Hessian`] that supplies its diagonal).
#[derive(Debug, Clone, PartialEq)]
pub struct DenseHessian(pub DMatrix<f64>);

impl Hessian for DenseHessian {
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), ContactError> {
        let m = &self.0;
        if m.nrows() != x.len() || m.ncols() != x.len() || y.len() != x.len() {
            return Err(ContactError::InvalidParameter(format!(
                "dense Hessian is {}×{}, vectors have {} and {} entries",
                m.nrows(),
                m.ncols(),
                x.len(),
                y.len()
            )));
        }
        y.iter_mut().for_each(|v| *v = 0.0);
        for (j, &xj) in x.iter().enumerate() {
            if xj != 0.0 {
                for (yi, hij) in y.iter_mut().zip(m.column(j).iter()) {
                    *yi += hij * xj;
                }
            }
        }
        Ok(())
    }
    fn diagonal(&mut self) -> Option<Vec<f64>> {
        Some(self.0.diagonal().iter().copied().collect())
    }
}

/// One factor `Ω_i` of a separable convex feasible set `Ω = Ω_1 × … × Ω_s`; consecutive blocks
/// occupy consecutive entries of `x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ConvexBlock {
    /// One entry with `lower ≤ x ≤ upper` (either bound may be infinite; `lower = 0`,
    /// `upper = ∞` is the half-line of a normal contact multiplier).
    Interval {
        /// Lower bound `l` (may be `−∞`).
        lower: f64,
        /// Upper bound `u ≥ l` (may be `+∞`).
        upper: f64,
    },
    /// `dim` entries with `‖x‖ ≤ radius` (the unit disc of a 3D friction multiplier:
    /// `dim = 2`, `radius = 1`).
    Ball {
        /// Number of entries.
        dim: usize,
        /// Radius `r ≥ 0`.
        radius: f64,
    },
}

impl ConvexBlock {
    /// Number of entries of `x` the block occupies.
    pub fn len(&self) -> usize {
        match *self {
            ConvexBlock::Interval { .. } => 1,
            ConvexBlock::Ball { dim, .. } => dim,
        }
    }
    /// `true` for a ball of dimension 0.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The Euclidean projection `P_{Ω_i}` applied in place.
    pub fn project(&self, x: &mut [f64]) {
        match *self {
            ConvexBlock::Interval { lower, upper } => {
                if let Some(v) = x.first_mut() {
                    *v = v.max(lower).min(upper);
                }
            }
            ConvexBlock::Ball { radius, .. } => synovia_contact::project_on_disc(x, radius),
        }
    }
}

/// The step taken after an infeasible conjugate gradient step (module docs, *Longer expansion
/// steps*).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Expansion {
    /// Dostál's expansion step: `x^{½} = x − α_f p`, then `x ← P_Ω(x^{½} − ᾱ φ(x^{½}))` with the
    /// fixed length `ᾱ = step_factor/‖H‖` (default).
    #[default]
    Fixed,
    /// The projected CG step `x ← P_Ω(x − α_cg p)`, kept if `q` does not exceed `q(x^{½})`,
    /// else the fixed step (one product with `H` per step, plus one on a fallback).
    ProjectedCg,
    /// From `x^{½}`, the preconditioned free gradient `z = M_F⁻¹ φ` with the step `α_z = φᵀz /
    /// zᵀHz` that minimises `q` along `−z`, projected: `x ← P_Ω(x^{½} − α_z z)`, kept if `q`
    /// does not exceed `q(x^{½})`, else the fixed step (two products with `H` and one
    /// application of the preconditioner per step). Without preconditioning in face
    /// (`precondition = false`, or a Hessian with neither a preconditioner nor a diagonal)
    /// `z = φ`: the free gradient with its optimal length.
    Preconditioned,
}

/// Options of [`mprgp`] and [`mpgp`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct QpOptions {
    /// Relative tolerance `ε`: stop when `‖g^P‖ ≤ ε ‖b‖` (default `1e-10`).
    pub tolerance: f64,
    /// Absolute tolerance: stop also when `‖g^P‖ ≤ absolute_tolerance` (default `0`).
    pub absolute_tolerance: f64,
    /// Maximum iterations (steps of any kind; default `10 000`).
    pub max_iterations: usize,
    /// Proportioning parameter `Γ > 0` (default `1`).
    pub gamma: f64,
    /// Fixed step length factor: `ᾱ = step_factor / ‖H‖`, in `(0, 2]` (default `1.9`).
    pub step_factor: f64,
    /// `‖H‖` (`λ_max`) if known; otherwise estimated by the power method.
    pub hessian_norm: Option<f64>,
    /// Power-method steps for the estimate of `‖H‖` (default `20`).
    pub power_iterations: usize,
    /// Preconditioning in face of the CG steps (default `true`): by the [`Hessian`]'s own
    /// [`Hessian::precondition_in_face`] if it has one, else Jacobi if it supplies its diagonal.
    pub precondition: bool,
    /// The expansion step (default [`Expansion::Fixed`], Dostál's).
    pub expansion: Expansion,
}

impl Default for QpOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            absolute_tolerance: 0.0,
            max_iterations: 10_000,
            gamma: 1.0,
            step_factor: 1.9,
            hessian_norm: None,
            power_iterations: 20,
            precondition: true,
            expansion: Expansion::Fixed,
        }
    }
}

impl QpOptions {
    /// Sets [`Self::tolerance`].
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }
    /// Sets [`Self::absolute_tolerance`].
    pub fn with_absolute_tolerance(mut self, absolute_tolerance: f64) -> Self {
        self.absolute_tolerance = absolute_tolerance;
        self
    }
    /// Sets [`Self::max_iterations`].
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }
    /// Sets [`Self::gamma`].
    pub fn with_gamma(mut self, gamma: f64) -> Self {
        self.gamma = gamma;
        self
    }
    /// Sets [`Self::step_factor`].
    pub fn with_step_factor(mut self, step_factor: f64) -> Self {
        self.step_factor = step_factor;
        self
    }
    /// Sets [`Self::hessian_norm`].
    pub fn with_hessian_norm(mut self, hessian_norm: Option<f64>) -> Self {
        self.hessian_norm = hessian_norm;
        self
    }
    /// Sets [`Self::power_iterations`].
    pub fn with_power_iterations(mut self, power_iterations: usize) -> Self {
        self.power_iterations = power_iterations;
        self
    }
    /// Sets [`Self::precondition`].
    pub fn with_precondition(mut self, precondition: bool) -> Self {
        self.precondition = precondition;
        self
    }
    /// Sets [`Self::expansion`].
    pub fn with_expansion(mut self, expansion: Expansion) -> Self {
        self.expansion = expansion;
        self
    }
}

/// What [`mprgp`] / [`mpgp`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct QpReport {
    /// Iterations (CG, expansion and proportioning steps).
    pub iterations: usize,
    /// Products with `H` (including the power method).
    pub hessian_products: usize,
    /// Conjugate gradient steps.
    pub cg_steps: usize,
    /// Expansion steps.
    pub expansion_steps: usize,
    /// Expansion steps whose longer candidate ([`Expansion::ProjectedCg`],
    /// [`Expansion::Preconditioned`]) raised the cost above `q(x^{½})` and was replaced by the
    /// fixed-length step (or had no usable length).
    pub expansion_fallbacks: usize,
    /// Proportioning steps.
    pub proportioning_steps: usize,
    /// Final `‖g^P‖`.
    pub projected_gradient_norm: f64,
    /// Final `‖g^P‖ / ‖b‖` (`‖b‖` replaced by `‖g^P(x_0)‖` when `b = 0`).
    pub relative_residual: f64,
    /// The `‖H‖` used (estimated or given).
    pub hessian_norm: f64,
    /// The fixed step length `ᾱ`.
    pub step_length: f64,
    /// Whether the stopping test was met.
    pub converged: bool,
}

/// The state passed to a monitor after every iteration (crate-internal).
pub(crate) struct QpState<'a> {
    pub iteration: usize,
    pub x: &'a [f64],
    pub g: &'a [f64],
}

/// How a disproportional iterate is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Proportioning {
    /// Exact (feasibility-limited) minimisation along `−β` (MPRGP, boxes).
    Chopped,
    /// Projected gradient step `P_Ω(x − ᾱ g)` (MPGP).
    Projected,
}

/// Estimates `‖H‖ = λ_max(H)` by `iterations` steps of the power method from a fixed positive
/// start vector: `v ← H v / ‖H v‖`, `λ ≈ ‖H v‖` (a lower bound converging to `λ_max`).
/// Returns the estimate and the number of products with `H`.
pub fn estimate_norm<H: Hessian + ?Sized>(
    hessian: &mut H,
    n: usize,
    iterations: usize,
) -> Result<(f64, usize), ContactError> {
    if n == 0 {
        return Ok((0.0, 0));
    }
    let mut v: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 17) as f64 / 17.0).collect();
    let nv = norm(&v);
    v.iter_mut().for_each(|x| *x /= nv);
    let mut w = vec![0.0; n];
    let mut lambda = 0.0;
    let mut products = 0;
    for _ in 0..iterations.max(1) {
        hessian.apply(&v, &mut w)?;
        products += 1;
        let l = norm(&w);
        if !l.is_finite() {
            return Err(ContactError::InvalidParameter("Hessian product is not finite".into()));
        }
        if l == 0.0 {
            return Ok((0.0, products));
        }
        let done = (l - lambda).abs() <= 1e-4 * l;
        lambda = l;
        for (a, b) in v.iter_mut().zip(&w) {
            *a = b / l;
        }
        if done {
            break;
        }
    }
    Ok((lambda, products))
}

/// **MPRGP** (Dostál & Schöberl 2005; Dostál 2009, Ch. 5): solves
///
/// ```text
/// min ½ xᵀ H x − bᵀ x   s.t.  l ≤ x ≤ u
/// ```
///
/// (`l_i = −∞` / `u_i = +∞` allowed) by conjugate gradient steps on the free set, expansion
/// steps `x ← P(x − α_f p − ᾱ φ)` with the fixed length `ᾱ = step_factor/‖H‖ ∈ (0, 2/‖H‖]`,
/// and proportioning steps along the chopped gradient `β` (`Γ = options.gamma`), until
/// `‖g^P‖ ≤ ε ‖b‖`; see the [module docs](self). With `options.precondition` and a Hessian
/// that supplies a preconditioner in face ([`Hessian::precondition_in_face`], `z = M_F⁻¹ φ`) or
/// `diag H`, the CG steps are preconditioned in face by it or by `diag(H)_F`.
///
/// `x` holds the initial guess (projected onto the box first) and receives the solution — also
/// the last iterate when an error is returned.
///
/// # Errors
/// [`ContactError::InvalidParameter`] for inconsistent sizes, non-finite data or options out
/// of range; [`ContactError::Infeasible`] if some `l_i > u_i` or `q` is unbounded below on the
/// box (for a dual contact problem: the primal constraints cannot be met);
/// [`ContactError::NoConvergence`] (solver `"mprgp"`, history of `‖g^P‖/‖b‖` per iteration in
/// the `normal` field) after `max_iterations`.
pub fn mprgp<H: Hessian + ?Sized>(
    hessian: &mut H,
    b: &[f64],
    lower: &[f64],
    upper: &[f64],
    x: &mut [f64],
    options: &QpOptions,
) -> Result<QpReport, ContactError> {
    let n = b.len();
    if lower.len() != n || upper.len() != n {
        return Err(ContactError::InvalidParameter(format!(
            "mprgp: b has {n} entries, lower {} and upper {}",
            lower.len(),
            upper.len()
        )));
    }
    let blocks: Vec<ConvexBlock> =
        lower.iter().zip(upper).map(|(&l, &u)| ConvexBlock::Interval { lower: l, upper: u }).collect();
    finish("mprgp", run(hessian, b, &blocks, x, options, Proportioning::Chopped, None))
}

/// **MPGP** (Dostál & Kozubek 2012; Dostál 2009 for the bound-constrained special case): solves
///
/// ```text
/// min ½ xᵀ H x − bᵀ x   s.t.  x ∈ Ω_1 × … × Ω_s
/// ```
///
/// for separable convex constraints given block by block ([`ConvexBlock`]: intervals such as
/// the half-line `ν_n ≥ 0`, and balls such as the unit disc `‖ν_t‖ ≤ 1` of a 3D friction
/// cell). Same steps as [`mprgp`] with the gradient splitting of the [module docs](self)
/// (outer normals of the active balls), except that a proportioning step is the projected
/// gradient step `x ← P_Ω(x − ᾱ g)` with the fixed length `ᾱ` — or, if it reaches a lower cost,
/// the retracted truncated-CG step on the current face described in the
/// [module docs](self#extension-in-mpgp-this-crate).
///
/// # Errors
/// As [`mprgp`] (solver name `"mpgp"`); a ball with a negative radius or the blocks not covering
/// `b` exactly are [`ContactError::InvalidParameter`].
pub fn mpgp<H: Hessian + ?Sized>(
    hessian: &mut H,
    b: &[f64],
    blocks: &[ConvexBlock],
    x: &mut [f64],
    options: &QpOptions,
) -> Result<QpReport, ContactError> {
    finish("mpgp", run(hessian, b, blocks, x, options, Proportioning::Projected, None))
}

/// A caller's stopping test `stop(iteration, x, g)` for [`qp_until`].
pub type StopTest<'a> = dyn FnMut(usize, &[f64], &[f64]) -> bool + 'a;

/// [`mprgp`] (`chopped = true`: proportioning along the chopped gradient, boxes only) or
/// [`mpgp`] (`chopped = false`) with the caller's stopping test instead of the fixed tolerance:
/// the iteration stops as converged as soon as `stop(iteration, x, g)` returns `true` for the
/// current iterate `x` and its gradient `g = H x − b` (or at an exactly stationary point). For
/// outer iterations whose inner precision depends on the iterate, e.g. the adaptive test
/// `‖g^P(x)‖ ≤ min(M ‖G x‖, η)` of SMALBE (Dostál 2009, Ch. 6). `options.tolerance` and
/// `options.absolute_tolerance` are ignored; after `options.max_iterations` the report is
/// returned with `converged = false` (no error), so the caller decides.
///
/// # Errors
/// As [`mpgp`], except [`ContactError::NoConvergence`].
pub fn qp_until<H: Hessian + ?Sized>(
    hessian: &mut H,
    b: &[f64],
    blocks: &[ConvexBlock],
    x: &mut [f64],
    options: &QpOptions,
    chopped: bool,
    stop: &mut StopTest<'_>,
) -> Result<QpReport, ContactError> {
    let opts = QpOptions { tolerance: 0.0, absolute_tolerance: f64::MAX, ..*options };
    let mut monitor = |s: &QpState<'_>| stop(s.iteration, s.x, s.g);
    solve_qp(hessian, b, blocks, x, &opts, chopped, Some(&mut monitor)).map(|(rep, _)| rep)
}

/// The MPRGP/MPGP iteration for crate-internal callers: returns the report (with
/// `converged = false` instead of an error after `max_iterations`). The monitor is called with
/// every iterate (iteration 0 = the projected initial guess) and must also return `true` for the
/// iteration to stop as converged (except at an exactly stationary point, `g^P = 0`).
pub(crate) fn solve_qp<H: Hessian + ?Sized>(
    hessian: &mut H,
    b: &[f64],
    blocks: &[ConvexBlock],
    x: &mut [f64],
    options: &QpOptions,
    chopped: bool,
    monitor: Option<&mut dyn FnMut(&QpState<'_>) -> bool>,
) -> Result<(QpReport, Vec<IterationResidual>), ContactError> {
    let prop = if chopped { Proportioning::Chopped } else { Proportioning::Projected };
    run(hessian, b, blocks, x, options, prop, monitor)
}

fn finish(
    name: &str,
    r: Result<(QpReport, Vec<IterationResidual>), ContactError>,
) -> Result<QpReport, ContactError> {
    let (rep, history) = r?;
    if rep.converged {
        Ok(rep)
    } else {
        Err(ContactError::NoConvergence { solver: name.to_string(), iterations: rep.iterations, history })
    }
}

pub(crate) fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Blocks with their offsets, validated.
struct Layout<'a> {
    blocks: &'a [ConvexBlock],
    start: Vec<usize>,
}

impl<'a> Layout<'a> {
    fn new(blocks: &'a [ConvexBlock], n: usize) -> Result<Self, ContactError> {
        let mut start = Vec::with_capacity(blocks.len() + 1);
        let mut s = 0;
        for (i, b) in blocks.iter().enumerate() {
            start.push(s);
            match *b {
                ConvexBlock::Interval { lower, upper } => {
                    if lower.is_nan()
                        || upper.is_nan()
                        || lower == f64::INFINITY
                        || upper == f64::NEG_INFINITY
                    {
                        return Err(ContactError::InvalidParameter(format!(
                            "block {i}: bounds [{lower}, {upper}] are not valid"
                        )));
                    }
                    if lower > upper {
                        return Err(ContactError::Infeasible(format!(
                            "block {i}: lower bound {lower} exceeds upper bound {upper}"
                        )));
                    }
                }
                ConvexBlock::Ball { dim, radius } => {
                    if dim == 0 || !(radius.is_finite() && radius >= 0.0) {
                        return Err(ContactError::InvalidParameter(format!(
                            "block {i}: ball of dimension {dim} and radius {radius}"
                        )));
                    }
                }
            }
            s += b.len();
        }
        start.push(s);
        if s != n {
            return Err(ContactError::InvalidParameter(format!(
                "the constraint blocks cover {s} entries, the problem has {n}"
            )));
        }
        Ok(Self { blocks, start })
    }

    fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.start[i]..self.start[i + 1]
    }

    fn project(&self, x: &mut [f64]) {
        for (i, b) in self.blocks.iter().enumerate() {
            b.project(&mut x[self.range(i)]);
        }
    }

    /// Fills `phi`, `beta`, the free-entry flags, and returns `(‖β‖², φ̃ᵀφ, ‖g^P‖)`.
    fn split(&self, x: &[f64], g: &[f64], alpha: f64, w: &mut Split) -> (f64, f64, f64) {
        let Split { phi, beta, free } = w;
        let (mut bb, mut rf, mut gp) = (0.0, 0.0, 0.0);
        for (i, blk) in self.blocks.iter().enumerate() {
            let r = self.range(i);
            match *blk {
                ConvexBlock::Interval { lower, upper } => {
                    let k = r.start;
                    let (xi, gi) = (x[k], g[k]);
                    free[k] = false;
                    if lower == upper {
                        phi[k] = 0.0;
                        beta[k] = 0.0;
                    } else if xi <= lower {
                        phi[k] = 0.0;
                        beta[k] = gi.min(0.0);
                    } else if xi >= upper {
                        phi[k] = 0.0;
                        beta[k] = gi.max(0.0);
                    } else {
                        free[k] = true;
                        phi[k] = gi;
                        beta[k] = 0.0;
                        let red = if gi > 0.0 {
                            gi.min((xi - lower) / alpha)
                        } else {
                            gi.max((xi - upper) / alpha)
                        };
                        rf += red * gi;
                    }
                    bb += beta[k] * beta[k];
                    gp += (phi[k] + beta[k]).powi(2);
                }
                ConvexBlock::Ball { radius, .. } => {
                    let (xi, gi) = (&x[r.clone()], &g[r.clone()]);
                    let nx = norm(xi);
                    if nx >= radius * (1.0 - 1e-12) {
                        // active: outer normal n = x/‖x‖ (radius 0: the whole gradient is chopped)
                        let ng = if nx > 0.0 { dot(xi, gi) / nx } else { 0.0 };
                        let c = ng.min(0.0);
                        for (k, j) in r.clone().enumerate() {
                            free[j] = false;
                            phi[j] = 0.0;
                            let nk = if nx > 0.0 { xi[k] / nx } else { 0.0 };
                            beta[j] = if radius > 0.0 { gi[k] - c * nk } else { 0.0 };
                            bb += beta[j] * beta[j];
                            gp += beta[j] * beta[j];
                        }
                    } else {
                        // free: φ̃ = (x − P(x − ᾱ g)) / ᾱ
                        let mut y: Vec<f64> = xi.iter().zip(gi).map(|(a, b)| a - alpha * b).collect();
                        blk.project(&mut y);
                        for (k, j) in r.clone().enumerate() {
                            free[j] = true;
                            phi[j] = gi[k];
                            beta[j] = 0.0;
                            rf += (xi[k] - y[k]) / alpha * gi[k];
                            gp += gi[k] * gi[k];
                        }
                    }
                }
            }
        }
        (bb, rf, gp.sqrt())
    }

    /// Largest `α ≥ 0` with `x − α p ∈ Ω` (`∞` if unbounded); per-block steps in `steps`.
    fn feasible_step(&self, x: &[f64], p: &[f64], steps: &mut [f64]) -> f64 {
        let mut amin = f64::INFINITY;
        for (i, blk) in self.blocks.iter().enumerate() {
            let r = self.range(i);
            let a = match *blk {
                ConvexBlock::Interval { lower, upper } => {
                    let (xi, pi) = (x[r.start], p[r.start]);
                    if pi > 0.0 {
                        ((xi - lower) / pi).max(0.0)
                    } else if pi < 0.0 {
                        ((xi - upper) / pi).max(0.0)
                    } else {
                        f64::INFINITY
                    }
                }
                ConvexBlock::Ball { radius, .. } => {
                    let (xi, pi) = (&x[r.clone()], &p[r]);
                    let pp = dot(pi, pi);
                    if pp == 0.0 {
                        f64::INFINITY
                    } else {
                        // ‖x − α p‖² = r²: pp α² − 2 xp α + (xx − r²) = 0, positive root
                        let xp = dot(xi, pi);
                        let c = (radius * radius - dot(xi, xi)).max(0.0);
                        let disc = (xp * xp + pp * c).sqrt();
                        if xp > 0.0 {
                            (xp + disc) / pp
                        } else if disc - xp > 0.0 {
                            c / (disc - xp)
                        } else {
                            0.0
                        }
                    }
                }
            };
            steps[i] = a;
            amin = amin.min(a);
        }
        amin
    }

    /// The face of `Ω` at `x` for a proportioning step (see [`Face`]).
    fn face(&self, x: &[f64], g: &[f64], beta: &[f64]) -> Face {
        let n = x.len();
        let mut f = Face { kind: Vec::with_capacity(self.blocks.len()), normal: vec![0.0; n] };
        for (i, blk) in self.blocks.iter().enumerate() {
            let r = self.range(i);
            let kind = match *blk {
                ConvexBlock::Interval { lower, upper } => {
                    let xi = x[r.start];
                    if lower == upper || ((xi <= lower || xi >= upper) && beta[r.start] == 0.0) {
                        FaceKind::Fixed
                    } else {
                        FaceKind::Full
                    }
                }
                ConvexBlock::Ball { radius, .. } => {
                    let xi = &x[r.clone()];
                    let nx = norm(xi);
                    if radius == 0.0 {
                        FaceKind::Fixed
                    } else if nx < radius * (1.0 - 1e-12) || nx == 0.0 {
                        FaceKind::Full
                    } else {
                        let ng = dot(xi, &g[r.clone()]) / nx;
                        if ng >= 0.0 {
                            FaceKind::Full
                        } else {
                            for k in r {
                                f.normal[k] = x[k] / nx;
                            }
                            FaceKind::Tangent { curvature: -ng / radius }
                        }
                    }
                }
            };
            f.kind.push(kind);
        }
        f
    }

    /// After `x ← x − α_f p`, puts the blocks that reached their boundary exactly on it.
    fn snap(&self, x: &mut [f64], p: &[f64], steps: &[f64], alpha: f64) {
        for (i, blk) in self.blocks.iter().enumerate() {
            if steps[i] > alpha * (1.0 + 1e-12) {
                continue;
            }
            let r = self.range(i);
            match *blk {
                ConvexBlock::Interval { lower, upper } => {
                    let k = r.start;
                    if p[k] > 0.0 {
                        x[k] = lower;
                    } else if p[k] < 0.0 {
                        x[k] = upper;
                    }
                }
                ConvexBlock::Ball { radius, .. } => {
                    let xi = &mut x[r];
                    let nx = norm(xi);
                    if nx > 0.0 {
                        let s = radius / nx;
                        xi.iter_mut().for_each(|v| *v *= s);
                    }
                }
            }
        }
    }
}

/// Steps and relative residual reduction (squared) of the truncated CG in a proportioning step of
/// MPGP.
const FACE_CG_STEPS: usize = 25;
const FACE_CG_REDUCTION: f64 = 1e-6;

/// How a block may move in an MPGP proportioning step.
#[derive(Debug, Clone, Copy, PartialEq)]
enum FaceKind {
    /// Not at all (an interval at a bound the gradient pushes against, a fixed entry).
    Fixed,
    /// Freely (interior blocks, blocks the gradient pushes inwards).
    Full,
    /// In the tangent plane of an active sphere; the model adds the curvature `λ/r` of the
    /// sphere (`λ = −nᵀg > 0` the multiplier of the ball constraint).
    Tangent {
        /// `λ / r`.
        curvature: f64,
    },
}

/// The face of `Ω` at `x` on which a proportioning step of MPGP minimises the second-order model
/// `gᵀv + ½ vᵀ (H + K) v` of `q` (`K` the curvature of the active spheres on their tangent
/// planes) by truncated CG; the step is retracted onto `Ω` by the projection.
struct Face {
    kind: Vec<FaceKind>,
    /// Outer unit normals of the tangent blocks.
    normal: Vec<f64>,
}

impl Face {
    /// Orthogonal projection onto the face directions.
    fn project(&self, layout: &Layout<'_>, v: &mut [f64]) {
        for (i, k) in self.kind.iter().enumerate() {
            let r = layout.range(i);
            match k {
                FaceKind::Fixed => v[r].iter_mut().for_each(|a| *a = 0.0),
                FaceKind::Full => {}
                FaceKind::Tangent { .. } => {
                    let nv = dot(&self.normal[r.clone()], &v[r.clone()]);
                    for j in r {
                        v[j] -= nv * self.normal[j];
                    }
                }
            }
        }
    }
    /// `out += K v`.
    fn add_curvature(&self, layout: &Layout<'_>, v: &[f64], out: &mut [f64]) {
        for (i, k) in self.kind.iter().enumerate() {
            if let FaceKind::Tangent { curvature } = *k {
                for j in layout.range(i) {
                    out[j] += curvature * v[j];
                }
            }
        }
    }
}

/// Work vectors of the gradient splitting.
struct Split {
    phi: Vec<f64>,
    beta: Vec<f64>,
    free: Vec<bool>,
}

/// `q(x) = ½ xᵀ H x − bᵀ x = ½ xᵀ (g − b)` from the gradient `g = H x − b`.
fn cost(x: &[f64], g: &[f64], b: &[f64]) -> f64 {
    0.5 * x.iter().zip(g.iter().zip(b)).map(|(x, (g, b))| x * (g - b)).sum::<f64>()
}

fn check_finite(v: &[f64], what: &str) -> Result<(), ContactError> {
    if v.iter().all(|a| a.is_finite()) {
        Ok(())
    } else {
        Err(ContactError::InvalidParameter(format!("{what} is not finite")))
    }
}

#[allow(clippy::too_many_lines, clippy::needless_range_loop)]
fn run<H: Hessian + ?Sized>(
    hessian: &mut H,
    b: &[f64],
    blocks: &[ConvexBlock],
    x: &mut [f64],
    opt: &QpOptions,
    prop: Proportioning,
    mut monitor: Option<&mut dyn FnMut(&QpState<'_>) -> bool>,
) -> Result<(QpReport, Vec<IterationResidual>), ContactError> {
    let n = b.len();
    if x.len() != n {
        return Err(ContactError::InvalidParameter(format!(
            "initial guess has {} entries, b has {n}",
            x.len()
        )));
    }
    let layout = Layout::new(blocks, n)?;
    if !(opt.tolerance.is_finite()
        && opt.tolerance >= 0.0
        && opt.absolute_tolerance.is_finite()
        && opt.absolute_tolerance >= 0.0)
        || (opt.tolerance == 0.0 && opt.absolute_tolerance == 0.0)
    {
        return Err(ContactError::InvalidParameter(format!(
            "QP tolerances {} (relative) and {} (absolute) must be non-negative, finite, not both 0",
            opt.tolerance, opt.absolute_tolerance
        )));
    }
    if !(opt.gamma.is_finite() && opt.gamma > 0.0) {
        return Err(ContactError::InvalidParameter(format!("proportioning parameter Γ = {}", opt.gamma)));
    }
    if !(opt.step_factor > 0.0 && opt.step_factor <= 2.0) {
        return Err(ContactError::InvalidParameter(format!(
            "step factor {} is outside (0, 2]",
            opt.step_factor
        )));
    }
    check_finite(b, "b")?;
    for v in x.iter_mut() {
        if !v.is_finite() {
            *v = 0.0;
        }
    }
    let mut rep = QpReport::default();
    let mut history = Vec::new();
    if n == 0 {
        rep.converged = true;
        return Ok((rep, history));
    }

    // ‖H‖ and the fixed step ᾱ
    let hnorm = match opt.hessian_norm {
        Some(h) if h.is_finite() && h > 0.0 => h,
        Some(h) => return Err(ContactError::InvalidParameter(format!("‖H‖ = {h} must be positive"))),
        None => {
            let (l, k) = estimate_norm(hessian, n, opt.power_iterations)?;
            rep.hessian_products += k;
            1.05 * l
        }
    };
    // H = 0: any positive step is admissible for the (linear) problem
    let hnorm = if hnorm > 0.0 { hnorm } else { 1.0 };
    let abar = opt.step_factor / hnorm;
    rep.hessian_norm = hnorm;
    rep.step_length = abar;

    // preconditioner in face: the Hessian's own (general), else Jacobi, else none
    let prec: Option<Vec<f64>> = if opt.precondition {
        hessian
            .diagonal()
            .filter(|d| d.len() == n && d.iter().all(|v| v.is_finite()))
            .map(|d| d.iter().map(|&v| if v > 0.0 { 1.0 / v } else { 1.0 / hnorm }).collect())
    } else {
        None
    };
    let mut general = opt.precondition;
    let precondition =
        |hessian: &mut H, general: &mut bool, w: &Split, z: &mut [f64]| -> Result<(), ContactError> {
            if *general {
                if hessian.precondition_in_face(&w.free, &w.phi, z)? {
                    return check_finite(z, "the preconditioned free gradient");
                }
                *general = false;
            }
            match &prec {
                Some(m) => z.iter_mut().zip(w.phi.iter().zip(m)).for_each(|(z, (p, m))| *z = p * m),
                None => z.copy_from_slice(&w.phi),
            }
            Ok(())
        };

    layout.project(x);
    let mut g = vec![0.0; n];
    let mut hp = vec![0.0; n];
    let gradient = |hessian: &mut H, x: &[f64], g: &mut [f64], rep: &mut QpReport| {
        hessian.apply(x, g)?;
        rep.hessian_products += 1;
        for (gi, bi) in g.iter_mut().zip(b) {
            *gi -= bi;
        }
        check_finite(g, "the gradient H x − b")
    };
    gradient(hessian, x, &mut g, &mut rep)?;
    let mut w = Split { phi: vec![0.0; n], beta: vec![0.0; n], free: vec![false; n] };
    let (mut xa, mut ga, mut xb, mut gb) = match prop {
        Proportioning::Projected => (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]),
        Proportioning::Chopped => (Vec::new(), Vec::new(), Vec::new(), Vec::new()),
    };
    let nf = if prop == Proportioning::Projected { n } else { 0 };
    let (mut d, mut fr, mut fp) = (vec![0.0; nf], vec![0.0; nf], vec![0.0; nf]);
    let mut z = vec![0.0; n];
    let ne = if opt.expansion == Expansion::Fixed { 0 } else { n };
    let (mut xc, mut gc) = (vec![0.0; ne], vec![0.0; ne]);
    let mut steps = vec![0.0; blocks.len()];
    let (mut bb, mut rf, mut gpn) = layout.split(x, &g, abar, &mut w);
    let bnorm = norm(b);
    let scale = if bnorm > 0.0 { bnorm } else { gpn.max(f64::MIN_POSITIVE) };
    let target = (opt.tolerance * scale).max(opt.absolute_tolerance);
    precondition(hessian, &mut general, &w, &mut z)?;
    let mut p = z.clone();
    let mut free_prev = w.free.clone();

    let unbounded = || {
        ContactError::Infeasible(
            "the quadratic function is unbounded below on the feasible set (a direction of zero \
             curvature and descent is feasible without limit; in a dual contact problem the \
             constraints cannot all be met)"
                .into(),
        )
    };
    let mut iteration = 0;
    loop {
        rep.projected_gradient_norm = gpn;
        rep.relative_residual = gpn / scale;
        if iteration > 0 {
            let changes = w.free.iter().zip(&free_prev).filter(|(a, b)| a != b).count();
            free_prev.copy_from_slice(&w.free);
            history.push(IterationResidual {
                iteration,
                normal: rep.relative_residual,
                tangential: 0.0,
                set_changes: changes,
            });
        }
        let accept = match monitor.as_mut() {
            Some(m) => m(&QpState { iteration, x, g: &g }),
            None => true,
        };
        // an exactly stationary point cannot be improved: converged whatever the monitor says
        if (gpn <= target && accept) || gpn == 0.0 {
            rep.converged = true;
            break;
        }
        if iteration >= opt.max_iterations {
            break;
        }
        iteration += 1;
        rep.iterations = iteration;

        if bb <= opt.gamma * opt.gamma * rf {
            // proportional: trial conjugate gradient step
            hessian.apply(&p, &mut hp)?;
            rep.hessian_products += 1;
            let php = dot(&p, &hp);
            let pp = dot(&p, &p);
            let gp = dot(&g, &p);
            let acg = if php > 1e-14 * hnorm * pp { gp / php } else { f64::INFINITY };
            let mut af = layout.feasible_step(x, &p, &mut steps);
            if acg.is_infinite() && af.is_infinite() {
                if gp > 0.0 {
                    return Err(unbounded());
                }
                // no usable direction (round-off): a plain projected step, restarting CG
                af = 0.0;
            }
            if acg <= af {
                rep.cg_steps += 1;
                for k in 0..n {
                    x[k] -= acg * p[k];
                    g[k] -= acg * hp[k];
                }
                (bb, rf, gpn) = layout.split(x, &g, abar, &mut w);
                precondition(hessian, &mut general, &w, &mut z)?;
                let bcg = dot(&z, &hp) / php;
                for k in 0..n {
                    p[k] = z[k] - bcg * p[k];
                }
            } else {
                // expansion: to the boundary, then a fixed-length projected free-gradient step
                rep.expansion_steps += 1;
                for k in 0..n {
                    x[k] -= af * p[k];
                    g[k] -= af * hp[k];
                }
                layout.snap(x, &p, &steps, af);
                layout.split(x, &g, abar, &mut w);
                // a longer candidate from x½, kept if q(x^c) ≤ q(x½)
                let mut longer = false;
                if opt.expansion != Expansion::Fixed {
                    let q_half = cost(x, &g, b);
                    let usable = match opt.expansion {
                        Expansion::ProjectedCg => {
                            let s = acg - af;
                            if s.is_finite() && s > 0.0 {
                                for k in 0..n {
                                    xc[k] = x[k] - s * p[k];
                                }
                                true
                            } else {
                                false
                            }
                        }
                        _ => {
                            precondition(hessian, &mut general, &w, &mut z)?;
                            hessian.apply(&z, &mut hp)?;
                            rep.hessian_products += 1;
                            let (gz, zhz) = (dot(&w.phi, &z), dot(&z, &hp));
                            if gz > 0.0 && zhz > 1e-14 * hnorm * dot(&z, &z) {
                                let a = gz / zhz;
                                for k in 0..n {
                                    xc[k] = x[k] - a * z[k];
                                }
                                true
                            } else {
                                false
                            }
                        }
                    };
                    if usable {
                        layout.project(&mut xc);
                        gradient(hessian, &xc, &mut gc, &mut rep)?;
                        if cost(&xc, &gc, b) <= q_half {
                            x.copy_from_slice(&xc);
                            g.copy_from_slice(&gc);
                            longer = true;
                        }
                    }
                    if !longer {
                        rep.expansion_fallbacks += 1;
                    }
                }
                if !longer {
                    for k in 0..n {
                        x[k] -= abar * w.phi[k];
                    }
                    layout.project(x);
                    gradient(hessian, x, &mut g, &mut rep)?;
                }
                (bb, rf, gpn) = layout.split(x, &g, abar, &mut w);
                precondition(hessian, &mut general, &w, &mut z)?;
                p.copy_from_slice(&z);
            }
        } else {
            rep.proportioning_steps += 1;
            match prop {
                Proportioning::Chopped => {
                    hessian.apply(&w.beta, &mut hp)?;
                    rep.hessian_products += 1;
                    let bhb = dot(&w.beta, &hp);
                    let acg = if bhb > 1e-14 * hnorm * bb { dot(&g, &w.beta) / bhb } else { f64::INFINITY };
                    let af = layout.feasible_step(x, &w.beta, &mut steps);
                    let a = acg.min(af);
                    if a.is_infinite() {
                        return Err(unbounded());
                    }
                    for k in 0..n {
                        x[k] -= a * w.beta[k];
                        g[k] -= a * hp[k];
                    }
                    if af <= acg {
                        layout.snap(x, &w.beta, &steps, af);
                    }
                }
                Proportioning::Projected => {
                    // candidate a: the projected gradient step P(x − ᾱ g)
                    for k in 0..n {
                        xa[k] = x[k] - abar * g[k];
                    }
                    layout.project(&mut xa);
                    gradient(hessian, &xa, &mut ga, &mut rep)?;
                    let qa = cost(&xa, &ga, b);
                    // candidate b: truncated CG on the second-order model of q on the current
                    // face (free blocks, active blocks the gradient pushes inwards, tangent
                    // planes of the active spheres with their curvature λ_c/r_c), retracted by
                    // the projection
                    let face = layout.face(x, &g, &w.beta);
                    let mut chopped = false;
                    for k in 0..n {
                        fr[k] = -g[k];
                    }
                    face.project(&layout, &mut fr);
                    d.iter_mut().for_each(|v| *v = 0.0);
                    fp.copy_from_slice(&fr);
                    let rr0 = dot(&fr, &fr);
                    let mut rr = rr0;
                    for step in 0..FACE_CG_STEPS {
                        hessian.apply(&fp, &mut hp)?;
                        rep.hessian_products += 1;
                        face.add_curvature(&layout, &fp, &mut hp);
                        let php = dot(&fp, &hp);
                        if php.is_nan() || php <= 1e-14 * hnorm * dot(&fp, &fp) {
                            // zero curvature along the descent direction −P_face g: unbounded
                            // if Ω contains the whole ray
                            if step == 0 && rr0 > 0.0 {
                                let back: Vec<f64> = fp.iter().map(|v| -v).collect();
                                if layout.feasible_step(x, &back, &mut steps).is_infinite() {
                                    return Err(unbounded());
                                }
                            }
                            break;
                        }
                        let a = rr / php;
                        face.project(&layout, &mut hp);
                        for k in 0..n {
                            d[k] += a * fp[k];
                            fr[k] -= a * hp[k];
                        }
                        let rr_new = dot(&fr, &fr);
                        if rr_new <= FACE_CG_REDUCTION * rr0 {
                            break;
                        }
                        let bcg = rr_new / rr;
                        rr = rr_new;
                        for k in 0..n {
                            fp[k] = fr[k] + bcg * fp[k];
                        }
                    }
                    if rr0 > 0.0 {
                        for k in 0..n {
                            xb[k] = x[k] + d[k];
                        }
                        layout.project(&mut xb);
                        gradient(hessian, &xb, &mut gb, &mut rep)?;
                        chopped = cost(&xb, &gb, b) < qa;
                    }
                    if chopped {
                        x.copy_from_slice(&xb);
                        g.copy_from_slice(&gb);
                    } else {
                        x.copy_from_slice(&xa);
                        g.copy_from_slice(&ga);
                    }
                }
            }
            (bb, rf, gpn) = layout.split(x, &g, abar, &mut w);
            precondition(hessian, &mut general, &w, &mut z)?;
            p.copy_from_slice(&z);
        }
    }
    Ok((rep, history))
}
