#!/usr/bin/env python3
"""Chord statistics of a folder of quad surfaces, as a markdown table (issue 31's input class).

    bench/quad_surface_stats.py HEXPEEL DIR      (DIR as written by bench/gmsh_quad_surfaces.sh)

For every DIR/*.obj it runs `HEXPEEL check --json` and prints: quads, parity, chords, chords
that cross themselves and the quads where they do, the path `mesh` would take; and, when
DIR/hexref/SOLID_SIZE.msh exists (gmsh's own all-hex mesh of the solid), its hexes and min / mean
scaled Jacobian from `HEXPEEL quality`, the figures hexpeel's meshes are to beat. Totals last.
"""
import json
import os
import subprocess
import sys
import tempfile


def run_json(cmd, out):
    subprocess.run(cmd + ["--json", out], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        with open(out) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    hexpeel, folder = sys.argv[1], sys.argv[2]
    names = sorted(f[:-4] for f in os.listdir(folder) if f.endswith(".obj"))
    tmp = tempfile.mkdtemp()
    rows, counts = [], {"surfaces": 0, "odd": 0, "self": 0, "valid": 0}
    refs = {}
    print("| surface | quads | parity | chords | self-crossing chords | quads crossed twice | path | "
          "gmsh hexes | gmsh min SJ | gmsh mean SJ |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        d = run_json([hexpeel, "check", os.path.join(folder, name + ".obj")], os.path.join(tmp, "c.json"))
        if d is None:
            print(f"| {name} | check failed | | | | | | | | |")
            continue
        quads = d["validation"]["quads"]
        ch = d.get("chords", {})
        selfc = len(ch.get("self_intersecting", []))
        code = d["status"]["code"]
        path = "elimination" if code == "ok" else ("none (" + code + ")")
        counts["surfaces"] += 1
        counts["odd"] += quads % 2
        counts["self"] += selfc > 0
        counts["valid"] += code == "ok"
        solid = name.rsplit("_", 1)[0]
        if solid not in refs:
            ref = os.path.join(folder, "hexref", solid + ".msh")
            refs[solid] = run_json([hexpeel, "quality", ref], os.path.join(tmp, "q.json")) if os.path.exists(ref) else None
        q = refs[solid]
        sj = q["scaled_jacobian"] if q else None
        ref_cols = (f"{q['hexes']} | {sj['min']:.3f} | {sj['mean']:.3f}" if sj else "- | - | -")
        print(f"| {name} | {quads} | {'odd' if quads % 2 else 'even'} | {ch.get('count', '-')} | {selfc} | "
              f"{ch.get('self_crossings', '-')} | {path} | {ref_cols} |")
    print()
    print(f"{counts['surfaces']} surfaces: {counts['odd']} odd, {counts['self']} with a self-crossing chord, "
          f"{counts['valid']} valid input for dual cycle elimination.")


if __name__ == "__main__":
    main()
