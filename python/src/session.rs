//! `synovia.Session`: the re-solve session of a model (factorise once, solve again with new
//! loads), its solves with the GIL released.
//!
//! A [`JointSession`](synovia::session::JointSession) borrows its
//! [`JointModel`](synovia::builder::JointModel) and holds the contact solver (not `Send`), so
//! it lives on a worker thread of its own that owns a shared reference to the model: the
//! Python object sends it commands over a channel and waits for the reply with the GIL
//! released. Load histories that are Python callables take the GIL on the worker thread while
//! the caller waits without it.

use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use synovia::builder::JointModel;
use synovia::session::{JointSession, SolveReport};

use crate::error::{msg, solved, take_callback_error};
use crate::model::Joint;
use crate::result::{contact_rows, finish, nodal_pressure, PyRunResult, RunData};
use crate::rigid::{self, PoseInputs};

#[derive(Debug, Clone, Copy)]
enum Cmd {
    Static(f64),
    Step(f64),
    Reset,
    Close,
}

#[derive(Debug, Clone)]
struct Info {
    setup_s: f64,
    n_dofs: usize,
    factor_nnz: usize,
    contact_nodes: usize,
    solver: String,
    /// Numeric factorisations done by the session (updated after each solve).
    factorizations: usize,
}

#[derive(Debug)]
enum Reply {
    Started(Info),
    /// A solve's results and the session's numeric factorisations so far.
    Solved(Box<RunData>, usize),
    Done,
}

type Message = Result<Reply, String>;

fn snapshot<const D: usize>(
    s: &JointSession<'_, D>,
    report: SolveReport,
    info: &Info,
) -> Result<RunData, String> {
    let model = s.model();
    let mut data = RunData { warm_started: Some(report.warm_started), ..Default::default() };
    if let Some(result) = s.result() {
        data.pressure = vec![nodal_pressure(model, s.geometry(), result)];
        data.contact = contact_rows(s.geometry(), result);
        if !s.geometry().is_empty() {
            data.kkt = Some(result.kkt);
        }
        // stresses with the bodies' kinematics (finite strain for a nonlinear model's session)
        finish(&mut data, model, &result.displacement, s.kinematics())?;
    }
    data.records = s.record().cloned().into_iter().collect();
    data.n_dofs = info.n_dofs;
    data.contact_nodes = info.contact_nodes;
    data.solver =
        s.record().map(|r| r.solver.clone()).filter(|n| !n.is_empty()).unwrap_or_else(|| info.solver.clone());
    data.setup_s = info.setup_s;
    data.total_s = report.seconds;
    Ok(data)
}

fn worker<const D: usize>(joint: Arc<JointModel<D>>, rx: Receiver<Cmd>, tx: Sender<Message>) {
    let mut session = match joint.prepare() {
        Ok(s) => s,
        Err(e) => {
            let _ = tx.send(Err(e.to_string()));
            return;
        }
    };
    let ei = session.elastic_info();
    let info = Info {
        setup_s: session.setup_s(),
        n_dofs: ei.n_dofs,
        factor_nnz: ei.factor_nnz,
        contact_nodes: session.geometry().len(),
        solver: session.solver_name().to_string(),
        factorizations: session.factorizations(),
    };
    if tx.send(Ok(Reply::Started(info.clone()))).is_err() {
        return;
    }
    while let Ok(cmd) = rx.recv() {
        let r = match cmd {
            Cmd::Static(t) => session.solve_static(t),
            Cmd::Step(t) => session.step(t),
            Cmd::Reset => {
                session.reset();
                if tx.send(Ok(Reply::Done)).is_err() {
                    break;
                }
                continue;
            }
            Cmd::Close => break,
        };
        let reply = r
            .map_err(|e| e.to_string())
            .and_then(|rep| snapshot(&session, rep, &info))
            .map(|d| Reply::Solved(Box::new(d), session.factorizations()));
        if tx.send(reply).is_err() {
            break;
        }
    }
}

/// A prepared model (`synovia.Session`, from `Model.prepare()`): factorised once; each
/// `solve_static(t)` / `step(t)` solves it again with the current load values (set
/// `synovia.Parameter`s, change what callables read, or pass a new time), warm-started,
/// without refactorising. Solves release the GIL. Close it (or use it as a context manager)
/// to change the model again.
#[pyclass(name = "Session", module = "synovia")]
#[derive(Debug)]
pub struct PySession {
    tx: Sender<Cmd>,
    rx: Mutex<Receiver<Message>>,
    handle: Option<JoinHandle<()>>,
    info: Info,
    solves: usize,
    /// The pose inputs of the model's rigid bodies (shared with the model: set between solves).
    poses: PoseInputs,
}

impl PySession {
    /// Starts the worker thread of a session of `joint` and waits (GIL released) until it has
    /// factorised the model.
    pub(crate) fn open(py: Python<'_>, joint: Joint, poses: PoseInputs) -> PyResult<Self> {
        let (tx, worker_rx) = channel::<Cmd>();
        let (worker_tx, rx) = channel::<Message>();
        take_callback_error();
        let spawned = std::thread::Builder::new().name("synovia-session".into()).spawn(move || match joint {
            Joint::D2(j) => worker(j, worker_rx, worker_tx),
            Joint::D3(j) => worker(j, worker_rx, worker_tx),
        });
        let handle = spawned.map_err(|e| msg(format!("cannot start the session thread: {e}")))?;
        let (rx, first) = py.allow_threads(move || {
            let first = rx.recv().map_err(|_| "the session thread ended".to_string());
            (rx, first)
        });
        let info = match solved(first.and_then(|m| m))? {
            Reply::Started(info) => info,
            _ => return Err(msg("unexpected reply of the session thread")),
        };
        Ok(Self { tx, rx: Mutex::new(rx), handle: Some(handle), info, solves: 0, poses })
    }

    fn request(&self, py: Python<'_>, cmd: Cmd) -> PyResult<Reply> {
        if self.handle.is_none() {
            return Err(msg("the session is closed"));
        }
        take_callback_error();
        let reply = py.allow_threads(|| -> Result<Reply, String> {
            self.tx.send(cmd).map_err(|_| "the session thread ended".to_string())?;
            let rx = self.rx.lock().map_err(|_| "the session is broken (a solve panicked)".to_string())?;
            rx.recv().map_err(|_| "the session thread ended".to_string())?
        });
        solved(reply)
    }

    fn solve(&mut self, py: Python<'_>, cmd: Cmd) -> PyResult<PyRunResult> {
        match self.request(py, cmd)? {
            Reply::Solved(data, factorizations) => {
                self.solves += 1;
                self.info.factorizations = factorizations;
                Ok(PyRunResult { data: *data })
            }
            _ => Err(msg("unexpected reply of the session thread")),
        }
    }
}

#[pymethods]
impl PySession {
    /// Solves the static problem at `t` with the current loads, warm-started from the last
    /// solution (equals `Model.run_static(t)` to the solver's tolerance); starts a new
    /// quasi-static sequence. Returns a one-step `RunResult`.
    #[pyo3(signature = (t = 0.0))]
    fn solve_static(&mut self, py: Python<'_>, t: f64) -> PyResult<PyRunResult> {
        self.solve(py, Cmd::Static(t))
    }
    /// One level of the quasi-static scheme at `t` (later than the last solve): a sequence
    /// of `step` calls is `Model.run_quasistatic` one frame at a time.
    fn step(&mut self, py: Python<'_>, t: f64) -> PyResult<PyRunResult> {
        self.solve(py, Cmd::Step(t))
    }
    /// Sets the pose of rigid body `rigid` (added with `pose_input=True`) for the next
    /// solves — a navigation tracker's frame: the `translation` of its reference point and
    /// its rotation, in 3D one of `quaternion=[w, x, y, z]` (normalised), `axis=[x, y, z]`
    /// with `angle` (rad, right-handed), or `rotation` (a 3 × 3 rotation matrix to 1e-9); no
    /// rotation: the identity. 2D: `translation` `[x, y]` and `angle`. Then `solve_static(t)`
    /// (warm-started from the last solution) or `step(t)` (the next quasi-static level,
    /// friction measured relative to the moving body) solves at the new pose without
    /// refactorising. Invalid input (shapes, non-finite values, a zero quaternion or axis, a
    /// matrix that is not a rotation) raises `SynoviaError` and keeps the previous pose.
    #[pyo3(signature = (rigid, translation, quaternion = None, axis = None, angle = None, rotation = None))]
    #[allow(clippy::too_many_arguments)]
    fn set_pose(
        &self,
        rigid: &str,
        translation: &Bound<'_, PyAny>,
        quaternion: Option<&Bound<'_, PyAny>>,
        axis: Option<&Bound<'_, PyAny>>,
        angle: Option<f64>,
        rotation: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        if self.handle.is_none() {
            return Err(msg("the session is closed"));
        }
        rigid::set_pose(&self.poses, rigid, translation, quaternion, axis, angle, rotation)
    }
    /// Forgets the last solution and friction state (the factorisation is kept).
    fn reset(&mut self, py: Python<'_>) -> PyResult<()> {
        match self.request(py, Cmd::Reset)? {
            Reply::Done => Ok(()),
            _ => Err(msg("unexpected reply of the session thread")),
        }
    }
    /// Ends the session's thread and releases the model (it can be changed again).
    fn close(&mut self, py: Python<'_>) -> PyResult<()> {
        if let Some(h) = self.handle.take() {
            let _ = self.tx.send(Cmd::Close);
            py.allow_threads(|| h.join()).map_err(|_| msg("the session thread panicked"))?;
        }
        Ok(())
    }
    /// Whether the session is closed.
    #[getter]
    fn closed(&self) -> bool {
        self.handle.is_none()
    }
    /// Set-up time (validation, assembly, factorisation, contact geometry), s.
    #[getter]
    fn setup_s(&self) -> f64 {
        self.info.setup_s
    }
    /// Reduced unknowns.
    #[getter]
    fn n_dofs(&self) -> usize {
        self.info.n_dofs
    }
    /// Contact nodes of all pairs.
    #[getter]
    fn contact_nodes(&self) -> usize {
        self.info.contact_nodes
    }
    /// Numeric factorisations done by the session: for a linear model always 1 (of the
    /// stiffness, when it was prepared); for a nonlinear model the tangent factorisations of
    /// the Newton iterations of its solves so far.
    #[getter]
    fn factorizations(&self) -> usize {
        self.info.factorizations
    }
    /// Solves done so far.
    #[getter]
    fn solves(&self) -> usize {
        self.solves
    }
    /// The factorisation's figures: `n_dofs`, `factor_nnz`, `setup_s`, `contact_nodes`,
    /// `solver`.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new_bound(py);
        d.set_item("n_dofs", self.info.n_dofs)?;
        d.set_item("factor_nnz", self.info.factor_nnz)?;
        d.set_item("setup_s", self.info.setup_s)?;
        d.set_item("contact_nodes", self.info.contact_nodes)?;
        d.set_item("solver", &self.info.solver)?;
        Ok(d)
    }
    fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }
    #[pyo3(signature = (*_args))]
    fn __exit__(&mut self, py: Python<'_>, _args: &Bound<'_, pyo3::types::PyTuple>) -> PyResult<bool> {
        self.close(py)?;
        Ok(false)
    }
    fn __repr__(&self) -> String {
        format!(
            "Session(n_dofs={}, contact_nodes={}, solves={}, closed={})",
            self.info.n_dofs,
            self.info.contact_nodes,
            self.solves,
            self.handle.is_none()
        )
    }
}

impl Drop for PySession {
    fn drop(&mut self) {
        // the thread is idle between requests: it ends on `Close` (or when the channel
        // closes) and drops its reference to the model; it is not joined here, where the
        // GIL may be held
        let _ = self.tx.send(Cmd::Close);
    }
}
