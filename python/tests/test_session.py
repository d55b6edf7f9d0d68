"""The re-solve session: factorise once, new loads through Parameters and callables, warm
starts, the GIL released during solves, the model locked while a session is open."""

import threading

import numpy as np
import pytest

import synovia
from conftest import rectangle
from test_model import E, FORCE_2D, NU, PUSH, cubes


def model_with(history):
    nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
    m = synovia.Model(2)
    m.add_body("block", nodes, cells, synovia.Material.plane_strain(E, NU), parts=parts)
    m.symmetry("block", "left")
    m.prescribe("block", "top", [0.0, -PUSH], history=history, components=[1])
    m.contact_plane("floor", "block", "bottom", [0.0, 0.0], [0.0, 1.0])
    return m


def test_parameter_loads_without_refactorising():
    push = synovia.Parameter(1.0)
    m = model_with(push)
    s = m.prepare()
    assert s.factorizations == 1 and s.n_dofs > 0 and s.contact_nodes == 9
    r1 = s.solve_static()
    assert r1.pairs()["floor"]["normal_force"] == pytest.approx(FORCE_2D, rel=1e-9)
    assert r1.warm_started is False
    for value in (0.5, 0.25, 2.0):
        push.set(value)
        r = s.solve_static()
        assert r.warm_started is True
        assert r.pairs()["floor"]["normal_force"] == pytest.approx(value * FORCE_2D, rel=1e-9)
        assert r.displacement("block").shape == (45, 2)
    assert s.solves == 4
    # the model is locked while the session is open
    with pytest.raises(synovia.SynoviaError, match="in use by an open Session"):
        m.clamp("block", "right")
    s.close()
    assert s.closed
    with pytest.raises(synovia.SynoviaError, match="closed"):
        s.solve_static()
    direct = m.run_static()
    assert direct.pairs()["floor"]["normal_force"] == pytest.approx(2.0 * FORCE_2D, rel=1e-9)
    m.clamp("block", "right")  # unlocked after close


def test_quasistatic_steps_equal_the_run():
    m = model_with(lambda t: t)
    times = [0.2, 0.6, 1.0]
    run = m.run_quasistatic(times)
    with m.prepare() as s:
        forces = [s.step(t).pairs()["floor"]["normal_force"] for t in times]
        s.reset()
        again = s.step(0.2).pairs()["floor"]["normal_force"]
    np.testing.assert_allclose(forces, run.pair_history("floor", "normal_force"), rtol=1e-9)
    assert again == pytest.approx(forces[0], rel=1e-9)


def test_session_errors():
    m = model_with(None)
    with m.prepare() as s:
        s.step(1.0)
        with pytest.raises(synovia.SynoviaError, match="later|increas|after"):
            s.step(0.5)
        # the session still works after an error
        assert s.solve_static(1.0).pairs()["floor"]["normal_force"] == pytest.approx(FORCE_2D, rel=1e-9)


def test_callable_error_in_a_session_is_reraised():
    state = {"fail": False}

    def h(t):
        if state["fail"]:
            raise RuntimeError("navigation input lost")
        return 1.0

    with model_with(h).prepare() as s:
        s.solve_static()
        state["fail"] = True
        with pytest.raises(RuntimeError, match="navigation input lost"):
            s.solve_static()


def test_prepare_reports_model_errors():
    nodes, cells, parts = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2)
    m = synovia.Model(2)
    m.add_body("free", nodes, cells, synovia.Material.plane_strain(E, NU), parts=parts)
    m.traction("free", "top", [0.0, -1.0])
    with pytest.raises(synovia.SynoviaError):
        m.prepare()


def test_solves_release_the_gil():
    m = cubes("mortar", n_upper=6)
    errors = []
    with m.prepare() as s:
        done = threading.Event()
        count = [0]

        def work():
            try:
                for _ in range(5):
                    s.solve_static()
            except Exception as e:  # noqa: BLE001 - reported below
                errors.append(e)
            finally:
                done.set()

        t = threading.Thread(target=work)
        t.start()
        while not done.is_set():
            count[0] += 1
        t.join()
    assert not errors, errors
    assert count[0] > 1000


def compare_session(result, ref):
    from conftest import assert_rel

    rec = result.records[0]
    assert rec["time"] == ref["time"]
    for p, rp in zip(rec["pairs"], ref["pairs"]):
        assert p["name"] == rp["name"]
        for k in ("normal_force", "contact_area"):
            assert_rel(p[k], rp[k], 1e-12, k)
        scale = max(abs(x) for x in rp["force"]) or 1.0
        np.testing.assert_allclose(p["force"], rp["force"], rtol=0, atol=1e-12 * scale)
        assert abs(p["tangential_force"] - rp["tangential_force"]) <= 1e-12 * max(abs(rp["normal_force"]), 1e-300)
    for r, rr in zip(rec["rigid"], ref["rigid_dofs"]):
        np.testing.assert_allclose(r["dofs"], rr, rtol=1e-12, atol=1e-12)
    for b, u in enumerate(ref["displacement"]):
        u = np.array(u)
        got = result.displacement(b).ravel()
        assert np.max(np.abs(got - u)) <= 1e-12 * max(np.max(np.abs(u)), 1e-300), f"displacement of body {b}"


def test_session_with_friction_equals_rust(rust_reference):
    """Quasi-static steps with Coulomb friction (Cattaneo–Mindlin scenario) through a Python
    session against the same session in Rust."""
    from conftest import SCENARIOS

    path = SCENARIOS / "cattaneo_mindlin2d.toml"
    model = synovia.Model.from_scenario(path)
    times = model.analysis["times"][:5]
    ref = rust_reference("session", path, *times)["solves"]
    with model.prepare() as s:
        results = [s.solve_static(times[0])] + [s.step(t) for t in times[1:]]
    assert len(results) == len(ref)
    for r, rr in zip(results, ref):
        compare_session(r, rr)
    assert any(p["tangential_force"] > 0 for r in results for p in r.records[0]["pairs"])


def test_neo_hookean_session_steps_equal_the_run():
    """A neo-Hookean block in finite strain (the Newton iteration): the session's steps are the
    quasi-static run one frame at a time — forces, displacements and finite-strain stresses —
    and solve_static from the last frame gives run_static's force."""

    def nh_model():
        nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
        m = synovia.Model(2)
        m.add_body("block", nodes, cells, synovia.Material.neo_hookean(E, NU), parts=parts)
        m.set_kinematics("block", "finite")
        m.symmetry("block", "left")
        m.prescribe("block", "top", [0.0, -0.2], history=lambda t: t, components=[1])
        m.contact_plane("floor", "block", "bottom", [0.0, 0.0], [0.0, 1.0])
        return m

    m = nh_model()
    times = [0.25, 0.5, 1.0]
    run = m.run_quasistatic(times)
    static = m.run_static(1.0)
    with m.prepare() as s:
        frames = [s.step(t) for t in times]
        assert s.factorizations > 0
        warm = s.solve_static(1.0)
    forces = [f.pairs()["floor"]["normal_force"] for f in frames]
    np.testing.assert_allclose(forces, run.pair_history("floor", "normal_force"), rtol=1e-12)
    np.testing.assert_allclose(frames[-1].displacement("block"), run.displacement("block"), rtol=0, atol=1e-14)
    np.testing.assert_allclose(frames[-1].stress("block", "cell"), run.stress("block", "cell"), rtol=1e-10, atol=1e-12)
    assert frames[-1].kkt["max"] < 1e-8
    assert warm.warm_started is True
    assert warm.pairs()["floor"]["normal_force"] == pytest.approx(
        static.pairs()["floor"]["normal_force"], rel=1e-7
    )
