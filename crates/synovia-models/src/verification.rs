//! Verification problems with exact solutions, shared by the examples and the test suite so
//! that anyone can re-run them on their own machine.
//!
//! ## Manufactured solution for bonded multi-body elasticity (docs/model.md §8)
//!
//! On the box `[0, 1]^D`, split at `x = ½` into two bodies bonded along the interface — body
//! `"iso"` (isotropic) on the left, body `"aniso"` (a fully anisotropic Voigt matrix) on the
//! right — the exact displacement is
//!
//! ```text
//! u_k(x) = a_k sin(b_k · x + c_k),   k = 1 … D.
//! ```
//!
//! The data are derived from it: body forces `F = −div C e(u)` in each body, Dirichlet
//! `u₂ = u` on the outer boundary except the right face, the traction `P = C_aniso e(u) n`
//! there, and on the interface the jump `(C_iso − C_aniso) e(u) n_iso` of the tractions (the
//! exact solution is smooth, but the stress jumps with the material). The P1 error is
//! `O(h)` in the energy norm and `O(h²)` in `L²` (docs/model.md §8).

use std::sync::Arc;

use nalgebra::{DMatrix, Vector2, Vector3};
use synovia_fem::element::{stress_tensor, voigt_strain, SimplexGeometry};
use synovia_fem::{ElasticParams, ElasticSolver, FemError, Model, QuadratureRule};
use synovia_material::{
    anisotropic, isotropic, plane_strain, transversely_isotropic, transversely_isotropic_plane_strain,
    LinearElastic, Material, TransverseIsotropy,
};
use synovia_mesh::generators::{box_mesh, rectangle, Grading};
use synovia_mesh::math::{Point, Real, Tensor, Vector};
use synovia_mesh::{BoundaryKind, Mesh};

/// The manufactured field `u_k = a_k sin(b_k · x + c_k)`.
#[derive(Debug, Clone, Copy)]
pub struct SineField<const D: usize> {
    a: [Real; 3],
    b: [Vector<D>; 3],
    c: [Real; 3],
}

impl<const D: usize> SineField<D> {
    /// The field used by the convergence study (a few wavelengths per unit, all components
    /// coupled).
    pub fn standard() -> Self {
        let mut b = [Vector::<D>::zeros(); 3];
        let dirs = [[2.1, 1.3, 0.7], [-1.1, 2.4, 1.2], [0.9, -0.8, 2.2]];
        for k in 0..3 {
            for j in 0..D {
                b[k][j] = dirs[k][j];
            }
        }
        Self { a: [0.05, 0.04, 0.03], b, c: [0.3, 1.1, -0.4] }
    }
    /// `u(x)`.
    pub fn value(&self, x: &Point<D>) -> Vector<D> {
        Vector::<D>::from_fn(|k, _| self.a[k] * (self.b[k].dot(x) + self.c[k]).sin())
    }
    /// `∇u(x)`, `(k, j) = ∂_j u_k`.
    pub fn gradient(&self, x: &Point<D>) -> Tensor<D> {
        Tensor::<D>::from_fn(|k, j| self.a[k] * (self.b[k].dot(x) + self.c[k]).cos() * self.b[k][j])
    }
    /// `∂_j ∇u`: the tensor `(k, l) ↦ ∂_j ∂_l u_k`.
    pub fn gradient_derivative(&self, x: &Point<D>, j: usize) -> Tensor<D> {
        Tensor::<D>::from_fn(|k, l| {
            -self.a[k] * (self.b[k].dot(x) + self.c[k]).sin() * self.b[k][l] * self.b[k][j]
        })
    }
    /// Voigt stress `C e(u)` at `x`.
    pub fn stress(&self, c: &DMatrix<Real>, x: &Point<D>) -> Tensor<D> {
        let e = nalgebra::DVector::from_vec(voigt_strain::<D>(&self.gradient(x)));
        stress_tensor::<D>((c * e).as_slice())
    }
    /// `−div (C e(u))` at `x`, for a constant `C`.
    pub fn body_force(&self, c: &DMatrix<Real>, x: &Point<D>) -> Vector<D> {
        let mut f = Vector::<D>::zeros();
        for j in 0..D {
            let de = nalgebra::DVector::from_vec(voigt_strain::<D>(&self.gradient_derivative(x, j)));
            let ds = stress_tensor::<D>((c * de).as_slice());
            for i in 0..D {
                f[i] -= ds[(i, j)];
            }
        }
        f
    }
}

/// One row of a convergence table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConvergenceRow {
    /// Cells per unit length along x.
    pub n: usize,
    /// Mesh size (longest edge).
    pub h: Real,
    /// Reduced unknowns.
    pub dofs: usize,
    /// Relative energy-norm error `‖u − u_h‖_a / ‖u‖_a`.
    pub energy_error: Real,
    /// Relative `L²` error.
    pub l2_error: Real,
    /// Wall time of assembly + factorisation + solve (s).
    pub solve_s: Real,
}

/// Observed convergence rate between consecutive rows: `log(e_i/e_{i+1}) / log(h_i/h_{i+1})`.
pub fn rates(rows: &[ConvergenceRow], error: impl Fn(&ConvergenceRow) -> Real) -> Vec<Real> {
    rows.windows(2).map(|w| (error(&w[0]) / error(&w[1])).ln() / (w[0].h / w[1].h).ln()).collect()
}

/// Least-squares slope of `log e` against `log h` over all rows.
pub fn fitted_rate(rows: &[ConvergenceRow], error: impl Fn(&ConvergenceRow) -> Real) -> Real {
    let pts: Vec<(Real, Real)> = rows.iter().map(|r| (r.h.ln(), error(r).ln())).collect();
    let n = pts.len() as Real;
    let mx = pts.iter().map(|p| p.0).sum::<Real>() / n;
    let my = pts.iter().map(|p| p.1).sum::<Real>() / n;
    let sxy: Real = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: Real = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// The isotropic material of the left body (E = 1, ν = 0.3; plane strain in 2D).
fn left_material<const D: usize>() -> Result<LinearElastic<D>, FemError> {
    let c = if D == 2 {
        plane_strain(1.0, 0.3)?.stiffness().clone()
    } else {
        isotropic(1.0, 0.3)?.stiffness().clone()
    };
    Ok(anisotropic::<D>(c)?)
}

/// The anisotropic material of the right body: a transversely isotropic material with a tilted
/// axis, handed over as a general (fully populated) Voigt matrix.
fn right_material<const D: usize>() -> Result<LinearElastic<D>, FemError> {
    let p = TransverseIsotropy { e_p: 1.0, nu_p: 0.25, e_a: 4.0, nu_ap: 0.3, g_a: 0.6 };
    let c = if D == 2 {
        transversely_isotropic_plane_strain(p, Vector2::new(0.8, 0.6))?.stiffness().clone()
    } else {
        transversely_isotropic(p, Vector3::new(0.6, 0.48, 0.64))?.stiffness().clone()
    };
    Ok(anisotropic::<D>(c)?)
}

fn mesh_error(body: &str) -> impl Fn(synovia_mesh::MeshError) -> FemError + '_ {
    move |source| FemError::Mesh { body: body.to_string(), source }
}

/// Calls `f(∇u_h, x, u_h(x), w |T|)` at every point of `rule` in every cell of `mesh`, for the
/// P1 field of nodal values `u` (the error integrals of the convergence studies).
fn for_each_quadrature_point<const D: usize>(
    mesh: &Mesh<D>,
    u: &[Vector<D>],
    rule: &QuadratureRule,
    mut f: impl FnMut(&Tensor<D>, Point<D>, Vector<D>, Real),
) -> Result<(), FemError> {
    let mut ue = vec![0.0; D * (D + 1)];
    for cell in 0..mesh.n_cells() {
        let pts = mesh.cell_points(cell);
        let geo = SimplexGeometry::<D>::new(&pts)
            .ok_or_else(|| FemError::InvalidParameter("degenerate cell".into()))?;
        for (a, &nd) in mesh.cell(cell).iter().enumerate() {
            for i in 0..D {
                ue[D * a + i] = u[nd][i];
            }
        }
        let grad_h = geo.displacement_gradient(&ue);
        for (lam, w) in rule.barycentric.iter().zip(&rule.weights) {
            let mut x = Point::<D>::zeros();
            let mut uh = Vector::<D>::zeros();
            for a in 0..=D {
                x += pts[a] * lam[a];
                for i in 0..D {
                    uh[i] += lam[a] * ue[D * a + i];
                }
            }
            f(&grad_h, x, uh, w * geo.measure);
        }
    }
    Ok(())
}

/// Solves the bonded two-body manufactured problem in dimension `D` with `n` cells per unit
/// length, and measures the errors.
pub fn bonded_mms<const D: usize>(n: usize) -> Result<ConvergenceRow, FemError> {
    let half = (n / 2).max(1);
    let (left, right): (Mesh<D>, Mesh<D>) = if D == 2 {
        let l = rectangle(0.0, 0.5, 0.0, 1.0, half, n, Grading::Uniform, Grading::Uniform)
            .map_err(mesh_error("iso"))?;
        let r = rectangle(0.5, 1.0, 0.0, 1.0, half, n, Grading::Uniform, Grading::Uniform)
            .map_err(mesh_error("aniso"))?;
        (l.recast::<D>().map_err(mesh_error("iso"))?, r.recast::<D>().map_err(mesh_error("aniso"))?)
    } else {
        let g = [Grading::Uniform; 3];
        let l = box_mesh([0.0, 0.0, 0.0], [0.5, 1.0, 1.0], [half, n, n], g).map_err(mesh_error("iso"))?;
        let r = box_mesh([0.5, 0.0, 0.0], [1.0, 1.0, 1.0], [half, n, n], g).map_err(mesh_error("aniso"))?;
        (l.recast::<D>().map_err(mesh_error("iso"))?, r.recast::<D>().map_err(mesh_error("aniso"))?)
    };
    let sides: Vec<&str> =
        if D == 2 { vec!["bottom", "top"] } else { vec!["bottom", "top", "front", "back"] };
    let mut left = left;
    let mut right = right;
    left.set_part_kind("left", BoundaryKind::Prescribed).map_err(mesh_error("iso"))?;
    for p in &sides {
        left.set_part_kind(p, BoundaryKind::Prescribed).map_err(mesh_error("iso"))?;
        right.set_part_kind(p, BoundaryKind::Prescribed).map_err(mesh_error("aniso"))?;
    }
    right.remove_boundary_part("left").map_err(mesh_error("aniso"))?;
    right
        .add_boundary_part("interface", BoundaryKind::TractionFree, |x, _| (x[0] - 0.5).abs() < 1e-12)
        .map_err(mesh_error("aniso"))?;
    left.set_part_kind("right", BoundaryKind::Traction).map_err(mesh_error("iso"))?;
    right.set_part_kind("right", BoundaryKind::Traction).map_err(mesh_error("aniso"))?;

    let ml = left_material::<D>()?;
    let mr = right_material::<D>()?;
    let (cl, cr) = (ml.stiffness().clone(), mr.stiffness().clone());
    let exact = SineField::<D>::standard();

    let mut model = Model::<D>::new();
    let bl = model.add_body("iso", left, Arc::new(ml))?;
    let br = model.add_body("aniso", right, Arc::new(mr))?;
    model.prescribe(bl, "left", move |x, _| exact.value(x))?;
    for p in &sides {
        model.prescribe(bl, p, move |x, _| exact.value(x))?;
        model.prescribe(br, p, move |x, _| exact.value(x))?;
    }
    let (c1, c2) = (cl.clone(), cr.clone());
    model.body_force(bl, move |x, _| exact.body_force(&c1, x))?;
    model.body_force(br, move |x, _| exact.body_force(&c2, x))?;
    let c3 = cr.clone();
    model.traction(br, "right", move |x, nrm, _| exact.stress(&c3, x) * nrm)?;
    let (c4, c5) = (cl.clone(), cr.clone());
    model.traction(bl, "right", move |x, nrm, _| (exact.stress(&c4, x) - exact.stress(&c5, x)) * nrm)?;
    model.tie(bl, "right", br, "interface")?;

    let t0 = std::time::Instant::now();
    let mut solver = ElasticSolver::new(&model, ElasticParams::default().with_load_degree(4))?;
    let sol = solver.solve(&model, 0.0)?;
    let solve_s = t0.elapsed().as_secs_f64();

    // errors by a degree-4 rule
    let rule = QuadratureRule::simplex(D, 4)?;
    let (mut e_en, mut n_en, mut e_l2, mut n_l2) = (0.0, 0.0, 0.0, 0.0);
    let mut h: Real = 0.0;
    for (bi, body) in model.bodies().iter().enumerate() {
        let c = if bi == 0 { &cl } else { &cr };
        h = h.max(body.mesh.max_edge_length());
        for_each_quadrature_point(&body.mesh, &sol.displacement[bi], &rule, |grad_h, x, uh, wt| {
            let eh = nalgebra::DVector::from_vec(voigt_strain::<D>(grad_h));
            let ex = exact.value(&x);
            let ee = nalgebra::DVector::from_vec(voigt_strain::<D>(&exact.gradient(&x)));
            let de = &ee - &eh;
            e_en += wt * de.dot(&(c * &de));
            n_en += wt * ee.dot(&(c * &ee));
            e_l2 += wt * (ex - uh).norm_squared();
            n_l2 += wt * ex.norm_squared();
        })?;
    }
    Ok(ConvergenceRow {
        n,
        h,
        dofs: solver.info().n_dofs,
        energy_error: (e_en / n_en).sqrt(),
        l2_error: (e_l2 / n_l2).sqrt(),
        solve_s,
    })
}

/// Keeps the material trait in scope for downstream docs.
#[doc(hidden)]
pub fn _material_name<const D: usize>(m: &dyn Material<D>) -> String {
    m.name()
}

/// One row of the finite-strain convergence table ([`finite_strain_mms`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FiniteStrainRow {
    /// The table row: relative `H¹`-seminorm ("energy") and `L²` errors of the displacement.
    pub row: ConvergenceRow,
    /// Largest `‖∇u‖` of the exact field at the quadrature points (the strain level).
    pub max_gradient: Real,
    /// Newton iterations of the last load level.
    pub newton_iterations: usize,
    /// Final relative equilibrium residual.
    pub residual: Real,
}

/// Manufactured finite-strain solution (docs/model.md §2.3, §8): on `[0, 1]^D` a compressible
/// neo-Hookean body (`λ = 1.5`, `μ = 1`; 2D plane strain) in total Lagrangian kinematics with
/// the exact displacement `u = s · SineField::standard()` (`s = 2`: `‖∇u‖` up to ≈ 0.3),
/// Dirichlet data `u` on the whole boundary and the body force `b = −Div P(F)`,
/// `P = F S(E)`, `F = I + ∇u` — the divergence by central differences of `P` along `∂F/∂X_J`
/// (step `1e-6`, independent of the element tangent). Loaded in two levels (`u` and `b` scaled
/// with the time) and solved by [`synovia::nonlinear::NonlinearContact`]. P1 converges with
/// rate 1 in the `H¹` seminorm and 2 in `L²`.
///
/// # Errors
/// Mesh, model and solve errors (as [`FemError::InvalidParameter`] for the nonlinear solve).
pub fn finite_strain_mms<const D: usize>(n: usize) -> Result<FiniteStrainRow, FemError> {
    use synovia::nonlinear::{NewtonParams, NonlinearContact};
    use synovia_fem::Kinematics;
    use synovia_material::NeoHookean;
    let mesh: Mesh<D> = if D == 2 {
        rectangle(0.0, 1.0, 0.0, 1.0, n, n, Grading::Uniform, Grading::Uniform)
            .map_err(mesh_error("block"))?
            .recast::<D>()
            .map_err(mesh_error("block"))?
    } else {
        box_mesh([0.0; 3], [1.0; 3], [n, n, n], [Grading::Uniform; 3])
            .map_err(mesh_error("block"))?
            .recast::<D>()
            .map_err(mesh_error("block"))?
    };
    let mut mesh = mesh;
    let faces: Vec<String> = mesh.boundary_parts().iter().map(|p| p.name().to_string()).collect();
    for p in &faces {
        mesh.set_part_kind(p, BoundaryKind::Prescribed).map_err(mesh_error("block"))?;
    }
    let law = Arc::new(synovia_material::Hyperelastic::new(NeoHookean::from_lame(1.5, 1.0)?));
    let scale = 2.0;
    let exact = SineField::<D>::standard();
    let first_piola = {
        let law = law.clone();
        move |f: &Tensor<D>| -> Tensor<D> {
            let e = (f.transpose() * f - Tensor::<D>::identity()) * 0.5;
            let ev: Vec<Real> = if D == 2 {
                vec![e[(0, 0)], e[(1, 1)], 2.0 * e[(0, 1)]]
            } else {
                vec![e[(0, 0)], e[(1, 1)], e[(2, 2)], 2.0 * e[(1, 2)], 2.0 * e[(0, 2)], 2.0 * e[(0, 1)]]
            };
            let s = Material::<D>::stress(law.as_ref(), &nalgebra::DVector::from_vec(ev));
            f * stress_tensor::<D>(s.as_slice())
        }
    };
    let mut model = Model::<D>::new();
    let b = model.add_body("block", mesh, law.clone())?;
    for p in &faces {
        model.prescribe(b, p, move |x, t| exact.value(x) * (scale * t))?;
    }
    model.body_force(b, move |x, t| {
        let s = scale * t;
        let f = Tensor::<D>::identity() + exact.gradient(x) * s;
        let h = 1e-6;
        let mut out = Vector::<D>::zeros();
        for j in 0..D {
            let df = exact.gradient_derivative(x, j) * s;
            let dp = (first_piola(&(f + df * h)) - first_piola(&(f - df * h))) / (2.0 * h);
            for i in 0..D {
                out[i] -= dp[(i, j)];
            }
        }
        out
    })?;
    let t0 = std::time::Instant::now();
    let params = NewtonParams::default().with_tolerance(1e-11).with_load_degree(4);
    let invalid = |e: synovia::nonlinear::NonlinearError| FemError::InvalidParameter(e.to_string());
    let mut nl = NonlinearContact::new(
        &model,
        &[],
        &[Kinematics::FiniteStrain],
        ElasticParams::default().with_load_degree(4),
        params,
    )
    .map_err(invalid)?;
    let results =
        nl.run(&model, &[0.5, 1.0], &synovia::pdas::Pdas::default(), |_| Ok(())).map_err(invalid)?;
    let last = results.last().ok_or_else(|| FemError::InvalidParameter("no level solved".into()))?;
    let solve_s = t0.elapsed().as_secs_f64();
    let u = &last.contact.displacement[0];
    let body = &model.bodies()[0];
    let rule = QuadratureRule::simplex(D, 4)?;
    let (mut e_h1, mut n_h1, mut e_l2, mut n_l2, mut max_gradient) = (0.0, 0.0, 0.0, 0.0, 0.0f64);
    for_each_quadrature_point(&body.mesh, u, &rule, |grad_h, x, uh, wt| {
        let ex = exact.value(&x) * scale;
        let ge = exact.gradient(&x) * scale;
        max_gradient = max_gradient.max(ge.norm());
        e_h1 += wt * (ge - grad_h).norm_squared();
        n_h1 += wt * ge.norm_squared();
        e_l2 += wt * (ex - uh).norm_squared();
        n_l2 += wt * ex.norm_squared();
    })?;
    Ok(FiniteStrainRow {
        row: ConvergenceRow {
            n,
            h: body.mesh.max_edge_length(),
            dofs: nl.dofs().n_dofs(),
            energy_error: (e_h1 / n_h1).sqrt(),
            l2_error: (e_l2 / n_l2).sqrt(),
            solve_s,
        },
        max_gradient,
        newton_iterations: last.report.iterations.len(),
        residual: last.report.residual(),
    })
}
