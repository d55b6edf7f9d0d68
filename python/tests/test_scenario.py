"""Scenario files from Python against the Rust API (the reference binary builds and runs the
same file with `synovia_scenario`): records and displacements to 1e-12."""

import numpy as np
import pytest

import synovia
from conftest import SCENARIOS, assert_rel


def check_against_rust(path, ref, result):
    assert result.n_dofs == ref["n_dofs"]
    assert len(result.records) == len(ref["records"])
    for rec, rrec in zip(result.records, ref["records"]):
        assert rec["time"] == rrec["time"]
        assert_rel(rec["strain_energy"], rrec["strain_energy"], 1e-12, f"{path.name} strain energy")
        for p, rp in zip(rec["pairs"], rrec["pairs"]):
            assert p["name"] == rp["name"]
            for k in ("normal_force", "contact_area", "peak_pressure"):
                assert_rel(p[k], rp[k], 1e-12, f"{path.name} {p['name']} {k}")
            scale = max(abs(x) for x in rp["force"]) or 1.0
            np.testing.assert_allclose(p["force"], rp["force"], rtol=0, atol=1e-12 * scale)
    for b, u in enumerate(ref["displacement"]):
        got = result.displacement(b).ravel()
        scale = max(np.max(np.abs(u)), 1e-300)
        assert np.max(np.abs(got - np.array(u))) <= 1e-12 * scale, f"{path.name} displacement of body {b}"


@pytest.mark.parametrize(
    "name",
    [
        "hertz2d.toml",
        "hertz2d_mortar.toml",
        "hertz2d_node_to_segment.toml",
        "cattaneo_mindlin2d.toml",
        "tibial_plateau2d.toml",
        "dynamic_drop2d.toml",
        "dynamic_drop2d_neo_hookean.toml",
        "gmsh_block2d.toml",
        "hertz3d.toml",
    ],
)
def test_scenario_equals_rust(rust_reference, name):
    path = SCENARIOS / name
    model = synovia.Model.from_scenario(path)
    assert model.analysis["type"] in ("static", "quasistatic", "dynamic")
    result = model.run()
    check_against_rust(path, rust_reference("scenario", path), result)
    if result.kkt is not None:
        assert result.kkt["max"] < 1e-6


def test_run_scenario_function():
    r = synovia.run_scenario(SCENARIOS / "hertz2d.toml")
    assert r.bodies == ["cylinder"]
    pair = r.pairs()["cylinder-flat"]
    assert pair["normal_force"] > 0
    assert r.contact_pressure("cylinder").max() == pytest.approx(
        r.contact["pressure"].max(), rel=1e-12
    )


def test_scenario_errors_carry_the_location(tmp_path):
    with pytest.raises(synovia.SynoviaError, match="cannot read the scenario file"):
        synovia.Model.from_scenario(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text(
        'dimension = 2\n[[body]]\nname = "b"\n'
        'mesh = { generator = "rectangle", x = [0.0, 1.0], y = [0.0, 1.0], cells = [2, 2] }\n'
        'material = { type = "isotropic", E = -1.0, nu = 0.3 }\n'
        '[analysis]\ntype = "static"\n'
    )
    with pytest.raises(synovia.SynoviaError, match=r"body\[0\]\.material"):
        synovia.Model.from_scenario(bad)


def test_scenario_model_can_be_extended_and_prepared():
    model = synovia.Model.from_scenario(SCENARIOS / "hertz2d.toml")
    with model.prepare() as session:
        first = session.solve_static(model.analysis.get("time", 0.0))
    direct = model.run()
    assert_rel(
        first.pairs()["cylinder-flat"]["normal_force"],
        direct.pairs()["cylinder-flat"]["normal_force"],
        1e-8,
        "session vs run",
    )
