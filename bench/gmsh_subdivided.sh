#!/usr/bin/env bash
# Stress surfaces: boundaries of gmsh all-hex meshes made by subdividing tetrahedra into hexes
# (Mesh.SubdivisionAlgorithm = 2). Each surface triangle becomes 3 quads around a valence-3
# vertex, so a third of the vertices have valence 3 and the chords are short: far more irregular
# than the boundaries of published hex meshes, and a hard case for dual cycle elimination. Every
# surface is the boundary of a known (poor) hex mesh: the .msh beside it.
#   bench/gmsh_subdivided.sh OUTDIR     (needs Debian's gmsh, python3-meshio, python3-numpy)
# then e.g. build/bench/hexpeel_corpus OUTDIR. Writes OUTDIR/NAME.{geo,msh,obj}.
set -euo pipefail
out=${1:?usage: gmsh_subdivided.sh OUTDIR}
here=$(cd "$(dirname "$0")/.." && pwd)
command -v gmsh > /dev/null || { echo "gmsh not found: apt-get install gmsh" >&2; exit 2; }
mkdir -p "$out"
shape() {  # NAME MAX_EDGE_LENGTH OPENCASCADE_BODY
  local name=$1 lc=$2 body=$3
  cat > "$out/$name.geo" <<GEO
SetFactory("OpenCASCADE");
$body
Mesh.CharacteristicLengthMax = $lc;
Mesh.Algorithm = 6;
Mesh.Algorithm3D = 1;
Mesh.SubdivisionAlgorithm = 2;
GEO
  gmsh -3 -format msh22 -o "$out/$name.msh" "$out/$name.geo" > "$out/$name.gmsh.log" 2>&1
  /usr/bin/python3 "$here/scripts/gmsh_boundary.py" "$out/$name.msh" "$out/$name.obj" 1e-2 > /dev/null
  echo "$out/$name.obj"
}
shape sub_sphere 0.35 "Sphere(1) = {0,0,0,1};"
shape sub_cyl 0.35 "Cylinder(1) = {0,0,0, 0,0,2, 0.7};"
shape sub_cone 0.3 "Cone(1) = {0,0,0, 0,0,1.5, 0.8, 0.2};"
shape sub_capsule 0.3 "Cylinder(1) = {0,0,0, 0,0,2, 0.6}; Sphere(2) = {0,0,0,0.6}; Sphere(3) = {0,0,2,0.6}; BooleanUnion{Volume{1}; Delete;}{Volume{2}; Volume{3}; Delete;}"
shape sub_Lbox 0.3 "Box(1) = {0,0,0,2,1,1}; Box(2) = {0,0,0,1,2,1}; BooleanUnion{Volume{1}; Delete;}{Volume{2}; Delete;}"
shape sub_blind 0.3 "Box(1) = {0,0,0,2,2,1}; Cylinder(2) = {1,1,0.4, 0,0,1, 0.5}; BooleanDifference{Volume{1}; Delete;}{Volume{2}; Delete;}"
shape sub_bracket 0.25 "Box(1) = {0,0,0,3,1,0.4}; Box(2) = {0,0,0,0.4,1,2}; Cylinder(3) = {2.3,0.5,0.4, 0,0,0.6, 0.35}; BooleanUnion{Volume{1}; Delete;}{Volume{2}; Volume{3}; Delete;}"
