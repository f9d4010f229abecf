#!/usr/bin/env python3
"""Surface repair benchmark (issue 31): `hexpeel mesh --repair-surface` on every surface of a
folder made by bench/gmsh_quad_surfaces.sh, against gmsh's own all-hex mesh of the same solid.

  bench/repair_benchmark.py DIR [--hexpeel build/hexpeel] [--timeout 60] [--out OUTDIR]
                              [--extra "--repair-tets only ..."]

Prints one markdown row per surface (input quads, odd, self-crossings, refined quads, status,
hexes, min / mean SJ, wall seconds, gmsh's hexes and min / mean SJ from DIR/hexref/SOLID.msh)
and a summary. A surface whose run exceeds --timeout counts as a failure ("timeout").
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time


def gmsh_reference(hexpeel, msh, cache):
    if msh in cache:
        return cache[msh]
    ref = None
    if os.path.exists(msh):
        out = subprocess.run([hexpeel, "quality", msh, "--json", msh + ".json"],
                             capture_output=True, text=True)
        if out.returncode in (0, 5) and os.path.exists(msh + ".json"):
            j = json.load(open(msh + ".json"))
            ref = (j["hexes"], j["scaled_jacobian"]["min"], j["scaled_jacobian"]["mean"])
    cache[msh] = ref
    return ref


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--hexpeel", default=os.path.join(os.path.dirname(__file__), "..", "build", "hexpeel"))
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--out", default="repair_bench_out")
    ap.add_argument("--extra", default="", help="more options for hexpeel mesh, one string")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    names = sorted(f[:-4] for f in os.listdir(a.dir) if f.endswith(".obj"))
    cache = {}
    print("| surface | quads | odd | self-crossings | refined quads | via | status | hexes | min SJ | "
          "mean SJ | s | gmsh hexes | gmsh min SJ | gmsh mean SJ |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for n in names:
        rep = os.path.join(a.out, n + ".json")
        if os.path.exists(rep):
            os.remove(rep)
        t0 = time.monotonic()
        try:
            p = subprocess.run([a.hexpeel, "mesh", os.path.join(a.dir, n + ".obj"), "-o",
                                os.path.join(a.out, n + ".vtk"), "--repair-surface", "--report",
                                rep, "--quiet"] + a.extra.split(), capture_output=True, text=True,
                               timeout=a.timeout)
            status = None
        except subprocess.TimeoutExpired:
            status = "timeout"
        secs = time.monotonic() - t0
        j = json.load(open(rep)) if status is None and os.path.exists(rep) else {}
        status = status or j.get("status", "?")
        r = j.get("repair", {})
        sj = j.get("scaled_jacobian", {})
        ref = gmsh_reference(a.hexpeel, os.path.join(a.dir, "hexref", re.sub(r"_[bdsq]$", "", n) + ".msh"), cache)
        ok = status == "ok" and sj.get("count_nonpositive", 1) == 0
        # which mesh was kept: the grown refinement's, the all-six split's, or the tet fill's
        via = ("tets" if (r.get("tet_fill") or {}).get("kept") else
               "six" if r.get("six_split_count") == r.get("input_quads") else "grown") if r else "-"
        rows.append((n, status, ok, sj.get("min"), sj.get("mean"), secs, ref, r))
        f = lambda x: "-" if x is None else ("%.3f" % x if isinstance(x, float) else str(x))
        print("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %.1f | %s | %s | %s |" % (
            n, f(r.get("input_quads")), "yes" if r.get("input_odd") else "", f(r.get("input_self_crossings")),
            f(r.get("output_quads")), via, status, f(j.get("hexes")), f(sj.get("min")), f(sj.get("mean")), secs,
            f(ref and ref[0]), f(ref and ref[1]), f(ref and ref[2])), flush=True)
    valid = [x for x in rows if x[2]]
    above = [x for x in valid if x[6] and x[3] > x[6][1]]
    print()
    print("%d surfaces: %d meshed with every hex SJ > 0 (%d with min SJ above gmsh's), %d timeouts, "
          "%d other failures" % (len(rows), len(valid), len(above),
                                 sum(x[1] == "timeout" for x in rows),
                                 sum(not x[2] and x[1] != "timeout" for x in rows)))
    if valid:
        mins = sorted(x[3] for x in valid)
        print("min SJ over the valid ones: median %.3f, lowest %.3f; median time %.1f s" % (
            mins[len(mins) // 2], mins[0], sorted(x[5] for x in valid)[len(valid) // 2]))


if __name__ == "__main__":
    sys.exit(main())
