#!/usr/bin/env bash
# Renders the README's picture: a surface and the hex mesh hexpeel makes of it, cut open and
# coloured by scaled Jacobian, from the page of `hexpeel mesh --html` in headless Chromium.
#   scripts/readme_picture.sh [SURFACE [OUT.png]]   (default tests/data/cad/cylinder.obj,
#                                                    docs/picture.png; needs build/ and chromium)
set -euo pipefail
cd "$(dirname "$0")/.."
in=${1:-tests/data/cad/cylinder.obj}
out=${2:-docs/picture.png}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
./build/hexpeel mesh "$in" -o "$tmp/m.vtk" --html "$tmp/m.html" -q
shot() {  # FRAGMENT PNG: the page's canvas alone, as the fragment sets it
  timeout 120 chromium --headless --no-sandbox --use-gl=angle --use-angle=swiftshader \
    --enable-unsafe-swiftshader --hide-scrollbars --window-size=800,560 \
    --virtual-time-budget=10000 --user-data-dir="$tmp/profile" \
    --screenshot="$2" "file://$tmp/m.html#figure&$1" > /dev/null 2>&1
}
shot "cut=1000&worst=0&zoom=1.25" "$tmp/surface.png"
shot "axis=1&cut=500&worst=1&zoom=1.25&yaw=3.6" "$tmp/cut.png"
# Side by side, halved (VTK from python3-vtk9 does the image work).
/usr/bin/python3 - "$tmp/surface.png" "$tmp/cut.png" "$out" <<'PY'
import sys, vtk
def read(p):
    r = vtk.vtkPNGReader(); r.SetFileName(p); r.Update(); return r.GetOutput()
a = vtk.vtkImageAppend(); a.SetAppendAxis(0)
for p in sys.argv[1:3]:
    a.AddInputData(read(p))
s = vtk.vtkImageResize(); s.SetInputConnection(a.GetOutputPort())
s.SetMagnificationFactors(0.5, 0.5, 1); s.SetResizeMethodToMagnificationFactors()
w = vtk.vtkPNGWriter(); w.SetFileName(sys.argv[3]); w.SetInputConnection(s.GetOutputPort()); w.Write()
PY
echo "wrote $out"
