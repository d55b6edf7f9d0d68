"""synovia: finite-element contact mechanics of human joints, from Python.

Python bindings (PyO3) of the synovia Rust library: joint models from NumPy arrays, meshio
meshes or TOML scenario files; materials; boundary conditions by part name with load histories
(numbers, NumPy tables, Python callables, settable :class:`Parameter` values); contact pairs of
every discretisation (node-to-node, node-to-segment / node-to-facet, dual mortar, rigid
obstacles of any :class:`Shape`, STL surfaces); rigid bodies with mixed control (each degree of
freedom prescribed or force-controlled, tied plates, shapes as contact partners, poses set
between session solves); friction laws by name; contact solvers by name; static, quasi-static and dynamic runs; results as NumPy
arrays and meshio meshes; the re-solve :class:`Session` (factorise once, solve again with new
loads) with the GIL released during solves; and the Hertz verification problems.

Errors of the library are raised as :class:`SynoviaError` with the Rust message.

Example::

    import numpy as np, synovia
    m = synovia.Model(2)
    ...  # see Model.add_body, Model.clamp, Model.contact_plane, Model.run_static
"""

from ._synovia import (
    SOLVER_NAMES,
    Material,
    Model,
    Parameter,
    RunResult,
    Session,
    Shape,
    Surface,
    SynoviaError,
    __version__,
    hertz2d,
    hertz3d,
    read_stl,
    run_scenario,
)
from ._meshio import arrays_from_meshio, result_to_meshio

__all__ = [
    "__version__",
    "SOLVER_NAMES",
    "Material",
    "Model",
    "Parameter",
    "RunResult",
    "Session",
    "Shape",
    "Surface",
    "SynoviaError",
    "arrays_from_meshio",
    "hertz2d",
    "hertz3d",
    "read_stl",
    "result_to_meshio",
    "run_scenario",
    "hertz_json",
]


def hertz_json(run):
    """The JSON line of a Hertz run (the dict returned by :func:`hertz2d` / :func:`hertz3d`),
    exactly as the Rust examples ``hertz2d`` / ``hertz3d`` print it."""
    return run["json"]
