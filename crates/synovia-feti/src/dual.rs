//! The TFETI dual problem and its solution by SMALBE with MPRGP/MPGP inner solves
//! (docs/model.md §11).
//!
//! With the subdomain stiffnesses `K = diag K_s`, kernels `R = diag R_s`, the constraint rows
//! `B = [B_E; Ĉ]` (equality rows of [`crate::Decomposition`], contact rows `Ĉ` of the
//! undecomposed problem mapped onto the owner copies and scaled to unit norm), offsets
//! `c = (0, d, s)` and the load `f̂`, the primal problem `min ½ uᵀKu − f̂ᵀu` s.t. `B_E u = 0`,
//! `B_hn u ≤ d`, Tresca on `B_Ht` has the dual
//!
//! ```text
//! min ½ λᵀ F λ − λᵀ d̃   s.t.  λ ∈ Ω,  G λ = e,
//! F = B K⁺ Bᵀ,  d̃ = B K⁺ f̂ − c,  G = Rᵀ Bᵀ,  e = Rᵀ f̂,
//! Ω: λ_E free, λ_n ≥ 0, ‖λ_t,c‖ ≤ 1/s_c (the unit disc in the unscaled multipliers).
//! ```
//!
//! `λ₀ = G_Eᵀ (G_E G_Eᵀ)⁻¹ e` lives on the equality rows, so it is feasible for `Ω`; with
//! `λ = λ₀ + λ̃`, `G̃ = L⁻¹ G` (`G Gᵀ = L Lᵀ`), `Q = G̃ᵀ G̃` and `P = I − Q` (the projector onto
//! the natural coarse space's complement) the problem becomes
//!
//! ```text
//! min ½ λ̃ᵀ (P F P + ρ Q) λ̃ − λ̃ᵀ P (d̃ − F λ₀)   s.t.  λ̃ ∈ Ω,  G̃ λ̃ = 0,
//! ```
//!
//! solved by SMALBE-M (Dostál 2009, *Optimal Quadratic Programming Algorithms*, Ch. 6):
//! the inner bound/disc-constrained problems of the augmented Lagrangian
//! `L(λ̃, μ) = ½ λ̃ᵀ(PFP + ρQ)λ̃ − λ̃ᵀ b + μᵀ G̃ λ̃` by MPRGP (2D) or MPGP (3D) of
//! `synovia-uzawa` (conjugate gradient steps preconditioned in face by
//! `M⁻¹ = P B S Bᵀ P + Q/ρ + I/‖H‖`, [`Preconditioner`]) to the adaptive precision
//! `‖g^P‖ ≤ min(M ‖G̃ λ̃‖, η)`, then
//! `μ ← μ + ρ G̃ λ̃`, and `M ← M/β` when `L` did not increase by `ρ/2 ‖G̃ λ̃‖²`. The primal
//! solution is `u = K⁺ (f̂ − Bᵀ λ) + R α` with `α = −(G_E G_Eᵀ)⁻¹ G_E (d̃ − F λ)_E` (the
//! equality rows hold exactly).
//!
//! With [`CoarseConstraint::Projector`] the coarse condition is eliminated instead of penalised:
//! `λ = λ₀ + T x`, `T = I − U (G_E G_Eᵀ)⁻¹ G` with `U = [G_Eᵀ; 0]`, and one MPRGP/MPGP run
//! solves `min ½ xᵀ Tᵀ F T x − xᵀ Tᵀ (d̃ − F λ₀)` s.t. `x_I ∈ Ω_I` (see its docs).

use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use synovia_contact::{ContactError, FrictionConstraints, NormalConstraints};
use synovia_uzawa::{estimate_norm, qp_until, ConvexBlock, Expansion, Hessian, QpOptions};

use crate::comm::Communicator;
use crate::decomposition::{Decomposition, Entry};
use crate::error::FetiError;

/// Parameters of the TFETI solve.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TfetiParams {
    /// Relative tolerance `ε`: stop when `‖g^P‖ ≤ ε ‖b‖` and `‖G̃ λ̃‖ ≤ ε ‖b‖` (default `1e-12`).
    pub tolerance: f64,
    /// Maximum SMALBE (outer) iterations (default 200).
    pub max_outer: usize,
    /// Maximum MPRGP/MPGP iterations in total (default 50 000).
    pub max_inner: usize,
    /// Penalty `ρ` as a multiple of `‖P F P‖` (default 1).
    pub rho_factor: f64,
    /// Initial `M` as a multiple of `ρ` (default 1).
    pub m_factor: f64,
    /// `η` as a multiple of `‖b‖` (default 0.1).
    pub eta_factor: f64,
    /// Decrease factor `β > 1` of `M` (default 10).
    pub beta: f64,
    /// Preconditioner in face of the inner MPRGP/MPGP conjugate gradient steps (default
    /// [`Preconditioner::Dirichlet`]).
    pub preconditioner: Preconditioner,
    /// How the coarse condition `G λ = e` is enforced (default [`CoarseConstraint::Penalty`]:
    /// SMALBE).
    pub coarse: CoarseConstraint,
    /// The expansion step of the inner MPRGP/MPGP iterations (default
    /// [`Expansion::Fixed`]: Dostál's fixed length `ᾱ = 1.9/‖H‖`; see `synovia_uzawa`'s
    /// *Longer expansion steps*).
    pub expansion: Expansion,
}

/// How the natural coarse condition `G λ = e` of the dual problem is enforced (module docs).
///
/// * `Penalty` (SMALBE): `λ = λ₀ + λ̃` with `G̃ λ̃ = 0` enforced by the augmented Lagrangian
///   `½ λ̃ᵀ(PFP + ρQ)λ̃ − λ̃ᵀb + μᵀG̃λ̃` (outer iterations update `μ`).
/// * `Projector`: the coarse condition is eliminated through the equality rows. With
///   `U = [G_Eᵀ; 0]` (coarse columns on the gluing/Dirichlet rows only) the oblique projector
///
///   ```text
///   T = I − U (G_E G_Eᵀ)⁻¹ G,   G T = 0,   T = I on Ker G,   (T x)_I = x_I,
///   ```
///
///   maps every `x` onto `Ker G` without touching the contact rows `I`, so with
///   `λ = λ₀ + T x` (`λ₀ = U (G_E G_Eᵀ)⁻¹ e`, zero on `I`) the dual becomes the purely bound/disc
///   constrained problem
///
///   ```text
///   min ½ xᵀ Tᵀ F T x − xᵀ Tᵀ (d̃ − F λ₀)   s.t.  x_I ∈ Ω_I   (x_E free),
///   ```
///
///   solved by one MPRGP/MPGP run (no outer loop). Its gradient `Tᵀ(Fλ − d̃)` is the KKT
///   residual with the coarse multiplier `α = −(G_E G_Eᵀ)⁻¹ G_E (d̃ − Fλ)_E` of the primal
///   recovery. The conjugate gradient steps are preconditioned in face `F` (free rows) by
///   `z = P_F (B A Bᵀ + I/‖H‖) P_F r` with `P_F = I − G_Fᵀ(G_F G_Fᵀ)⁻¹ G_F` the orthogonal
///   projector onto `Ker G_F` (the coarse columns of the free rows): with the bound rows
///   fixed, the face problem is a TFETI problem on the free rows, whose preconditioned operator
///   `P_F B A Bᵀ P_F F` on `Ker G_F` is the projected Dirichlet (or lumped) one of FETI
///   (`P_F Tᵀ = P_F`, since `T P_F = P_F`), bounded by `C (1 + log H/h)²` for the Dirichlet
///   preconditioner (Farhat, Mandel, Roux 1994). `(G_F G_Fᵀ)⁻¹` is applied by the Woodbury
///   update of the factor of `G_E G_Eᵀ` by the free contact rows' columns
///   (`G_F G_Fᵀ = G_E G_Eᵀ + Σ_{i ∈ F∩I} g_i g_iᵀ`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum CoarseConstraint {
    /// SMALBE: augmented Lagrangian (penalty `ρ Q`) outer iterations.
    #[default]
    Penalty,
    /// The oblique projector `T` onto `Ker G` along the equality rows' coarse columns.
    Projector,
}

/// The preconditioner `M⁻¹ ≈ (P F P + ρ Q)⁻¹` of the inner iterations, applied in face
/// (`z = Z_F M⁻¹ Z_Fᵀ φ` on the free rows `F`):
///
/// ```text
/// M⁻¹ = P B A Bᵀ P + Q / ρ + I / ‖H‖,
/// ```
///
/// with `A = diag S_s` (Dirichlet: the Schur complements of `K_s` on the dofs the dual rows
/// touch) or `A = diag K_s` (lumped). `P B A Bᵀ P` is positive definite on `Im P` where `B` has
/// independent rows (`Bᵀλ` with `Gλ = 0` is orthogonal to `Ker K`), `Q/ρ` inverts the penalty
/// on `Im Q`, and the small shift `I/‖H‖` covers `Ker Bᵀ` of redundant rows (a contact row on a
/// node whose Dirichlet rows fix the same direction), so `M⁻¹` is positive definite and so is
/// its restriction to a face (Dostál 2009, Ch. 5: MPRGP with
/// preconditioning in face; Farhat, Mandel, Roux 1994 for the projected Dirichlet
/// preconditioner of FETI).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Preconditioner {
    /// None (plain CG steps on the face).
    None,
    /// Lumped: `A = K`.
    Lumped,
    /// Dirichlet: `A = S` (one solve with the interior block `K_ii` of each subdomain per
    /// application, like a product with `F`).
    #[default]
    Dirichlet,
}

impl Default for TfetiParams {
    fn default() -> Self {
        Self {
            tolerance: 1e-12,
            max_outer: 200,
            max_inner: 50_000,
            rho_factor: 1.0,
            m_factor: 1.0,
            eta_factor: 0.1,
            beta: 10.0,
            preconditioner: Preconditioner::default(),
            coarse: CoarseConstraint::default(),
            expansion: Expansion::Fixed,
        }
    }
}

impl TfetiParams {
    /// Sets [`Self::tolerance`].
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }
    /// Sets [`Self::preconditioner`].
    pub fn with_preconditioner(mut self, preconditioner: Preconditioner) -> Self {
        self.preconditioner = preconditioner;
        self
    }
    /// Sets [`Self::coarse`].
    pub fn with_coarse(mut self, coarse: CoarseConstraint) -> Self {
        self.coarse = coarse;
        self
    }
    /// Sets [`Self::max_outer`].
    pub fn with_max_outer(mut self, max_outer: usize) -> Self {
        self.max_outer = max_outer;
        self
    }
    /// Sets [`Self::rho_factor`].
    pub fn with_rho_factor(mut self, rho_factor: f64) -> Self {
        self.rho_factor = rho_factor;
        self
    }
    /// Sets [`Self::max_inner`].
    pub fn with_max_inner(mut self, max_inner: usize) -> Self {
        self.max_inner = max_inner;
        self
    }
    /// Sets [`Self::expansion`].
    pub fn with_expansion(mut self, expansion: Expansion) -> Self {
        self.expansion = expansion;
        self
    }
}

/// What a TFETI solve did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TfetiReport {
    /// Subdomains.
    pub subdomains: usize,
    /// Ranks.
    pub ranks: usize,
    /// Dual unknowns: gluing, Dirichlet, normal, tangential rows.
    pub dual: [usize; 4],
    /// Coarse dimension `Σ r_s`.
    pub coarse_dim: usize,
    /// SMALBE iterations (1 with [`CoarseConstraint::Projector`]).
    pub outer_iterations: usize,
    /// MPRGP/MPGP iterations (all outer iterations together).
    pub inner_iterations: usize,
    /// MPRGP/MPGP iterations of each outer iteration.
    pub inner_per_outer: Vec<usize>,
    /// Of the inner iterations: conjugate gradient, expansion and proportioning steps.
    pub inner_steps: [usize; 3],
    /// Of the expansion steps: those whose longer candidate ([`TfetiParams::expansion`]) was
    /// replaced by the fixed-length step.
    pub expansion_fallbacks: usize,
    /// Products with `F` (one subdomain solve each per subdomain).
    pub f_products: usize,
    /// Applications of the preconditioner (one interior solve per subdomain each with
    /// [`Preconditioner::Dirichlet`]).
    pub preconditioner_products: usize,
    /// Factorisations of the face's capacitance matrix `I + Wᵀ(G_E G_Eᵀ)⁻¹W` (the update of
    /// `G_F G_Fᵀ` by the free contact rows `W`; [`CoarseConstraint::Projector`] with a
    /// preconditioner; one per change of the free contact rows).
    pub face_factorisations: usize,
    /// Final `‖g^P‖/‖b‖`.
    pub gradient: f64,
    /// Final `‖G̃ λ̃‖/‖b‖`.
    pub feasibility: f64,
    /// Seconds of the dual set-up (rows, coarse problem).
    pub setup_s: f64,
    /// Seconds of the SMALBE iteration and the primal recovery.
    pub solve_s: f64,
}

/// The solution in the terms of the undecomposed problem (docs/model.md §5).
#[derive(Debug, Clone, PartialEq)]
pub struct TfetiSolution {
    /// Reduced displacement `U`.
    pub u: Vec<f64>,
    /// `Λ_n` per normal row.
    pub lambda_n: Vec<f64>,
    /// `Λ_t` per tangential row.
    pub lambda_t: Vec<f64>,
    /// What was done.
    pub report: TfetiReport,
}

/// A subdomain's dual rows and its entries `(position in rows, local dof, value)`.
#[derive(Debug, Default)]
struct SubRows {
    rows: Vec<usize>,
    entries: Vec<(usize, usize, f64)>,
}

impl SubRows {
    /// `B_s x`: the subdomain's rows applied to its local vector `x`.
    fn apply(&self, x: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.rows.len()];
        for &(pos, dof, v) in &self.entries {
            out[pos] += v * x[dof];
        }
        out
    }
    /// `x += scale · B_sᵀ λ` (`λ` over all dual rows).
    fn add_transpose(&self, scale: f64, lambda: &[f64], x: &mut [f64]) {
        for &(pos, dof, v) in &self.entries {
            x[dof] += scale * v * lambda[self.rows[pos]];
        }
    }
}

/// The assembled dual operator of one contact problem.
struct Dual<'a> {
    dec: &'a Decomposition,
    comm: &'a dyn Communicator,
    m: usize,
    sub_rows: Vec<SubRows>,
    loads: Vec<Vec<f64>>,
    counts: Vec<usize>,
    offsets: Vec<f64>,
    /// Coarse columns `G[:, ρ]`.
    g_cols: Vec<Vec<(usize, f64)>>,
    n_coarse: usize,
    /// `L` with `G Gᵀ = L Lᵀ`.
    l: DMatrix<f64>,
    /// Cholesky of `G_E G_Eᵀ`.
    ge: nalgebra::Cholesky<f64, nalgebra::Dyn>,
    /// Equality rows (the first `n_eq` rows).
    n_eq: usize,
    products: std::sync::atomic::AtomicUsize,
    /// The preconditioner and, for [`Preconditioner::Dirichlet`], the blocks of the owned
    /// subdomains (`None` elsewhere).
    preconditioner: Preconditioner,
    dirichlet: Vec<Option<crate::subdomain::DirichletBlock>>,
    /// Applications of the preconditioner.
    prec_products: std::sync::atomic::AtomicUsize,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl<'a> Dual<'a> {
    #[allow(clippy::too_many_arguments)]
    fn new(
        dec: &'a Decomposition,
        comm: &'a dyn Communicator,
        rows: &[Vec<Entry>],
        offsets: Vec<f64>,
        load: &[f64],
        preconditioner: Preconditioner,
    ) -> Result<Self, FetiError> {
        let d = dec.dim;
        let n_sub = dec.subdomains.len();
        let m = rows.len();
        let mut sub_rows: Vec<SubRows> = (0..n_sub).map(|_| SubRows::default()).collect();
        for (r, row) in rows.iter().enumerate() {
            for &(s, dof, v) in row {
                let sr = &mut sub_rows[s];
                if sr.rows.last() != Some(&r) {
                    sr.rows.push(r);
                }
                let pos = sr.rows.len() - 1;
                sr.entries.push((pos, dof, v));
            }
        }
        // f̂ on the owner copies
        let mut loads: Vec<Vec<f64>> = dec.subdomains.iter().map(|s| vec![0.0; s.n_dofs()]).collect();
        for g in &dec.groups {
            let Some(&(s, a)) = g.copies.first() else { continue };
            for k in 0..g.n_dofs {
                let fk = load[g.first_dof + k];
                for c in 0..d {
                    loads[s][d * a + c] += fk * g.basis[k * d + c];
                }
            }
        }
        let counts: Vec<usize> =
            dec.ranks.iter().map(|r| r.clone().map(|s| sub_rows[s].rows.len()).sum()).collect();
        // coarse
        let mut coarse_off = Vec::with_capacity(n_sub);
        let mut n_coarse = 0;
        for s in &dec.subdomains {
            coarse_off.push(n_coarse);
            n_coarse += s.kernel.ncols();
        }
        let mut g_cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m];
        for (r, row) in rows.iter().enumerate() {
            let mut col: Vec<(usize, f64)> = Vec::new();
            for &(s, dof, v) in row {
                let ker = &dec.subdomains[s].kernel;
                for k in 0..ker.ncols() {
                    col.push((coarse_off[s] + k, v * ker[(dof, k)]));
                }
            }
            col.sort_by_key(|e| e.0);
            let mut merged: Vec<(usize, f64)> = Vec::with_capacity(col.len());
            for e in col {
                match merged.last_mut() {
                    Some(l) if l.0 == e.0 => l.1 += e.1,
                    _ => merged.push(e),
                }
            }
            g_cols[r] = merged;
        }
        let n_eq = dec.equality.len();
        let gram = |range: std::ops::Range<usize>| {
            let mut a = DMatrix::<f64>::zeros(n_coarse, n_coarse);
            for col in &g_cols[range] {
                for &(i, vi) in col {
                    for &(j, vj) in col {
                        a[(i, j)] += vi * vj;
                    }
                }
            }
            a
        };
        let ge = nalgebra::Cholesky::new(gram(0..n_eq)).ok_or(FetiError::SemiCoercive { pivot: 0 })?;
        let l = nalgebra::Cholesky::new(gram(0..m)).ok_or(FetiError::SemiCoercive { pivot: 0 })?.l();
        let dirichlet: Vec<Option<crate::subdomain::DirichletBlock>> =
            if preconditioner == Preconditioner::Dirichlet {
                (0..n_sub)
                    .into_par_iter()
                    .map(|s| {
                        if !dec.owned.contains(&s) {
                            return Ok(None);
                        }
                        let mut boundary: Vec<usize> = sub_rows[s].entries.iter().map(|e| e.1).collect();
                        boundary.sort_unstable();
                        boundary.dedup();
                        dec.subdomains[s].dirichlet_block(&boundary, s).map(Some)
                    })
                    .collect::<Result<_, FetiError>>()?
            } else {
                Vec::new()
            };
        Ok(Self {
            dec,
            comm,
            m,
            sub_rows,
            loads,
            counts,
            offsets,
            g_cols,
            n_coarse,
            l,
            ge,
            n_eq,

            products: std::sync::atomic::AtomicUsize::new(0),
            preconditioner,
            dirichlet,
            prec_products: std::sync::atomic::AtomicUsize::new(0),
        })
    }

    /// `B K⁺ (f̂ [with_load] − Bᵀ λ)`, summed in subdomain order (docs: [`crate::comm`]).
    fn bkb(&self, lambda: &[f64], with_load: bool) -> Result<Vec<f64>, FetiError> {
        self.products.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let (dec, sub_rows, loads) = (self.dec, &self.sub_rows, &self.loads);
        let local: Vec<Vec<f64>> = dec
            .owned
            .clone()
            .into_par_iter()
            .map(|s| {
                let x = subdomain_solve(dec, sub_rows, loads, s, lambda, with_load)?;
                Ok(sub_rows[s].apply(&x))
            })
            .collect::<Result<_, FetiError>>()?;
        self.sum_rows(&local)
    }

    /// `y = Σ_s` (the rows of subdomain `s`, `local[s]` on this rank's subdomains): the
    /// values of every rank gathered, then added row by row in subdomain order (the same sum on
    /// every rank and for every number of ranks).
    fn sum_rows(&self, local: &[Vec<f64>]) -> Result<Vec<f64>, FetiError> {
        let all = self.comm.all_gather(&local.concat(), &self.counts)?;
        let mut y = vec![0.0; self.m];
        let mut k = 0;
        for sr in &self.sub_rows {
            for &r in &sr.rows {
                y[r] += all[k];
                k += 1;
            }
        }
        Ok(y)
    }

    /// `B A Bᵀ λ` with `A = diag S_s` or `diag K_s` ([`Preconditioner`]), summed in subdomain
    /// order like [`Self::bkb`].
    fn bab(&self, lambda: &[f64]) -> Result<Vec<f64>, FetiError> {
        self.prec_products.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let (dec, sub_rows, dirichlet) = (self.dec, &self.sub_rows, &self.dirichlet);
        let kind = self.preconditioner;
        let local: Vec<Vec<f64>> = dec
            .owned
            .clone()
            .into_par_iter()
            .map(|s| {
                let sub = &dec.subdomains[s];
                let sr = &sub_rows[s];
                let mut x = vec![0.0; sub.n_dofs()];
                sr.add_transpose(1.0, lambda, &mut x);
                let mut y = vec![0.0; x.len()];
                match (kind, dirichlet.get(s).and_then(Option::as_ref)) {
                    (Preconditioner::Dirichlet, Some(block)) => block.apply(sub, &x, &mut y)?,
                    _ => sub.apply_stiffness(&x, &mut y),
                }
                Ok(sr.apply(&y))
            })
            .collect::<Result<_, FetiError>>()?;
        self.sum_rows(&local)
    }

    /// `F λ`.
    fn f(&self, lambda: &[f64]) -> Result<Vec<f64>, FetiError> {
        let mut y = self.bkb(lambda, false)?;
        y.iter_mut().for_each(|v| *v = -*v);
        Ok(y)
    }

    /// `G λ` (rows `range` only).
    fn g(&self, lambda: &[f64], range: std::ops::Range<usize>) -> DVector<f64> {
        let mut out = DVector::zeros(self.n_coarse);
        for r in range {
            if lambda[r] != 0.0 {
                for &(i, v) in &self.g_cols[r] {
                    out[i] += v * lambda[r];
                }
            }
        }
        out
    }

    /// `Gᵀ μ` into the rows `range` of a vector of length `m`.
    fn gt(&self, mu: &DVector<f64>, range: std::ops::Range<usize>) -> Vec<f64> {
        let mut out = vec![0.0; self.m];
        for r in range {
            out[r] = self.g_cols[r].iter().map(|&(i, v)| v * mu[i]).sum();
        }
        out
    }

    /// `G̃ λ = L⁻¹ G λ`.
    fn gt_orth(&self, lambda: &[f64]) -> DVector<f64> {
        let mut v = self.g(lambda, 0..self.m);
        self.l.solve_lower_triangular_mut(&mut v);
        v
    }

    /// `G̃ᵀ μ = Gᵀ L⁻ᵀ μ`.
    fn gt_orth_t(&self, mu: &DVector<f64>) -> Vec<f64> {
        let mut v = mu.clone();
        self.l.tr_solve_lower_triangular_mut(&mut v);
        self.gt(&v, 0..self.m)
    }

    /// `Q λ = G̃ᵀ G̃ λ`.
    fn q(&self, lambda: &[f64]) -> Vec<f64> {
        let v = self.gt_orth(lambda);
        self.gt_orth_t(&v)
    }

    /// `P λ = λ − Q λ`.
    fn p(&self, lambda: &[f64]) -> Vec<f64> {
        let q = self.q(lambda);
        lambda.iter().zip(&q).map(|(a, b)| a - b).collect()
    }

    /// `T x = x − U (G_E G_Eᵀ)⁻¹ G x` with `U = [G_Eᵀ; 0]` ([`CoarseConstraint::Projector`]).
    fn t(&self, x: &[f64]) -> Vec<f64> {
        let y = self.ge.solve(&self.g(x, 0..self.m));
        let u = self.gt(&y, 0..self.n_eq);
        x.iter().zip(&u).map(|(a, b)| a - b).collect()
    }

    /// `Tᵀ y = y − Gᵀ (G_E G_Eᵀ)⁻¹ G_E y_E`.
    fn t_tr(&self, y: &[f64]) -> Vec<f64> {
        let v = self.ge.solve(&self.g(y, 0..self.n_eq));
        let w = self.gt(&v, 0..self.m);
        y.iter().zip(&w).map(|(a, b)| a - b).collect()
    }

    /// `(G_E G_Eᵀ)⁻¹ g_r` of row `r`'s coarse column `g_r`.
    fn ge_solve_col(&self, r: usize) -> DVector<f64> {
        let mut v = DVector::zeros(self.n_coarse);
        for &(i, x) in &self.g_cols[r] {
            v[i] += x;
        }
        self.ge.solve(&v)
    }

    /// `g_rᵀ y` of row `r`'s coarse column.
    fn col_dot(&self, r: usize, y: &DVector<f64>) -> f64 {
        self.g_cols[r].iter().map(|&(i, v)| v * y[i]).sum()
    }
}

/// `H = P F P + ρ Q` as a [`Hessian`], with `‖H‖` (estimated; `0` if unknown) for the
/// preconditioner's shift.
struct ProjectedHessian<'d, 'a> {
    dual: &'d Dual<'a>,
    rho: f64,
    norm: f64,
}

impl Hessian for ProjectedHessian<'_, '_> {
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), ContactError> {
        let d = self.dual;
        let px = d.p(x);
        let fpx = d.f(&px).map_err(ContactError::from)?;
        let pfpx = d.p(&fpx);
        if self.rho != 0.0 {
            let qx = d.q(x);
            for ((yi, a), b) in y.iter_mut().zip(&pfpx).zip(&qx) {
                *yi = a + self.rho * b;
            }
        } else {
            y.copy_from_slice(&pfpx);
        }
        Ok(())
    }

    /// `z = Z_F (P B A Bᵀ P + Q/ρ + I/‖H‖) Z_Fᵀ r` ([`Preconditioner`]; the shift `I/‖H‖`
    /// keeps the preconditioner definite on `Ker Bᵀ`, the directions of redundant rows — e.g. a
    /// contact row on a node whose Dirichlet rows fix the same direction — where `H` has zero
    /// curvature and the iteration must still move by expansion steps).
    fn precondition_in_face(
        &mut self,
        free: &[bool],
        r: &[f64],
        z: &mut [f64],
    ) -> Result<bool, ContactError> {
        let d = self.dual;
        if d.preconditioner == Preconditioner::None || self.rho <= 0.0 {
            return Ok(false);
        }
        let rf: Vec<f64> = r.iter().zip(free).map(|(&v, &f)| if f { v } else { 0.0 }).collect();
        let pr = d.p(&rf);
        let apr = d.bab(&pr).map_err(ContactError::from)?;
        let papr = d.p(&apr);
        let qr = d.q(&rf);
        for (((zi, a), q), &f) in z.iter_mut().zip(&papr).zip(&qr).zip(free) {
            *zi = if f { a + q / self.rho } else { 0.0 };
        }
        if self.norm > 0.0 {
            for (zi, r) in z.iter_mut().zip(&rf) {
                *zi += r / self.norm;
            }
        }
        Ok(true)
    }
}

/// A dense Cholesky factor.
type Factor = nalgebra::Cholesky<f64, nalgebra::Dyn>;

/// `H = Tᵀ F T` of [`CoarseConstraint::Projector`] as a [`Hessian`], with `‖H‖` (estimated;
/// `0` if unknown) for the preconditioner's shift and the factor of `G_F G_Fᵀ` of the last face.
struct ObliqueHessian<'d, 'a> {
    dual: &'d Dual<'a>,
    norm: f64,
    /// `a_r = (G_E G_Eᵀ)⁻¹ g_r` of the contact rows met in a face so far (index `r − n_eq`).
    a_cols: Vec<Option<DVector<f64>>>,
    /// The free contact rows `W = [g_r]` of the last face and the Cholesky factor of its
    /// capacitance matrix `C = I + Wᵀ (G_E G_Eᵀ)⁻¹ W`.
    face: Option<(Vec<usize>, Option<Factor>)>,
    /// Factorisations of `C` (one per change of the free contact rows).
    face_factorisations: usize,
}

impl<'d, 'a> ObliqueHessian<'d, 'a> {
    fn new(dual: &'d Dual<'a>) -> Self {
        Self { dual, norm: 0.0, a_cols: vec![None; dual.m - dual.n_eq], face: None, face_factorisations: 0 }
    }

    /// Sets the face to the free contact rows `key` (Woodbury:
    /// `(G_E G_Eᵀ + W Wᵀ)⁻¹ = A⁻¹ − A⁻¹ W C⁻¹ Wᵀ A⁻¹` with `A = G_E G_Eᵀ`, `C = I + Wᵀ A⁻¹ W`,
    /// so only the `k × k` matrix `C` of the `k` free contact rows is factorised).
    fn set_face(&mut self, key: Vec<usize>) -> Result<(), FetiError> {
        if self.face.as_ref().is_some_and(|(k, _)| *k == key) {
            return Ok(());
        }
        let d = self.dual;
        for &r in &key {
            if self.a_cols[r - d.n_eq].is_none() {
                self.a_cols[r - d.n_eq] = Some(d.ge_solve_col(r));
            }
        }
        let chol = if key.is_empty() {
            None
        } else {
            let k = key.len();
            let mut c = DMatrix::<f64>::identity(k, k);
            for (i, &ri) in key.iter().enumerate() {
                for (j, &rj) in key.iter().enumerate() {
                    if let Some(aj) = &self.a_cols[rj - d.n_eq] {
                        c[(i, j)] += d.col_dot(ri, aj);
                    }
                }
            }
            self.face_factorisations += 1;
            Some(nalgebra::Cholesky::new(c).ok_or(FetiError::SemiCoercive { pivot: 0 })?)
        };
        self.face = Some((key, chol));
        Ok(())
    }

    /// `P_F v = v − Z_F G_Fᵀ (G_F G_Fᵀ)⁻¹ G_F v` for `v` zero off the face.
    fn project_face(&self, free: &[bool], v: &[f64]) -> Vec<f64> {
        let d = self.dual;
        let mut s = d.ge.solve(&d.g(v, 0..d.m));
        if let Some((key, Some(chol))) = &self.face {
            let t = DVector::from_iterator(key.len(), key.iter().map(|&r| d.col_dot(r, &s)));
            let w = chol.solve(&t);
            for (&r, wi) in key.iter().zip(w.iter()) {
                if let Some(a) = &self.a_cols[r - d.n_eq] {
                    s.axpy(-wi, a, 1.0);
                }
            }
        }
        let w = d.gt(&s, 0..d.m);
        v.iter().zip(&w).zip(free).map(|((a, b), &f)| if f { a - b } else { 0.0 }).collect()
    }
}

impl Hessian for ObliqueHessian<'_, '_> {
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), ContactError> {
        let d = self.dual;
        let tx = d.t(x);
        let ftx = d.f(&tx).map_err(ContactError::from)?;
        y.copy_from_slice(&d.t_tr(&ftx));
        Ok(())
    }

    /// `z = P_F (B A Bᵀ + I/‖H‖) P_F Z_Fᵀ r` ([`CoarseConstraint::Projector`]; the shift as in
    /// [`ProjectedHessian`], for the directions of redundant rows).
    fn precondition_in_face(
        &mut self,
        free: &[bool],
        r: &[f64],
        z: &mut [f64],
    ) -> Result<bool, ContactError> {
        let d = self.dual;
        if d.preconditioner == Preconditioner::None {
            return Ok(false);
        }
        let key: Vec<usize> = (d.n_eq..d.m).filter(|&i| free[i]).collect();
        self.set_face(key).map_err(ContactError::from)?;
        let rf: Vec<f64> = r.iter().zip(free).map(|(&v, &f)| if f { v } else { 0.0 }).collect();
        let pr = self.project_face(free, &rf);
        let mut a = d.bab(&pr).map_err(ContactError::from)?;
        if self.norm > 0.0 {
            a.iter_mut().zip(&pr).for_each(|(ai, p)| *ai += p / self.norm);
        }
        a.iter_mut().zip(free).for_each(|(ai, &f)| {
            if !f {
                *ai = 0.0;
            }
        });
        z.copy_from_slice(&self.project_face(free, &a));
        Ok(true)
    }
}

/// `‖g^P‖` of `x ∈ Ω` with gradient `g` (see `synovia_uzawa::qp`).
fn projected_gradient(blocks: &[ConvexBlock], x: &[f64], g: &[f64]) -> f64 {
    let mut s = 0.0;
    let mut k = 0;
    for b in blocks {
        match *b {
            ConvexBlock::Interval { lower, upper } => {
                let gi = g[k];
                let v = if x[k] <= lower {
                    gi.min(0.0)
                } else if x[k] >= upper {
                    gi.max(0.0)
                } else {
                    gi
                };
                s += v * v;
                k += 1;
            }
            ConvexBlock::Ball { dim, radius } => {
                let (xi, gi) = (&x[k..k + dim], &g[k..k + dim]);
                let nx = norm(xi);
                if nx >= radius * (1.0 - 1e-12) && nx > 0.0 {
                    let ng: f64 = xi.iter().zip(gi).map(|(a, b)| a * b).sum::<f64>() / nx;
                    let c = ng.min(0.0);
                    for (a, b) in xi.iter().zip(gi) {
                        let v = b - c * a / nx;
                        s += v * v;
                    }
                } else {
                    s += gi.iter().map(|v| v * v).sum::<f64>();
                }
                k += dim;
            }
        }
    }
    s.sqrt()
}

/// The dual data of one solve: `F`, `G`, the rows' scales and feasible sets, `λ₀` and the
/// projected right-hand side `b = P (d̃ − F λ₀)` (module docs).
struct SetUp<'a> {
    dual: Dual<'a>,
    scale: Vec<f64>,
    blocks: Vec<ConvexBlock>,
    lambda0: Vec<f64>,
    b: Vec<f64>,
    n_eq: usize,
    mn: usize,
    mt: usize,
}

/// Builds the dual problem of [`solve`] (module docs): rows `B = [B_E; Ĉ]` (normal rows scaled
/// to unit norm, Tresca cells by a common scale), `Ω`, `λ₀ = G_Eᵀ (G_E G_Eᵀ)⁻¹ e` and
/// `b = P (B K⁺ (f̂ − Bᵀ λ₀) − c)`.
fn set_up<'a>(
    dec: &'a Decomposition,
    comm: &'a dyn Communicator,
    load: &[f64],
    normal: &NormalConstraints,
    friction: Option<&FrictionConstraints>,
    params: &TfetiParams,
) -> Result<SetUp<'a>, FetiError> {
    let n = dec.n_reduced;
    if load.len() != n || normal.rows.ncols() != n || friction.is_some_and(|f| f.rows.ncols() != n) {
        return Err(FetiError::Mismatch { expected: n, got: load.len() });
    }
    let (mn, mt) = (normal.rows.nrows(), friction.map_or(0, |f| f.rows.nrows()));
    if normal.weights.len() != mn || normal.gap.len() != mn {
        return Err(FetiError::InvalidParameter("normal rows, weights and gaps differ in length".into()));
    }
    let comps = friction.map_or(1, |f| f.components.max(1));
    if friction.is_some_and(|f| f.shift.len() != mt || mt % comps != 0) {
        return Err(FetiError::InvalidParameter("friction rows and shifts differ in length".into()));
    }
    if !(params.tolerance > 0.0 && params.rho_factor > 0.0 && params.beta > 1.0 && params.m_factor > 0.0) {
        return Err(FetiError::InvalidParameter(format!("{params:?}")));
    }
    // rows: equality, normal (unit norm), friction (cell-wise common scale)
    let n_eq = dec.equality.len();
    let mut rows: Vec<Vec<Entry>> = dec.equality.clone();
    let mut scale = vec![1.0; n_eq];
    let mut offsets = vec![0.0; n_eq];
    let mut blocks: Vec<ConvexBlock> =
        vec![ConvexBlock::Interval { lower: f64::NEG_INFINITY, upper: f64::INFINITY }; n_eq];
    for r in 0..mn {
        let row = dec.map_row(normal.rows.row(r));
        let nr = row.iter().map(|e| e.2 * e.2).sum::<f64>().sqrt();
        let s = if nr > 0.0 { 1.0 / nr } else { 1.0 };
        rows.push(row.into_iter().map(|(a, b, v)| (a, b, v * s)).collect());
        scale.push(s);
        offsets.push(s * normal.gap[r]);
        blocks.push(ConvexBlock::Interval { lower: 0.0, upper: f64::INFINITY });
    }
    if let Some(fr) = friction {
        for c in 0..mt / comps {
            let cell: Vec<Vec<Entry>> = (0..comps).map(|k| dec.map_row(fr.rows.row(c * comps + k))).collect();
            let n2: f64 = cell.iter().flatten().map(|e| e.2 * e.2).sum::<f64>() / comps as f64;
            let s = if n2 > 0.0 { 1.0 / n2.sqrt() } else { 1.0 };
            for (k, row) in cell.into_iter().enumerate() {
                rows.push(row.into_iter().map(|(a, b, v)| (a, b, v * s)).collect());
                scale.push(s);
                offsets.push(s * fr.shift[c * comps + k]);
            }
            if comps == 1 {
                blocks.push(ConvexBlock::Interval { lower: -1.0 / s, upper: 1.0 / s });
            } else {
                blocks.push(ConvexBlock::Ball { dim: comps, radius: 1.0 / s });
            }
        }
    }
    let dual = Dual::new(dec, comm, &rows, offsets, load, params.preconditioner)?;
    // e = Rᵀ f̂, λ₀ = G_Eᵀ (G_E G_Eᵀ)⁻¹ e
    let mut e = DVector::zeros(dual.n_coarse);
    {
        let mut off = 0;
        for (s, sub) in dec.subdomains.iter().enumerate() {
            for k in 0..sub.kernel.ncols() {
                e[off + k] = sub.kernel.column(k).iter().zip(&dual.loads[s]).map(|(a, b)| a * b).sum();
            }
            off += sub.kernel.ncols();
        }
    }
    let lambda0 = dual.gt(&dual.ge.solve(&e), 0..n_eq);
    // b = P (d̃ − F λ₀) = P (B K⁺ (f̂ − Bᵀ λ₀) − c)
    let mut r0 = dual.bkb(&lambda0, true)?;
    r0.iter_mut().zip(&dual.offsets).for_each(|(a, c)| *a -= c);
    let b = match params.coarse {
        CoarseConstraint::Penalty => dual.p(&r0),
        CoarseConstraint::Projector => dual.t_tr(&r0),
    };
    Ok(SetUp { dual, scale, blocks, lambda0, b, n_eq, mn, mt })
}

/// Lanczos estimates of the spectrum of the SMALBE Hessian on a face (a diagnostic of the inner
/// iterations, docs/scale-out.md).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpectrumEstimate {
    /// Rows of the face.
    pub rows: usize,
    /// `‖P F P‖` (power method; `‖Tᵀ F T‖` with [`CoarseConstraint::Projector`]).
    pub norm_pfp: f64,
    /// Smallest and largest Ritz values of `H_FF`.
    pub extreme: [f64; 2],
    /// Their ratio, the estimate of `κ(H_FF)`.
    pub condition: f64,
    /// (Preconditioned) conjugate gradient steps to `‖r‖ ≤ 1e-8 ‖b_F‖`.
    pub cg_steps: usize,
}

/// Estimates the spectrum of `H_FF = Z_Fᵀ (P F P + ρ Q) Z_F` (`ρ = rho_factor ‖PFP‖`, `Z_F` the
/// rows of the face `F`; with [`CoarseConstraint::Projector`] `H_FF = Z_Fᵀ Tᵀ F T Z_F`, on
/// `Im Tᵀ`) — preconditioned by `params.preconditioner` in face: of `M_F⁻¹ H_FF` —
/// by the (preconditioned) conjugate gradient method on `H_FF x = b_F` from `x = 0`:
/// the Lanczos tridiagonal matrix `T` built from the CG coefficients
/// (`T_kk = 1/α_k + β_{k−1}/α_{k−1}`, `T_{k,k+1} = √β_k / α_k`) has Ritz values that converge to
/// the extreme eigenvalues of `H_FF` from inside. The face holds the equality rows and the contact
/// rows with `contact_free[r]` (`None`: none of them — the linear problem of the gluing and
/// Dirichlet rows alone, as if no contact row were active).
///
/// # Errors
/// As [`solve`].
#[allow(clippy::too_many_arguments)]
pub fn face_spectrum(
    dec: &Decomposition,
    comm: &dyn Communicator,
    load: &[f64],
    normal: &NormalConstraints,
    friction: Option<&FrictionConstraints>,
    params: &TfetiParams,
    contact_free: Option<&[bool]>,
    max_steps: usize,
) -> Result<SpectrumEstimate, FetiError> {
    let su = set_up(dec, comm, load, normal, friction, params)?;
    let m = su.dual.m;
    let free: Vec<bool> = (0..m)
        .map(|r| r < su.n_eq || contact_free.and_then(|f| f.get(r - su.n_eq).copied()).unwrap_or(false))
        .collect();
    let (est, mut hess): (f64, Box<dyn Hessian + '_>) = match params.coarse {
        CoarseConstraint::Penalty => {
            let mut pfp = ProjectedHessian { dual: &su.dual, rho: 0.0, norm: 0.0 };
            let (est, _) = estimate_norm(&mut pfp, m, 30)?;
            let rho = params.rho_factor * est;
            (est, Box::new(ProjectedHessian { dual: &su.dual, rho, norm: 1.05 * est.max(rho) }))
        }
        CoarseConstraint::Projector => {
            let mut h = ObliqueHessian::new(&su.dual);
            let (est, _) = estimate_norm(&mut h, m, 30)?;
            h.norm = 1.05 * est;
            (est, Box::new(h))
        }
    };
    let mut r = su.b.clone();
    r.iter_mut().zip(&free).for_each(|(a, &f)| {
        if !f {
            *a = 0.0;
        }
    });
    let r0 = norm(&r).max(f64::MIN_POSITIVE);
    let mut z = vec![0.0; m];
    let precondition = |hess: &mut dyn Hessian, r: &[f64], z: &mut [f64]| -> Result<(), FetiError> {
        if !hess.precondition_in_face(&free, r, z)? {
            z.copy_from_slice(r);
        }
        Ok(())
    };
    precondition(hess.as_mut(), &r, &mut z)?;
    let mut p = z.clone();
    let mut hp = vec![0.0; m];
    let mut rz = r.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>();
    let (mut alphas, mut betas) = (Vec::new(), Vec::new());
    let mut steps = 0;
    while steps < max_steps && norm(&r) > 1e-8 * r0 {
        hess.apply(&p, &mut hp).map_err(FetiError::from)?;
        hp.iter_mut().zip(&free).for_each(|(a, &f)| {
            if !f {
                *a = 0.0;
            }
        });
        let php: f64 = p.iter().zip(&hp).map(|(a, b)| a * b).sum();
        if php <= 0.0 {
            break;
        }
        let a = rz / php;
        r.iter_mut().zip(&hp).for_each(|(ri, h)| *ri -= a * h);
        precondition(hess.as_mut(), &r, &mut z)?;
        let rz_new = r.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>();
        let b = rz_new / rz;
        rz = rz_new;
        p.iter_mut().zip(&z).for_each(|(pi, zi)| *pi = zi + b * *pi);
        alphas.push(a);
        betas.push(b);
        steps += 1;
    }
    let k = alphas.len();
    let mut t = DMatrix::<f64>::zeros(k, k);
    for i in 0..k {
        t[(i, i)] = 1.0 / alphas[i] + if i > 0 { betas[i - 1] / alphas[i - 1] } else { 0.0 };
        if i + 1 < k {
            let o = betas[i].sqrt() / alphas[i];
            t[(i, i + 1)] = o;
            t[(i + 1, i)] = o;
        }
    }
    let ev = t.symmetric_eigenvalues();
    let lo = ev.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ev.iter().copied().fold(0.0, f64::max);
    Ok(SpectrumEstimate {
        rows: free.iter().filter(|&&f| f).count(),
        norm_pfp: est,
        extreme: [lo, hi],
        condition: if lo > 0.0 { hi / lo } else { f64::INFINITY },
        cg_steps: steps,
    })
}

/// Solves the contact problem with load `load` (reduced unknowns of the decomposed model),
/// normal rows and optional Tresca rows by TFETI (module docs). Collective: every rank calls it
/// with the same data.
///
/// # Errors
/// [`FetiError::Mismatch`] for a problem on other unknowns, [`FetiError::SemiCoercive`],
/// [`FetiError::NoConvergence`], and the errors of the subdomain solves and communication.
pub fn solve(
    dec: &Decomposition,
    comm: &dyn Communicator,
    load: &[f64],
    normal: &NormalConstraints,
    friction: Option<&FrictionConstraints>,
    params: &TfetiParams,
) -> Result<TfetiSolution, FetiError> {
    let t0 = Instant::now();
    let SetUp { dual, scale, blocks, lambda0, b, n_eq, mn, mt } =
        set_up(dec, comm, load, normal, friction, params)?;
    let m = dual.m;
    let bnorm = norm(&b).max(f64::MIN_POSITIVE);
    let setup_s = t0.elapsed().as_secs_f64();

    let mut report = TfetiReport {
        subdomains: dec.subdomains.len(),
        ranks: comm.size(),
        dual: [dec.n_gluing, n_eq - dec.n_gluing, mn, mt],
        coarse_dim: dual.n_coarse,
        setup_s,
        ..Default::default()
    };
    let x = match params.coarse {
        CoarseConstraint::Projector => solve_projected(&dual, &blocks, &b, params, &mut report)?,
        CoarseConstraint::Penalty => {
            // ‖P F P‖, ρ, M, η
            let mut pfp = ProjectedHessian { dual: &dual, rho: 0.0, norm: 0.0 };
            let (est, _) = estimate_norm(&mut pfp, m, 30)?;
            let est = est.max(f64::MIN_POSITIVE);
            let rho = params.rho_factor * est;
            let mut hess = ProjectedHessian { dual: &dual, rho, norm: 1.05 * est.max(rho) };
            let mut big_m = params.m_factor * rho;
            let eta = params.eta_factor * bnorm;
            let eps = params.tolerance * bnorm;
            let chopped = blocks.iter().all(|b| matches!(b, ConvexBlock::Interval { .. }));
            let mut opts = QpOptions::default()
                .with_hessian_norm(Some(1.05 * est.max(rho)))
                .with_precondition(params.preconditioner != Preconditioner::None)
                .with_expansion(params.expansion);

            let mut x = vec![0.0; m];
            let mut mu = DVector::<f64>::zeros(dual.n_coarse);
            let mut l_prev = f64::NEG_INFINITY;
            let mut converged = false;
            let (mut gp_last, mut gx_last) = (f64::INFINITY, f64::INFINITY);
            for outer in 1..=params.max_outer {
                report.outer_iterations = outer;
                let gtmu = dual.gt_orth_t(&mu);
                let bk: Vec<f64> = b.iter().zip(&gtmu).map(|(a, c)| a - c).collect();
                let mut last_g = Vec::new();
                let mut final_reached = false;
                let (mut gp_s, mut gx_s) = (0.0, 0.0);
                opts =
                    opts.with_max_iterations(params.max_inner.saturating_sub(report.inner_iterations).max(1));
                let rep = {
                    let mut stop = |_it: usize, xi: &[f64], gi: &[f64]| {
                        let gp = projected_gradient(&blocks, xi, gi);
                        let gx = dual.gt_orth(xi).norm();
                        let fin = gp <= eps && gx <= eps;
                        if fin || gp <= (big_m * gx).min(eta) {
                            final_reached = fin;
                            last_g = gi.to_vec();
                            gp_s = gp;
                            gx_s = gx;
                            true
                        } else {
                            false
                        }
                    };
                    qp_until(&mut hess, &bk, &blocks, &mut x, &opts, chopped, &mut stop)?
                };
                report.inner_iterations += rep.iterations;
                report.inner_per_outer.push(rep.iterations);
                report.inner_steps[0] += rep.cg_steps;
                report.inner_steps[1] += rep.expansion_steps;
                report.inner_steps[2] += rep.proportioning_steps;
                report.expansion_fallbacks += rep.expansion_fallbacks;
                gp_last = gp_s;
                gx_last = gx_s;
                if !rep.converged {
                    gp_last = rep.projected_gradient_norm;
                    break;
                }
                if final_reached {
                    converged = true;
                    break;
                }
                let gx = dual.gt_orth(&x);
                // L(λ_k, μ_k) = ½ λ_kᵀ(g + b_k) − bᵀλ_k + μ_kᵀ G̃ λ_k with the multiplier μ_k of this
                // inner problem; M decreases if L(λ_k, μ_k) < L(λ_{k−1}, μ_{k−1}) + ρ/2 ‖G̃ λ_k‖²
                // (Dostál 2009, Alg. 6.1, step 3)
                let half: f64 =
                    x.iter().zip(last_g.iter().zip(&bk)).map(|(xi, (g, c))| xi * (g + c)).sum::<f64>() * 0.5;
                let l_new = half - x.iter().zip(&b).map(|(a, c)| a * c).sum::<f64>() + mu.dot(&gx);
                if outer > 1 && l_new < l_prev + 0.5 * rho * gx.norm_squared() {
                    big_m /= params.beta;
                }
                l_prev = l_new;
                mu += &gx * rho;
            }
            report.gradient = gp_last / bnorm;
            report.feasibility = gx_last / bnorm;
            if !converged {
                report.f_products = dual.products.load(std::sync::atomic::Ordering::Relaxed);
                return Err(FetiError::NoConvergence {
                    outer: report.outer_iterations,
                    inner: report.inner_iterations,
                    gradient: report.gradient,
                    feasibility: report.feasibility,
                });
            }

            x
        }
    };

    // primal recovery
    let lambda: Vec<f64> = x.iter().zip(&lambda0).map(|(a, c)| a + c).collect();
    let mut rt = dual.bkb(&lambda, true)?;
    rt.iter_mut().zip(&dual.offsets).for_each(|(a, c)| *a -= c);
    let alpha = -dual.ge.solve(&dual.g(&rt, 0..n_eq));
    let u = recover(&dual, &lambda, &alpha)?;
    let lambda_n: Vec<f64> =
        (0..mn).map(|r| scale[n_eq + r] * lambda[n_eq + r] / normal.weights[r]).collect();
    let lambda_t: Vec<f64> = (0..mt).map(|r| scale[n_eq + mn + r] * lambda[n_eq + mn + r]).collect();
    report.f_products = dual.products.load(std::sync::atomic::Ordering::Relaxed);
    report.preconditioner_products = dual.prec_products.load(std::sync::atomic::Ordering::Relaxed);
    report.solve_s = t0.elapsed().as_secs_f64() - setup_s;
    Ok(TfetiSolution { u, lambda_n, lambda_t, report })
}

/// [`CoarseConstraint::Projector`]: one MPRGP/MPGP run on `min ½ xᵀ Tᵀ F T x − xᵀ b`,
/// `x_I ∈ Ω_I`, until `‖g^P‖ ≤ ε ‖b‖`; returns `λ̃ = T x` (so `λ = λ₀ + λ̃`, `G λ̃ = 0`).
fn solve_projected(
    dual: &Dual<'_>,
    blocks: &[ConvexBlock],
    b: &[f64],
    params: &TfetiParams,
    report: &mut TfetiReport,
) -> Result<Vec<f64>, FetiError> {
    let m = dual.m;
    let bnorm = norm(b).max(f64::MIN_POSITIVE);
    let eps = params.tolerance * bnorm;
    let mut hess = ObliqueHessian::new(dual);
    let (est, _) = estimate_norm(&mut hess, m, 30)?;
    let hnorm = 1.05 * est.max(f64::MIN_POSITIVE);
    hess.norm = hnorm;
    let chopped = blocks.iter().all(|b| matches!(b, ConvexBlock::Interval { .. }));
    let opts = QpOptions::default()
        .with_hessian_norm(Some(hnorm))
        .with_precondition(params.preconditioner != Preconditioner::None)
        .with_expansion(params.expansion)
        .with_max_iterations(params.max_inner.max(1));
    let mut x = vec![0.0; m];
    let mut gp_last = f64::INFINITY;
    let rep = {
        let mut stop = |_it: usize, xi: &[f64], gi: &[f64]| {
            gp_last = projected_gradient(blocks, xi, gi);
            gp_last <= eps
        };
        qp_until(&mut hess, b, blocks, &mut x, &opts, chopped, &mut stop)?
    };
    report.outer_iterations = 1;
    report.inner_iterations = rep.iterations;
    report.inner_per_outer = vec![rep.iterations];
    report.inner_steps = [rep.cg_steps, rep.expansion_steps, rep.proportioning_steps];
    report.expansion_fallbacks = rep.expansion_fallbacks;
    report.face_factorisations = hess.face_factorisations;
    report.gradient = gp_last / bnorm;
    let lt = dual.t(&x);
    report.feasibility = dual.gt_orth(&lt).norm() / bnorm;
    if !rep.converged {
        report.f_products = dual.products.load(std::sync::atomic::Ordering::Relaxed);
        return Err(FetiError::NoConvergence {
            outer: 1,
            inner: report.inner_iterations,
            gradient: report.gradient,
            feasibility: report.feasibility,
        });
    }
    Ok(lt)
}

/// `K_s⁺ (f̂_s [with_load] − B_sᵀ λ)` of subdomain `s` (the fields of [`Dual`] it needs are
/// passed apart: the closures over subdomains run on rayon's pool, and the communicator is not
/// `Sync`).
fn subdomain_solve(
    dec: &Decomposition,
    sub_rows: &[SubRows],
    loads: &[Vec<f64>],
    s: usize,
    lambda: &[f64],
    with_load: bool,
) -> Result<Vec<f64>, FetiError> {
    let sub = &dec.subdomains[s];
    let sr = &sub_rows[s];
    let mut x = if with_load { loads[s].clone() } else { vec![0.0; sub.n_dofs()] };
    sr.add_transpose(-1.0, lambda, &mut x);
    sub.pinv_in_place(&mut x, s)?;
    Ok(x)
}

/// `u_s = K_s⁺ (f̂_s − B_sᵀ λ) + R_s α_s` on the owned subdomains, read back on the owner copies
/// as reduced unknowns and gathered.
fn recover(dual: &Dual<'_>, lambda: &[f64], alpha: &DVector<f64>) -> Result<Vec<f64>, FetiError> {
    let dec = dual.dec;
    let d = dec.dim;
    let n_sub = dec.subdomains.len();
    let mut owner_groups: Vec<Vec<usize>> = vec![Vec::new(); n_sub];
    for (gi, g) in dec.groups.iter().enumerate() {
        if let Some(&(s, _)) = g.copies.first() {
            owner_groups[s].push(gi);
        }
    }
    let mut coarse_off = Vec::with_capacity(n_sub);
    let mut off = 0;
    for s in &dec.subdomains {
        coarse_off.push(off);
        off += s.kernel.ncols();
    }
    let (sub_rows, loads) = (&dual.sub_rows, &dual.loads);
    let local: Vec<Vec<f64>> = dec
        .owned
        .clone()
        .into_par_iter()
        .map(|s| {
            let sub = &dec.subdomains[s];
            let mut x = subdomain_solve(dec, sub_rows, loads, s, lambda, true)?;
            for k in 0..sub.kernel.ncols() {
                let a = alpha[coarse_off[s] + k];
                for (xi, r) in x.iter_mut().zip(sub.kernel.column(k).iter()) {
                    *xi += a * r;
                }
            }
            let mut out = Vec::new();
            for &gi in &owner_groups[s] {
                let g = &dec.groups[gi];
                let a = g.copies[0].1;
                for k in 0..g.n_dofs {
                    out.push((0..d).map(|c| g.basis[k * d + c] * x[d * a + c]).sum::<f64>());
                }
            }
            Ok(out)
        })
        .collect::<Result<_, FetiError>>()?;
    let counts: Vec<usize> = dec
        .ranks
        .iter()
        .map(|r| {
            r.clone().map(|s| owner_groups[s].iter().map(|&g| dec.groups[g].n_dofs).sum::<usize>()).sum()
        })
        .collect();
    let all = dual.comm.all_gather(&local.concat(), &counts)?;
    let mut u = vec![0.0; dec.n_reduced];
    let mut k = 0;
    for groups in &owner_groups {
        for &gi in groups {
            let g = &dec.groups[gi];
            for j in 0..g.n_dofs {
                u[g.first_dof + j] = all[k];
                k += 1;
            }
        }
    }
    Ok(u)
}
