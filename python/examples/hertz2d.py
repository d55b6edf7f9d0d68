"""2D Hertz contact through Python: a cylinder on a rigid flat, and two cylinders of different
stiffness (the Rust example ``examples/hertz2d.rs``: same runs, same tables and checks, the
same JSON lines; the Rust example also writes a VTU file and an SVG plot, see
``hertz_study.py`` for the plots).

Run: ``python python/examples/hertz2d.py [pdas|au-pdas|uzawa-mprgp|dual-mprgp]``
"""

import sys

import synovia


def table(title, runs):
    print(f"\n{title}")
    print(
        f"{'level':>6} {'h':>10} {'dofs':>8} {'active':>7} {'across':>6} {'iter':>5} {'coarse':>6} {'a':>10} "
        f"{'a err':>10} {'p0 err':>10} {'L2 err':>10} {'solve s':>8} {'A s':>8}"
    )
    for r in runs:
        print(
            f"{r['level']:>6} {r['h']:>10.3e} {r['dofs']:>8} {r['active_nodes']:>7} "
            f"{2.0 * r['a_exact'] / r['h']:>6.0f} {r['iterations']:>5} {r['coarse_iterations']:>6} {r['a']:>10.5f} "
            f"{r['a_rel_err']:>10.2e} {r['p0_rel_err']:>10.2e} {r['pressure_l2_err']:>10.2e} "
            f"{r['solve_s']:>8.3f} {r['linear_solve_s']:>8.3f}"
        )


def main():
    name = sys.argv[1] if len(sys.argv) > 1 else "pdas"
    rigid = [synovia.hertz2d(levels, name) for levels in (8, 10, 12, 14)]
    table("cylinder on a rigid flat (E = 1, ν = 0.3, R = 1)", rigid)
    cold = [synovia.hertz2d(levels, name, nested=False) for levels in (8, 10, 12, 14)]
    table("the same from a cold start (no nested iteration)", cold)
    pair = [synovia.hertz2d(levels, name, e2=3.0) for levels in (8, 10, 12)]
    table("two cylinders (E₁ = 1, E₂ = 3, ν = 0.3, R₁ = R₂ = 1)", pair)

    for r in rigid + pair:
        if 2.0 * r["a_exact"] / r["h"] >= 40.0:
            assert r["a_rel_err"] < 0.02 and r["p0_rel_err"] < 0.02 and r["pressure_l2_err"] < 0.03, r
    first, last = rigid[0]["iterations"], rigid[-1]["iterations"]
    print(f"\n{name} iterations over refinement (levels 8, 10, 12, 14; h halves per step):")
    print(f"  nested, final solve: {[r['iterations'] for r in rigid]}")
    print(f"  nested, coarse levels: {[r['coarse_iterations'] for r in rigid]}")
    print(f"  cold start: {[r['iterations'] for r in cold]}")
    assert name != "pdas" or last <= first + 3, "PDAS iterations grow with refinement"
    for r in rigid + cold + pair:
        print(synovia.hertz_json(r))


if __name__ == "__main__":
    main()
