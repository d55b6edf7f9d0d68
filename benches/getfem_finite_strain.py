#!/usr/bin/env python3
"""Large-deformation indentation: synovia against GetFEM on the identical discrete problem.

Reads the problem written by `cargo run --release --example getfem_finite_strain`
(`out/getfem_finite_strain/problem{2,3}d.json`: nodes, P1 cells, the facets of the contact part
and of the prescribed top, λ, μ, the flat obstacle, the push, and synovia's solutions), solves it
with GetFEM (Debian's `python3-getfem`) and compares.

The GetFEM model is the same discrete problem:
  * P1 Lagrange displacement on the same nodes and cells (one-point quadrature is exact: the
    deformation gradient of a P1 cell is constant);
  * `add_finite_strain_elasticity_brick(mim, 'Compressible_Neo_Hookean_Bonet', 'u', [λ; μ])`
    (W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)², GetFEM switches to plane strain, C = diag(C₂ₓ₂, 1),
    on a 2D mesh — the same embedding as synovia's);
  * the prescribed top displacement by `add_Dirichlet_condition_with_simplification` (nodal
    values, as synovia's lift);
  * nodal contact with the rigid flat `y ≥ 0` (`z ≥ 0` in 3D) on the nodes of the contact facets,
    `add_nodal_contact_with_rigid_obstacle_brick` (Alart–Curnier, one multiplier per node = the
    nodal contact force); for a flat obstacle its condition `u_n ≤ φ(x)` is synovia's
    node-to-obstacle row `x_n + u_n ≥ 0`;
  * Newton's method (`Model.solve`) with load stepping on the push.
For contrast the linearised (small-strain) model is solved by GetFEM too
(`add_isotropic_linearized_elasticity_brick`, plane strain in 2D with the same λ, μ), and
synovia's linear solution is compared with GetFEM's finite-strain one.

Run: /usr/bin/python3 benches/getfem_finite_strain.py [problem2d.json problem3d.json ...]
Prints a table and one JSON line; exits with status 1 if the finite-strain solutions differ by
more than `--tolerance` (default 1e-6, relative) or the linear model does not differ by more
than 1 % (the comparison must be able to fail).
"""

import argparse
import json
import os
import sys
import time

import numpy as np
import getfem as gf
from scipy.spatial import cKDTree

TOP, CONTACT = 1, 2


def getfem_version():
    try:
        import importlib.metadata as md

        return md.version("getfem")
    except Exception:  # the Debian package has no Python metadata: ask dpkg
        try:
            import subprocess

            out = subprocess.run(
                ["dpkg-query", "-W", "-f=${Version}", "python3-getfem"], capture_output=True, text=True
            )
            return out.stdout.strip() or "unknown"
        except Exception:
            return "unknown"


class Discretisation:
    """The mesh, the P1 space, the regions and the node ↔ dof maps of one problem."""

    def __init__(self, p):
        self.dim = d = p["dim"]
        self.X = np.array(p["nodes"], dtype=float)  # n × d
        cells = np.array(p["cells"], dtype=int)  # c × (d+1)
        self.mesh = gf.Mesh("ptND", self.X.T, cells.T)
        pts = self.mesh.pts().T
        if pts.shape != self.X.shape or np.max(np.abs(pts - self.X)) != 0.0:
            raise RuntimeError("GetFEM renumbered or moved the mesh points")
        if self.mesh.nbcvs() != cells.shape[0]:
            raise RuntimeError("GetFEM merged cells")
        # boundary regions: the outer faces whose vertex set is a facet of the part
        outer = self.mesh.outer_faces()
        by_vertices = {}
        for k in range(outer.shape[1]):
            face = outer[:, k : k + 1]
            pids = self.mesh.pid_in_faces(face)
            by_vertices[frozenset(int(i) for i in pids)] = face
        for region, key in ((TOP, "prescribed_facets"), (CONTACT, "contact_facets")):
            faces = []
            for f in p[key]:
                face = by_vertices.get(frozenset(f))
                if face is None:
                    raise RuntimeError(f"{key}: facet {f} is not an outer face of the GetFEM mesh")
                faces.append(face)
            self.mesh.set_region(region, np.hstack(faces))
        self.mf = gf.MeshFem(self.mesh, d)
        self.mf.set_classical_fem(1)
        self.mim = gf.MeshIm(self.mesh, 1)  # F is constant on a P1 cell: exact
        # node of every vector dof, and the component (checked, not assumed)
        dof_x = self.mf.basic_dof_nodes().T  # ndof × d
        dist, node = cKDTree(self.X).query(dof_x)
        if np.max(dist) > 1e-12:
            raise RuntimeError("a dof does not sit on a mesh node")
        self.ndof = dof_x.shape[0]
        self.dof_node = node
        self.dof_comp = np.zeros(self.ndof, dtype=int)
        seen = {}
        for k, n in enumerate(node):
            self.dof_comp[k] = seen.get(n, 0)
            seen[n] = self.dof_comp[k] + 1
        self.node_dof = np.full((self.X.shape[0], d), -1, dtype=int)
        self.node_dof[self.dof_node, self.dof_comp] = np.arange(self.ndof)
        if np.any(self.node_dof < 0):
            raise RuntimeError("a node without its d dofs")
        # the contact nodes in the order of the brick's multipliers: GetFEM's nodal contact
        # bricks take the dofs of the region in increasing order, one row per node (the
        # first dof of each node); checked below against the reaction forces
        region_dofs = np.sort(self.mf.basic_dof_on_region(CONTACT))
        self.contact_nodes_gf, seen = [], set()
        for k in region_dofs:
            n = int(self.dof_node[k])
            if n not in seen:
                seen.add(n)
                self.contact_nodes_gf.append(n)
        if sorted(self.contact_nodes_gf) != sorted(p["contact_nodes"]):
            raise RuntimeError("GetFEM's contact region has other nodes than synovia's contact part")

    def nodal(self, U):
        """Vector dofs → n × d nodal array."""
        return U[self.node_dof]


def solve_getfem(p, disc, finite, steps, max_res):
    """GetFEM's solution (nodal displacements, nodal contact forces per node, report)."""
    d = disc.dim
    md = gf.Model("real")
    md.add_fem_variable("u", disc.mf)
    lam, mu = p["lambda"], p["mu"]
    if finite:
        md.add_initialized_data("params", [lam, mu])
        md.add_finite_strain_elasticity_brick(disc.mim, "Compressible_Neo_Hookean_Bonet", "u", "params")
    else:
        md.add_initialized_data("lambda", [lam])
        md.add_initialized_data("mu", [mu])
        md.add_isotropic_linearized_elasticity_brick(disc.mim, "u", "lambda", "mu")
    push = np.array(p["prescribed_displacement"], dtype=float)
    md.add_initialized_data("top", np.zeros(d))
    md.add_Dirichlet_condition_with_simplification("u", TOP, "top")
    nbc = len(disc.contact_nodes_gf)
    md.add_variable("lambda_n", nbc)
    md.add_initialized_data("r", [p["youngs_modulus"]])
    obstacle = "y" if d == 2 else "z"
    md.add_nodal_contact_with_rigid_obstacle_brick(disc.mim, "u", "lambda_n", "r", CONTACT, obstacle)
    iterations, curve = [], []
    start = time.time()
    for k in range(1, steps + 1):
        md.set_variable("top", push * k / steps)
        out = md.solve("max_iter", 100, "max_res", max_res, "lsearch", "simplest")
        iterations.append(int(np.ravel(out)[0]))
        if len(np.ravel(out)) > 1 and not np.ravel(out)[1]:
            raise RuntimeError(f"GetFEM Newton did not converge at step {k}")
        curve.append((float(np.linalg.norm(push)) * k / steps, float(-np.sum(md.variable("lambda_n")))))
    elapsed = time.time() - start
    U = md.variable("u")
    multipliers = md.variable("lambda_n")
    # nodal contact forces from the elastic reaction: F_int at the contact nodes (the only
    # other loads on them); independent of the multipliers' ordering and sign convention
    start_u, size_u = (int(v) for v in np.ravel(md.interval_of_variable("u")))
    residual = elastic_force(md, disc, finite, lam, mu)[start_u : start_u + size_u]
    reaction = disc.nodal(residual)[:, d - 1]
    return {
        "u": disc.nodal(U),
        "multipliers": multipliers,
        "reaction": reaction,
        "iterations": iterations,
        "curve": curve,
        "time_s": elapsed,
    }


def elastic_force(md, disc, finite, lam, mu):
    """F_int(u) assembled by GetFEM's generic assembly (the weak form of the brick)."""
    d = disc.dim
    if finite:
        law = "Compressible_Neo_Hookean_Bonet"
        if d == 2:
            law = "Plane_Strain_" + law
        # first Piola–Kirchhoff P = F S with S = ∂W/∂E from the potential's derivative
        md.add_initialized_data("lm_params", [lam, mu])
        expr = f"({law}_PK2(Grad_u, lm_params)) : ((Id(meshdim)+Grad_u)'*Grad_Test_u)"
    else:
        md.add_initialized_data("lin_lambda", [lam])
        md.add_initialized_data("lin_mu", [mu])
        expr = "(lin_lambda*Trace(Sym(Grad_u))*Id(meshdim) + 2*lin_mu*Sym(Grad_u)) : Grad_Test_u"
    return gf.asm("generic", disc.mim, 1, expr, -1, md)


def strain_measures(disc, cells, u, touching=None):
    """max |eig E| (Green–Lagrange), max ‖∇u‖₂, min det F over the cells (those with a node in
    `touching` if given)."""
    d = disc.dim
    X = disc.X
    e_max, h_max, j_min = 0.0, 0.0, np.inf
    for c in cells:
        if touching is not None and not any(int(i) in touching for i in c):
            continue
        dm = (X[c[1:]] - X[c[0]]).T
        du = (u[c[1:]] - u[c[0]]).T
        h = du @ np.linalg.inv(dm)
        f = np.eye(d) + h
        e = 0.5 * (f.T @ f - np.eye(d))
        e_max = max(e_max, np.max(np.abs(np.linalg.eigvalsh(e))))
        h_max = max(h_max, np.linalg.norm(h, 2))
        j_min = min(j_min, np.linalg.det(f))
    return e_max, h_max, j_min


def contact_forces(p, solution, disc):
    """Per mesh node: synovia's κ Λ_n at its contact nodes."""
    n = disc.X.shape[0]
    f = np.zeros(n)
    c = solution["contact"]
    f[np.array(c["nodes"], dtype=int)] = np.array(c["nodal_force"])
    return f


def compare(p, disc, steps, max_res):
    d = disc.dim
    cells = np.array(p["cells"], dtype=int)
    contact = np.array(sorted(p["contact_nodes"]), dtype=int)
    sy_fs = p["synovia"]["finite_strain"]
    sy_lin = p["synovia"]["linear"]
    u_sy = np.array(sy_fs["displacement"])
    u_sy_lin = np.array(sy_lin["displacement"])
    f_sy = contact_forces(p, sy_fs, disc)
    f_sy_lin = contact_forces(p, sy_lin, disc)

    gf_fs = solve_getfem(p, disc, True, steps or p["levels"], max_res)
    gf_lin = solve_getfem(p, disc, False, 1, max_res)

    # the multipliers: GetFEM's sign convention (compression negative) and ordering, checked
    # against the reaction forces
    mult = np.zeros(disc.X.shape[0])
    mult[np.array(disc.contact_nodes_gf)] = -gf_fs["multipliers"]
    mult_vs_reaction = np.max(np.abs(mult[contact] - gf_fs["reaction"][contact])) / np.max(np.abs(mult))

    umax = np.max(np.linalg.norm(u_sy, axis=1))

    def u_diff(a, b):
        return float(np.max(np.linalg.norm(a - b, axis=1)) / umax)

    f_gf = mult
    F_gf = float(np.sum(f_gf))
    F_sy = float(np.sum(f_sy))
    F_sy_lin = float(np.sum(f_sy_lin))
    f_gf_lin = np.zeros(disc.X.shape[0])
    f_gf_lin[np.array(disc.contact_nodes_gf)] = -gf_lin["multipliers"]
    F_gf_lin = float(np.sum(f_gf_lin))
    fmax = np.max(np.abs(f_gf))

    def active(f, u):
        # in contact: a positive nodal force, or the node on the plane
        on_plane = np.abs(disc.X[:, d - 1] + u[:, d - 1]) <= 1e-9
        return set(int(i) for i in contact if f[i] > 1e-9 * fmax), set(int(i) for i in contact if on_plane[i])

    act_gf, plane_gf = active(f_gf, gf_fs["u"])
    act_sy, plane_sy = active(f_sy, u_sy)
    e_gf, h_gf, j_gf = strain_measures(disc, cells, gf_fs["u"])
    e_surface, _, _ = strain_measures(disc, cells, gf_fs["u"], act_gf)
    # force–indentation curve at the indentations both computed
    curve_diff, curve_points = 0.0, 0
    for a, f in sy_fs["force_indentation"]:
        for b, g in gf_fs["curve"]:
            if abs(a - b) <= 1e-12 * max(abs(a), 1.0):
                curve_diff = max(curve_diff, abs(f - g) / abs(g))
                curve_points += 1
    res = {
        "dim": d,
        "nodes": int(disc.X.shape[0]),
        "cells": int(cells.shape[0]),
        "contact_nodes": int(contact.size),
        "push": float(-np.sum(p["prescribed_displacement"])),
        "max_abs_u": float(umax),
        "max_green_lagrange_getfem": float(e_gf),
        "max_green_lagrange_synovia": float(sy_fs["max_green_lagrange"]),
        "max_green_lagrange_contact_cells": float(e_surface),
        "max_grad_u_getfem": float(h_gf),
        "min_det_f_getfem": float(j_gf),
        "u_diff_finite": u_diff(u_sy, gf_fs["u"]),
        "force_getfem": F_gf,
        "force_synovia": F_sy,
        "force_rel_diff": abs(F_sy - F_gf) / abs(F_gf),
        "nodal_force_max_diff_rel": float(np.max(np.abs(f_sy - f_gf)) / fmax),
        "force_indentation_getfem": gf_fs["curve"],
        "force_indentation_points": curve_points,
        "force_indentation_max_rel_diff": curve_diff,
        "active_getfem": len(act_gf),
        "active_synovia": len(act_sy),
        "active_set_symmetric_difference": sorted(act_gf ^ act_sy),
        "on_plane_getfem": len(plane_gf),
        "on_plane_synovia": len(plane_sy),
        "getfem_multiplier_vs_reaction": float(mult_vs_reaction),
        "getfem_newton_iterations": gf_fs["iterations"],
        "getfem_time_s": gf_fs["time_s"],
        "synovia_time_s": sy_fs["time_s"],
        # the linear model on the same mesh: GetFEM vs synovia (the driver), and against the
        # finite-strain solution (the comparison can fail)
        "u_diff_linear_getfem_vs_synovia": u_diff(u_sy_lin, gf_lin["u"]),
        "force_linear_getfem": F_gf_lin,
        "force_linear_synovia": F_sy_lin,
        "force_linear_rel_diff": abs(F_sy_lin - F_gf_lin) / abs(F_gf_lin),
        "u_diff_linear_synovia_vs_finite_getfem": u_diff(u_sy_lin, gf_fs["u"]),
        "force_linear_vs_finite_rel_diff": abs(F_sy_lin - F_gf) / abs(F_gf),
    }
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    default_dir = os.path.join(os.path.dirname(here), "out", "getfem_finite_strain")
    ap.add_argument("problems", nargs="*", help="problem files (default: problem2d.json, problem3d.json present)")
    ap.add_argument("--steps", type=int, default=0, help="GetFEM load steps (default: synovia's levels)")
    ap.add_argument("--max-res", type=float, default=1e-11, help="GetFEM Newton residual (default 1e-11)")
    ap.add_argument("--tolerance", type=float, default=1e-6, help="agreement required (default 1e-6)")
    args = ap.parse_args()
    files = args.problems or [
        os.path.join(default_dir, f) for f in ("problem2d.json", "problem3d.json") if os.path.exists(os.path.join(default_dir, f))
    ]
    if not files:
        sys.exit("no problem file: run `cargo run --release --example getfem_finite_strain` first")
    gf.util_trace_level(0)
    gf.util_warning_level(0)
    results = []
    ok = True
    for path in files:
        with open(path) as fh:
            p = json.load(fh)
        disc = Discretisation(p)
        r = compare(p, disc, args.steps, args.max_res)
        r["file"] = path
        results.append(r)
        print(f"\n{r['dim']}D: {r['nodes']} nodes, {r['cells']} cells, {r['contact_nodes']} contact nodes, push {r['push']}")
        print(f"  strain: max |eig E| {r['max_green_lagrange_getfem']:.4f} (GetFEM) / {r['max_green_lagrange_synovia']:.4f} (synovia), "
              f"max ‖∇u‖ {r['max_grad_u_getfem']:.3f}, min det F {r['min_det_f_getfem']:.3f}; "
              f"in the cells touching the contact zone max |eig E| {r['max_green_lagrange_contact_cells']:.4f}")
        print(f"  finite strain: max |u_synovia − u_GetFEM| / max |u| = {r['u_diff_finite']:.2e}")
        print(f"  contact force: GetFEM {r['force_getfem']:.12e}, synovia {r['force_synovia']:.12e}, rel. diff {r['force_rel_diff']:.2e}")
        print(f"  nodal contact forces: max diff / max force = {r['nodal_force_max_diff_rel']:.2e}")
        print(f"  force–indentation curve: {r['force_indentation_points']} common points, max rel. diff {r['force_indentation_max_rel_diff']:.2e}")
        print(f"  contact set: {r['active_getfem']} (GetFEM) / {r['active_synovia']} (synovia) nodes with force, "
              f"{r['on_plane_getfem']} / {r['on_plane_synovia']} on the plane, differing nodes {r['active_set_symmetric_difference']}")
        print(f"  GetFEM multipliers vs its elastic reaction: {r['getfem_multiplier_vs_reaction']:.1e}; Newton iterations {r['getfem_newton_iterations']}, {r['getfem_time_s']:.2f} s")
        print(f"  linear (small strain): GetFEM vs synovia u {r['u_diff_linear_getfem_vs_synovia']:.2e}, force {r['force_linear_rel_diff']:.2e}")
        print(f"  linear synovia vs finite-strain GetFEM: u {r['u_diff_linear_synovia_vs_finite_getfem']:.2e}, force {r['force_linear_vs_finite_rel_diff']:.2e}")
        agree = (
            r["u_diff_finite"] <= args.tolerance
            and r["force_rel_diff"] <= args.tolerance
            and r["force_indentation_max_rel_diff"] <= args.tolerance
            and not r["active_set_symmetric_difference"]
        )
        differs = r["u_diff_linear_synovia_vs_finite_getfem"] > 1e-2 or r["force_linear_vs_finite_rel_diff"] > 1e-2
        r["agree"] = bool(agree)
        r["linear_differs"] = bool(differs)
        ok = ok and agree and differs
    print(json.dumps({"bench": "getfem_finite_strain", "getfem": getfem_version(), "tolerance": args.tolerance, "ok": ok, "runs": results}))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
