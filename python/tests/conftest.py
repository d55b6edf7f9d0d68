"""Shared helpers of the Python tests: small structured meshes, the repository root, and the
Rust reference binary (tests/rust_reference) that prints figures of the Rust API."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

PYTHON_DIR = pathlib.Path(__file__).resolve().parents[1]
ROOT = PYTHON_DIR.parent
SCENARIOS = ROOT / "examples" / "scenarios"
REFERENCE_MANIFEST = PYTHON_DIR / "tests" / "rust_reference" / "Cargo.toml"


def rectangle(x0, x1, y0, y1, nx, ny):
    """A structured triangulation of [x0, x1] × [y0, y1]: nodes, cells and the boundary parts
    `bottom`, `top`, `left`, `right` as facet (edge) arrays."""
    xs, ys = np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)
    nodes = np.array([(x, y) for y in ys for x in xs])
    idx = lambda i, j: j * (nx + 1) + i  # noqa: E731
    cells = []
    for j in range(ny):
        for i in range(nx):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            cells += [(a, b, c), (a, c, d)]
    parts = {
        "bottom": np.array([(idx(i, 0), idx(i + 1, 0)) for i in range(nx)]),
        "top": np.array([(idx(i, ny), idx(i + 1, ny)) for i in range(nx)]),
        "left": np.array([(idx(0, j), idx(0, j + 1)) for j in range(ny)]),
        "right": np.array([(idx(nx, j), idx(nx, j + 1)) for j in range(ny)]),
    }
    return nodes, np.array(cells), parts


def box(x0, x1, y0, y1, z0, z1, n):
    """A structured tetrahedral mesh of a box (`n` cells per edge, 6 tetrahedra per cube,
    conforming): nodes and cells."""
    xs, ys, zs = np.linspace(x0, x1, n + 1), np.linspace(y0, y1, n + 1), np.linspace(z0, z1, n + 1)
    nodes = np.array([(x, y, z) for z in zs for y in ys for x in xs])
    idx = lambda i, j, k: (k * (n + 1) + j) * (n + 1) + i  # noqa: E731
    cells = []
    for k in range(n):
        for j in range(n):
            for i in range(n):
                v = [idx(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)) for c in range(8)]
                # Kuhn subdivision along the diagonal v0 → v7
                for p in ((1, 3), (1, 5), (2, 3), (2, 6), (4, 5), (4, 6)):
                    a = v[p[0]]
                    b = v[p[0] | p[1]]
                    cells.append((v[0], a, b, v[7]))
    return nodes, np.array(cells)


@pytest.fixture(scope="session")
def rust_reference():
    """Runs the Rust reference binary with arguments and returns its JSON output (built once
    with cargo, in CARGO_TARGET_DIR if set)."""
    build = subprocess.run(
        ["cargo", "build", "--release", "--quiet", "--manifest-path", str(REFERENCE_MANIFEST)],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    if build.returncode != 0:
        pytest.fail("cannot build the Rust reference binary:\n" + build.stderr[-4000:])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", PYTHON_DIR / "tests" / "rust_reference" / "target"))
    if not target.is_absolute():
        target = ROOT / target
    exe = target / "release" / "synovia-python-reference"

    def run(*args):
        out = subprocess.run([str(exe), *map(str, args)], cwd=ROOT, capture_output=True, text=True)
        if out.returncode != 0:
            pytest.fail(f"reference {args} failed:\n{out.stderr}")
        return json.loads(out.stdout.strip().splitlines()[-1])

    return run


def assert_rel(a, b, tol=1e-12, what=""):
    """`|a − b| ≤ tol · max(|b|, tiny)` elementwise."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, f"{what}: shapes {a.shape} vs {b.shape}"
    scale = np.maximum(np.abs(b), 1e-300)
    err = np.max(np.abs(a - b) / scale) if a.size else 0.0
    assert err <= tol, f"{what}: relative difference {err:.3e} > {tol:.0e}"
