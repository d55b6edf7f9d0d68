import pathlib
import re

import synovia

from conftest import ROOT


def workspace_version():
    text = (ROOT / "Cargo.toml").read_text()
    section = text.split("[workspace.package]", 1)[1]
    return re.search(r'^version\s*=\s*"([^"]+)"', section, re.M).group(1)


def test_version_is_the_rust_crate_version():
    assert synovia.__version__ == workspace_version()


def test_error_class():
    assert issubclass(synovia.SynoviaError, Exception)
    assert synovia.SynoviaError.__module__ == "synovia"


def test_solver_names():
    assert synovia.SOLVER_NAMES == ["pdas", "au-pdas", "uzawa-mprgp", "dual-mprgp"]


def test_bad_dimension():
    try:
        synovia.Model(4)
    except synovia.SynoviaError as e:
        assert "dimension must be 2 or 3, got 4" in str(e)
    else:
        raise AssertionError("no error")


def test_stub_file_is_shipped():
    pkg = pathlib.Path(synovia.__file__).parent
    assert (pkg / "__init__.pyi").exists() and (pkg / "py.typed").exists()
