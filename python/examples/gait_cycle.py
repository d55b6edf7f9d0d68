"""The total knee replacement over a gait cycle, driven from Python (the `tkr3d` main job,
docs/tkr3d.md): the Grand Challenge subject DM's tibial insert (UHMWPE, meshed from its STL,
tray face clamped, 42 063 unknowns) under the rigid femoral component bounded by its STL
surface, posed from the fluoroscopic gait kinematics, its superior–inferior translation
force-controlled by the ISO 14243-1 axial force, with lubricated friction (μ = 0.04) against
the moving femur.

The model is the scenario ``examples/scenarios/tkr3d_stance.toml`` with friction added; it is
factorised once (``Model.prepare()``) and the poses are solved one after the other by the
re-solve session (``solve_static`` for the first pose, quasi-static ``step`` after it), as the
Rust example does. (The scenario's ISO force is a digitised table; the Rust example uses
``synovia_models::knee2d::iso14243_axial_force``, so the figures differ slightly.)

Writes to ``out/python/gait_cycle/``: ``pressure_map.png`` (PyVista, off-screen: the contact
pressure on the insert seen from above at the two load peaks and mid-stance),
``forces.png`` (Matplotlib: medial / lateral force and peak pressure over the cycle) and
``gait_cycle.csv``; prints one table row per pose and one JSON line.

Run: ``python python/examples/gait_cycle.py [--poses 0,13,25,50] [--friction 0.04] [--out DIR]``
"""

import argparse
import json
import os
import pathlib
import re
import tempfile
import time

import numpy as np

import synovia

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "examples" / "scenarios" / "tkr3d_stance.toml"


def scenario_with_friction(friction, directory):
    """The stance scenario with absolute data paths and the friction coefficient."""
    text = SCENARIO.read_text()
    text = text.replace('"../../data/', '"' + (ROOT / "data").as_posix() + "/")
    text, n = re.subn(r"(?m)^search_distance = 3\.0$", f"search_distance = 3.0\nfriction = {friction}", text)
    if n != 1:
        raise RuntimeError("tkr3d_stance.toml changed: cannot add the friction coefficient")
    path = pathlib.Path(directory) / "tkr3d_gait.toml"
    path.write_text(text)
    return path


def run(poses, friction):
    with tempfile.TemporaryDirectory() as tmp:
        model = synovia.Model.from_scenario(scenario_with_friction(friction, tmp))
    start = time.perf_counter()
    rows, pressures = [], []
    with model.prepare() as session:
        print(f"factorised once: {session.n_dofs} unknowns, {session.contact_nodes} contact candidates, "
              f"{session.setup_s:.1f} s")
        print("| cycle % | F (N) | SI (mm) | balance | KKT | medial (N) | lateral (N) | area (mm²) | peak p (MPa) | s |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for k, pct in enumerate(poses):
            t = pct / 100.0
            t0 = time.perf_counter()
            r = session.solve_static(t) if k == 0 or friction == 0 else session.step(t)
            wall = time.perf_counter() - t0
            rec = r.records[0]
            pair, femur = rec["pairs"][0], rec["rigid"][0]
            sides = {s["name"]: s for s in pair["sides"]}
            row = {
                "percent": pct,
                "load": -femur["applied"][1],
                "si_mm": femur["dofs"][1],
                "balance": femur["balance_error"],
                "kkt": r.kkt["max"],
                "medial": sides["medial"]["normal_force"],
                "lateral": sides["lateral"]["normal_force"],
                "friction": pair["tangential_force"],
                "area": pair["contact_area"],
                "peak": pair["peak_pressure"],
                "seconds": wall,
            }
            rows.append(row)
            pressures.append(r.contact_pressure("insert"))
            print(f"| {pct} | {row['load']:.0f} | {row['si_mm']:.3f} | {row['balance']:.1e} | {row['kkt']:.1e} | "
                  f"{row['medial']:.0f} | {row['lateral']:.0f} | {row['area']:.1f} | {row['peak']:.2f} | "
                  f"{row['seconds']:.2f} |")
        nodes, cells = r.nodes("insert"), r.cells("insert")
    return rows, pressures, nodes, cells, time.perf_counter() - start


def plot_forces(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pct = [r["percent"] for r in rows]
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2))
    ax[0].plot(pct, [r["load"] for r in rows], "k-", label="ISO axial force (applied)")
    ax[0].plot(pct, [r["medial"] for r in rows], "b.-", label="medial normal contact force")
    ax[0].plot(pct, [r["lateral"] for r in rows], "r.-", label="lateral normal contact force")
    ax[0].set_xlabel("gait cycle (%)")
    ax[0].set_ylabel("force (N)")
    ax[0].legend(fontsize=8)
    ax[0].grid(alpha=0.3)
    ax[1].plot(pct, [r["peak"] for r in rows], "m.-")
    ax[1].set_xlabel("gait cycle (%)")
    ax[1].set_ylabel("peak contact pressure (MPa)")
    ax[1].grid(alpha=0.3)
    fig.suptitle("TKR (Grand Challenge DM) over the gait cycle, from Python")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def plot_pressure_maps(rows, pressures, nodes, cells, path):
    import pyvista as pv

    pv.OFF_SCREEN = True
    pct = [r["percent"] for r in rows]
    # the two load peaks and mid-stance (the poses nearest to 13 %, 25 % and 50 %)
    wanted = []
    for target in (13, 25, 50):
        k = int(np.argmin([abs(p - target) for p in pct]))
        if k not in wanted:
            wanted.append(k)
    grid = pv.UnstructuredGrid({pv.CellType.TETRA: cells.astype(np.int64)}, nodes)
    surface_ids = grid.extract_surface(algorithm="dataset_surface").point_data["vtkOriginalPointIds"]
    pmax = max(float(np.max(pressures[k])) for k in wanted) or 1.0
    plotter = pv.Plotter(shape=(1, len(wanted)), off_screen=True, window_size=(520 * len(wanted), 560))
    for i, k in enumerate(wanted):
        plotter.subplot(0, i)
        g = grid.copy()
        # no contact: grey, so the insert's shape shows under the lighting
        g.point_data["contact pressure (MPa)"] = np.where(pressures[k] > 0.0, pressures[k], np.nan)
        surf = g.extract_surface(algorithm="dataset_surface")
        plotter.add_mesh(
            surf,
            scalars="contact pressure (MPa)",
            cmap="turbo",
            clim=[0.0, pmax],
            nan_color="lightgray",
            show_edges=False,
            scalar_bar_args={"title": "contact pressure (MPa)", "fmt": "%.0f", "vertical": False},
        )
        r = rows[k]
        plotter.add_text(
            f"{r['percent']} % of the cycle: F = {r['load']:.0f} N\n"
            f"medial {r['medial']:.0f} N, lateral {r['lateral']:.0f} N, peak {r['peak']:.1f} MPa",
            font_size=9,
        )
        plotter.add_text("seen from above: +x (anterior) up, +z (lateral) right", position="lower_right", font_size=7)
        # seen from above (superior = +y), anterior (+x) up, lateral (+z) to the right
        plotter.view_vector((0.0, 1.0, 0.0), viewup=(1.0, 0.0, 0.0))
        plotter.camera.zoom(1.3)
    plotter.screenshot(str(path))
    plotter.close()
    return len(surface_ids)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", default="0-100", help="percentages of the cycle: 0-100 or e.g. 0,13,25,50")
    parser.add_argument("--friction", type=float, default=0.04)
    parser.add_argument("--out", default=os.path.join("out", "python", "gait_cycle"))
    args = parser.parse_args()
    if "-" in args.poses:
        a, b = map(int, args.poses.split("-"))
        poses = list(range(a, b + 1))
    else:
        poses = [int(p) for p in args.poses.split(",")]
    os.makedirs(args.out, exist_ok=True)

    rows, pressures, nodes, cells, seconds = run(poses, args.friction)
    with open(os.path.join(args.out, "gait_cycle.csv"), "w") as f:
        keys = list(rows[0])
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(f"{r[k]:.9g}" for k in keys) + "\n")
    plot_forces(rows, os.path.join(args.out, "forces.png"))
    plot_pressure_maps(rows, pressures, nodes, cells, os.path.join(args.out, "pressure_map.png"))
    print(f"wrote {args.out}/pressure_map.png, forces.png, gait_cycle.csv")
    worst_balance = max(r["balance"] for r in rows)
    worst_kkt = max(r["kkt"] for r in rows)
    summary = {
        "poses": len(rows),
        "friction": args.friction,
        "solve_s": round(seconds, 2),
        "max_balance_error": worst_balance,
        "max_kkt": worst_kkt,
        "peak_load_n": max(r["load"] for r in rows),
        "peak_pressure_mpa": max(r["peak"] for r in rows),
        "peak_pressure_at_percent": max(rows, key=lambda r: r["peak"])["percent"],
        "max_contact_area_mm2": max(r["area"] for r in rows),
        "max_medial_force_n": max(r["medial"] for r in rows),
        "max_lateral_force_n": max(r["lateral"] for r in rows),
        "max_friction_force_n": max(r["friction"] for r in rows),
    }
    print(json.dumps(summary))
    assert worst_balance < 1e-3 and worst_kkt < 1e-3, summary


if __name__ == "__main__":
    main()
