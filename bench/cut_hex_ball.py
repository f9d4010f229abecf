#!/usr/bin/env python3
"""cut_hex_ball.py - cut a topological ball of hexes out of a hex mesh.

Reads a hex mesh in MEDIT .mesh format (ASCII; the Vertices and Hexahedra sections
are used, other sections are skipped), grows a ball of hexes from a seed hex and
writes

  * the boundary of the ball as an OBJ quad surface (only the vertices it uses,
    renumbered, every quad oriented outward), and
  * optionally (--ball) the ball itself as a legacy VTK UNSTRUCTURED_GRID of
    VTK_HEXAHEDRON cells (type 12), so that its quality can be compared with that
    of a mesh generated from the surface.

The boundary of a ball is a closed, manifold, genus-0 quad surface, i.e. a valid
input for a tool that fills such surfaces with hexes, and the ball is a known
all-hex filling of it.

Hex orientation.  MEDIT lists the 8 corners of a hex like VTK does (one quad, then
the opposite quad with corner i+4 joined to corner i), but files differ in the
orientation of the first quad.  Every hex is therefore checked: if its signed volume
in VTK order (determinant of the principal-axes Jacobian at the centre, falling back
to the sum of the 8 corner Jacobians when that is ~0) is negative, it is re-ordered
0 3 2 1 4 7 6 5.  Output hexes are all positive in VTK order.

Growing.  The seed is the hex of rank --seed in the order "distance from the hex
centroid to the mesh centroid, then hex index" (rank 0 = the most central hex).
Candidates are the hexes sharing a face with the ball, processed breadth-first (FIFO).
A candidate h is added only if its intersection with the ball B is a closed 2-disk on
the boundary of h:

  * the set F of faces of h shared with B is non-empty, not all 6, connected through
    cube edges, and its complement on the cube is connected too (so F is a disk), and
  * no other vertex or edge of h belongs to B (h may touch B only through F).

Gluing a ball to a ball along a disk in both boundaries gives a ball, so B stays a
ball and its boundary stays a closed manifold genus-0 surface; in particular no
vertex's hex-link becomes a non-ball (no pinched vertex or edge, no tunnel, no
cavity).  A rejected candidate is re-examined whenever a hex sharing one of its
vertices is added.  Growth stops at --max-hexes hexes, or when no candidate can be
added (--whole: no limit, take every hex that can be taken this way).

Checks.  The result is verified globally before anything is written: every boundary
edge lies in exactly 2 boundary quads, the quad fan around every boundary vertex is a
single disk, the surface is connected with Euler characteristic V-E+F == 2, the ball
complex has Euler characteristic V-E+F-C == 1, and the enclosed signed volume is
positive (outward orientation).  --paranoid repeats the global check after every
addition (slow; for testing).  Output is deterministic.

Usage:
  cut_hex_ball.py IN.mesh OUT.obj [--ball OUT_ball.vtk] [--seed K]
                  [--max-hexes N | --whole] [--paranoid] [--quiet]
  cut_hex_ball.py --selftest

Requires python3 and numpy only.
"""
import argparse
import collections
import os
import sys

try:
    import numpy as np
except ImportError:  # e.g. a pyenv python3 first on PATH: retry with Debian's python3
    if (os.path.exists("/usr/bin/python3")
            and os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3")):
        os.execv("/usr/bin/python3", ["/usr/bin/python3", os.path.abspath(__file__)] + sys.argv[1:])
    raise

# VTK_HEXAHEDRON faces, outward for a positive hex (same table as hexquality.py).
HEX_FACES = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4),
             (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))
HEX_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6),
             (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7))
FLIP = (0, 3, 2, 1, 4, 7, 6, 5)


def _face_edges(f):
    return tuple(tuple(sorted((f[k], f[(k + 1) % 4]))) for k in range(4))


FACE_EDGES = tuple(_face_edges(f) for f in HEX_FACES)          # local edges per face
FACE_ADJ = tuple(tuple(j for j in range(6) if j != i and
                       len(set(HEX_FACES[i]) & set(HEX_FACES[j])) == 2)
                 for i in range(6))                               # faces sharing an edge

# MEDIT keywords whose entries have a fixed number of tokens (excluding Vertices).
MEDIT_ENTRY_TOKENS = {
    "edges": 3, "triangles": 4, "quadrilaterals": 5, "tetrahedra": 5,
    "prisms": 7, "pyramids": 6, "hexahedra": 9, "corners": 1, "ridges": 1,
    "requiredvertices": 1, "requirededges": 1, "requiredtriangles": 1,
    "requiredquadrilaterals": 1, "tangentatedges": 2, "normalatvertices": 2,
    "normalattrianglevertices": 3, "normalatquadrilateralvertices": 3,
}


class MeshError(Exception):
    pass


# ----------------------------------------------------------------------------- I/O

def read_medit(path):
    """Return (points (n,3) float, hexes (m,8) int, 0-based) from an ASCII MEDIT file."""
    toks = []
    with open(path, "r") as fh:
        for line in fh:
            line = line.split("#", 1)[0]
            toks.extend(line.split())
    pts = None
    hexes = None
    dim = 3
    i = 0
    n = len(toks)

    def need(k):
        if i + k > n:
            raise MeshError("%s: truncated file" % path)

    while i < n:
        key = toks[i].lower()
        i += 1
        if key in ("meshversionformatted", "meshversion"):
            i += 1
        elif key == "dimension":
            need(1)
            dim = int(toks[i])
            i += 1
        elif key == "vertices":
            need(1)
            cnt = int(toks[i])
            i += 1
            need(cnt * (dim + 1))
            arr = np.array(toks[i:i + cnt * (dim + 1)], dtype=float).reshape(cnt, dim + 1)
            i += cnt * (dim + 1)
            pts = np.zeros((cnt, 3))
            pts[:, :dim] = arr[:, :dim]
        elif key == "hexahedra":
            need(1)
            cnt = int(toks[i])
            i += 1
            need(cnt * 9)
            arr = np.array(toks[i:i + cnt * 9], dtype=np.int64).reshape(cnt, 9)
            i += cnt * 9
            hexes = arr[:, :8] - 1
        elif key == "end":
            break
        elif key in MEDIT_ENTRY_TOKENS:
            need(1)
            cnt = int(toks[i])
            i += 1 + cnt * MEDIT_ENTRY_TOKENS[key]
        else:
            raise MeshError("%s: unsupported MEDIT keyword %r" % (path, toks[i - 1]))
    if pts is None or hexes is None:
        raise MeshError("%s: needs both Vertices and Hexahedra sections" % path)
    if len(hexes) == 0:
        raise MeshError("%s: no hexahedra" % path)
    if hexes.min() < 0 or hexes.max() >= len(pts):
        raise MeshError("%s: hex vertex index out of range" % path)
    if any(len(set(h)) != 8 for h in hexes.tolist()):
        raise MeshError("%s: a hex repeats a vertex" % path)
    return pts, hexes


def write_obj(path, pts, quads, comment):
    with open(path, "w") as fh:
        fh.write("# %s\n" % comment)
        for p in pts:
            fh.write("v %r %r %r\n" % (float(p[0]), float(p[1]), float(p[2])))
        for q in quads:
            fh.write("f %d %d %d %d\n" % (q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1))


def write_vtk(path, pts, hexes, comment):
    with open(path, "w") as fh:
        fh.write("# vtk DataFile Version 3.0\n%s\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                 % comment[:255])
        fh.write("POINTS %d double\n" % len(pts))
        for p in pts:
            fh.write("%r %r %r\n" % (float(p[0]), float(p[1]), float(p[2])))
        fh.write("CELLS %d %d\n" % (len(hexes), 9 * len(hexes)))
        for h in hexes:
            fh.write("8 %s\n" % " ".join(str(int(v)) for v in h))
        fh.write("CELL_TYPES %d\n" % len(hexes))
        fh.write("12\n" * len(hexes))


# ------------------------------------------------------------------------ geometry

def orient_hexes(pts, hexes):
    """Return (hexes re-ordered so that every one is positive in VTK order, #flipped)."""
    P = pts[hexes]                                            # (m,8,3)
    a1 = (P[:, 1] + P[:, 2] + P[:, 6] + P[:, 5]) - (P[:, 0] + P[:, 3] + P[:, 7] + P[:, 4])
    a2 = (P[:, 2] + P[:, 3] + P[:, 7] + P[:, 6]) - (P[:, 0] + P[:, 1] + P[:, 5] + P[:, 4])
    a3 = (P[:, 4] + P[:, 5] + P[:, 6] + P[:, 7]) - (P[:, 0] + P[:, 1] + P[:, 2] + P[:, 3])
    det = np.einsum("ij,ij->i", a1, np.cross(a2, a3))
    # corner Jacobians: corner k with its three edge neighbours (right-handed in VTK order)
    nb = ((1, 3, 4), (2, 0, 5), (3, 1, 6), (0, 2, 7),
          (7, 5, 0), (4, 6, 1), (5, 7, 2), (6, 4, 3))
    csum = np.zeros(len(hexes))
    for k, (x, y, z) in enumerate(nb):
        e1 = P[:, x] - P[:, k]
        e2 = P[:, y] - P[:, k]
        e3 = P[:, z] - P[:, k]
        csum += np.einsum("ij,ij->i", e1, np.cross(e2, e3))
    scale = np.linalg.norm(a1, axis=1) * np.linalg.norm(a2, axis=1) * np.linalg.norm(a3, axis=1)
    use = np.where(np.abs(det) > 1e-12 * np.maximum(scale, 1e-300), det, csum)
    neg = use < 0
    out = hexes.copy()
    out[neg] = hexes[neg][:, FLIP]
    return out, int(neg.sum())


# ------------------------------------------------------------------------- topology

class HexMesh:
    def __init__(self, pts, hexes):
        self.pts = pts
        self.hexes = [tuple(int(v) for v in h) for h in hexes]
        m = len(self.hexes)
        owner = {}
        self.nbr = [[-1] * 6 for _ in range(m)]
        for c, h in enumerate(self.hexes):
            for fi, f in enumerate(HEX_FACES):
                key = tuple(sorted(h[k] for k in f))
                if key in owner:
                    oc, ofi = owner[key]
                    if oc < 0:
                        raise MeshError("a quad face is shared by more than two hexes")
                    self.nbr[c][fi] = oc
                    self.nbr[oc][ofi] = c
                    owner[key] = (-1, -1)
                else:
                    owner[key] = (c, fi)
        self.vhex = collections.defaultdict(list)              # vertex -> hexes
        for c, h in enumerate(self.hexes):
            for v in h:
                self.vhex[v].append(c)


class Ball:
    """Incrementally grown set of hexes that stays a topological ball."""

    def __init__(self, mesh):
        self.mesh = mesh
        self.inb = bytearray(len(mesh.hexes))
        self.order = []                                         # hexes in order of addition
        self.vcount = collections.Counter()
        self.ecount = collections.Counter()

    def _add(self, c):
        h = self.mesh.hexes[c]
        self.inb[c] = 1
        self.order.append(c)
        for v in h:
            self.vcount[v] += 1
        for a, b in HEX_EDGES:
            self.ecount[tuple(sorted((h[a], h[b])))] += 1

    def shared_faces(self, c):
        return [fi for fi in range(6) if self.mesh.nbr[c][fi] >= 0
                and self.inb[self.mesh.nbr[c][fi]]]

    def can_add(self, c):
        """True iff (hex c) intersected with the ball is a closed 2-disk on its boundary."""
        if self.inb[c]:
            return False
        F = self.shared_faces(c)
        if not 1 <= len(F) <= 5:
            return False
        if not _connected(F) or not _connected([i for i in range(6) if i not in F]):
            return False
        h = self.mesh.hexes[c]
        cl_v = set(k for fi in F for k in HEX_FACES[fi])
        cl_e = set(e for fi in F for e in FACE_EDGES[fi])
        for k in range(8):
            if k not in cl_v and self.vcount[h[k]]:
                return False
        for a, b in HEX_EDGES:
            if (min(a, b), max(a, b)) not in cl_e and self.ecount[tuple(sorted((h[a], h[b])))]:
                return False
        return True

    def grow(self, seed, max_hexes=None, paranoid=False):
        mesh = self.mesh
        self._add(seed)
        queue = collections.deque()
        queued = bytearray(len(mesh.hexes))

        def push_around(c):
            # every hex sharing a vertex with c may have changed status
            cand = set()
            for v in mesh.hexes[c]:
                cand.update(mesh.vhex[v])
            for d in sorted(cand, key=lambda d: (_face_rank(mesh, c, d), d)):
                if not self.inb[d] and not queued[d] and self.shared_faces(d):
                    queued[d] = 1
                    queue.append(d)

        push_around(seed)
        while queue and (max_hexes is None or len(self.order) < max_hexes):
            c = queue.popleft()
            queued[c] = 0
            if self.can_add(c):
                self._add(c)
                if paranoid:
                    verify(mesh, self.order)
                push_around(c)
        return self.order


def _face_rank(mesh, c, d):
    """Order candidates: face neighbours of c first (in local face order), then others."""
    for fi in range(6):
        if mesh.nbr[c][fi] == d:
            return fi
    return 6


def _connected(faces):
    faces = list(faces)
    if not faces:
        return True
    s = set(faces)
    seen = {faces[0]}
    stack = [faces[0]]
    while stack:
        f = stack.pop()
        for g in FACE_ADJ[f]:
            if g in s and g not in seen:
                seen.add(g)
                stack.append(g)
    return len(seen) == len(s)


def boundary_quads(mesh, cells):
    """Boundary quads (outward, original vertex ids) of a set of hexes, deterministic order."""
    inset = set(cells)
    quads = []
    for c in sorted(inset):
        h = mesh.hexes[c]
        for fi, f in enumerate(HEX_FACES):
            d = mesh.nbr[c][fi]
            if d < 0 or d not in inset:
                quads.append(tuple(h[k] for k in f))
    return quads


def verify(mesh, cells):
    """Raise MeshError unless the hexes form a ball with a closed manifold genus-0 boundary."""
    quads = boundary_quads(mesh, cells)
    if not quads:
        raise MeshError("empty boundary")
    # boundary edges: each in exactly 2 quads, used once in each direction
    edir = collections.Counter()
    for q in quads:
        for k in range(4):
            edir[(q[k], q[(k + 1) % 4])] += 1
    for (a, b), n in edir.items():
        if n != 1 or edir.get((b, a), 0) != 1:
            raise MeshError("boundary edge %d-%d is not shared by exactly two consistently "
                            "oriented quads" % (a, b))
    # vertex fans: the quads around each vertex form a single cycle (a disk)
    nxt = collections.defaultdict(dict)          # v -> {previous vertex: next vertex}
    for q in quads:
        for k in range(4):
            v, p, n = q[k], q[(k - 1) % 4], q[(k + 1) % 4]
            if p in nxt[v]:
                raise MeshError("vertex %d: fan is not manifold" % v)
            nxt[v][p] = n
    for v, m in nxt.items():
        start = next(iter(m))
        cur, steps = start, 0
        while True:
            if cur not in m:
                raise MeshError("vertex %d: fan is open" % v)
            cur = m[cur]
            steps += 1
            if cur == start:
                break
            if steps > len(m):
                raise MeshError("vertex %d: fan is broken" % v)
        if steps != len(m):
            raise MeshError("vertex %d: quad fan is not a single disk (pinched vertex)" % v)
    V = len(nxt)
    E = len(edir) // 2
    F = len(quads)
    if V - E + F != 2:
        raise MeshError("boundary Euler characteristic %d, want 2" % (V - E + F))
    # connected
    adj = collections.defaultdict(set)
    for a, b in edir:
        adj[a].add(b)
    start = quads[0][0]
    seen = {start}
    stack = [start]
    while stack:
        v = stack.pop()
        for w in adj[v]:
            if w not in seen:
                seen.add(w)
                stack.append(w)
    if len(seen) != V:
        raise MeshError("boundary is not connected")
    # solid Euler characteristic
    vs, es, fs = set(), set(), set()
    for c in cells:
        h = mesh.hexes[c]
        vs.update(h)
        for a, b in HEX_EDGES:
            es.add(tuple(sorted((h[a], h[b]))))
        for f in HEX_FACES:
            fs.add(tuple(sorted(h[k] for k in f)))
    chi = len(vs) - len(es) + len(fs) - len(cells)
    if chi != 1:
        raise MeshError("ball Euler characteristic %d, want 1" % chi)
    # outward orientation: enclosed signed volume > 0
    P = mesh.pts
    vol = 0.0
    for q in quads:
        a, b, c, d = (P[q[0]], P[q[1]], P[q[2]], P[q[3]])
        vol += np.dot(a, np.cross(b, c)) + np.dot(a, np.cross(c, d))
    if vol <= 0:
        raise MeshError("boundary is not oriented outward (volume %g)" % (vol / 6))
    return quads


# ----------------------------------------------------------------------------- main

def seed_order(pts, hexes):
    cent = pts[hexes].mean(axis=1)
    mc = pts[np.unique(hexes)].mean(axis=0)
    d = np.linalg.norm(cent - mc, axis=1)
    return sorted(range(len(hexes)), key=lambda i: (round(float(d[i]), 9), i))


def cut(pts, hexes, seed_rank=0, max_hexes=None, paranoid=False):
    """Return (oriented hex array, ball cell ids, boundary quads, #flipped, seed hex)."""
    hexes, nflip = orient_hexes(pts, np.asarray(hexes, dtype=np.int64))
    mesh = HexMesh(pts, hexes)
    order = seed_order(pts, hexes)
    if not 0 <= seed_rank < len(order):
        raise MeshError("--seed %d out of range (mesh has %d hexes)" % (seed_rank, len(order)))
    seed = order[seed_rank]
    ball = Ball(mesh)
    cells = ball.grow(seed, max_hexes=max_hexes, paranoid=paranoid)
    quads = verify(mesh, cells)
    return mesh, cells, quads, nflip, seed


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="Grow a topological ball of hexes from a seed hex of a MEDIT hex mesh "
                    "and write its boundary (OBJ quad surface, outward) and, optionally, "
                    "the ball (legacy VTK hexahedra).",
        epilog="Seed = hex of rank K when hexes are sorted by distance of their centroid to "
               "the mesh centroid (then by index). See the module docstring for the ball test.")
    ap.add_argument("mesh", nargs="?", help="input hex mesh, ASCII MEDIT .mesh")
    ap.add_argument("obj", nargs="?", help="output boundary surface (.obj)")
    ap.add_argument("--ball", metavar="VTK", help="also write the ball as legacy VTK hexahedra")
    ap.add_argument("--seed", type=int, default=0, metavar="K",
                    help="rank of the seed hex in the centroid-distance order (default 0)")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--max-hexes", type=int, default=2000, metavar="N",
                   help="stop when the ball has N hexes (default 2000)")
    g.add_argument("--whole", action="store_true",
                   help="no limit: take every hex that can be taken")
    ap.add_argument("--paranoid", action="store_true",
                    help="verify the whole ball after every addition (slow)")
    ap.add_argument("--quiet", action="store_true", help="no summary line")
    ap.add_argument("--selftest", action="store_true", help="run built-in tests and exit")
    a = ap.parse_args(argv)
    if a.selftest:
        return selftest()
    if not a.mesh or not a.obj:
        ap.error("MESH and OBJ are required")
    try:
        pts, hexes = read_medit(a.mesh)
        limit = None if a.whole else a.max_hexes
        if limit is not None and limit < 1:
            raise MeshError("--max-hexes must be >= 1")
        mesh, cells, quads, nflip, seed = cut(pts, hexes, a.seed, limit, a.paranoid)
    except (MeshError, OSError, ValueError) as e:
        print("cut_hex_ball: error: %s" % e, file=sys.stderr)
        return 2
    bverts = sorted(set(v for q in quads for v in q))
    bmap = {v: i for i, v in enumerate(bverts)}
    comment = ("boundary of a %d-hex ball cut from %s (seed rank %d = hex %d)"
               % (len(cells), a.mesh, a.seed, seed + 1))
    write_obj(a.obj, mesh.pts[bverts], [tuple(bmap[v] for v in q) for q in quads], comment)
    if a.ball:
        cs = sorted(cells)
        cverts = sorted(set(v for c in cs for v in mesh.hexes[c]))
        cmap = {v: i for i, v in enumerate(cverts)}
        write_vtk(a.ball, mesh.pts[cverts],
                  [[cmap[v] for v in mesh.hexes[c]] for c in cs],
                  "%d-hex ball cut from %s (seed rank %d)" % (len(cells), a.mesh, a.seed))
    if not a.quiet:
        print("%s: %d of %d hexes, %d boundary quads, %d boundary vertices, %d hexes re-oriented"
              % (a.obj, len(cells), len(hexes), len(quads), len(bverts), nflip))
    return 0


# ------------------------------------------------------------------------ self-test

def _grid_mesh(mask):
    """Hex mesh of unit voxels where mask[i][j][k] is true (MEDIT-like, mixed orientation)."""
    nx, ny, nz = len(mask), len(mask[0]), len(mask[0][0])
    idx = {}
    pts = []
    for i in range(nx + 1):
        for j in range(ny + 1):
            for k in range(nz + 1):
                idx[(i, j, k)] = len(pts)
                pts.append((float(i), float(j), float(k)))
    hexes = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                if mask[i][j][k]:
                    c = [(i, j, k), (i + 1, j, k), (i + 1, j + 1, k), (i, j + 1, k)]
                    h = [idx[p] for p in c] + [idx[(p[0], p[1], p[2] + 1)] for p in c]
                    if (i + j + k) % 2:          # negative orientation, must be fixed
                        h = [h[x] for x in FLIP]
                    hexes.append(h)
    return np.array(pts), np.array(hexes)


def selftest():
    ok = True

    def check(name, cond):
        nonlocal ok
        print("%-52s %s" % (name, "ok" if cond else "FAIL"))
        ok = ok and cond

    full = [[[True] * 3 for _ in range(3)] for _ in range(3)]
    pts, hexes = _grid_mesh(full)
    mesh, cells, quads, nflip, _ = cut(pts, hexes, 0, None, paranoid=True)
    check("3x3x3 block: all 27 hexes taken", len(cells) == 27)
    check("3x3x3 block: 54 boundary quads", len(quads) == 54)
    check("3x3x3 block: 13 hexes re-oriented", nflip == 13)
    mesh, cells, quads, _, _ = cut(pts, hexes, 0, 5, paranoid=True)
    check("3x3x3 block: --max-hexes 5 gives 5 hexes", len(cells) == 5)
    ring = [[[not (1 <= i <= 2 and 1 <= j <= 2)] for j in range(4)] for i in range(4)]
    pts, hexes = _grid_mesh(ring)
    mesh, cells, quads, _, _ = cut(pts, hexes, 0, None, paranoid=True)
    check("12-hex ring (torus): ball stops at 11 hexes", len(cells) == 11)
    # two blocks touching along one edge only: the second can never be reached
    two = [[[False] * 2 for _ in range(2)] for _ in range(2)]
    two[0][0][0] = two[1][1][0] = True
    pts, hexes = _grid_mesh(two)
    mesh, cells, quads, _, _ = cut(pts, hexes, 0, None, paranoid=True)
    check("edge-touching hexes: only the seed", len(cells) == 1)
    # L of three hexes around a corner plus the diagonal one closing a pinched edge
    m = [[[False] * 2 for _ in range(2)] for _ in range(2)]
    m[0][0][0] = m[1][0][0] = m[0][1][0] = m[1][1][0] = True
    pts, hexes = _grid_mesh(m)
    mesh, cells, quads, _, _ = cut(pts, hexes, 0, None, paranoid=True)
    check("2x2x1 block: all 4 hexes", len(cells) == 4)
    print("selftest: %s" % ("PASS" if ok else "FAIL"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
