#!/usr/bin/env bash
# Quad surfaces as a quad mesher makes them: gmsh 4.8 (Debian) all-quad surface meshes of CAD
# solids, the input class of issue 31 (self-intersecting chords, odd counts, orientation that
# follows each CAD face). For every solid, size and setting it writes OUTDIR/NAME.obj (the
# surface, exactly as gmsh wrote it: quads, in gmsh's orientation) and, once per solid and size,
# gmsh's own all-hex mesh of the solid (tetrahedra split into hexes) as OUTDIR/hexref/NAME.msh,
# to compare qualities with `hexpeel quality`.
#   bench/gmsh_quad_surfaces.sh OUTDIR      (needs Debian's gmsh, python3-meshio, python3-numpy)
# then build/bench/hexpeel_corpus OUTDIR. Settings (NAME suffix):
#   _b   frontal-Delaunay (Mesh.Algorithm 6), blossom full-quad recombination
#   _d   Delaunay (Mesh.Algorithm 5), blossom full-quad recombination
#   _s   frontal-Delaunay, recombination, then every quad split into 4 (Mesh.SubdivisionAlgorithm 1)
#   _q   quasi-structured quad (Mesh.Algorithm 11)
# gmsh 4.8's full-quad recombination refuses periodic surfaces (cylinders, cones, spheres), so
# curved solids come out as _s and _q only.
# Surfaces that gmsh does not make all-quad (a triangle left) are skipped and listed.
set -euo pipefail
out=${1:?usage: gmsh_quad_surfaces.sh OUTDIR}
here=$(cd "$(dirname "$0")/.." && pwd)
command -v gmsh > /dev/null || { echo "gmsh not found: apt-get install gmsh" >&2; exit 2; }
mkdir -p "$out/hexref" "$out/geo"
skipped=()

surface() {  # NAME LC ALGO RECOMB_ALGO SUBDIV BODY
  local name=$1 lc=$2 algo=$3 recomb=$4 subdiv=$5 body=$6
  local geo="$out/geo/$name.geo" msh="$out/geo/$name.msh"
  cat > "$geo" <<GEO
SetFactory("OpenCASCADE");
$body
Mesh.CharacteristicLengthMax = $lc;
Mesh.CharacteristicLengthMin = $(awk "BEGIN{print $lc/4}");
Mesh.Algorithm = $algo;
Mesh.RecombineAll = 1;
Mesh.RecombinationAlgorithm = $recomb;
Mesh.SubdivisionAlgorithm = $subdiv;
GEO
  if gmsh -2 -format msh22 -o "$msh" "$geo" > "$out/geo/$name.log" 2>&1 &&
     /usr/bin/python3 "$here/bench/gmsh_quads_to_obj.py" "$msh" "$out/$name.obj" >> "$out/geo/$name.log" 2>&1; then
    echo "$out/$name.obj"
  else
    skipped+=("$name")
  fi
}

hexref() {  # NAME LC BODY: gmsh's own all-hex mesh (tetrahedra split into hexes)
  local name=$1 lc=$2 body=$3
  cat > "$out/hexref/$name.geo" <<GEO
SetFactory("OpenCASCADE");
$body
Mesh.CharacteristicLengthMax = $lc;
Mesh.Algorithm = 6;
Mesh.Algorithm3D = 1;
Mesh.SubdivisionAlgorithm = 2;
GEO
  gmsh -3 -format msh22 -o "$out/hexref/$name.msh" "$out/hexref/$name.geo" > "$out/hexref/$name.log" 2>&1 ||
    echo "gmsh's hex mesh of $name failed (see $out/hexref/$name.log)" >&2
}

solid() {  # NAME BODY LC...
  local name=$1 body=$2
  shift 2
  for lc in "$@"; do
    local tag=${lc/./p}
    surface "${name}_${tag}_b" "$lc" 6 2 0 "$body"
    surface "${name}_${tag}_d" "$lc" 5 2 0 "$body"
    surface "${name}_${tag}_s" "$(awk "BEGIN{print $lc*2}")" 6 1 1 "$body"
    surface "${name}_${tag}_q" "$lc" 11 1 0 "$body"
    hexref "${name}_${tag}" "$lc" "$body"
  done
}

solid box "Box(1) = {0,0,0, 2,1,0.6};" 0.25 0.15
solid cube "Box(1) = {0,0,0, 1,1,1};" 0.2 0.12
solid lbox "Box(1) = {0,0,0,2,1,1}; Box(2) = {0,0,0,1,2,1}; BooleanUnion{Volume{1}; Delete;}{Volume{2}; Delete;}" 0.3 0.18
solid cyl "Cylinder(1) = {0,0,0, 0,0,2, 0.7};" 0.3 0.2
solid cone "Cone(1) = {0,0,0, 0,0,1.5, 0.8, 0.3};" 0.3 0.2
solid sphere "Sphere(1) = {0,0,0,1};" 0.35 0.25
solid capsule "Cylinder(1) = {0,0,0, 0,0,2, 0.6}; Sphere(2) = {0,0,0,0.6}; Sphere(3) = {0,0,2,0.6}; BooleanUnion{Volume{1}; Delete;}{Volume{2}; Volume{3}; Delete;}" 0.3 0.2
solid wedge "Wedge(1) = {0,0,0, 2,1,1};" 0.25 0.15
solid blind "Box(1) = {0,0,0,2,2,1}; Cylinder(2) = {1,1,0.4, 0,0,1, 0.5}; BooleanDifference{Volume{1}; Delete;}{Volume{2}; Delete;}" 0.3 0.2
solid pocket "Box(1) = {0,0,0,3,2,1}; Box(2) = {0.5,0.5,0.5,2,1,1}; BooleanDifference{Volume{1}; Delete;}{Volume{2}; Delete;}" 0.3 0.2
solid bracket "Box(1) = {0,0,0,3,1,0.4}; Box(2) = {0,0,0,0.4,1,2}; Cylinder(3) = {2.3,0.5,0.4, 0,0,0.6, 0.35}; BooleanUnion{Volume{1}; Delete;}{Volume{2}; Volume{3}; Delete;}" 0.25 0.15
solid flange "Cylinder(1) = {0,0,0, 0,0,0.4, 1.5}; Cylinder(2) = {0,0,0, 0,0,1.5, 0.6}; BooleanUnion{Volume{1}; Delete;}{Volume{2}; Delete;}" 0.3 0.2
solid shaft "Cylinder(1) = {0,0,0, 2,0,0, 0.5}; Cylinder(2) = {2,0,0, 1,0,0, 0.3}; Cylinder(3) = {3,0,0, 0.8,0,0, 0.2}; BooleanUnion{Volume{1}; Delete;}{Volume{2}; Volume{3}; Delete;}" 0.25 0.15
solid fillet "Box(1) = {0,0,0, 2,1.5,1}; Fillet{1}{1,3,5,7}{0.3};" 0.25 0.15
solid torusless_cup "Cylinder(1) = {0,0,0, 0,0,1.2, 1}; Cylinder(2) = {0,0,0.3, 0,0,1.2, 0.7}; BooleanDifference{Volume{1}; Delete;}{Volume{2}; Delete;}" 0.3 0.2

if ((${#skipped[@]})); then
  echo "not made all-quad by gmsh (skipped): ${skipped[*]}" >&2
fi
