"""The total knee replacement (docs/tkr3d.md) driven from Python: the scenario
`examples/scenarios/tkr3d_stance.toml` (tibial insert meshed from its STL, 42 063 unknowns,
the rigid femoral component bounded by its STL surface, posed from the fluoroscopic gait
kinematics with the superior–inferior translation force-controlled by the ISO axial force)
at three stance poses, against the same file run by the Rust API; then the first poses of the
gait cycle through a re-solve Session, as the `tkr3d` main job drives it (one factorisation,
`solve_static` for the first pose, quasi-static `step`s after it)."""

import numpy as np
import pytest

import synovia
from conftest import SCENARIOS
from test_scenario import check_against_rust

TKR3D = SCENARIOS / "tkr3d_stance.toml"


@pytest.fixture(scope="module")
def stance():
    model = synovia.Model.from_scenario(TKR3D)
    return model, model.run()


def test_tkr3d_stance_equals_rust(rust_reference, stance):
    model, result = stance
    assert model.bodies == ["insert"] and model.pairs == ["femur-insert"]
    assert result.n_dofs == 42063
    check_against_rust(TKR3D, rust_reference("scenario", TKR3D), result)


def test_tkr3d_stance_balance_and_results(stance):
    model, result = stance
    for rec in result.records:
        femur = rec["rigid"][0]
        assert femur["name"] == "femur"
        # the axial force is carried by the contact (force control converged)
        assert femur["balance_error"] < 1e-6
        # the ISO axial force pushes the femur down (applied −F along y); the contact force on
        # the insert is −F along y too
        applied = femur["applied"][1]
        assert applied < 0
        pair = rec["pairs"][0]
        assert pair["force"][1] == pytest.approx(applied, rel=1e-6)
        sides = {s["name"]: s for s in pair["sides"]}
        assert set(sides) == {"lateral", "medial"}
        assert sides["lateral"]["normal_force"] + sides["medial"]["normal_force"] == pytest.approx(
            pair["normal_force"], rel=1e-9
        )
    p = result.contact_pressure("insert")
    assert p.shape == (len(model.nodes("insert")),)
    assert p.max() == pytest.approx(result.pairs()["femur-insert"]["peak_pressure"], rel=1e-12)
    assert result.kkt["max"] < 1e-6


def test_tkr3d_gait_session_from_python():
    model = synovia.Model.from_scenario(TKR3D)
    with model.prepare() as session:
        assert session.factorizations == 1 and session.n_dofs == 42063
        first = session.solve_static(0.10)
        second = session.step(0.11)
        third = session.step(0.12)
        assert session.solves == 3
    for r in (first, second, third):
        rec = r.records[0]
        assert rec["rigid"][0]["balance_error"] < 1e-6
        assert r.kkt["max"] < 1e-6
    assert second.warm_started and third.warm_started
    forces = [-r.records[0]["pairs"][0]["force"][1] for r in (first, second, third)]
    # the scenario's ISO axial force: 2150, 2400, 2500 N at 10, 11, 12 % of the cycle
    np.testing.assert_allclose(forces, [2150.0, 2400.0, 2500.0], rtol=1e-6)


def test_tkr3d_gait_with_friction_session_equals_rust(rust_reference, tmp_path):
    """The first poses of the gait cycle as the main job solves them (μ = 0.04, one
    factorisation, solve_static then quasi-static steps; the rigid femur force-controlled)
    through a Python session, against the same session in Rust: to 1e-12."""
    import sys

    from conftest import PYTHON_DIR
    from test_session import compare_session

    sys.path.insert(0, str(PYTHON_DIR / "examples"))
    from gait_cycle import scenario_with_friction

    path = scenario_with_friction(0.04, tmp_path)
    times = [0.0, 0.01, 0.02]
    ref = rust_reference("session", path, *times)["solves"]
    model = synovia.Model.from_scenario(path)
    with model.prepare() as s:
        results = [s.solve_static(times[0])] + [s.step(t) for t in times[1:]]
    for r, rr in zip(results, ref):
        compare_session(r, rr)
    assert results[-1].records[0]["pairs"][0]["tangential_force"] > 0
