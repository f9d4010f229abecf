#!/usr/bin/env bash
# Verification harness (not a test): hexpeel against the independent checker hexquality.py.
#
#   bench/verify_against_hexquality.sh SURFACE_DIR HEXQUALITY_PY [HEXPEEL_BIN]
#
# 1. `hexpeel check` must accept every surface (.obj .off .ply .mesh .msh .vtk) under SURFACE_DIR.
# 2. Every surface is meshed by `hexpeel mesh` into each format we write (.vtk .vtu .mesh .msh;
#    the same input meshes byte-identically each time, so these are one mesh), and the .vtk is
#    rewritten by meshio (binary legacy VTK, zlib VTU, MEDIT, Gmsh 4.1 binary, Gmsh 2.2 ASCII).
#    For each file `hexpeel quality MESH --surface IN --json` and `hexquality.py MESH IN --json`
#    must agree: hex count, count of SJ <= 0, boundary equality, and min and mean scaled
#    Jacobian within TOL (default 1e-9).
# Prints markdown tables; exits 1 on any rejection or disagreement, 2 on usage errors.
# Environment: TOL (1e-9), TIME_LIMIT (elimination time limit per surface in s, default 120),
# MESH_ARGS (extra options for `hexpeel mesh`, e.g. "--method original"),
# PYTHON (/usr/bin/python3: Debian's python has vtk and meshio).
set -u
if [ $# -lt 2 ]; then
  echo "usage: $0 SURFACE_DIR HEXQUALITY_PY [HEXPEEL_BIN]" >&2
  exit 2
fi
surfdir=$1
hq=$2
bin=${3:-$(cd "$(dirname "$0")/.." && pwd)/build-cli/hexpeel}
tol=${TOL:-1e-9}
time_limit=${TIME_LIMIT:-120}
read -r -a mesh_args <<<"${MESH_ARGS:-}"
py=${PYTHON:-/usr/bin/python3}
for f in "$bin" "$hq"; do
  [ -e "$f" ] || { echo "$0: $f not found" >&2; exit 2; }
done
[ -d "$surfdir" ] || { echo "$0: $surfdir is not a directory" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
mesh_failures=0
mapfile -t surfaces < <(find "$surfdir" -type f \( -name '*.obj' -o -name '*.off' -o -name '*.ply' \
  -o -name '*.mesh' -o -name '*.msh' -o -name '*.vtk' \) | sort)
[ ${#surfaces[@]} -gt 0 ] || { echo "$0: no surfaces under $surfdir" >&2; exit 2; }

echo "## hexpeel check"
echo
echo "| surface | exit | quads | genus | chords | chord length min/mean/max | self-intersecting | verdict |"
echo "|---|---|---|---|---|---|---|---|"
for s in "${surfaces[@]}"; do
  rel=${s#"$surfdir"/}
  "$bin" check "$s" --json "$work/check.json" >"$work/check.out" 2>"$work/check.err"
  rc=$?
  row=$("$py" - "$work/check.json" <<'EOF'
import json, sys
try:
    j = json.load(open(sys.argv[1]))
except Exception:
    print("| - | - | - | - | - "); sys.exit()
v, c = j.get("validation", {}), j.get("chords", {})
print("| %s | %s | %s | %s/%.2f/%s | %s " % (v.get("quads", "-"), v.get("genus", "-"), c.get("count", "-"),
      c.get("min_length", "-"), c.get("mean_length", float("nan")), c.get("max_length", "-"),
      len(c.get("self_intersecting", []))))
EOF
)
  if [ $rc -eq 0 ]; then verdict=accepted; else verdict="REJECTED: $(head -c 200 "$work/check.err" | tr '\n|' ' /')"; failures=$((failures + 1)); fi
  rm -f "$work/check.json"
  echo "| $rel | $rc $row| $verdict |"
done

echo
echo "## hexpeel quality vs hexquality.py (tolerance $tol)"
echo
echo "| surface | file | writer | hexes | ours min / mean | hexquality min / mean | max abs diff | SJ<=0 ours/hq | boundary ours/hq | exit ours/hq | result |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for s in "${surfaces[@]}"; do
  rel=${s#"$surfdir"/}
  name=$(basename "${s%.*}")
  files=()
  ok=1
  for ext in vtk vtu mesh msh; do
    "$bin" mesh "$s" -o "$work/$name.$ext" --quiet --time-limit "$time_limit" ${mesh_args[@]+"${mesh_args[@]}"} >"$work/mesh.out" 2>"$work/mesh.err"
    rc=$?
    # 5: written, with hexes at scaled Jacobian <= 0; the checkers below judge it.
    if [ $rc -ne 0 ] && [ $rc -ne 5 ]; then
      echo "| $rel | .$ext | hexpeel mesh | - | - | - | - | - | - | - | mesh exit $rc: $(head -c 160 "$work/mesh.err" | tr '\n|' ' /') |"
      ok=0
      mesh_failures=$((mesh_failures + 1))
      break
    fi
    files+=("$work/$name.$ext:hexpeel")
  done
  [ $ok -eq 1 ] || continue
  if "$py" - "$work/$name.vtk" "$work/${name}_meshio" >"$work/meshio.log" 2>&1 <<'EOF'
import sys, meshio
m = meshio.read(sys.argv[1])
base = sys.argv[2]
meshio.write(base + ".vtk", m, binary=True)
meshio.write(base + ".vtu", m, compression="zlib")
meshio.write(base + ".mesh", m)
meshio.write(base + "_41.msh", m, file_format="gmsh", binary=True)
meshio.write(base + "_22.msh", m, file_format="gmsh22", binary=False)
EOF
  then
    files+=("$work/${name}_meshio.vtk:meshio binary" "$work/${name}_meshio.vtu:meshio zlib"
            "$work/${name}_meshio.mesh:meshio" "$work/${name}_meshio_41.msh:meshio 4.1 binary"
            "$work/${name}_meshio_22.msh:meshio 2.2 ascii")
  else
    echo "| $rel | - | meshio | - | - | - | - | - | - | - | meshio conversion failed: $(tail -n1 "$work/meshio.log" | tr '|' '/') |"
    failures=$((failures + 1))
  fi
  for entry in "${files[@]}"; do
    f=${entry%%:*}
    writer=${entry#*:}
    "$bin" quality "$f" --surface "$s" --json "$work/ours.json" >/dev/null 2>"$work/ours.err"
    ours_rc=$?
    "$py" "$hq" "$f" "$s" --json >"$work/hq.json" 2>"$work/hq.err"
    hq_rc=$?
    row=$("$py" - "$work/ours.json" "$work/hq.json" "$ours_rc" "$hq_rc" "$tol" <<'EOF'
import json, math, sys
def load(p):
    try:
        return json.load(open(p))
    except Exception:
        return None
o, h = load(sys.argv[1]), load(sys.argv[2])
ours_rc, hq_rc, tol = int(sys.argv[3]), int(sys.argv[4]), float(sys.argv[5])
# ours exits 2 both on a read error (no JSON) and on a mesh that fails the check (JSON written);
# hexquality exits 1 on a mesh that fails, 2 on a read error.
if o is None or h is None or hq_rc >= 2 or ours_rc not in (0, 2):
    print("| - | - | - | - | - | - | %d/%d | FAIL (exit ours %d, hexquality %d)" % (ours_rc, hq_rc, ours_rc, hq_rc)); sys.exit()
sj = o["scaled_jacobian"]
omin = sj["min"] if sj["min"] is not None else math.nan
omean = sj["mean"] if sj["mean"] is not None else math.nan
d = max(abs(omin - h["sj_min"]), abs(omean - h["sj_avg"]))
b_o = o.get("boundary_matches_surface")
b_h = h.get("boundary", {}).get("boundary_equal")
verdict_agrees = (ours_rc == 0) == (hq_rc == 0)
agree = (o["hexes"] == h["hexes"] and d <= tol and verdict_agrees
         and sj["count_nonpositive"] == h["hexes_sj_le_0"] and b_o == b_h)
print("| %d | %.12f / %.12f | %.12f / %.12f | %.2e | %d/%d | %s/%s | %d/%d | %s" % (
    o["hexes"], omin, omean, h["sj_min"], h["sj_avg"], d, sj["count_nonpositive"],
    h["hexes_sj_le_0"], b_o, b_h, ours_rc, hq_rc,
    "agree" if agree else "DISAGREE: " + ("verdict only (see hexquality's topology line)"
                                          if not verdict_agrees and d <= tol else "numbers")))
EOF
)
    case $row in *"agree"*) case $row in *DISAGREE*) failures=$((failures + 1)) ;; esac ;; *) failures=$((failures + 1)) ;; esac
    echo "| $rel | $(basename "$f") | $writer $row |"
    rm -f "$work/ours.json" "$work/hq.json"
  done
  rm -f "$work/$name".* "$work/${name}_meshio"*
done

echo
[ $mesh_failures -eq 0 ] || echo "$mesh_failures surface(s) could not be meshed (listed above; not a quality disagreement)"
if [ $failures -eq 0 ]; then
  echo "all checks agree"
  exit 0
fi
echo "$failures failure(s)"
exit 1
