"""3D Hertz contact through Python: a hemisphere on a rigid flat (the Rust example
``examples/hertz3d.rs``, same runs, same table, the same JSON lines).

Run: ``python python/examples/hertz3d.py [pdas|au-pdas|uzawa-mprgp|dual-mprgp]``
"""

import sys

import synovia


def main():
    solver = sys.argv[1] if len(sys.argv) > 1 else "pdas"
    runs = [synovia.hertz3d(levels, solver) for levels in (10, 12, 14)]
    print(
        f"{'level':>6} {'h':>10} {'dofs':>8} {'active':>7} {'iter':>5} {'a':>10} {'a err':>10} "
        f"{'p0 err':>10} {'L2 err':>10} {'solve s':>8} {'A s':>8}"
    )
    for r in runs:
        print(
            f"{r['level']:>6} {r['h']:>10.3e} {r['dofs']:>8} {r['active_nodes']:>7} {r['iterations']:>5} "
            f"{r['a']:>10.5f} {r['a_rel_err']:>10.2e} {r['p0_rel_err']:>10.2e} {r['pressure_l2_err']:>10.2e} "
            f"{r['solve_s']:>8.3f} {r['linear_solve_s']:>8.3f}"
        )
    finest = runs[-1]
    assert finest["a_rel_err"] < 0.05 and finest["p0_rel_err"] < 0.05, finest
    for r in runs:
        print(synovia.hertz_json(r))


if __name__ == "__main__":
    main()
