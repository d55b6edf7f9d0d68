"""The Python Hertz scripts (python/examples/hertz2d.py, hertz3d.py) print the JSON lines of
the Rust examples (examples/hertz2d.rs, hertz3d.rs): same keys, same values (the Rust API's
`ContactRun::json` of the same runs) except the wall times.

With SYNOVIA_RUST_EXAMPLES=1 the Rust examples themselves are run (`cargo run --release
--example hertz3d` / `hertz2d` in the repository root; this builds the root workspace's
examples) and their JSON lines compared with the Python ones to 1e-12 relative."""

import json
import os
import subprocess
import sys

import pytest

from conftest import PYTHON_DIR, ROOT

TIMINGS = {"solve_s", "linear_solve_s"}


def json_lines(text):
    return [json.loads(line) for line in text.splitlines() if line.startswith("{")]


def run_python_example(name, *args):
    out = subprocess.run(
        [sys.executable, str(PYTHON_DIR / "examples" / name), *args], cwd=ROOT, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def same_runs(py_lines, rust_lines, tol):
    assert len(py_lines) == len(rust_lines)
    for a, b in zip(py_lines, rust_lines):
        assert list(a) == list(b)
        for k in a:
            if k in TIMINGS:
                continue
            if isinstance(b[k], float) and b[k] != 0.0:
                assert abs(a[k] - b[k]) <= tol * abs(b[k]), (a["problem"], a["level"], k, a[k], b[k])
            else:
                assert a[k] == b[k], (a["problem"], a["level"], k)


def test_hertz3d_script_prints_the_rust_json(rust_reference):
    lines = json_lines(run_python_example("hertz3d.py"))
    assert [r["level"] for r in lines] == [10, 12, 14]
    reference = [json.loads(rust_reference("hertz3d", level, "pdas")["json"]) for level in (10, 12, 14)]
    same_runs(lines, reference, 0.0)


def test_hertz2d_script_prints_the_rust_json(rust_reference):
    lines = json_lines(run_python_example("hertz2d.py"))
    cases = [("rigid", lv) for lv in (8, 10, 12, 14)] + [("cold", lv) for lv in (8, 10, 12, 14)]
    cases += [("pair", lv) for lv in (8, 10, 12)]
    reference = [json.loads(rust_reference("hertz2d", lv, "pdas", case)["json"]) for case, lv in cases]
    same_runs(lines, reference, 0.0)


@pytest.mark.skipif(os.environ.get("SYNOVIA_RUST_EXAMPLES") != "1", reason="set SYNOVIA_RUST_EXAMPLES=1")
@pytest.mark.parametrize("name", ["hertz3d", "hertz2d"])
def test_scripts_equal_the_rust_examples(name):
    rust = subprocess.run(
        ["cargo", "run", "--release", "--quiet", "--example", name], cwd=ROOT, capture_output=True, text=True
    )
    assert rust.returncode == 0, rust.stderr[-4000:]
    same_runs(json_lines(run_python_example(f"{name}.py")), json_lines(rust.stdout), 1e-12)
