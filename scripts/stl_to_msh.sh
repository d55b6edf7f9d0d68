#!/usr/bin/env bash
# Turns a closed STL surface into a P1 tetrahedral volume mesh (Gmsh MSH 4.1, ASCII) with named
# parts, for synovia's reader (synovia_io::gmsh; JointModel::add_gmsh_bodies; scenario
# `mesh = { gmsh = "...", group = "insert" }`). See docs/meshing.md.
#
# usage: scripts/stl_to_msh.sh IN.stl OUT.msh [options]
#   -h SIZE      element size (mm) above y = YFINE, i.e. on the articular surface   (default 1)
#   -H SIZE      largest element size (mm), reached YGROW mm below YFINE           (default 3.5)
#   -f YFINE     height (mm) above which the size is SIZE                          (default 5)
#   -g YGROW     height (mm) over which the size grows from SIZE to the largest one (default 4)
#   -i FACTOR    interior element size: FACTOR times the surface size, at most the largest
#                size (tetrahedra at the surface follow the surface triangles)    (default 3)
#   -s SCALE     factor from the STL's units to mm                                 (default 1000: STL in m)
#   -y YMIN      articular part: facets with centroid above YMIN mm ...           (default 6)
#   -n NYMIN     ... and outward normal y-component above NYMIN                    (default 0.5)
#   -b NAME      name of the body (physical volume)                                (default insert)
#   -k           keep the working directory (printed)
#   -u           do not unfold the STL's folds first (scripts/stl_unfold.py)
# Needs `gmsh` (4.8 or later) and `python3` on PATH.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"

usage() { sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
[ $# -ge 2 ] || usage
in="$1"; out="$2"; shift 2
h=1; H=3.5; ifac=3; yfine=5; ygrow=4; scale=1000; ymin=6; nymin=0.5; body=insert; keep=0; unfold=1
while getopts "h:H:i:f:g:s:y:n:b:ku" opt; do
    case "$opt" in
        h) h="$OPTARG" ;; H) H="$OPTARG" ;; i) ifac="$OPTARG" ;; f) yfine="$OPTARG" ;; g) ygrow="$OPTARG" ;;
        s) scale="$OPTARG" ;; y) ymin="$OPTARG" ;; n) nymin="$OPTARG" ;;
        b) body="$OPTARG" ;; k) keep=1 ;; u) unfold=0 ;; *) usage ;;
    esac
done
[ -f "$in" ] || { echo "stl_to_msh.sh: no such file: $in" >&2; exit 1; }
command -v gmsh >/dev/null || { echo "stl_to_msh.sh: gmsh is not on PATH (Debian: apt-get install gmsh)" >&2; exit 1; }
command -v python3 >/dev/null || { echo "stl_to_msh.sh: python3 is not on PATH" >&2; exit 1; }

work="$(mktemp -d "${TMPDIR:-/tmp}/stl_to_msh.XXXXXX")"
[ "$keep" = 1 ] && echo "working directory: $work" || trap 'rm -rf "$work"' EXIT

# 1. Prepare the surface (scripts/stl_unfold.py): unfold the crumples of decimated surfaces
#    (they make the surface intersect itself), then split edges longer than the target size,
#    SIZE above YFINE growing linearly to the largest size YGROW below it. Bisection keeps the
#    STL's shape exactly; Gmsh keeps these triangles as the boundary of the volume mesh.
nounfold=""; [ "$unfold" = 1 ] || nounfold="--no-unfold"
start=$(date +%s)
python3 "$here/stl_unfold.py" "$in" "$work/surface.stl" $nounfold --refine "$h" "$H" "$yfine" "$ygrow" "$scale" \
    2> "$work/prepare.log" || { cat "$work/prepare.log" >&2; exit 1; }
grep -v '^round' "$work/prepare.log"

# 2. Mesh the volume. Gmsh works in the STL's units; the mesh is written scaled to mm
#    (Mesh.ScalingFactor). The same size function, times FACTOR (capped at the largest size), as a
#    MathEval background field grades the interior.
cat > "$work/mesh.geo" <<GEO
Merge "surface.stl";
Surface Loop(1) = Surface{:};
Volume(1) = {1};
Physical Volume("$body") = {1};
s = $scale;
Field[1] = MathEval;
hi = Min($H, $ifac * $h);
Field[1].F = Sprintf("Min(%.10g, %.10g + %.10g * Max(0, %.10g - y))", $H / s, hi / s, ($H - hi) / $ygrow, $yfine / s);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm3D = 1;
Mesh.Optimize = 1;
Mesh.ScalingFactor = s;
Mesh.MshFileVersion = 2.2;
Mesh.Binary = 0;
GEO
(cd "$work" && gmsh mesh.geo -3 -nt 1 -o raw.msh > gmsh.log 2>&1) \
    || { grep -v '^Info' "$work/gmsh.log" | grep -v 'Poor input mesh' >&2; echo "stl_to_msh.sh: gmsh failed (log: $work/gmsh.log)" >&2; exit 1; }
grep -q '^Error' "$work/gmsh.log" && { grep '^Error' "$work/gmsh.log" | grep -v 'Wrong topology' >&2 || true; }
[ -s "$work/raw.msh" ] || { echo "stl_to_msh.sh: gmsh wrote no mesh" >&2; exit 1; }

# 3. Name the boundary parts by geometry and write MSH 4.1 ASCII.
python3 "$here/msh_parts.py" "$work/raw.msh" "$out" "$body" "$ymin" "$nymin" 0.05
echo "wrote $out ($(wc -c < "$out") bytes) in $(( $(date +%s) - start )) s"
