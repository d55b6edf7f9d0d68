"""Type stubs of the synovia Python package (the extension module synovia._synovia and the
pure-Python helpers)."""

import os
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
SOLVER_NAMES: List[str]

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
IndexArray = npt.NDArray[np.uint64]
BodyRef = Union[int, str]
PathLike = Union[str, "os.PathLike[str]"]
#: A load history: None (1 at every time), a number, a Parameter, an (n, 2) table of (t, h)
#: rows (piecewise linear, constant beyond its ends) or a callable h(t).
History = Union[None, float, "Parameter", ArrayLike, Callable[[float], float]]

class SynoviaError(Exception):
    """An error of the synovia library; the message is the Rust error's."""

class Parameter:
    """A settable scalar load history: h(t) is the current value for every t. Set it between
    the solves of a Session to change a load or a prescribed displacement without
    refactorising."""

    def __init__(self, value: float = 0.0) -> None: ...
    def set(self, value: float) -> None:
        """Sets the value (read by the next solve); must be finite."""
    def get(self) -> float:
        """The current value."""
    @property
    def value(self) -> float: ...
    def __float__(self) -> float: ...

class Material:
    """The material of a body, made by the static constructors."""

    @staticmethod
    def isotropic(E: float, nu: float) -> "Material":
        """Isotropic linear elasticity: 3D, or plane strain on a 2D body."""
    @staticmethod
    def plane_strain(E: float, nu: float) -> "Material":
        """Isotropic, plane strain (2D bodies only)."""
    @staticmethod
    def plane_stress(E: float, nu: float) -> "Material":
        """Isotropic, plane stress (2D bodies only)."""
    @staticmethod
    def anisotropic(C: ArrayLike) -> "Material":
        """Anisotropic elasticity from the Voigt stiffness (3 × 3 in 2D, 6 × 6 in 3D)."""
    @staticmethod
    def neo_hookean(E: float, nu: float) -> "Material":
        """Compressible neo-Hookean hyperelasticity with the small-strain E, nu (plane strain in 2D)."""
    @staticmethod
    def mooney_rivlin(c1: float, c2: float, lam: float) -> "Material":
        """Compressible Mooney–Rivlin hyperelasticity (c1, c2, volumetric lambda)."""

class Surface:
    """A triangle surface in 3D (e.g. from an STL file): the boundary of a rigid shape."""

    def __init__(self, vertices: ArrayLike, triangles: ArrayLike) -> None:
        """From (n, 3) vertices and (m, 3) vertex indices (right-hand rule gives the normal);
        checks finiteness, indices and non-degenerate triangles."""
    @property
    def vertices(self) -> FloatArray: ...
    @property
    def triangles(self) -> IndexArray: ...
    @property
    def area(self) -> float: ...
    @property
    def signed_volume(self) -> float:
        """Enclosed volume, positive for a closed surface with outward normals."""
    @property
    def bounding_box(self) -> Optional[Tuple[List[float], List[float]]]: ...
    @property
    def is_closed_solid(self) -> bool:
        """Closed, manifold, outward oriented and not crossing itself (Shape.surface(solid=True))."""
    def scaled(self, factor: float) -> "Surface":
        """Scaled about the origin (units: 1000 from m to mm)."""
    def __len__(self) -> int: ...

def read_stl(path: PathLike, scale: Optional[float] = None) -> Surface:
    """Reads an ASCII or binary STL file; `scale` multiplies the coordinates."""

class Shape:
    """A rigid contact shape: a fixed obstacle (Model.contact_obstacle) or the shape of a rigid
    body in its own frame (Model.contact_rigid_body). The signed distance is positive on the
    elastic body's side."""

    @staticmethod
    def plane(point: ArrayLike, normal: ArrayLike) -> "Shape":
        """Half-space bounded by the plane through `point` with outward `normal`."""
    @staticmethod
    def sphere(center: ArrayLike, radius: float, cavity: bool = False) -> "Shape":
        """Ball (cavity=False) or spherical cavity (cavity=True); a disc in 2D."""
    @staticmethod
    def cylinder(point: ArrayLike, axis: ArrayLike, radius: float, cavity: bool = False) -> "Shape":
        """Cylinder (3D)."""
    @staticmethod
    def surface(
        surface: Surface,
        solid: bool = True,
        subdivide: int = 0,
        crease_angle_deg: float = 30.0,
        fillet: float = 0.0,
        fillet_max_offset: Optional[float] = None,
    ) -> "Shape":
        """Bounded by a triangle surface (3D): solid=True needs a closed surface with outward
        normals (else SynoviaError), solid=False accepts an oriented open patch. subdivide=n
        (0-4) smooths a faceted surface by n levels of Loop subdivision, keeping edges whose
        facets meet at more than crease_angle_deg sharp. fillet=r rounds the concave edges by
        cylinders of radius r, each within fillet_max_offset of the faceted surface."""
    @staticmethod
    def stl(
        path: PathLike,
        scale: Optional[float] = None,
        solid: bool = True,
        subdivide: int = 0,
        crease_angle_deg: float = 30.0,
        fillet: float = 0.0,
        fillet_max_offset: Optional[float] = None,
    ) -> "Shape":
        """Shape.surface(read_stl(path, scale), solid, subdivide, crease_angle_deg, fillet,
        fillet_max_offset)."""
    def distance(self, x: ArrayLike) -> FloatArray:
        """Signed distance of points (n, D) in the shape's own frame."""

class RunResult:
    """The result of a run or of a session solve: records, NumPy fields, KKT residuals."""

    @property
    def dimension(self) -> int: ...
    @property
    def bodies(self) -> List[str]: ...
    @property
    def n_steps(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def times(self) -> FloatArray:
        """The time of each step, shape (n_steps,)."""
    @property
    def records(self) -> List[Dict[str, Any]]:
        """Per step: step, time, pairs (list of pair dicts), energies, iterations, step_s,
        solver, fallback, rigid (rigid-body states: dofs, reaction, force, moment, ...)."""
    def pairs(self, step: int = -1) -> Dict[str, Dict[str, Any]]:
        """{pair name: {force, normal_force, tangential_force, contact_area, peak_pressure,
        mean_pressure, stick_area, slip_area, moment, centre_of_pressure, sides}} of a step."""
    def rigid_bodies(self, step: int = -1) -> Dict[str, Dict[str, Any]]:
        """{rigid body name: {dofs, reaction, applied, force, moment, balance_error, solves}} of a
        step: coordinates q (lengths, radians), generalised reactions Q of the elastic bodies,
        applied generalised forces F (None where prescribed), resultant force and moment about
        the moved reference point."""
    def pair_history(self, pair: str, quantity: str) -> FloatArray:
        """One scalar figure of a pair over the steps, shape (n_steps,)."""
    def nodes(self, body: BodyRef) -> FloatArray:
        """Node coordinates, shape (n_nodes, D)."""
    def cells(self, body: BodyRef) -> IndexArray:
        """Cells, shape (n_cells, D + 1)."""
    def displacement(self, body: Optional[BodyRef] = None, step: Optional[int] = None) -> FloatArray:
        """Nodal displacements (n_nodes, D): the last step, or `step` with keep_steps=True."""
    def contact_pressure(self, body: Optional[BodyRef] = None, step: int = -1) -> FloatArray:
        """Nodal contact pressure Λ_n (0 away from contact nodes), shape (n_nodes,)."""
    def stress(self, body: Optional[BodyRef] = None, location: str = "node") -> FloatArray:
        """Voigt stress at the last step: "node" (n_nodes, nv) or "cell" (n_cells, nv);
        nv = 3 (σxx, σyy, σxy) in 2D, 6 (σxx, σyy, σzz, σyz, σxz, σxy) in 3D."""
    def von_mises(self, body: Optional[BodyRef] = None, location: str = "node") -> FloatArray:
        """Von Mises stress at nodes or per cell."""
    @property
    def strain_energy(self) -> List[float]:
        """Strain energy per body at the last step."""
    @property
    def contact(self) -> Dict[str, Any]:
        """Contact rows of the last step: pair (names), body, node, position (n, D), pressure."""
    @property
    def kkt(self) -> Optional[Dict[str, float]]:
        """KKT residuals of the last step (equilibrium, penetration, negative_pressure,
        complementarity, friction_bound, stick_slip, slip_direction, displacement_scale, max);
        None without contact pairs."""
    @property
    def n_dofs(self) -> int: ...
    @property
    def contact_nodes(self) -> int: ...
    @property
    def solver(self) -> str: ...
    @property
    def setup_s(self) -> float: ...
    @property
    def total_s(self) -> float: ...
    @property
    def warm_started(self) -> Optional[bool]:
        """Session solves: whether the solve was warm-started; None for runs."""
    def to_meshio(self, body: Optional[BodyRef] = None, step: int = -1) -> Any:
        """The body as a meshio.Mesh with displacement, contact_pressure, von_mises, stress."""

class Session:
    """A factorised model that solves again with new loads (Model.prepare()); solves release
    the GIL. Use as a context manager or close() it to change the model again."""

    def solve_static(self, t: float = 0.0) -> RunResult:
        """The static problem at t with the current loads, warm-started."""
    def step(self, t: float) -> RunResult:
        """One quasi-static level at t (later than the last solve)."""
    def set_pose(
        self,
        rigid: str,
        translation: ArrayLike,
        quaternion: Optional[ArrayLike] = None,
        axis: Optional[ArrayLike] = None,
        angle: Optional[float] = None,
        rotation: Optional[ArrayLike] = None,
    ) -> None:
        """Sets the pose of a rigid body added with pose_input=True for the next solves: the
        translation of its reference point and, in 3D, quaternion=[w, x, y, z] (normalised),
        axis with angle (rad), or a 3 × 3 rotation matrix (none: identity); in 2D, angle.
        Then solve_static(t) (warm-started) or step(t) (quasi-static, friction relative to the
        moving body) solves at that pose without refactorising. Bad input raises SynoviaError
        and keeps the previous pose."""
    def reset(self) -> None:
        """Forgets the last solution and friction state; keeps the factorisation."""
    def close(self) -> None:
        """Ends the session and releases the model."""
    @property
    def closed(self) -> bool: ...
    @property
    def setup_s(self) -> float: ...
    @property
    def n_dofs(self) -> int: ...
    @property
    def contact_nodes(self) -> int: ...
    @property
    def factorizations(self) -> int: ...
    @property
    def solves(self) -> int: ...
    @property
    def info(self) -> Dict[str, Any]: ...
    def __enter__(self) -> "Session": ...
    def __exit__(self, *args: Any) -> bool: ...

class Model:
    """A joint model in 2D or 3D: bodies from arrays / meshio / scenario files, materials,
    conditions by part name with load histories, contact pairs, solver, runs."""

    def __init__(self, dimension: int) -> None: ...
    @staticmethod
    def from_scenario(path: PathLike) -> "Model":
        """A model from a TOML scenario file (docs/scenario.md); run() runs its analysis."""
    @property
    def dimension(self) -> int: ...
    @property
    def name(self) -> Optional[str]: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def bodies(self) -> List[str]: ...
    @property
    def pairs(self) -> List[str]: ...
    @property
    def analysis(self) -> Optional[Dict[str, Any]]: ...
    @property
    def solver_name(self) -> str: ...
    def parts(self, body: BodyRef) -> List[str]: ...
    def nodes(self, body: BodyRef) -> FloatArray: ...
    def cells(self, body: BodyRef) -> IndexArray: ...
    def facets(self, body: BodyRef, part: str) -> IndexArray:
        """The facets (node indices, (k, D)) of a boundary part."""
    def add_body(
        self,
        name: str,
        nodes: ArrayLike,
        cells: ArrayLike,
        material: Material,
        parts: Optional[Mapping[str, ArrayLike]] = None,
    ) -> int:
        """Adds a body from (n, D) nodes, (m, D + 1) cells and {part: (k, D) facets}."""
    def add_meshio(self, name: str, mesh: Any, material: Material) -> int:
        """Adds a body from a meshio.Mesh (parts from cell_sets or gmsh:physical tags)."""
    def add_part(self, body: BodyRef, name: str, facets: ArrayLike) -> None: ...
    def add_part_where(self, body: BodyRef, name: str, select: Callable[[FloatArray, FloatArray], bool]) -> None:
        """A part of the boundary facets whose centroid x and outward normal n satisfy select(x, n)."""
    def clamp(self, body: BodyRef, part: str) -> None: ...
    def symmetry(self, body: BodyRef, part: str) -> None: ...
    def prescribe(
        self,
        body: BodyRef,
        part: str,
        value: ArrayLike,
        history: History = None,
        components: Optional[Sequence[int]] = None,
    ) -> None:
        """u(x, t) = h(t) value on a part (only `components` if given)."""
    def prescribe_field(
        self,
        body: BodyRef,
        part: str,
        field: Callable[[FloatArray, float], ArrayLike],
        components: Optional[Sequence[int]] = None,
    ) -> None: ...
    def traction(self, body: BodyRef, part: str, value: ArrayLike, history: History = None) -> None: ...
    def pressure(self, body: BodyRef, part: str, value: float, history: History = None) -> None: ...
    def body_force(self, body: BodyRef, value: ArrayLike, history: History = None) -> None: ...
    def tie(self, body_a: BodyRef, part_a: str, body_b: BodyRef, part_b: str) -> None: ...
    def set_kinematics(self, body: BodyRef, kinematics: str) -> None:
        """"small" (default) or "finite" (total Lagrangian; solved by the Newton iteration)."""
    def newton_params(
        self,
        *,
        tolerance: Optional[float] = None,
        max_iterations: Optional[int] = None,
        line_search: Optional[bool] = None,
        max_cutbacks: Optional[int] = None,
        tangent_reuse: Optional[float] = None,
        fresh_tangent: bool = False,
        geometry: Optional[str] = None,
        geometry_tolerance: Optional[float] = None,
        max_geometry_passes: Optional[int] = None,
        geometry_relaxation: Optional[float] = None,
        geometry_aitken: Optional[bool] = None,
        geometry_pass_tolerance: Optional[float] = None,
        settled_increment: Optional[float] = None,
    ) -> None:
        """The Newton iteration of nonlinear models (only the given parameters change):
        tangent_reuse=rho in (0, 1) for modified Newton, fresh_tangent=True for Newton's method,
        geometry "converged" / "per_level" / "reference", geometry_aitken for Aitken's
        relaxation of the geometry passes, geometry_pass_tolerance for the relative residual at
        which a pass ends while its geometry still moves, settled_increment for the relative full
        step that ends the iteration once the geometry has settled. SynoviaError for a
        parameter out of range."""
    def force_control(
        self,
        *,
        tolerance: Optional[float] = None,
        max_solves: Optional[int] = None,
        geometry_tolerance: Optional[float] = None,
        bordered: Optional[bool] = None,
        fresh_jacobian: Optional[bool] = None,
    ) -> None:
        """The iteration that finds the force-controlled coordinates of rigid bodies (only the
        given parameters change): tolerance in (0, 1) for the relative balance, max_solves per
        level, geometry_tolerance (relative to the model size) before the contact geometry is
        rebuilt, bordered=False for the search over trial solves instead of the coordinates
        solved inside the contact solve, fresh_jacobian for that search. SynoviaError for a
        parameter out of range."""
    def set_density(self, body: BodyRef, density: float) -> None: ...
    def initial_velocity(self, body: BodyRef, velocity: ArrayLike) -> None: ...
    def contact(
        self,
        name: str,
        body_k: BodyRef,
        part_k: str,
        body_l: BodyRef,
        part_l: str,
        friction: float = 0.0,
        discretisation: str = "node-to-node",
        search_distance: Optional[float] = None,
    ) -> None:
        """Body–body pair: "node-to-node", "node-to-segment" (node-to-facet) or "mortar"."""
    def contact_plane(
        self, name: str, body: BodyRef, part: str, point: ArrayLike, normal: ArrayLike, friction: float = 0.0
    ) -> None: ...
    def contact_sphere(
        self,
        name: str,
        body: BodyRef,
        part: str,
        center: ArrayLike,
        radius: float,
        cavity: bool = False,
        friction: float = 0.0,
    ) -> None: ...
    def contact_cylinder(
        self,
        name: str,
        body: BodyRef,
        part: str,
        point: ArrayLike,
        axis: ArrayLike,
        radius: float,
        cavity: bool = False,
        friction: float = 0.0,
    ) -> None: ...
    def contact_obstacle(
        self,
        name: str,
        body: BodyRef,
        part: str,
        shape: Shape,
        friction: float = 0.0,
        search_distance: Optional[float] = None,
    ) -> None:
        """Contact pair between a part and a fixed rigid obstacle of any Shape (e.g. an STL surface)."""
    def add_rigid_body(
        self,
        name: str,
        center: Optional[ArrayLike] = None,
        rotation_order: Optional[str] = None,
        prescribe: Optional[Mapping[str, History]] = None,
        force: Optional[Mapping[str, History]] = None,
        guess: Optional[Mapping[str, History]] = None,
        pose_input: bool = False,
    ) -> int:
        """A rigid body with mixed control (a scenario's [[rigid_body]]): reference point
        `center` (default origin), `rotation_order` (3D, default "zxy": R = R_z R_x R_y).
        Degrees of freedom by name ("tx", "ty", "tz", "rx", "ry", "rz"; 2D "tx", "ty", "rz"),
        held at 0 unless in `prescribe` (coordinate history, lengths and radians) or `force`
        (generalised force history: force along the axis / moment about the angle's axis;
        the coordinate follows from equilibrium), with `guess` a predictor of a
        force-controlled coordinate. pose_input=True: the other degrees of freedom follow
        Session.set_pose / Model.set_pose. Returns the rigid body's index."""
    @property
    def rigid_bodies(self) -> List[str]: ...
    def tie_to_rigid_body(self, body: BodyRef, part: str, rigid: str) -> None:
        """Ties a part to a rigid body (rigid plate): it moves with the pose, its reactions load the body."""
    def contact_rigid_body(
        self,
        name: str,
        body: BodyRef,
        part: str,
        rigid: str,
        shape: Shape,
        friction: float = 0.0,
        search_distance: Optional[float] = None,
    ) -> None:
        """Contact pair between a part and a rigid body's shape (its own frame, placed by its pose)."""
    def set_pose(
        self,
        rigid: str,
        translation: ArrayLike,
        quaternion: Optional[ArrayLike] = None,
        axis: Optional[ArrayLike] = None,
        angle: Optional[float] = None,
        rotation: Optional[ArrayLike] = None,
    ) -> None:
        """Sets the pose of a rigid body with pose_input=True for the next runs (as Session.set_pose)."""
    def friction_law(
        self,
        pair: str,
        law: str,
        mu: Optional[float] = None,
        static: Optional[float] = None,
        kinetic: Optional[float] = None,
        speed: Optional[float] = None,
    ) -> None:
        """Friction law of a pair by name: "coulomb" (mu) or "exponential" (static, kinetic,
        speed: F_c(v) = μ_k + (μ_s − μ_k) exp(−v / v_c)); quasi-static and dynamic runs."""
    def quasistatic_options(
        self,
        coulomb_fixed_point: Optional[bool] = None,
        max_fixed_point: Optional[int] = None,
        fixed_point_tolerance: Optional[float] = None,
        incremental_slip: Optional[bool] = None,
        initial_friction: Optional[bool] = None,
    ) -> None:
        """Friction scheme of quasi-static runs and session steps: Tresca with the bound frozen
        from the previous level (default) or the Coulomb fixed point (coulomb_fixed_point=True)."""
    def solver(self, name: str) -> None:
        """"pdas-fallback" (default), "pdas", "au-pdas", "uzawa-mprgp", "dual-mprgp"."""
    def nested_iteration(self, min_rows: Optional[int]) -> None: ...
    def solver_options(self, interface_block_dofs: Optional[int] = None, screening_band: Optional[float] = None) -> None:
        """The scenario's [solver] keys: the largest dense interface block (0: none) and the
        screening band of each solve (exact)."""
    def split_pair(
        self, pair: str, point: ArrayLike, normal: ArrayLike, positive: str = "positive", negative: str = "negative"
    ) -> None:
        """Reports a pair's figures also per side of a plane (pair dict `sides`; e.g. medial /
        lateral). Reporting only."""
    def run_static(self, t: float = 0.0) -> RunResult: ...
    def run_quasistatic(self, times: Sequence[float], keep_steps: bool = False) -> RunResult: ...
    def run_dynamic(self, dt: float, steps: int, keep_steps: bool = False) -> RunResult: ...
    def run(self, keep_steps: bool = False) -> RunResult:
        """Runs the analysis of the scenario file the model came from."""
    def prepare(self) -> Session:
        """Factorises once and returns a re-solve Session."""

def run_scenario(path: PathLike, keep_steps: bool = False) -> RunResult:
    """Model.from_scenario(path).run()."""

def hertz2d(
    levels: int = 10,
    solver: str = "pdas",
    *,
    radius: float = 1.0,
    e1: float = 1.0,
    nu1: float = 0.3,
    e2: Optional[float] = None,
    nu2: float = 0.3,
    push: float = 0.01,
    n: int = 8,
    refine_radius: float = 0.16,
    nested: bool = True,
) -> Dict[str, Any]:
    """2D Hertz (synovia_models::hertz::hertz2d): figures, profile (n, 2) and json."""

def hertz3d(
    levels: int = 12,
    solver: str = "pdas",
    *,
    radius: float = 1.0,
    e: float = 1.0,
    nu: float = 0.3,
    push: float = 0.01,
    n: int = 4,
    refine_radius: float = 0.15,
    nested: bool = True,
) -> Dict[str, Any]:
    """3D Hertz (synovia_models::hertz::hertz3d): figures, profile (n, 2) and json."""

def hertz_json(run: Mapping[str, Any]) -> str:
    """The JSON line of a Hertz run, as the Rust examples print it."""

def arrays_from_meshio(mesh: Any, dimension: int) -> Tuple[FloatArray, npt.NDArray[np.int64], Dict[str, npt.NDArray[np.int64]]]: ...
def result_to_meshio(result: RunResult, body: BodyRef = 0, step: int = -1) -> Any: ...
