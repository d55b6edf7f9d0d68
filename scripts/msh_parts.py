#!/usr/bin/env python3
"""Names the boundary of a one-body tetrahedral mesh by geometry and writes it as MSH 4.1 ASCII.

Reads a Gmsh MSH 2.2 ASCII file (the 4-node tetrahedra, type 4; everything else is ignored),
finds the boundary triangles (faces of exactly one tetrahedron, oriented outward) and writes
one physical volume BODY and three physical surfaces:

  tray       boundary triangles whose three nodes have |y| <= TRAY_TOL (mm) and whose outward normal
             points down (n_y < -0.99): the flat back face at y = 0;
  articular  boundary triangles with outward normal n_y > NY_MIN whose centroid lies above
             y = Y_MIN: the upward-facing top surfaces;
  side       every other boundary triangle.

Prints node and tetrahedron counts, the triangles of each part, the volume, and the minimum
mean-ratio quality of the tetrahedra (12 (3V)^(2/3) / sum of squared edge lengths: 1 for a
regular tetrahedron, 0 for a flat one). Python standard library only.

usage: msh_parts.py IN.msh OUT.msh BODY Y_MIN NY_MIN TRAY_TOL
"""
import math
import sys


def read_msh22(path):
    nodes, tets = {}, []
    with open(path) as f:
        lines = iter(f)
        for line in lines:
            s = line.strip()
            if s == "$MeshFormat":
                version = next(lines).split()
                if not version[0].startswith("2") or version[1] != "0":
                    sys.exit(f"{path}: expected MSH 2.2 ASCII, found {' '.join(version)}")
            elif s == "$Nodes":
                for _ in range(int(next(lines))):
                    w = next(lines).split()
                    nodes[int(w[0])] = tuple(float(x) for x in w[1:4])
            elif s == "$Elements":
                for _ in range(int(next(lines))):
                    w = next(lines).split()
                    if w[1] == "4":
                        tets.append([int(x) for x in w[3 + int(w[2]) :]])
    return nodes, tets


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def main():
    if len(sys.argv) != 7:
        sys.exit(__doc__)
    src, dst, body = sys.argv[1:4]
    y_min, ny_min, tray_tol = (float(x) for x in sys.argv[4:7])
    nodes, tets = read_msh22(src)
    volume, quality = 0.0, 1.0
    faces = {}
    for k, t in enumerate(tets):
        p = [nodes[i] for i in t]
        v6 = dot(sub(p[1], p[0]), cross(sub(p[2], p[0]), sub(p[3], p[0])))
        if v6 < 0:  # orient positively
            t[1], t[2] = t[2], t[1]
            p[1], p[2] = p[2], p[1]
            v6 = -v6
        volume += v6 / 6
        l2 = sum(dot(sub(p[i], p[j]), sub(p[i], p[j])) for i in range(4) for j in range(i + 1, 4))
        quality = min(quality, 12 * (v6 / 2) ** (2 / 3) / l2)
        # faces opposite each vertex, ordered so the normal points out of the tetrahedron
        for f in ((t[1], t[2], t[3]), (t[0], t[3], t[2]), (t[0], t[1], t[3]), (t[0], t[2], t[1])):
            key = frozenset(f)
            if key in faces:
                del faces[key]
            else:
                faces[key] = f
    parts = {"tray": [], "articular": [], "side": []}
    for f in faces.values():
        a, b, c = (nodes[i] for i in f)
        n = cross(sub(b, a), sub(c, a))
        ln = math.sqrt(dot(n, n))
        ny = n[1] / ln
        if max(abs(a[1]), abs(b[1]), abs(c[1])) <= tray_tol and ny < -0.99:
            parts["tray"].append(f)
        elif ny > ny_min and (a[1] + b[1] + c[1]) / 3 > y_min:
            parts["articular"].append(f)
        else:
            parts["side"].append(f)
    used = sorted({i for t in tets for i in t})
    print(f"{len(used)} nodes, {len(tets)} tetrahedra, volume {volume:.6g}, min mean-ratio quality {quality:.4f}")
    for name, fs in parts.items():
        if not fs:
            sys.exit(f"msh_parts.py: part {name} is empty")
        print(f"  {name}: {len(fs)} triangles")
    lo = [min(nodes[i][k] for i in used) for k in range(3)]
    hi = [max(nodes[i][k] for i in used) for k in range(3)]
    box = " ".join(f"{x:.17g}" for x in lo + hi)
    names = list(parts)
    with open(dst, "w") as out:
        w = out.write
        w("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")
        w(f"$PhysicalNames\n{1 + len(names)}\n")
        for s, name in enumerate(names, start=1):
            w(f'2 {s} "{name}"\n')
        w(f'3 1 "{body}"\n$EndPhysicalNames\n')
        w(f"$Entities\n0 0 {len(names)} 1\n")
        for s in range(1, len(names) + 1):
            w(f"{s} {box} 1 {s} 0\n")
        w(f"1 {box} 1 1 {len(names)} " + " ".join(str(s) for s in range(1, len(names) + 1)) + "\n")
        w("$EndEntities\n")
        w(f"$Nodes\n1 {len(used)} {used[0]} {used[-1]}\n3 1 0 {len(used)}\n")
        w("".join(f"{i}\n" for i in used))
        w("".join("%.8g %.8g %.8g\n" % nodes[i] for i in used))
        w("$EndNodes\n")
        n_elem = len(tets) + sum(len(fs) for fs in parts.values())
        w(f"$Elements\n{1 + len(names)} {n_elem} 1 {n_elem}\n")
        tag = 1
        for s, name in enumerate(names, start=1):
            w(f"2 {s} 2 {len(parts[name])}\n")
            for f in parts[name]:
                w(f"{tag} {f[0]} {f[1]} {f[2]}\n")
                tag += 1
        w(f"3 1 4 {len(tets)}\n")
        for t in tets:
            w(f"{tag} {t[0]} {t[1]} {t[2]} {t[3]}\n")
            tag += 1
        w("$EndElements\n")


if __name__ == "__main__":
    main()
