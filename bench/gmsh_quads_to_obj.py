#!/usr/bin/python3
"""A gmsh surface mesh (.msh) -> OBJ of its quads, as gmsh wrote them (orientation untouched,
unused nodes dropped). Exit 1 when the mesh is not all-quad (a triangle left by recombination).
Usage: gmsh_quads_to_obj.py IN.msh OUT.obj"""
import sys
import numpy as np
import meshio

def main(inp, out):
    m = meshio.read(inp)
    quads = [c.data for c in m.cells if c.type == "quad"]
    tris = sum(len(c.data) for c in m.cells if c.type == "triangle")
    if tris or not quads:
        print(f"{inp}: {tris} triangles, {sum(len(q) for q in quads)} quads: not all-quad")
        return 1
    F = np.vstack(quads).astype(np.int64)
    used = np.unique(F)
    ren = -np.ones(len(m.points), dtype=np.int64)
    ren[used] = np.arange(len(used))
    with open(out, "w") as f:
        f.write(f"# quads of {inp}: {len(used)} vertices, {len(F)} quads\n")
        for p in m.points[used]:
            f.write(f"v {p[0]:.17g} {p[1]:.17g} {p[2]:.17g}\n")
        for q in ren[F] + 1:
            f.write(f"f {q[0]} {q[1]} {q[2]} {q[3]}\n")
    return 0

sys.exit(main(sys.argv[1], sys.argv[2]))
