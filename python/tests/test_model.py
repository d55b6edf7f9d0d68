"""Models from NumPy arrays: materials, conditions by part name with histories, contact pairs
of every discretisation, static / quasi-static / dynamic runs, results as NumPy arrays, errors
as exceptions. The checks are exact solutions of P1 elements (uniform stress states)."""

import threading

import numpy as np
import pytest

import synovia
from conftest import box, rectangle

E, NU, PUSH = 1000.0, 0.3, 0.01
# plane strain, σ_xx = 0: σ_yy = E/(1 − ν²) ε_yy; the block is 2 wide and 1 high
FORCE_2D = E / (1 - NU**2) * PUSH * 2.0


def block_on_floor(history=None, solver=None, friction=0.0):
    nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
    m = synovia.Model(2)
    b = m.add_body("block", nodes, cells, synovia.Material.plane_strain(E, NU), parts=parts)
    assert b == 0
    m.symmetry("block", "left")
    m.prescribe("block", "top", [0.0, -PUSH], history=history, components=[1])
    m.contact_plane("floor", "block", "bottom", point=[0.0, 0.0], normal=[0.0, 1.0], friction=friction)
    if solver:
        m.solver(solver)
    return m


def test_block_on_floor_static():
    m = block_on_floor()
    assert m.bodies == ["block"] and m.pairs == ["floor"]
    assert set(m.parts("block")) == {"bottom", "top", "left", "right"}
    r = m.run_static()
    assert len(r) == 1 and r.dimension == 2 and r.bodies == ["block"]
    pair = r.pairs()["floor"]
    assert pair["normal_force"] == pytest.approx(FORCE_2D, rel=1e-9)
    assert pair["contact_area"] == pytest.approx(2.0, rel=1e-12)
    assert pair["peak_pressure"] == pytest.approx(FORCE_2D / 2, rel=1e-9)
    u = r.displacement("block")
    assert u.shape == (45, 2)
    nodes = m.nodes("block")
    # ε_yy = −0.01 uniform, ε_xx = ν/(1 − ν) · 0.01 (plane strain, σ_xx = 0)
    np.testing.assert_allclose(u[:, 1], -PUSH * nodes[:, 1], atol=1e-12)
    np.testing.assert_allclose(u[:, 0], NU / (1 - NU) * PUSH * nodes[:, 0], atol=1e-12)
    s = r.stress("block")
    assert s.shape == (45, 3)
    np.testing.assert_allclose(s[:, 1], -FORCE_2D / 2, rtol=1e-9)
    np.testing.assert_allclose(s[:, 0], 0.0, atol=1e-9)
    assert r.stress("block", "cell").shape == (64, 3)
    assert r.von_mises("block").shape == (45,)
    p = r.contact_pressure("block")
    bottom = nodes[:, 1] == 0.0
    np.testing.assert_allclose(p[~bottom], 0.0)
    assert np.all(p[bottom] > 0)
    kkt = r.kkt
    assert kkt["max"] < 1e-8 and set(kkt) >= {"equilibrium", "penetration", "complementarity"}
    c = r.contact
    assert len(c["pair"]) == 9 and c["position"].shape == (9, 2)
    assert r.strain_energy[0] == pytest.approx(0.5 * FORCE_2D * PUSH, rel=1e-9)


@pytest.mark.parametrize("solver", ["pdas", "au-pdas", "uzawa-mprgp", "dual-mprgp", "pdas-fallback"])
def test_every_solver_by_name(solver):
    r = block_on_floor(solver=solver).run_static()
    assert r.pairs()["floor"]["normal_force"] == pytest.approx(FORCE_2D, rel=1e-6)


def test_unknown_solver_is_an_error_with_the_rust_message():
    m = block_on_floor()
    with pytest.raises(synovia.SynoviaError, match="newton"):
        m.solver("newton")


@pytest.mark.parametrize(
    "history",
    [np.array([[0.0, 0.0], [1.0, 1.0]]), lambda t: t, [[0.0, 0.0], [1.0, 1.0]]],
    ids=["numpy-table", "callable", "list-table"],
)
def test_quasistatic_histories(history):
    r = block_on_floor(history=history).run_quasistatic([0.25, 0.5, 1.0], keep_steps=True)
    np.testing.assert_allclose(r.times, [0.25, 0.5, 1.0])
    f = r.pair_history("floor", "normal_force")
    np.testing.assert_allclose(f, FORCE_2D * np.array([0.25, 0.5, 1.0]), rtol=1e-9)
    assert [rec["step"] for rec in r.records] == [1, 2, 3] or len(r.records) == 3
    u0 = r.displacement("block", step=0)
    np.testing.assert_allclose(u0 * 4.0, r.displacement("block"), rtol=1e-9, atol=1e-14)
    assert r.contact_pressure("block", step=0).max() == pytest.approx(r.contact_pressure("block").max() / 4, rel=1e-9)


def test_callable_exception_is_reraised():
    def bad(t):
        raise ZeroDivisionError("from the history")

    with pytest.raises(ZeroDivisionError, match="from the history"):
        block_on_floor(history=bad).run_static(1.0)


def test_prescribe_field_callable():
    m = synovia.Model(2)
    nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
    m.add_body("block", nodes, cells, synovia.Material.plane_strain(E, NU), parts=parts)
    m.symmetry("block", "left")
    m.prescribe_field("block", "top", lambda x, t: [0.0, -PUSH * t], components=[1])
    m.contact_plane("floor", "block", "bottom", [0.0, 0.0], [0.0, 1.0])
    r = m.run_static(0.5)
    assert r.pairs()["floor"]["normal_force"] == pytest.approx(0.5 * FORCE_2D, rel=1e-9)


def test_input_errors_carry_the_rust_message():
    nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 2, 2)
    m = synovia.Model(2)
    with pytest.raises(synovia.SynoviaError, match="cells must have 3 columns"):
        m.add_body("b", nodes, cells[:, :2], synovia.Material.plane_strain(E, NU))
    with pytest.raises(synovia.SynoviaError, match="Poisson|poisson|ν"):
        m.add_body("b", nodes, cells, synovia.Material.plane_strain(E, 0.7))
    m.add_body("b", nodes, cells, synovia.Material.plane_strain(E, NU), parts=parts)
    with pytest.raises(synovia.SynoviaError, match="nope"):
        m.clamp("b", "nope")
    with pytest.raises(synovia.SynoviaError, match="3D only"):
        m.contact_cylinder("c", "b", "top", [0, 0, 0], [0, 0, 1], 1.0)
    with pytest.raises(synovia.SynoviaError, match="plane strain and plane stress"):
        synovia.Model(3).add_body("b", *box(0, 1, 0, 1, 0, 1, 1), synovia.Material.plane_stress(E, NU))
    m.clamp("b", "bottom")
    with pytest.raises(synovia.SynoviaError, match="already of kind"):
        m.traction("b", "bottom", [0.0, 1.0])
    with pytest.raises(synovia.SynoviaError, match="unknown discretisation"):
        m.contact("p", "b", "top", "b", "left", discretisation="magic")


def test_dynamic_run():
    m = synovia.Model(2)
    nodes, cells, parts = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4)
    m.add_body("b", nodes, cells, synovia.Material.plane_strain(E, NU), parts=parts)
    m.set_density("b", 1.0)
    m.clamp("b", "bottom")
    m.traction("b", "top", [0.0, -1.0])
    r = m.run_dynamic(0.01, 5)
    assert len(r) == 6 and r.records[0]["time"] == pytest.approx(0.0)
    assert r.records[-1]["kinetic_energy"] > 0.0


def test_neo_hookean_dynamic_run():
    """The dynamic scheme with a nonlinear elastic part (Newton iteration per step): at a small
    load the neo-Hookean block in finite strain moves as the linear one; without a density the
    run is refused with the body's name."""

    def run(material, load, kinematics=None, density=True):
        m = synovia.Model(2)
        nodes, cells, parts = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4)
        m.add_body("b", nodes, cells, material, parts=parts)
        if kinematics:
            m.set_kinematics("b", kinematics)
        if density:
            m.set_density("b", 1.0)
        m.clamp("b", "bottom")
        m.traction("b", "top", [load, -load])
        return m.run_dynamic(0.01, 10)

    load = 1e-4
    lin = run(synovia.Material.plane_strain(E, NU), load)
    nh = run(synovia.Material.neo_hookean(E, NU), load, "finite")
    assert len(nh) == 11
    u_lin, u_nh = lin.displacement("b"), nh.displacement("b")
    assert np.max(np.abs(u_nh - u_lin)) <= 1e-3 * np.max(np.abs(u_lin))
    assert nh.records[-1]["kinetic_energy"] == pytest.approx(lin.records[-1]["kinetic_energy"], rel=1e-2)
    with pytest.raises(synovia.SynoviaError, match="no density"):
        run(synovia.Material.neo_hookean(E, NU), load, "finite", density=False)


def cubes(discretisation, n_upper=2):
    """Two stacked unit cubes, symmetry planes x = 0 and y = 0, the upper top pushed down
    by 0.02: uniaxial stress σ_zz = −E · 0.01 in both."""
    m = synovia.Model(3)
    mat = synovia.Material.isotropic(E, NU)
    m.add_body("lower", *box(0, 1, 0, 1, 0, 1, 2), mat)
    m.add_body("upper", *box(0, 1, 0, 1, 1, 2, n_upper), mat)
    for b, z in (("lower", 0.0), ("upper", 1.0)):
        m.add_part_where(b, "xsym", lambda x, n: n[0] < -0.99)
        m.add_part_where(b, "ysym", lambda x, n: n[1] < -0.99)
        m.symmetry(b, "xsym")
        m.symmetry(b, "ysym")
    m.add_part_where("lower", "bottom", lambda x, n: n[2] < -0.99)
    m.add_part_where("lower", "top", lambda x, n: n[2] > 0.99)
    m.add_part_where("upper", "bottom", lambda x, n: n[2] < -0.99)
    m.add_part_where("upper", "top", lambda x, n: n[2] > 0.99)
    m.symmetry("lower", "bottom")
    m.prescribe("upper", "top", [0.0, 0.0, -0.02], components=[2])
    m.contact("interface", "upper", "bottom", "lower", "top", discretisation=discretisation)
    return m


@pytest.mark.parametrize("discretisation", ["node-to-node", "node-to-segment", "mortar"])
def test_every_discretisation_uniaxial(discretisation):
    r = cubes(discretisation).run_static()
    assert r.pairs()["interface"]["normal_force"] == pytest.approx(E * 0.01, rel=1e-9)
    np.testing.assert_allclose(r.stress("lower", "cell")[:, 2], -E * 0.01, rtol=1e-9)
    np.testing.assert_allclose(r.stress("upper", "cell")[:, 2], -E * 0.01, rtol=1e-9)


def test_mortar_patch_test_non_matching():
    r = cubes("mortar", n_upper=3).run_static()
    assert r.pairs()["interface"]["normal_force"] == pytest.approx(E * 0.01, rel=1e-8)
    np.testing.assert_allclose(r.stress("upper", "cell")[:, 2], -E * 0.01, rtol=1e-8)


def test_rigid_sphere_and_cylinder_obstacles():
    m = synovia.Model(3)
    m.add_body("b", *box(-1, 1, -1, 1, 0, 1, 4), synovia.Material.isotropic(E, NU))
    m.add_part_where("b", "bottom", lambda x, n: n[2] < -0.99)
    m.add_part_where("b", "top", lambda x, n: n[2] > 0.99)
    m.clamp("b", "bottom")
    m.contact_sphere("ball", "b", "top", center=[0.0, 0.0, 1.5 - 0.01], radius=0.5)
    r = m.run_static()
    pair = r.pairs()["ball"]
    assert pair["normal_force"] > 0 and pair["centre_of_pressure"][2] == pytest.approx(1.0)
    m2 = synovia.Model(3)
    m2.add_body("b", *box(-1, 1, -1, 1, 0, 1, 4), synovia.Material.isotropic(E, NU))
    m2.add_part_where("b", "bottom", lambda x, n: n[2] < -0.99)
    m2.add_part_where("b", "top", lambda x, n: n[2] > 0.99)
    m2.clamp("b", "bottom")
    m2.contact_cylinder("roller", "b", "top", point=[0.0, 0.0, 1.5 - 0.01], axis=[1.0, 0.0, 0.0], radius=0.5)
    assert m2.run_static().pairs()["roller"]["contact_area"] > 0


def test_run_releases_the_gil():
    m = cubes("mortar", n_upper=6)
    counter = {"n": 0}
    done = threading.Event()
    errors = []

    def solve():
        try:
            for _ in range(3):
                m.run_static()
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)
        finally:
            done.set()

    t = threading.Thread(target=solve)
    t.start()
    while not done.is_set():
        counter["n"] += 1
    t.join()
    assert not errors, errors
    assert counter["n"] > 1000


def test_anisotropic_material_equals_isotropic():
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    C = np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])
    nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
    m = synovia.Model(2)
    m.add_body("block", nodes, cells, synovia.Material.anisotropic(C), parts=parts)
    m.symmetry("block", "left")
    m.prescribe("block", "top", [0.0, -PUSH], components=[1])
    m.contact_plane("floor", "block", "bottom", [0.0, 0.0], [0.0, 1.0])
    assert m.run_static().pairs()["floor"]["normal_force"] == pytest.approx(FORCE_2D, rel=1e-9)
    with pytest.raises(synovia.SynoviaError):
        synovia.Model(2).add_body("b", nodes, cells, synovia.Material.anisotropic(np.eye(6)))


def test_neo_hookean_finite_strain_equals_linear_at_small_load_and_differs_at_large():
    """A neo-Hookean block in finite strain (Newton iteration) pressed on the floor: at a small
    push it carries the linear block's force, at a 20 % push a different one."""

    def floor_force(material, push, kinematics=None):
        nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
        m = synovia.Model(2)
        m.add_body("block", nodes, cells, material, parts=parts)
        if kinematics:
            m.set_kinematics("block", kinematics)
        m.symmetry("block", "left")
        m.prescribe("block", "top", [0.0, -push], components=[1])
        m.contact_plane("floor", "block", "bottom", point=[0.0, 0.0], normal=[0.0, 1.0])
        r = m.run_static()
        assert r.kkt["max"] < 1e-8
        return r.pairs()["floor"]["normal_force"], r

    small = 1e-5
    f_lin, _ = floor_force(synovia.Material.plane_strain(E, NU), small)
    f_nh, r = floor_force(synovia.Material.neo_hookean(E, NU), small, "finite")
    assert f_nh == pytest.approx(f_lin, rel=1e-4)
    assert r.stress("block", "cell").shape == (64, 3)
    big = 0.2
    f_lin, _ = floor_force(synovia.Material.plane_strain(E, NU), big)
    f_nh, _ = floor_force(synovia.Material.neo_hookean(E, NU), big, "finite")
    assert abs(f_nh / f_lin - 1.0) > 0.02
    f_mr, _ = floor_force(synovia.Material.mooney_rivlin(0.5 * E / (2 * (1 + NU)), 0.0, E * NU / ((1 + NU) * (1 - 2 * NU))), big, "finite")
    assert f_mr == pytest.approx(f_nh, rel=1e-7)  # c2 = 0: the neo-Hookean law with μ = 2c1
    with pytest.raises(synovia.SynoviaError, match="kinematics"):
        synovia.Model(2).set_kinematics(0, "large")


def test_newton_params_modified_newton_solves_the_same_problem():
    """Model.newton_params: modified Newton with Aitken's relaxation gives the neo-Hookean
    block's force of the default Newton iteration; parameters out of range are refused."""

    def floor_force(**newton):
        nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
        m = synovia.Model(2)
        m.add_body("block", nodes, cells, synovia.Material.neo_hookean(E, NU), parts=parts)
        m.set_kinematics("block", "finite")
        if newton:
            m.newton_params(**newton)
        m.symmetry("block", "left")
        m.prescribe("block", "top", [0.0, -0.2], components=[1])
        m.contact_plane("floor", "block", "bottom", point=[0.0, 0.0], normal=[0.0, 1.0])
        r = m.run_static()
        assert r.kkt["max"] < 1e-8
        return r.pairs()["floor"]["normal_force"]

    default = floor_force()
    modified = floor_force(tangent_reuse=0.5, geometry_aitken=True, tolerance=1e-11, max_iterations=60)
    assert modified == pytest.approx(default, rel=1e-7)
    passes = floor_force(geometry_pass_tolerance=1e-3, tolerance=1e-11)
    assert passes == pytest.approx(default, rel=1e-7)
    settled = floor_force(settled_increment=1e-9, tolerance=1e-11)
    assert settled == pytest.approx(default, rel=1e-7)
    m = synovia.Model(2)
    for bad in (
        dict(tangent_reuse=1.0),
        dict(geometry_relaxation=0.0),
        dict(tolerance=2.0),
        dict(max_iterations=0),
        dict(geometry="always"),
        dict(geometry_pass_tolerance=-1.0),
        dict(settled_increment=1.0),
        dict(settled_increment=0.0),
    ):
        with pytest.raises(synovia.SynoviaError):
            m.newton_params(**bad)
