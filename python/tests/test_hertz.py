"""Hertz through Python against the Rust API (the reference binary calls
`synovia_models::hertz` directly): every figure to 1e-12 relative, the JSON line with the keys
of the Rust examples `hertz2d` / `hertz3d`."""

import json

import numpy as np
import pytest

import synovia
from conftest import assert_rel

TIMINGS = {"solve_s", "linear_solve_s"}
RUST_JSON_KEYS = [
    "problem", "level", "h", "dofs", "contact_nodes", "active_nodes", "solver", "iterations",
    "coarse_iterations", "solve_s", "linear_solve_s", "force", "a", "a_exact", "a_rel_err", "p0",
    "p0_exact", "p0_rel_err", "pressure_l2_err", "kkt",
]


def compare(py, ref):
    for key, value in ref.items():
        if key in TIMINGS:
            continue
        if key == "json":
            a, b = json.loads(py["json"]), json.loads(value)
            assert list(a) == list(b) == RUST_JSON_KEYS
            for k in a:
                if k not in TIMINGS:
                    assert a[k] == b[k], k
        elif key == "profile":
            assert_rel(py["profile"], np.array(value), 1e-12, "profile")
        elif isinstance(value, (int, str)):
            assert py[key] == value, key
        else:
            assert_rel(py[key], value, 1e-12, key)


@pytest.mark.parametrize(
    "case,kwargs",
    [("rigid", {}), ("cold", {"nested": False}), ("pair", {"e2": 3.0})],
)
def test_hertz2d_equals_rust(rust_reference, case, kwargs):
    py = synovia.hertz2d(8, "pdas", **kwargs)
    compare(py, rust_reference("hertz2d", 8, "pdas", case))
    assert py["a_rel_err"] < 0.1 and py["kkt"] < 1e-8


@pytest.mark.parametrize("solver", ["pdas", "dual-mprgp"])
def test_hertz2d_level10_equals_rust(rust_reference, solver):
    py = synovia.hertz2d(10, solver)
    compare(py, rust_reference("hertz2d", 10, solver, "rigid"))


def test_hertz3d_equals_rust(rust_reference):
    py = synovia.hertz3d(10, "pdas")
    compare(py, rust_reference("hertz3d", 10, "pdas"))
    assert py["problem"] == "hertz3d_rigid"
    assert py["profile"].shape[1] == 2


def test_hertz_errors():
    with pytest.raises(synovia.SynoviaError, match="unknown"):
        synovia.hertz2d(8, "no-such-solver")
