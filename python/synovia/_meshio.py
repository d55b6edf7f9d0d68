"""Conversions between meshio meshes and synovia models / results."""

import numpy as np

_VOLUME = {2: "triangle", 3: "tetra"}
_FACET = {2: "line", 3: "triangle"}
_TAG_KEYS = ("gmsh:physical", "cell_tags", "medit:ref")


def arrays_from_meshio(mesh, dimension):
    """``(nodes, cells, parts)`` of a ``meshio.Mesh`` for :meth:`synovia.Model.add_body`.

    ``cells`` are the mesh's triangles (``dimension`` 2) or tetrahedra (3); ``nodes`` the points
    they use (renumbered; the first ``dimension`` coordinates); ``parts`` maps part names to the
    boundary facets (lines in 2D, triangles in 3D) named by ``mesh.cell_sets`` or tagged by
    ``gmsh:physical`` (named by ``mesh.field_data`` where given, else ``tag_<n>``).
    """
    if dimension not in (2, 3):
        raise ValueError(f"dimension must be 2 or 3, got {dimension}")
    vol_type, facet_type = _VOLUME[dimension], _FACET[dimension]
    blocks = list(mesh.cells)
    vol = [np.asarray(b.data) for b in blocks if b.type == vol_type]
    if not vol:
        raise ValueError(f"the mesh has no {vol_type} cells (cell types: {sorted({b.type for b in blocks})})")
    cells = np.concatenate(vol).astype(np.int64)
    used = np.unique(cells)
    renumber = -np.ones(len(mesh.points), dtype=np.int64)
    renumber[used] = np.arange(len(used))
    nodes = np.asarray(mesh.points, dtype=float)[used, :dimension]
    if mesh.points.shape[1] > dimension and np.any(np.asarray(mesh.points)[used, dimension:] != 0.0):
        raise ValueError(f"a {dimension}D mesh must have zero coordinates beyond the first {dimension}")
    cells = renumber[cells]

    parts = {}

    def add(name, facets):
        facets = renumber[np.asarray(facets, dtype=np.int64)]
        if np.any(facets < 0):
            raise ValueError(f"part `{name}`: facets use points that no {vol_type} cell uses")
        parts[name] = np.concatenate([parts[name], facets]) if name in parts else facets

    facet_blocks = [i for i, b in enumerate(blocks) if b.type == facet_type]
    for name, sets in (getattr(mesh, "cell_sets", None) or {}).items():
        for i in facet_blocks:
            if i < len(sets) and sets[i] is not None and len(sets[i]) > 0:
                add(name, np.asarray(blocks[i].data)[np.asarray(sets[i], dtype=np.int64)])
    if not parts:
        names = {}
        for name, value in (getattr(mesh, "field_data", None) or {}).items():
            value = np.atleast_1d(value)
            if len(value) >= 2 and int(value[1]) == dimension - 1:
                names[int(value[0])] = name
        for key in _TAG_KEYS:
            data = (mesh.cell_data or {}).get(key)
            if data is None:
                continue
            for i in facet_blocks:
                tags = np.asarray(data[i])
                facets = np.asarray(blocks[i].data)
                for tag in np.unique(tags):
                    add(names.get(int(tag), f"tag_{int(tag)}"), facets[tags == tag])
            break
    return nodes, cells, parts


def result_to_meshio(result, body=0, step=-1):
    """A body of a :class:`synovia.RunResult` as a ``meshio.Mesh``: point data
    ``displacement``, ``contact_pressure`` (at ``step``), ``von_mises``, ``stress``; cell data
    ``von_mises``, ``stress`` (last step)."""
    import meshio

    cell_type = _VOLUME[result.dimension]
    point_data = {
        "displacement": result.displacement(body),
        "contact_pressure": result.contact_pressure(body, step),
        "von_mises": result.von_mises(body, "node"),
        "stress": result.stress(body, "node"),
    }
    cell_data = {
        "von_mises": [result.von_mises(body, "cell")],
        "stress": [result.stress(body, "cell")],
    }
    return meshio.Mesh(
        result.nodes(body),
        [(cell_type, result.cells(body).astype(np.int64))],
        point_data=point_data,
        cell_data=cell_data,
    )
