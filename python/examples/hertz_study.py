"""A Hertz study through Python: 2D (cylinder on a rigid flat) and 3D (hemisphere on a rigid
flat) over refinements, the computed nodal contact pressure against the Hertz curve
``p(r) = p0 sqrt(1 - r²/a²)`` and the errors of ``a``, ``p0`` and the pressure profile against
the mesh size. Writes ``out/python/hertz_study.png`` (Matplotlib, no display needed) and prints
one JSON line per run (the keys of the Rust examples ``hertz2d`` / ``hertz3d``).

Run: ``python python/examples/hertz_study.py [solver] [out_dir]``
"""

import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import synovia  # noqa: E402


def hertz_curve(run, r):
    a, p0 = run["a_exact"], run["p0_exact"]
    return np.where(np.abs(r) < a, p0 * np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None)), 0.0)


def main():
    solver = sys.argv[1] if len(sys.argv) > 1 else "pdas"
    out_dir = sys.argv[2] if len(sys.argv) > 2 else os.path.join("out", "python")
    os.makedirs(out_dir, exist_ok=True)
    runs2d = [synovia.hertz2d(levels, solver) for levels in (8, 10, 12, 14)]
    runs3d = [synovia.hertz3d(levels, solver) for levels in (10, 12, 14)]

    fig, ax = plt.subplots(1, 3, figsize=(16, 4.8))
    for axis, run, title, xlabel in (
        (ax[0], runs2d[-1], "2D: cylinder on a rigid flat", "x / R"),
        (ax[1], runs3d[-1], "3D: hemisphere on a rigid flat", "r / R"),
    ):
        prof = run["profile"]
        rmax = 1.5 * run["a_exact"]
        r = np.linspace(-rmax if run["problem"].startswith("hertz2d") else 0.0, rmax, 400)
        axis.plot(r, hertz_curve(run, r), "r-", label="Hertz: $p_0\\sqrt{1 - r^2/a^2}$")
        sel = np.abs(prof[:, 0]) <= rmax
        axis.plot(prof[sel, 0], prof[sel, 1], "b.", ms=3, label="computed nodal pressure")
        axis.set_title(f"{title} (level {run['level']}, {run['dofs']} dofs)")
        axis.set_xlabel(xlabel)
        axis.set_ylabel("contact pressure / E")
        axis.legend(loc="upper right", fontsize=8)
        axis.set_ylim(0, 1.2 * run["p0_exact"])
        axis.grid(alpha=0.3)
    for runs, marker, name in ((runs2d, "o", "2D"), (runs3d, "s", "3D")):
        h = np.array([r["h"] for r in runs])
        ax[2].loglog(h, [r["a_rel_err"] for r in runs], marker + "-", label=f"{name}: |a − a_H| / a_H")
        ax[2].loglog(h, [r["p0_rel_err"] for r in runs], marker + "--", label=f"{name}: |p0 − p0_H| / p0_H")
        ax[2].loglog(h, [r["pressure_l2_err"] for r in runs], marker + ":", label=f"{name}: L² error of p")
    ax[2].set_xlabel("mesh size h at the contact point")
    ax[2].set_ylabel("relative error")
    ax[2].set_title(f"errors against Hertz ({solver})")
    ax[2].legend(fontsize=7)
    ax[2].grid(alpha=0.3, which="both")
    fig.tight_layout()
    png = os.path.join(out_dir, "hertz_study.png")
    fig.savefig(png, dpi=110)
    print(f"wrote {png}")
    for r in runs2d + runs3d:
        print(f"{r['problem']:>16} level {r['level']:>2}: a err {r['a_rel_err']:.2e}, p0 err {r['p0_rel_err']:.2e}, "
              f"L2 err {r['pressure_l2_err']:.2e}, KKT {r['kkt']:.1e}")
    for r in runs2d + runs3d:
        print(synovia.hertz_json(r))


if __name__ == "__main__":
    main()
