#!/usr/bin/env python3
"""Unfolds the crumpled spots of a closed triangle surface (binary or ASCII STL in, binary STL out).

Decimated implant surfaces (e.g. data/tka-grand-challenge-dm/tibial_insert.stl) have small
crumples along sharp rims: neighbouring triangles folded back onto each other (normals at more
than FOLD_DEG degrees), which make the surface intersect itself, and Gmsh's 3D mesher then stops
with "Invalid boundary mesh (segment-facet intersection)". This script moves only the vertices
near such folds: Laplacian smoothing (each vertex to the mean of its neighbours) of the vertices
within RING edges of a folded edge, repeated until no fold is left. Every other vertex is kept
bit for bit. Python standard library only.

usage: stl_unfold.py IN.stl OUT.stl [fold angle in degrees, default 110]

Folds that smoothing leaves unchanged (a genuine knife edge) are reported and kept.
"""
import argparse
import heapq
import math
import struct
import sys
from collections import defaultdict

RING = 2
# Edges end up between MAX_EDGE / 2 and MAX_EDGE times the target size (mean about the size).
MAX_EDGE = 1.25


def read_stl(path):
    data = open(path, "rb").read()
    corners = []
    if data[:5] == b"solid" and b"facet" in data[:1000]:
        for line in data.decode("ascii", "replace").splitlines():
            w = line.split()
            if w and w[0] == "vertex":
                corners.append(tuple(float(x) for x in w[1:4]))
    else:
        n = struct.unpack("<I", data[80:84])[0]
        for i in range(n):
            v = struct.unpack("<12f", data[84 + 50 * i : 84 + 50 * i + 48])
            corners.extend([v[3:6], v[6:9], v[9:12]])
    index, points, tris = {}, [], []
    for k in range(0, len(corners), 3):
        t = []
        for p in corners[k : k + 3]:
            if p not in index:
                index[p] = len(points)
                points.append(list(p))
            t.append(index[p])
        tris.append(t)
    return points, tris


def normal(points, t):
    a, b, c = (points[i] for i in t)
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    x = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    n = math.sqrt(sum(q * q for q in x)) or 1.0
    return [q / n for q in x]


def folded_vertices(points, tris, edges, cos_fold):
    out = set()
    normals = [normal(points, t) for t in tris]
    for e, ts in edges.items():
        if len(ts) == 2 and sum(normals[ts[0]][k] * normals[ts[1]][k] for k in range(3)) < cos_fold:
            out.update(e)
    return out


def adjacency(tris):
    edges = defaultdict(list)
    nbr = defaultdict(set)
    for i, t in enumerate(tris):
        for j in range(3):
            a, b = t[j], t[(j + 1) % 3]
            edges[(min(a, b), max(a, b))].append(i)
            nbr[a].add(b)
            nbr[b].add(a)
    return edges, nbr


def smooth(points, tris, edges, nbr, cos_fold, moved):
    """Laplacian smoothing near folds until none is left or the folds stop changing."""
    history = []
    for rnd in range(30):
        bad = folded_vertices(points, tris, edges, cos_fold)
        print(f"round {rnd}: {len(bad)} vertices on folded edges", file=sys.stderr)
        history.append(bad)
        if not bad or (len(history) >= 4 and history[-4] == bad):
            return bad
        region = set(bad)
        for _ in range(RING):
            region |= {m for v in region for m in nbr[v]}
        moved |= region
        for _ in range(5):
            new = {v: [sum(points[m][k] for m in nbr[v]) / len(nbr[v]) for k in range(3)] for v in region}
            for v, p in new.items():
                points[v] = p
    return bad


def collapse(points, tris, bad, nbr):
    target = {}
    for v in sorted(bad):
        if v in target:
            continue
        cluster, stack = {v}, [v]
        while stack:
            u = stack.pop()
            for m in nbr[u]:
                if m in bad and m not in cluster:
                    cluster.add(m)
                    stack.append(m)
        points.append([sum(points[u][k] for u in cluster) / len(cluster) for k in range(3)])
        for u in cluster:
            target[u] = len(points) - 1
    out = [[target.get(i, i) for i in t] for t in tris]
    out = [t for t in out if len(set(t)) == 3]
    count = defaultdict(int)
    for t in out:
        count[frozenset(t)] += 1
    return [t for t in out if count[frozenset(t)] == 1]


def refine(points, tris, size):
    """Longest-edge bisection until every edge is at most size(midpoint) long. The midpoint of a
    split edge lies on both of its triangles, so the shape of the surface does not change."""
    owners = defaultdict(list)
    for i, t in enumerate(tris):
        for j in range(3):
            owners[frozenset((t[j], t[(j + 1) % 3]))].append(i)

    def excess(e):
        a, b = (points[v] for v in e)
        return math.dist(a, b) / size([(a[k] + b[k]) / 2 for k in range(3)])

    while True:
        todo = sorted((e for e in owners if excess(e) > 1), key=excess, reverse=True)
        if not todo:
            return
        for e in todo:
            if e not in owners or excess(e) <= 1:
                continue
            a, b = tuple(e)
            points.append([(points[a][k] + points[b][k]) / 2 for k in range(3)])
            m = len(points) - 1
            for i in owners.pop(e):
                t = tris[i]
                j = next(j for j in range(3) if {t[j], t[(j + 1) % 3]} == {a, b})
                p, q, r = t[j], t[(j + 1) % 3], t[(j + 2) % 3]  # edge p-q split, r opposite
                tris[i] = [p, m, r]
                tris.append([m, q, r])
                n = len(tris) - 1
                owners[frozenset((q, r))] = [n if x == i else x for x in owners[frozenset((q, r))]]
                owners[frozenset((p, m))].append(i)
                owners[frozenset((m, q))].append(n)
                owners[frozenset((m, r))] += [i, n]


def tri_quality(p, q, r):
    """4 sqrt(3) area / sum of squared edges: 1 for an equilateral triangle, 0 for a flat one."""
    n = cross(sub(q, p), sub(r, p))
    l2 = dot(sub(q, p), sub(q, p)) + dot(sub(r, q), sub(r, q)) + dot(sub(p, r), sub(p, r))
    return 2 * math.sqrt(3) * math.sqrt(dot(n, n)) / l2 if l2 > 0 else 0.0


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def decimate(points, tris, size, ratio, feature_deg, normal_deg):
    """Edge collapse onto an existing vertex, shortest edges (relative to size) first, for edges
    shorter than ratio * size. Sharp edges (normals more than feature_deg apart) are kept: a
    vertex on one sharp line moves only along it, a corner of sharp lines never moves. A
    collapse is refused when it breaks the link condition (would make the surface
    non-manifold), turns a triangle's normal by more than normal_deg, makes a triangle worse
    than min(0.2, its old quality) or an edge longer than size. Vertices keep their positions,
    so the surface's points stay on the original surface."""
    cos_feat = math.cos(math.radians(feature_deg))
    cos_turn = math.cos(math.radians(normal_deg))
    vt = defaultdict(set)
    for i, t in enumerate(tris):
        for v in t:
            vt[v].add(i)
    edges, _ = adjacency(tris)
    normals = [normal(points, t) for t in tris]
    feature = set()
    for e, ts in edges.items():
        if len(ts) == 2 and dot(normals[ts[0]], normals[ts[1]]) < cos_feat:
            feature.add(frozenset(e))
    fdeg = defaultdict(int)
    for e in feature:
        for v in e:
            fdeg[v] += 1

    def nbrs(v):
        return {u for i in vt[v] for u in tris[i]} - {v}

    def rel_len(a, b):
        pa, pb = points[a], points[b]
        return math.dist(pa, pb) / size([(pa[k] + pb[k]) / 2 for k in range(3)])

    heap = []
    for e in edges:
        r = rel_len(*e)
        if r < ratio:
            heap.append((r, e[0], e[1]))
    heapq.heapify(heap)

    def try_collapse(a, b):
        """Moves a onto b if allowed; returns True when done."""
        if fdeg[a] not in (0, 2):
            return False
        if fdeg[a] == 2 and frozenset((a, b)) not in feature:
            return False
        shared = [i for i in vt[a] if b in tris[i]]
        if len(shared) != 2:
            return False
        opposite = {u for i in shared for u in tris[i]} - {a, b}
        if nbrs(a) & nbrs(b) != opposite:
            return False
        for i in vt[a]:
            if i in shared:
                continue
            t = tris[i]
            new = [b if v == a else v for v in t]
            p = [points[v] for v in new]
            n_new = cross(sub(p[1], p[0]), sub(p[2], p[0]))
            ln = math.sqrt(dot(n_new, n_new))
            if ln == 0 or dot(n_new, normals[i]) / ln < cos_turn:
                return False
            old_q = tri_quality(*(points[v] for v in t))
            if tri_quality(*p) < min(0.2, old_q):
                return False
            for u in new:
                if u != b and rel_len(u, b) > MAX_EDGE:
                    return False
        for i in shared:
            for v in tris[i]:
                if v != a:
                    vt[v].discard(i)
            tris[i] = None
        for i in vt[a]:
            if tris[i] is None:
                continue
            tris[i] = [b if v == a else v for v in tris[i]]
            normals[i] = normal(points, tris[i])
            vt[b].add(i)
        if fdeg[a]:
            for e in [e for e in feature if a in e]:
                feature.discard(e)
                (u,) = e - {a}
                fdeg[u] -= 1
                if u != b and frozenset((u, b)) not in feature:
                    feature.add(frozenset((u, b)))
                    fdeg[u] += 1
                    fdeg[b] += 1
        fdeg[a] = 0
        vt[a] = set()
        for u in nbrs(b):
            r = rel_len(u, b)
            if r < ratio:
                heapq.heappush(heap, (r, u, b))
        return True

    while heap:
        r, a, b = heapq.heappop(heap)
        if not vt[a] or not vt[b] or b not in nbrs(a) or abs(rel_len(a, b) - r) > 1e-12:
            continue
        if not try_collapse(a, b):
            try_collapse(b, a)
    return [t for t in tris if t is not None]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--fold", type=float, default=110.0, help="fold angle (degrees) between normals")
    ap.add_argument("--no-unfold", action="store_true", help="only refine")
    ap.add_argument(
        "--refine",
        nargs=5,
        type=float,
        metavar=("H", "HMAX", "YFINE", "YGROW", "SCALE"),
        help="target size min(HMAX, H + (HMAX - H) / YGROW * max(0, YFINE - y)): split edges longer "
        "than 1.25 times it (lengths in mm; the STL's units times SCALE are mm)",
    )
    ap.add_argument(
        "--coarsen",
        type=float,
        default=0.75,
        help="with --refine: first collapse edges shorter than this fraction of the size (0: none)",
    )
    args = ap.parse_args()
    cos_fold = math.cos(math.radians(args.fold))
    points, tris = read_stl(args.input)
    moved = set()
    for _ in range(0 if args.no_unfold else 5):
        edges, nbr = adjacency(tris)
        bad = smooth(points, tris, edges, nbr, cos_fold, moved)
        if not bad:
            break
        # Folds that smoothing does not undo are tangles of a few vertices: collapse each
        # connected cluster of them into one vertex at its mean, drop the triangles that
        # become degenerate or doubled, and smooth again.
        tris = collapse(points, tris, bad, nbr)
        print(f"collapsed {len(bad)} tangled vertices", file=sys.stderr)
    else:
        if not args.no_unfold:
            sys.exit("stl_unfold.py: folds remain")
    print(f"unfold: {len(moved)} of {len(points)} vertices moved, {len(tris)} triangles", file=sys.stderr)
    if args.refine:
        h, hmax, yfine, ygrow, scale = args.refine
        grow = (hmax - h) / ygrow

        def size(p):
            return min(hmax, h + grow * max(0.0, yfine - p[1] * scale)) / scale

        if args.coarsen > 0:
            tris = decimate(points, tris, size, args.coarsen, 45.0, 20.0)
            print(f"coarsen: {len(tris)} triangles", file=sys.stderr)
        refine(points, tris, lambda p: MAX_EDGE * size(p))
        print(f"refine: {len(tris)} triangles", file=sys.stderr)
    edges, _ = adjacency(tris)
    odd = [e for e, ts in edges.items() if len(ts) != 2]
    if odd:
        sys.exit(f"stl_unfold.py: the result is not closed and manifold ({len(odd)} bad edges)")
    with open(args.output, "wb") as f:
        f.write(b"stl_unfold.py".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", *normal(points, t)))
            for i in t:
                f.write(struct.pack("<3f", *points[i]))
            f.write(b"\0\0")


if __name__ == "__main__":
    main()
