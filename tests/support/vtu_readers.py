"""Reads synovia's .vtu files with meshio and with VTK's own XML reader and checks them against
what the Rust side says it wrote (tests/suite/vtu_readers.rs).

Usage: python3 vtu_readers.py EXPECTED.json

EXPECTED.json lists files, each with the point and cell counts, the cells of each body, the
fields (name -> number of components) and the sum of every field's values. Every reader must
see every cell and point of every body, every field with its components, and the same sums to
1e-12 (relative). Prints one JSON line per file and reader; exits non-zero on a mismatch.
"""

import json
import sys

import meshio
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def close(a, b):
    return abs(a - b) <= 1e-12 * max(1.0, abs(a), abs(b))


def check(reader, got, want, errors):
    """got: n_points, n_cells, body (cell array), point/cell {name: array (n, k)}."""
    name = f"{want['file']} [{reader}]"
    if got["n_points"] != want["n_points"]:
        errors.append(f"{name}: {got['n_points']} points, expected {want['n_points']}")
    if got["n_cells"] != want["n_cells"]:
        errors.append(f"{name}: {got['n_cells']} cells, expected {want['n_cells']}")
    per_body = np.bincount(got["body"].astype(np.int64).ravel(), minlength=len(want["cells_per_body"]))
    if per_body.tolist() != want["cells_per_body"]:
        errors.append(f"{name}: cells per body {per_body.tolist()}, expected {want['cells_per_body']}")
    for location in ("point", "cell"):
        for field, spec in want[location].items():
            arr = got[location].get(field)
            if arr is None:
                errors.append(f"{name}: no {location} field {field}")
                continue
            arr = arr.reshape(len(arr), -1)
            if arr.shape[1] != spec["components"]:
                errors.append(f"{name}: {field} has {arr.shape[1]} components, expected {spec['components']}")
            if not close(float(arr.sum()), spec["sum"]):
                errors.append(f"{name}: {field} sums to {float(arr.sum())!r}, expected {spec['sum']!r}")
    print(json.dumps({"file": want["file"], "reader": reader, "points": got["n_points"],
                      "cells": got["n_cells"], "cells_per_body": per_body.tolist()}))


def with_meshio(path):
    mesh = meshio.read(path)
    n_cells = sum(len(block.data) for block in mesh.cells)

    def joined(arrays):
        return np.concatenate([np.asarray(a) for a in arrays])

    cell = {k: joined(v) for k, v in mesh.cell_data.items()}
    return {"n_points": len(mesh.points), "n_cells": n_cells, "body": cell.get("body", np.zeros(0)),
            "point": dict(mesh.point_data), "cell": cell}


def with_vtk(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        raise RuntimeError(f"VTK could not read {path}: error code {reader.GetErrorCode()}")
    grid = reader.GetOutput()

    def arrays(data):
        return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i)) for i in range(data.GetNumberOfArrays())}

    cell = arrays(grid.GetCellData())
    return {"n_points": grid.GetNumberOfPoints(), "n_cells": grid.GetNumberOfCells(),
            "body": cell.get("body", np.zeros(0)), "point": arrays(grid.GetPointData()), "cell": cell}


def main():
    with open(sys.argv[1], encoding="utf-8") as f:
        expected = json.load(f)
    errors = []
    for want in expected:
        for reader, read in (("meshio", with_meshio), ("vtk", with_vtk)):
            try:
                check(reader, read(want["file"]), want, errors)
            except Exception as e:  # a reader that fails is a finding, reported like a mismatch
                errors.append(f"{want['file']} [{reader}]: {type(e).__name__}: {e}")
    for e in errors:
        print("MISMATCH", e, file=sys.stderr)
    sys.exit(1 if errors else 0)


if __name__ == "__main__":
    main()
