//! Load histories from Python: constants, NumPy tables `(t, h)`, Python callables `h(t)` and
//! settable [`PyParameter`]s.

use std::sync::Arc;

use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use synovia::prelude::{LoadHistory, PiecewiseLinear, SharedValue};

use crate::error::{err, msg, set_callback_error};

/// A settable scalar (`synovia.Parameter`): a load history whose value is set from Python
/// between solves (the navigation use of a `Session`: change a load or a prescribed
/// displacement without refactorising). `h(t)` is the current value for every `t`.
#[pyclass(name = "Parameter", module = "synovia", frozen)]
#[derive(Debug, Clone)]
pub struct PyParameter {
    pub(crate) value: SharedValue,
}

#[pymethods]
impl PyParameter {
    /// A parameter with the initial value `value`.
    #[new]
    #[pyo3(signature = (value = 0.0))]
    fn new(value: f64) -> Self {
        Self { value: SharedValue::new(value) }
    }
    /// Sets the value (read by the next solve).
    fn set(&self, value: f64) -> PyResult<()> {
        if !value.is_finite() {
            return Err(msg(format!("parameter value must be finite, got {value}")));
        }
        self.value.set(value);
        Ok(())
    }
    /// The current value.
    fn get(&self) -> f64 {
        self.value.get()
    }
    /// The current value.
    #[getter]
    fn value(&self) -> f64 {
        self.value.get()
    }
    fn __float__(&self) -> f64 {
        self.value.get()
    }
    fn __repr__(&self) -> String {
        format!("Parameter({})", self.value.get())
    }
}

/// A Python callable `h(t) -> float`. An exception (or a non-float return) is recorded
/// ([`set_callback_error`]) and the value is `NaN`.
#[derive(Debug)]
pub struct PyCallableHistory(pub Py<PyAny>);

impl LoadHistory for PyCallableHistory {
    fn value(&self, t: f64) -> f64 {
        Python::with_gil(|py| match self.0.call1(py, (t,)).and_then(|v| v.extract::<f64>(py)) {
            Ok(v) => v,
            Err(e) => {
                set_callback_error(e);
                f64::NAN
            }
        })
    }
}

/// Any load history (shared, so it can be cloned into closures).
#[derive(Debug, Clone)]
pub struct AnyHistory(pub Arc<dyn LoadHistory>);

impl LoadHistory for AnyHistory {
    fn value(&self, t: f64) -> f64 {
        self.0.value(t)
    }
}

#[derive(Debug)]
struct ConstantOne(f64);

impl LoadHistory for ConstantOne {
    fn value(&self, _t: f64) -> f64 {
        self.0
    }
}

/// The history of a Python argument: `None` (1 at every time), a number (that constant), a
/// `Parameter`, an `(n, 2)` table of `(t, h)` rows (piecewise linear, constant beyond its
/// ends) or a callable `h(t)`.
pub fn history(obj: Option<&Bound<'_, PyAny>>) -> PyResult<AnyHistory> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(AnyHistory(Arc::new(ConstantOne(1.0))));
    };
    if let Ok(p) = obj.downcast::<PyParameter>() {
        return Ok(AnyHistory(Arc::new(p.get().value.clone())));
    }
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(AnyHistory(Arc::new(ConstantOne(v))));
    }
    if obj.is_callable() {
        return Ok(AnyHistory(Arc::new(PyCallableHistory(obj.clone().unbind()))));
    }
    let table = table(obj)?;
    Ok(AnyHistory(Arc::new(table)))
}

/// A piecewise-linear history from an `(n, 2)` array-like of `(t, h)` rows.
pub fn table(obj: &Bound<'_, PyAny>) -> PyResult<PiecewiseLinear> {
    let np = obj.py().import_bound("numpy")?;
    let arr = np.call_method1("asarray", (obj, "float64"))?;
    let arr: PyReadonlyArray2<f64> = arr.extract().map_err(|_| {
        msg("a load history must be None, a number, a synovia.Parameter, a callable h(t) or an (n, 2) table of (t, h) rows")
    })?;
    let a = arr.as_array();
    if a.ncols() != 2 {
        return Err(msg(format!("a history table must have 2 columns (t, h), got {}", a.ncols())));
    }
    let rows: Vec<(f64, f64)> = a.rows().into_iter().map(|r| (r[0], r[1])).collect();
    PiecewiseLinear::new(&rows).map_err(err)
}
