//! The Hertz verification problems of `synovia-models` (examples `hertz2d`, `hertz3d`).

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use synovia_models::hertz::{ContactRun, Hertz2d, Hertz3d};

use crate::error::{err, solved};

/// A [`ContactRun`] as a dict: every figure at full precision, `a_rel_err`, `p0_rel_err`,
/// `profile` (an `(n, 2)` array of `(r, Λ_n)`) and `json` (the JSON line the Rust examples
/// print, [`ContactRun::json`]).
pub fn run_dict<'py>(py: Python<'py>, r: &ContactRun) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new_bound(py);
    d.set_item("problem", &r.problem)?;
    d.set_item("level", r.level)?;
    d.set_item("h", r.h)?;
    d.set_item("dofs", r.dofs)?;
    d.set_item("contact_nodes", r.contact_nodes)?;
    d.set_item("active_nodes", r.active_nodes)?;
    d.set_item("solver", &r.solver)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("coarse_iterations", r.coarse_iterations)?;
    d.set_item("solve_s", r.solve_s)?;
    d.set_item("linear_solve_s", r.linear_solve_s)?;
    d.set_item("force", r.force)?;
    d.set_item("a", r.a)?;
    d.set_item("a_exact", r.a_exact)?;
    d.set_item("a_rel_err", r.a_rel_err())?;
    d.set_item("p0", r.p0)?;
    d.set_item("p0_exact", r.p0_exact)?;
    d.set_item("p0_rel_err", r.p0_rel_err())?;
    d.set_item("pressure_l2_err", r.pressure_l2_err)?;
    d.set_item("kkt", r.kkt)?;
    let flat: Vec<f64> = r.profile.iter().flat_map(|&(x, p)| [x, p]).collect();
    d.set_item("profile", PyArray1::from_vec_bound(py, flat).reshape([r.profile.len(), 2])?)?;
    d.set_item("json", r.json())?;
    Ok(d)
}

/// Runs `problem` with the solver called `solver` (checked before, so a bad name is an error
/// without a solve) with the GIL released, and returns its [`run_dict`].
fn solve_to_dict<'py>(
    py: Python<'py>,
    solver: &str,
    problem: impl FnOnce(
            &dyn synovia::contact_ops::ContactSolver,
        ) -> Result<ContactRun, synovia::contact_ops::ContactError>
        + Send,
) -> PyResult<Bound<'py, PyDict>> {
    let name = solver.to_string();
    synovia::solvers::by_name(&name).map_err(err)?;
    let r = py.allow_threads(move || {
        let s = synovia::solvers::by_name(&name)?;
        problem(s.as_ref())
    });
    run_dict(py, &solved(r)?)
}

/// 2D Hertz (plane strain): a half-disc of radius `radius` (`E = e1`, `ν = nu1`) pushed by
/// `push` at its flat top onto a rigid flat (`e2=None`) or a mirrored half-disc (`E = e2`,
/// `ν = nu2`), refined `levels` times toward the contact point, solved by `solver`. Returns the
/// figures of `synovia_models::hertz::hertz2d` as a dict (see `synovia.hertz2d`).
#[pyfunction]
#[pyo3(signature = (levels = 10, solver = "pdas", *, radius = 1.0, e1 = 1.0, nu1 = 0.3, e2 = None, nu2 = 0.3, push = 0.01, n = 8, refine_radius = 0.16, nested = true))]
#[allow(clippy::too_many_arguments)]
pub fn hertz2d<'py>(
    py: Python<'py>,
    levels: usize,
    solver: &str,
    radius: f64,
    e1: f64,
    nu1: f64,
    e2: Option<f64>,
    nu2: f64,
    push: f64,
    n: usize,
    refine_radius: f64,
    nested: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let p = Hertz2d { radius, e1, nu1, e2, nu2, push, n, levels, refine_radius, nested };
    solve_to_dict(py, solver, move |s| synovia_models::hertz::hertz2d(&p, s))
}

/// 3D Hertz: a hemisphere of radius `radius` (`E = e`, `ν = nu`) pushed by `push` onto a
/// rigid flat, refined `levels` times toward the pole, solved by `solver`. Returns the
/// figures of `synovia_models::hertz::hertz3d` as a dict.
#[pyfunction]
#[pyo3(signature = (levels = 12, solver = "pdas", *, radius = 1.0, e = 1.0, nu = 0.3, push = 0.01, n = 4, refine_radius = 0.15, nested = true))]
#[allow(clippy::too_many_arguments)]
pub fn hertz3d<'py>(
    py: Python<'py>,
    levels: usize,
    solver: &str,
    radius: f64,
    e: f64,
    nu: f64,
    push: f64,
    n: usize,
    refine_radius: f64,
    nested: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let p = Hertz3d { radius, e, nu, push, n, levels, refine_radius, nested };
    solve_to_dict(py, solver, move |s| synovia_models::hertz::hertz3d(&p, s))
}
