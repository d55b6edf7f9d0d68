"""Models from meshio meshes and results as meshio meshes."""

import meshio
import numpy as np
import pytest

import synovia
from conftest import box, rectangle
from test_model import E, FORCE_2D, NU, PUSH


def block_mesh_2d():
    nodes, cells, parts = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
    names = list(parts)
    lines = np.concatenate([parts[n] for n in names])
    offsets = np.cumsum([0] + [len(parts[n]) for n in names])
    # 3 coordinates (z = 0), an unused point, lines tagged with gmsh:physical and named by field_data
    points = np.vstack([np.column_stack([nodes, np.zeros(len(nodes))]), [[9.0, 9.0, 0.0]]])
    tags = np.concatenate([np.full(len(parts[n]), 10 + i) for i, n in enumerate(names)])
    mesh = meshio.Mesh(
        points,
        [("line", lines), ("triangle", cells)],
        cell_data={"gmsh:physical": [tags, np.full(len(cells), 1)]},
        field_data={n: np.array([10 + i, 1]) for i, n in enumerate(names)},
    )
    return mesh, offsets


def test_model_from_meshio_2d(tmp_path):
    mesh, _ = block_mesh_2d()
    m = synovia.Model(2)
    m.add_meshio("block", mesh, synovia.Material.plane_strain(E, NU))
    assert sorted(m.parts("block")) == ["bottom", "left", "right", "top"]
    assert m.nodes("block").shape == (45, 2)  # the unused point is dropped
    m.symmetry("block", "left")
    m.prescribe("block", "top", [0.0, -PUSH], components=[1])
    m.contact_plane("floor", "block", "bottom", [0.0, 0.0], [0.0, 1.0])
    r = m.run_static()
    assert r.pairs()["floor"]["normal_force"] == pytest.approx(FORCE_2D, rel=1e-9)
    out = r.to_meshio("block")
    assert out.cells[0].type == "triangle" and len(out.cells[0].data) == 64
    np.testing.assert_array_equal(out.point_data["displacement"], r.displacement("block"))
    assert out.point_data["contact_pressure"].max() > 0
    assert out.cell_data["stress"][0].shape == (64, 3)
    path = tmp_path / "block.vtu"
    out.write(path)
    back = meshio.read(path)
    np.testing.assert_allclose(back.point_data["displacement"][:, :2], r.displacement("block"))
    assert synovia.result_to_meshio(r, 0).points.shape == (45, 2)


def test_model_from_meshio_3d_cell_sets():
    nodes, cells = box(0, 1, 0, 1, 0, 1, 2)
    # boundary triangles of the faces z = 0 and z = 1 from the tetrahedra's faces
    faces = {}
    for c in cells:
        for skip in range(4):
            f = tuple(sorted(np.delete(c, skip)))
            faces[f] = faces.get(f, 0) + 1
    boundary = np.array([f for f, k in faces.items() if k == 1])
    z = nodes[boundary][:, :, 2]
    bottom = np.where(np.all(z == 0.0, axis=1))[0]
    top = np.where(np.all(z == 1.0, axis=1))[0]
    mesh = meshio.Mesh(
        nodes,
        [("tetra", cells), ("triangle", boundary)],
        cell_sets={"bottom": [np.array([], dtype=int), bottom], "top": [np.array([], dtype=int), top]},
    )
    m = synovia.Model(3)
    m.add_meshio("cube", mesh, synovia.Material.isotropic(E, NU))
    assert sorted(m.parts("cube")) == ["bottom", "top"]
    m.clamp("cube", "bottom")
    m.prescribe("cube", "top", [0.0, 0.0, -0.01])
    r = m.run_static()
    assert r.kkt is None and r.n_steps == 1
    out = r.to_meshio("cube")
    assert out.cells[0].type == "tetra" and out.point_data["stress"].shape == (27, 6)


def test_meshio_errors():
    mesh = meshio.Mesh(np.zeros((3, 3)), [("line", np.array([[0, 1]]))])
    with pytest.raises(ValueError, match="no triangle cells"):
        synovia.Model(2).add_meshio("b", mesh, synovia.Material.plane_strain(E, NU))
