"""Rigid bodies with mixed control, STL shapes, friction laws and posed sessions built from
Python (issue 18): the same models as scenario files give the same figures to 1e-12, a
force-controlled plate carries its load, a posed session frame equals a fresh solve at that
pose, and bad input raises SynoviaError with the Rust message."""

import numpy as np
import pytest

import synovia
from conftest import SCENARIOS, box

MAT = synovia.Material.isotropic


def max_rel(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape
    scale = max(np.max(np.abs(b)) if b.size else 0.0, 1e-300)
    return np.max(np.abs(a - b)) / scale if a.size else 0.0


def same_runs(got, ref, tol, what):
    """Records (pairs, rigid bodies) and the displacements of two runs agree to `tol`
    (relative to each quantity's largest value); returns the largest difference seen."""
    worst = 0.0
    assert len(got.records) == len(ref.records)
    for rec, rrec in zip(got.records, ref.records):
        assert rec["time"] == rrec["time"]
        for p, rp in zip(rec["pairs"], rrec["pairs"]):
            assert p["name"] == rp["name"]
            for k in ("normal_force", "tangential_force", "contact_area", "peak_pressure"):
                worst = max(worst, max_rel(p[k], rp[k]))
            worst = max(worst, max_rel(p["force"], rp["force"]))
        for r, rr in zip(rec["rigid"], rrec["rigid"]):
            assert r["name"] == rr["name"]
            for k in ("dofs", "reaction", "force", "moment"):
                worst = max(worst, max_rel(r[k], rr[k]))
    for b in range(len(ref.bodies)):
        worst = max(worst, max_rel(got.displacement(b), ref.displacement(b)))
    assert worst <= tol, f"{what}: relative difference {worst:.3e} > {tol:.0e}"
    return worst


def copy_bodies(scenario_model, materials):
    """A Python model with the bodies (nodes, cells, boundary parts) of a scenario model."""
    m = synovia.Model(scenario_model.dimension)
    for b in scenario_model.bodies:
        parts = {p: scenario_model.facets(b, p) for p in scenario_model.parts(b)}
        m.add_body(b, scenario_model.nodes(b), scenario_model.cells(b), materials[b], parts=parts)
    return m


# ----- force-controlled rigid plate: hertz3d_force.toml built from Python -----


@pytest.fixture(scope="module")
def hertz_force():
    sc = synovia.Model.from_scenario(SCENARIOS / "hertz3d_force.toml")
    m = copy_bodies(sc, {"sphere": MAT(10.0, 0.3), "block": MAT(10000.0, 0.3)})
    m.add_rigid_body("plate", center=[0.0, 0.0, 10.0], force={"tz": -2.0})
    m.tie_to_rigid_body("sphere", "top", "plate")
    m.clamp("block", "bottom")
    m.contact("sphere-block", "sphere", "contact", "block", "top", discretisation="node-to-facet")
    m.solver("pdas")
    return m, m.run_static(0.0), sc.run()


def test_rigid_plate_from_python_equals_scenario(hertz_force):
    m, got, ref = hertz_force
    assert m.rigid_bodies == ["plate"]
    worst = same_runs(got, ref, 1e-12, "hertz3d_force from Python")
    print(f"hertz3d_force from Python vs scenario: largest relative difference {worst:.2e}")


def test_force_controlled_plate_carries_its_load(hertz_force):
    _, r, _ = hertz_force
    plate = r.rigid_bodies()["plate"]
    assert plate["applied"] == [None, None, -2.0, None, None, None]
    # the sphere pushes the plate up with the load: Q_z + F_z = 0
    assert abs(plate["reaction"][2] - 2.0) <= 1e-9 * 2.0
    assert abs(plate["force"][2] - 2.0) <= 1e-9 * 2.0
    # ... and the block carries it: the contact resultant equals P
    pair = r.pairs()["sphere-block"]
    print(f"plate: Q_z = {plate['reaction'][2]!r}, contact resultant {pair['force'][2]!r} (load 2)")
    assert abs(abs(pair["force"][2]) - 2.0) <= 1e-9 * 2.0
    assert abs(pair["normal_force"] - 2.0) <= 1e-9 * 2.0
    assert plate["balance_error"] < 1e-9
    assert r.records[-1]["rigid"][0] == plate
    # the prescribed degrees of freedom stay at 0, the plate moved down
    assert plate["dofs"][2] < 0 and all(plate["dofs"][k] == 0.0 for k in (0, 1, 3, 4, 5))


# ----- an STL ball as a rigid body's shape: force control, prescribed motion, friction -----


def uv_sphere(center, radius, n_lon=32, n_lat=16):
    """A closed triangulated sphere with outward normals: vertices and triangles."""
    c = np.asarray(center, dtype=float)
    verts = [c + [0.0, 0.0, -radius]]
    for i in range(1, n_lat):
        th = np.pi * i / n_lat - np.pi / 2
        for j in range(n_lon):
            ph = 2 * np.pi * j / n_lon
            verts.append(c + radius * np.array([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), np.sin(th)]))
    verts.append(c + [0.0, 0.0, radius])
    verts = np.array(verts)
    ring = lambda i, j: 1 + (i - 1) * n_lon + (j % n_lon)  # noqa: E731
    top = len(verts) - 1
    tris = []
    for j in range(n_lon):
        tris.append((0, ring(1, j + 1), ring(1, j)))
        tris.append((top, ring(n_lat - 1, j), ring(n_lat - 1, j + 1)))
        for i in range(1, n_lat - 1):
            a, b, cc, d = ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)
            tris += [(a, b, cc), (a, cc, d)]
    tris = np.array(tris)
    # orient every triangle outward
    for k, t in enumerate(tris):
        p = verts[t]
        if np.dot(np.cross(p[1] - p[0], p[2] - p[0]), p.mean(axis=0) - c) < 0:
            tris[k] = t[[0, 2, 1]]
    return verts, tris


def write_stl(path, verts, tris):
    with open(path, "w") as f:
        f.write("solid ball\n")
        for t in tris:
            p = verts[t]
            n = np.cross(p[1] - p[0], p[2] - p[0])
            n = n / np.linalg.norm(n)
            f.write(f"facet normal {n[0]:.17g} {n[1]:.17g} {n[2]:.17g}\n outer loop\n")
            for v in p:
                f.write(f"  vertex {v[0]:.17g} {v[1]:.17g} {v[2]:.17g}\n")
            f.write(" endloop\nendfacet\n")
        f.write("endsolid ball\n")


BALL_TOML = """
dimension = 3
title = "an STL ball pressed onto a block by a force, dragged and twisted"

[[body]]
name = "block"
mesh = { generator = "box", lo = [-1.0, -1.0, 0.0], hi = [1.0, 1.0, 1.0], cells = [8, 8, 4] }
material = { type = "isotropic", E = 1000.0, nu = 0.3 }

[[boundary]]
body = "block"
part = "bottom"
kind = "clamped"

[[rigid_body]]
name = "ball"
center = [0.0, 0.0, 1.5]
shape = { type = "stl", file = "ball_m.stl", scale = 1000.0 }
tx = { value = 1.0, history = { table = [[0.0, 0.0], [1.0, 0.02]] } }
tz = { force = -50.0 }
rz = { value = 2.0, history = { table = [[0.0, 0.0], [1.0, 1.0]] } }

[[contact]]
name = "ball-block"
body = "block"
part = "top"
rigid_body = "ball"
friction = 0.2
search_distance = 0.3

[solver]
name = "pdas"

[analysis]
type = "quasistatic"
times = [0.0, 0.5, 1.0]
"""


@pytest.fixture(scope="module")
def ball_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("ball")
    verts, tris = uv_sphere([0.0, 0.0, 1.5], 0.5)
    # in metres: the model is in millimetres (scale = 1000)
    write_stl(d / "ball_m.stl", verts / 1000.0, tris)
    (d / "ball.toml").write_text(BALL_TOML)
    return d


def run_ball_from_python(sc, ball_files, **smoothing):
    """BALL_TOML's model built with the Python API on the bodies of the scenario model `sc`
    (the STL ball's `Shape.stl` with `smoothing`), run over its three levels."""
    m = copy_bodies(sc, {"block": MAT(1000.0, 0.3)})
    m.clamp("block", "bottom")
    m.add_rigid_body(
        "ball",
        center=[0.0, 0.0, 1.5],
        prescribe={"tx": np.array([[0.0, 0.0], [1.0, 0.02]]), "rz": [[0.0, 0.0], [1.0, np.deg2rad(2.0)]]},
        force={"tz": -50.0},
    )
    shape = synovia.Shape.stl(ball_files / "ball_m.stl", scale=1000.0, **smoothing)
    m.contact_rigid_body("ball-block", "block", "top", "ball", shape, friction=0.2, search_distance=0.3)
    m.solver("pdas")
    return m.run_quasistatic([0.0, 0.5, 1.0])


def test_stl_rigid_body_with_friction_equals_scenario(ball_files):
    sc = synovia.Model.from_scenario(ball_files / "ball.toml")
    surface = synovia.read_stl(ball_files / "ball_m.stl", scale=1000.0)
    assert len(surface) == 2 * 32 * 15 and surface.is_closed_solid
    lo, hi = surface.bounding_box
    np.testing.assert_allclose(lo, [-0.5, -0.5, 1.0], atol=1e-12)
    np.testing.assert_allclose(hi, [0.5, 0.5, 2.0], atol=1e-12)
    got, ref = run_ball_from_python(sc, ball_files), sc.run()
    worst = same_runs(got, ref, 1e-12, "STL ball from Python")
    print(f"STL ball with friction from Python vs scenario: largest relative difference {worst:.2e}")
    for rec in got.records:
        ball = rec["rigid"][0]
        # force control: the contact carries the 50 N
        assert abs(ball["reaction"][2] - 50.0) <= 1e-9 * 50.0
        assert abs(rec["pairs"][0]["force"][2] + 50.0) <= 1e-9 * 50.0
    # the dragged ball pulls the surface along (friction relative to the moving body)
    assert got.records[-1]["pairs"][0]["tangential_force"] > 0.0
    assert got.rigid_bodies()["ball"]["dofs"][0] == pytest.approx(0.02, abs=1e-15)


def test_force_control_bordered_and_search_agree(ball_files):
    """Model.force_control: the coordinate solved inside the contact solve (the default) and
    the search over trial solves balance the 50 N at the same pose, the first in fewer solves;
    bad parameters raise."""
    sc = synovia.Model.from_scenario(ball_files / "ball.toml")

    def run(**params):
        m = copy_bodies(sc, {"block": MAT(1000.0, 0.3)})
        m.clamp("block", "bottom")
        m.add_rigid_body("ball", center=[0.0, 0.0, 1.5], force={"tz": -50.0})
        shape = synovia.Shape.stl(ball_files / "ball_m.stl", scale=1000.0)
        m.contact_rigid_body("ball-block", "block", "top", "ball", shape, friction=0.2, search_distance=0.3)
        m.solver("pdas")
        m.force_control(geometry_tolerance=1e-10, **params)
        r = m.run_quasistatic([0.0, 0.5, 1.0])
        return [(rec["rigid"][0]["dofs"][2], rec["rigid"][0]["solves"]) for rec in r.records]

    bordered, search = run(), run(bordered=False)
    for (zb, _), (zs, _) in zip(bordered, search):
        assert zb == pytest.approx(zs, abs=1e-9)
    assert sum(n for _, n in bordered) < sum(n for _, n in search)
    m = synovia.Model(3)
    for bad in (dict(tolerance=0.0), dict(tolerance=1.5), dict(max_solves=0), dict(geometry_tolerance=-1.0)):
        with pytest.raises(synovia.SynoviaError):
            m.force_control(**bad)


def test_smoothed_stl_rigid_body_equals_scenario(ball_files):
    """subdivide / crease_angle_deg of Shape.stl equal the scenario keys (Loop-subdivided
    surface), and the smoothing changes the figures; bad levels raise SynoviaError."""
    toml = BALL_TOML.replace('scale = 1000.0 }', 'scale = 1000.0, subdivide = 2, crease_angle_deg = 40.0 }')
    assert toml != BALL_TOML
    (ball_files / "ball_smooth.toml").write_text(toml)
    sc = synovia.Model.from_scenario(ball_files / "ball_smooth.toml")
    got, ref = run_ball_from_python(sc, ball_files, subdivide=2, crease_angle_deg=40.0), sc.run()
    same_runs(got, ref, 1e-12, "smoothed STL ball from Python")
    faceted = run_ball_from_python(sc, ball_files)
    # the smoothed ball (Loop shrinks it slightly) sits lower at the same force
    tz = [r["rigid"][0]["dofs"][2] for r in got.records]
    tz_faceted = [r["rigid"][0]["dofs"][2] for r in faceted.records]
    assert all(a < b - 1e-3 for a, b in zip(tz, tz_faceted)), (tz, tz_faceted)
    with pytest.raises(synovia.SynoviaError, match="at most 4"):
        synovia.Shape.stl(ball_files / "ball_m.stl", scale=1000.0, subdivide=5)


def test_stl_fillet_rounds_a_concave_edge(tmp_path):
    """Shape.stl(..., fillet=r): the concave crease of an open groove (faces z = 1 - 0.1 x and
    z = 1 + 0.25 x, free space below) rounded by a circle of radius r tangent to both faces.
    Below the crease the faceted distance is that of the steeper face, the filleted one
    r - |p - c| with c the circle's centre (both analytic); away from the crease both equal the
    face's distance; a negative radius raises SynoviaError."""
    f = lambda x: 1.0 - 0.1 * x if x >= 0.0 else 1.0 + 0.25 * x  # noqa: E731
    verts = np.array([[x, y, f(x)] for y in (-2.0, 2.0) for x in (-2.0, 0.0, 2.0)])
    # vertices 0-2 at y = -2, 3-5 at y = 2; triangles oriented with their normals down
    tris = np.array([[0, 4, 1], [0, 3, 4], [1, 5, 2], [1, 4, 5]])
    write_stl(tmp_path / "groove.stl", verts, tris)
    r = 0.05
    faceted = synovia.Shape.stl(tmp_path / "groove.stl", solid=False)
    rounded = synovia.Shape.stl(tmp_path / "groove.stl", solid=False, fillet=r, fillet_max_offset=0.01)
    below = np.array([0.0, 0.0, 0.99])
    sa, sb = np.sqrt(1.0 + 0.1**2), np.sqrt(1.0 + 0.25**2)
    # the centre: r below both faces, (c_z + 0.1 c_x - 1) / sa = -r = (c_z - 0.25 c_x - 1) / sb
    cx = r * (sb - sa) / 0.35
    cz = 1.0 - r * sa - 0.1 * cx
    # (STL stores single-precision coordinates: face x >= 0 ends at z = 0.8 in f32, 1.2e-8 off,
    # hence 1e-7 where that face enters; face x < 0 has exact f32 vertices)
    assert faceted.distance(below)[0] == pytest.approx(0.01 / sb, rel=1e-12)
    assert rounded.distance(below)[0] == pytest.approx(r - np.hypot(cx, 0.99 - cz), rel=1e-7)
    assert rounded.distance(below)[0] < faceted.distance(below)[0] - 4e-4
    away = np.array([1.0, 0.3, 0.8])
    assert rounded.distance(away)[0] == pytest.approx((f(1.0) - 0.8) / sa, rel=1e-7)
    assert faceted.distance(away)[0] == rounded.distance(away)[0]
    with pytest.raises(synovia.SynoviaError, match="fillet"):
        synovia.Shape.stl(tmp_path / "groove.stl", solid=False, fillet=-0.1)


def test_fixed_stl_obstacle_equals_sphere_and_open_patch(ball_files):
    """A fixed STL ball and an analytic ball of the same radius give close contact forces; an
    open patch needs solid=False."""
    nodes, cells = box(-1.0, 1.0, -1.0, 1.0, 0.0, 1.0, 6)

    def model(shape):
        m = synovia.Model(3)
        m.add_body("block", nodes, cells, MAT(1000.0, 0.3))
        m.add_part_where("block", "top", lambda x, n: n[2] > 0.9 and x[2] > 0.999)
        m.add_part_where("block", "bottom", lambda x, n: n[2] < -0.9 and x[2] < 1e-9)
        m.clamp("block", "bottom")
        m.contact_obstacle("ball", "block", "top", shape, search_distance=0.3)
        return m.run_static()

    stl = model(synovia.Shape.stl(ball_files / "ball_m.stl", scale=1000.0, solid=True))
    # the faceted ball, pushed 0.01 into the block, against the exact one
    assert abs(stl.pairs()["ball"]["normal_force"]) <= 1e-12
    verts, tris = uv_sphere([0.0, 0.0, 1.49], 0.5)
    pushed = model(synovia.Shape.surface(synovia.Surface(verts, tris)))
    exact = model(synovia.Shape.sphere([0.0, 0.0, 1.49], 0.5))
    f_stl, f_exact = pushed.pairs()["ball"]["normal_force"], exact.pairs()["ball"]["normal_force"]
    assert f_exact > 0 and abs(f_stl - f_exact) <= 0.05 * f_exact
    # an open patch: refused as a solid (the Rust message), accepted as an open surface
    patch = synovia.Surface([[-2, -2, 1.2], [2, -2, 1.2], [2, 2, 1.2], [-2, 2, 1.2]], [[0, 2, 1], [0, 3, 2]])
    assert not patch.is_closed_solid
    with pytest.raises(synovia.SynoviaError, match="the surface is open"):
        synovia.Shape.surface(patch)
    write_stl(ball_files / "patch.stl", np.asarray(patch.vertices), np.asarray(patch.triangles, dtype=int))
    with pytest.raises(synovia.SynoviaError, match=r"patch\.stl: .*the surface is open"):
        synovia.Shape.stl(ball_files / "patch.stl")
    assert len(synovia.read_stl(ball_files / "patch.stl")) == 2
    flat = synovia.Shape.surface(patch, solid=False)
    # normals point down (into the free space below the patch): φ > 0 below
    assert flat.distance([0.0, 0.0, 1.0])[0] == pytest.approx(0.2, abs=1e-12)


# ----- friction laws by name -----


def test_friction_law_by_name_equals_scenario(tmp_path):
    """The dynamic drop of examples/scenarios/dynamic_drop2d.toml: its exponential law set
    from Python on the same file without `friction_law` gives the file's run to 1e-12."""
    text = (SCENARIOS / "dynamic_drop2d.toml").read_text()
    line = "friction_law = { static = 0.5, kinetic = 0.3, speed = 50.0 }\n"
    assert line in text
    (tmp_path / "drop.toml").write_text(text.replace(line, ""))
    ref = synovia.Model.from_scenario(SCENARIOS / "dynamic_drop2d.toml").run()
    m = synovia.Model.from_scenario(tmp_path / "drop.toml")
    plain = m.run()
    m.friction_law("floor", "exponential", static=0.5, kinetic=0.3, speed=50.0)
    got = m.run()
    worst = same_runs(got, ref, 1e-12, "exponential friction law from Python")
    print(f"exponential friction law from Python vs scenario: largest relative difference {worst:.2e}")
    # the law matters: μ = 0.5 at rest against the constant 0.3
    assert max_rel(plain.displacement(0), ref.displacement(0)) > 1e-6
    # static = kinetic: the constant coefficient, as the law "coulomb"
    m.friction_law("floor", "exponential", static=0.3, kinetic=0.3, speed=50.0)
    same_runs(m.run(), plain, 1e-12, "exponential with μ_s = μ_k")
    m.friction_law("floor", "coulomb", mu=0.3)
    same_runs(m.run(), plain, 1e-12, "coulomb law")


def test_quasistatic_friction_law_and_scheme():
    """In quasi-static runs: "coulomb" with μ on a frictionless pair equals the pair's own
    coefficient; the Coulomb fixed point (quasistatic_options) changes the Tresca result."""
    nodes, cells = box(-1.0, 1.0, -1.0, 1.0, 0.0, 1.0, 4)

    def model(friction):
        m = synovia.Model(3)
        m.add_body("block", nodes, cells, MAT(1000.0, 0.3))
        m.add_part_where("block", "top", lambda x, n: n[2] > 0.9 and x[2] > 0.999)
        m.add_part_where("block", "bottom", lambda x, n: n[2] < -0.9 and x[2] < 1e-9)
        m.prescribe("block", "top", [0.05, 0.0, -0.02], history=[[0.0, 0.0], [1.0, 1.0]])
        m.contact_obstacle("floor", "block", "bottom", synovia.Shape.plane([0, 0, 0], [0, 0, 1]), friction=friction)
        return m

    times = [0.0, 0.5, 1.0]
    ref = model(0.3).run_quasistatic(times)
    m = model(0.0)
    m.friction_law("floor", "coulomb", mu=0.3)
    same_runs(m.run_quasistatic(times), ref, 1e-12, "coulomb law in quasi-static runs")
    assert ref.pairs()["floor"]["tangential_force"] > 0
    c = model(0.3)
    c.quasistatic_options(coulomb_fixed_point=True, max_fixed_point=100, fixed_point_tolerance=1e-10)
    coulomb = c.run_quasistatic(times)
    assert coulomb.kkt["max"] < 1e-6
    assert max_rel(coulomb.displacement(0), ref.displacement(0)) > 1e-9


# ----- posed sessions -----

CENTRE = [0.0, 0.0, 2.0]
# translation of the reference point, angles (rx, ry, rz) of R = R_z R_x R_y
FRAMES = [
    ([0.0, 0.0, -0.05], [0.0, 0.0, 0.0]),
    ([0.01, 0.02, -0.06], [0.05, -0.03, 0.2]),
    ([0.02, 0.03, -0.06], [0.1, -0.05, 0.4]),
    ([0.01, 0.02, -0.055], [0.05, 0.02, 0.1]),
]


def rot(axis, a):
    c, s = np.cos(a), np.sin(a)
    return {
        0: np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        1: np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        2: np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def quat_mul(p, q):
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return np.array([
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ])


def quat(axis, a):
    q = np.zeros(4)
    q[0], q[1 + axis] = np.cos(a / 2), np.sin(a / 2)
    return q


def ball_model(friction, **rigid):
    """A block clamped at its bottom, a rigid ball (radius 0.5, its centre 0.48 below the
    reference point, so rotations move it) just above its top."""
    nodes, cells = box(-1.0, 1.0, -1.0, 1.0, 0.0, 1.0, 6)
    m = synovia.Model(3)
    m.add_body("block", nodes, cells, MAT(1000.0, 0.3))
    m.add_part_where("block", "top", lambda x, n: n[2] > 0.9 and x[2] > 0.999)
    m.add_part_where("block", "bottom", lambda x, n: n[2] < -0.9 and x[2] < 1e-9)
    m.clamp("block", "bottom")
    m.add_rigid_body("ball", center=CENTRE, **rigid)
    m.contact_rigid_body("ball-block", "block", "top", "ball", synovia.Shape.sphere([0, 0, 1.52], 0.5), friction)
    return m


def fixed(frame):
    t, a = frame
    return {"tx": t[0], "ty": t[1], "tz": t[2], "rx": a[0], "ry": a[1], "rz": a[2]}


def test_posed_frames_equal_fresh_static_solves():
    m = ball_model(0.0, pose_input=True)
    worst = 0.0
    with m.prepare() as s:
        for i, (t, a) in enumerate(FRAMES):
            q = quat_mul(quat_mul(quat(2, a[2]), quat(0, a[0])), quat(1, a[1]))
            r = rot(2, a[2]) @ rot(0, a[0]) @ rot(1, a[1])
            # the three forms of the same rotation
            if i % 3 == 0:
                s.set_pose("ball", t, quaternion=q)
            elif i % 3 == 1:
                angle = 2 * np.arccos(np.clip(q[0], -1, 1))
                s.set_pose("ball", t, axis=q[1:], angle=angle)
            else:
                s.set_pose("ball", t, rotation=r)
            got = s.solve_static()
            assert got.warm_started == (i > 0)
            fresh = ball_model(0.0, prescribe=fixed((t, a))).run_static()
            assert fresh.pairs()["ball-block"]["normal_force"] > 0
            worst = max(worst, same_runs(got, fresh, 1e-10, f"frame {i}"))
            np.testing.assert_allclose(got.rigid_bodies()["ball"]["dofs"], list(t) + list(a), atol=1e-12)
        assert s.factorizations == 1 and s.solves == len(FRAMES)
    print(f"posed frames vs fresh static solves: largest relative difference {worst:.2e}")


def test_posed_steps_with_friction_equal_quasistatic_run():
    """Frames set by quaternion and solved by session steps (friction relative to the moving
    ball) equal the quasi-static run of the same poses as coordinate tables."""
    times = [0.0, 1.0, 2.0, 3.0]
    m = ball_model(0.3, pose_input=True)
    results = []
    with m.prepare() as s:
        for i, (t, a) in enumerate(FRAMES):
            q = quat_mul(quat_mul(quat(2, a[2]), quat(0, a[0])), quat(1, a[1]))
            s.set_pose("ball", t, quaternion=2.5 * q)  # normalised by the library
            results.append(s.solve_static(times[i]) if i == 0 else s.step(times[i]))
    tables = {
        name: np.array([[times[i], fixed(f)[name]] for i, f in enumerate(FRAMES)])
        for name in ("tx", "ty", "tz", "rx", "ry", "rz")
    }
    ref = ball_model(0.3, prescribe=tables).run_quasistatic(times)
    worst = 0.0
    for i, got in enumerate(results):
        rrec, prec = ref.records[i], got.records[0]
        for k in ("normal_force", "tangential_force"):
            worst = max(worst, max_rel(prec["pairs"][0][k], rrec["pairs"][0][k]))
        worst = max(worst, max_rel(prec["rigid"][0]["dofs"], rrec["rigid"][0]["dofs"]))
    worst = max(worst, max_rel(results[-1].displacement(0), ref.displacement(0)))
    assert worst <= 1e-9, f"posed steps vs quasi-static run: {worst:.2e}"
    assert all(r.records[0]["pairs"][0]["tangential_force"] > 0 for r in results[1:])
    print(f"posed steps with friction vs quasi-static run: largest relative difference {worst:.2e}")


def test_model_set_pose_and_2d_pose():
    m = ball_model(0.0, pose_input=True)
    t, a = FRAMES[2]
    m.set_pose("ball", t, rotation=rot(2, a[2]) @ rot(0, a[0]) @ rot(1, a[1]))
    same_runs(m.run_static(), ball_model(0.0, prescribe=fixed(FRAMES[2])).run_static(), 1e-10, "Model.set_pose")
    # 2D: a rigid disc posed by translation and angle, against prescribed coordinates
    from conftest import rectangle

    nodes, cells, parts = rectangle(-1.0, 1.0, 0.0, 1.0, 8, 4)

    def disc(**rigid):
        m2 = synovia.Model(2)
        m2.add_body("b", nodes, cells, synovia.Material.plane_strain(1000.0, 0.3), parts=parts)
        m2.clamp("b", "bottom")
        m2.add_rigid_body("disc", center=[0.0, 2.0], **rigid)
        m2.contact_rigid_body("d", "b", "top", "disc", synovia.Shape.sphere([0.0, 1.5], 0.5))
        return m2

    p = disc(pose_input=True)
    with p.prepare() as s:
        s.set_pose("disc", [0.0, -0.05], angle=0.1)
        got = s.solve_static()
        with pytest.raises(synovia.SynoviaError, match="2D pose"):
            s.set_pose("disc", [0.0, 0.0], quaternion=[1, 0, 0, 0])
    same_runs(got, disc(prescribe={"ty": -0.05, "rz": 0.1}).run_static(), 1e-10, "2D pose")
    assert got.pairs()["d"]["normal_force"] > 0


# ----- bad input: SynoviaError with the Rust message, never a panic -----


def test_bad_rigid_input_raises():
    m = ball_model(0.0, pose_input=True)
    with pytest.raises(synovia.SynoviaError, match="unknown rigid degree of freedom `tw`"):
        m.add_rigid_body("x", prescribe={"tw": 0.0})
    with pytest.raises(synovia.SynoviaError, match="both prescribed and force-controlled"):
        m.add_rigid_body("x", prescribe={"tz": 0.0}, force={"tz": 1.0})
    with pytest.raises(synovia.SynoviaError, match="rotation order `xxy` must be a permutation"):
        m.add_rigid_body("x", rotation_order="xxy")
    with pytest.raises(synovia.SynoviaError, match="is not finite"):
        m.add_rigid_body("x", center=[0.0, np.nan, 0.0])
    with pytest.raises(synovia.SynoviaError, match="two rigid bodies are called `ball`"):
        m.add_rigid_body("ball")
    with pytest.raises(synovia.SynoviaError, match="unknown rigid body `femur`"):
        m.tie_to_rigid_body("block", "top", "femur")
    with pytest.raises(synovia.SynoviaError, match="3D only"):
        synovia.Model(2).add_rigid_body("x", rotation_order="zxy")
    with pytest.raises(synovia.SynoviaError, match="unknown friction law `stribeck`"):
        m.friction_law("ball-block", "stribeck", mu=0.1)
    with pytest.raises(synovia.SynoviaError, match="no contact pair `nope`"):
        m.friction_law("nope", "coulomb", mu=0.1)
    with pytest.raises(synovia.SynoviaError, match="needs `speed`"):
        m.friction_law("ball-block", "exponential", static=0.5, kinetic=0.3)
    with pytest.raises(synovia.SynoviaError, match="cannot|No such file|not found"):
        synovia.read_stl("/nonexistent/ball.stl")
    m2 = synovia.Model(2)
    with pytest.raises(synovia.SynoviaError, match="3D only"):
        m2.add_rigid_body("c")
        m2.contact_obstacle("c", 0, "top", synovia.Shape.cylinder([0, 0, 0], [0, 0, 1], 1.0))
    with m.prepare() as s:
        with pytest.raises(synovia.SynoviaError, match=r"quaternion \[w, x, y, z\] must have 4 components, got 3"):
            s.set_pose("ball", [0, 0, 0], quaternion=[1.0, 0.0, 0.0])
        with pytest.raises(synovia.SynoviaError, match="pose: quaternion .* is not finite"):
            s.set_pose("ball", [0, 0, 0], quaternion=[np.nan, 0.0, 0.0, 1.0])
        with pytest.raises(synovia.SynoviaError, match="has no direction"):
            s.set_pose("ball", [0, 0, 0], quaternion=[0.0, 0.0, 0.0, 0.0])
        with pytest.raises(synovia.SynoviaError, match="pose: translation .* is not finite"):
            s.set_pose("ball", [0, np.inf, 0], axis=[0, 0, 1], angle=0.1)
        with pytest.raises(synovia.SynoviaError, match="is not a rotation"):
            s.set_pose("ball", [0, 0, 0], rotation=np.diag([1.0, 1.0, -1.0]))
        with pytest.raises(synovia.SynoviaError, match="translation must have 3 components"):
            s.set_pose("ball", [0, 0], quaternion=[1, 0, 0, 0])
        with pytest.raises(synovia.SynoviaError, match="give one rotation"):
            s.set_pose("ball", [0, 0, 0], quaternion=[1, 0, 0, 0], rotation=np.eye(3))
        with pytest.raises(synovia.SynoviaError, match="has no pose input"):
            s.set_pose("femur", [0, 0, 0])
        # a refused pose keeps the previous one: the session still solves the identity pose
        s.set_pose("ball", [0, 0, -0.05])
        r = s.solve_static()
        assert r.rigid_bodies()["ball"]["dofs"] == pytest.approx([0, 0, -0.05, 0, 0, 0], abs=1e-15)
    with pytest.raises(synovia.SynoviaError, match="the session is closed"):
        s.set_pose("ball", [0, 0, 0])


# ----- the knee replacement of tkr3d_stance.toml, built from Python -----

GAIT = SCENARIOS.parent.parent / "data" / "tka-grand-challenge-dm"
ISO_AXIAL = [
    [0.0, 168.0], [0.03, 500.0], [0.06, 1150.0], [0.09, 1900.0], [0.11, 2400.0], [0.13, 2600.0],
    [0.15, 2450.0], [0.18, 2000.0], [0.22, 1550.0], [0.27, 1250.0], [0.32, 1150.0], [0.37, 1300.0],
    [0.42, 1750.0], [0.46, 2250.0], [0.50, 2600.0], [0.53, 2250.0], [0.56, 1500.0], [0.59, 750.0],
    [0.62, 300.0], [0.65, 168.0], [1.0, 168.0],
]


def gait_table():
    """The fluoroscopic gait kinematics (OpenSim storage: metres, radians, time in % of the
    cycle) as {column: array}."""
    lines = (GAIT / "fluoroscopic_gait_kinematics.sto").read_text().splitlines()
    end = [l.strip() for l in lines].index("endheader")
    names = lines[end + 1].split()
    data = np.array([[float(x) for x in l.split()] for l in lines[end + 2 :] if l.strip()])
    return {n: data[:, i] for i, n in enumerate(names)}


def test_tkr3d_stance_from_python_equals_scenario():
    """The Grand Challenge knee (STL femoral component as a rigid body's shape, superior–
    inferior translation force-controlled by the ISO axial force with the measured one as a
    guess, five coordinates from the gait table) built with the Python API equals
    examples/scenarios/tkr3d_stance.toml to 1e-12."""
    sc = synovia.Model.from_scenario(SCENARIOS / "tkr3d_stance.toml")
    m = copy_bodies(sc, {"insert": MAT(463.0, 0.46)})
    m.clamp("insert", "tray")
    g = gait_table()
    t = g["time"] * 0.01
    col = lambda name, f=1.0: np.column_stack([t, g[name] * f])  # noqa: E731
    m.add_rigid_body(
        "femur",
        center=[0.0, 0.0, 0.0],
        rotation_order="zxy",
        prescribe={
            "tx": col("knee_ant_r", 1000.0),
            "tz": col("knee_lat_r", 1000.0),
            "rx": col("knee_flex_r"),
            "ry": col("knee_add_r"),
            "rz": col("knee_rot_r"),
        },
        force={"ty": np.array(ISO_AXIAL) * [1.0, -1.0]},  # pushing the femur down
        guess={"ty": col("knee_sup_r", 1000.0)},
    )
    femur = synovia.Shape.stl(GAIT / "femoral_component.stl", scale=1000.0)
    m.contact_rigid_body("femur-insert", "insert", "contact", "femur", femur, search_distance=3.0)
    m.split_pair("femur-insert", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], "lateral", "medial")
    m.solver("pdas-fallback")
    m.solver_options(interface_block_dofs=0, screening_band=0.5)
    times = sc.analysis["times"]
    got, ref = m.run_quasistatic(times), sc.run()
    assert got.n_dofs == ref.n_dofs == 42063
    worst = same_runs(got, ref, 1e-12, "tkr3d_stance from Python")
    for rec, rrec in zip(got.records, ref.records):
        femur_state = rec["rigid"][0]
        assert femur_state["balance_error"] < 1e-6
        sides = {s["name"]: s["normal_force"] for s in rec["pairs"][0]["sides"]}
        rsides = {s["name"]: s["normal_force"] for s in rrec["pairs"][0]["sides"]}
        assert set(sides) == {"lateral", "medial"}
        for k in sides:
            assert abs(sides[k] - rsides[k]) <= 1e-12 * max(abs(rsides[k]), 1.0)
    print(f"tkr3d_stance from Python vs scenario: largest relative difference {worst:.2e}")


def test_parameter_and_callable_rigid_histories():
    """Rigid coordinates driven by a settable Parameter and a callable h(t) re-solve in a
    session as fresh models with constant coordinates; an exception of the callable is
    re-raised as is."""
    push = synovia.Parameter(-0.05)
    m = ball_model(0.0, prescribe={"tz": push, "rz": lambda t: 0.1 * t})
    with m.prepare() as s:
        for t, z in ((1.0, -0.05), (2.0, -0.06), (3.0, -0.055)):
            push.set(z)
            got = s.solve_static(t)
            fresh = ball_model(0.0, prescribe={"tz": z, "rz": 0.1 * t}).run_static(t)
            same_runs(got, fresh, 1e-10, f"Parameter/callable at t = {t}")
            assert got.rigid_bodies()["ball"]["dofs"][2] == z
    bad = ball_model(0.0, prescribe={"tz": -0.05, "rx": lambda t: 1.0 / 0.0})
    with pytest.raises(ZeroDivisionError):
        bad.run_static()


# ----- a rigid body as a moving contact partner in a dynamic run -----


def test_dynamic_run_with_a_prescribed_rigid_roller():
    """examples/scenarios/dynamic_roller2d.toml through Python: the roller follows its
    prescribed path (20 mm along x, pressed 0.6 mm), its reaction is the contact force on it
    (minus the pair's force on the pad) at every step, and friction drags the pad along."""
    m = synovia.Model.from_scenario(SCENARIOS / "dynamic_roller2d.toml")
    r = m.run()
    assert len(r.records) == 101
    assert r.rigid_bodies()["roller"]["dofs"] == pytest.approx([20.0, -0.6, 0.0], abs=1e-12)
    in_contact = 0
    for rec in r.records:
        pair, roller = rec["pairs"][0], rec["rigid"][0]
        assert roller["name"] == "roller"
        scale = max(1.0, pair["normal_force"])
        assert np.allclose(roller["force"][:2], -np.asarray(pair["force"][:2]), atol=1e-12 * scale)
        if pair["normal_force"] > 1e-6:
            in_contact += 1
        if rec["time"] >= 0.003:
            # pressed in, the roller slides along +x and drags the pad along +x
            assert pair["force"][0] > 0.1 * pair["normal_force"]
    assert in_contact > 80
