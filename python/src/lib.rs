//! # synovia-python
//!
//! The Python extension module `synovia._synovia` (PyO3, abi3): the classes and functions the
//! pure-Python package `synovia` (python/synovia/) re-exports.
//!
//! * [`model::PyModel`] (`synovia.Model`): a [`JointModel`](synovia::builder::JointModel) in 2D
//!   or 3D built from NumPy arrays (or a TOML scenario file), with materials, boundary
//!   conditions by part name with load histories (constants, NumPy tables, Python callables,
//!   settable [`history::PyParameter`]s), contact pairs of every discretisation, the solver by
//!   name, and static, quasi-static and dynamic runs;
//! * [`result::PyRunResult`] (`synovia.RunResult`): records, displacements, stresses, contact
//!   pressures and KKT residuals as NumPy arrays;
//! * [`session::PySession`] (`synovia.Session`): the re-solve session (factorise once, solve
//!   again with new loads), its solves run with the GIL released;
//! * [`rigid`]: rigid bodies with mixed control, rigid contact shapes (`synovia.Shape`),
//!   STL surfaces (`synovia.Surface`, `synovia.read_stl`) and the pose inputs of sessions;
//! * [`hertz`]: the Hertz verification problems of `synovia-models`.
//!
//! Every Rust error becomes a `synovia.SynoviaError` (a subclass of `Exception`) carrying the
//! Rust message; an exception raised by a Python callable during a solve is re-raised as is.

// pyo3 0.22's `#[pymethods]` / `#[pyfunction]` expansion converts every `PyResult` error with
// `.into()`, which clippy reports at each signature (fixed in pyo3 0.23)
#![allow(clippy::useless_conversion)]

use pyo3::prelude::*;

pub mod error;
pub mod hertz;
pub mod history;
pub mod model;
pub mod result;
pub mod rigid;
pub mod session;

pub use error::SynoviaError;

/// The version of the Rust crates (the `synovia` workspace version).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

#[pymodule]
fn _synovia(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", VERSION)?;
    m.add("SynoviaError", m.py().get_type_bound::<SynoviaError>())?;
    m.add("SOLVER_NAMES", synovia::solvers::SOLVER_NAMES.to_vec())?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<model::PyMaterial>()?;
    m.add_class::<history::PyParameter>()?;
    m.add_class::<result::PyRunResult>()?;
    m.add_class::<session::PySession>()?;
    m.add_class::<rigid::PySurface>()?;
    m.add_class::<rigid::PyShape>()?;
    m.add_function(wrap_pyfunction!(hertz::hertz2d, m)?)?;
    m.add_function(wrap_pyfunction!(hertz::hertz3d, m)?)?;
    m.add_function(wrap_pyfunction!(model::run_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(rigid::read_stl, m)?)?;
    Ok(())
}
