#!/usr/bin/env python3
"""Tests of the Python module hexpeel (python/). Run by ctest (tests/python/CMakeLists.txt) as
    python3 test_hexpeel.py --cli BUILD/hexpeel --examples SOURCE/examples
with PYTHONPATH = BUILD/python. Plain unittest; numpy and meshio from Debian."""

import argparse
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import numpy as np

import hexpeel

CLI = None
EXAMPLES = None

# VTK hex: outward faces and right-handed corner frames (include/hexpeel/hex_mesh.h).
HEX_FACES = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
CORNER_FRAMES = [(1, 3, 4), (2, 0, 5), (3, 1, 6), (0, 2, 7), (7, 5, 0), (4, 6, 1), (5, 7, 2),
                 (6, 4, 3)]


# ---------------------------------------------------------------- surfaces made in numpy

def unit_cube():
    """8 points, 6 outward quads."""
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                    [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=np.float64)
    return pts, np.array(HEX_FACES, dtype=np.int64)


def grid_box(n=2):
    """Boundary of an n x n x n grid of unit cells: 6 n^2 outward quads on (n+1)^3 - (n-1)^3
    vertices, numbered in order of first use."""
    ids = {}
    pts = []

    def vid(p):
        if p not in ids:
            ids[p] = len(pts)
            pts.append(p)
        return ids[p]

    quads = []
    centre = np.array([n / 2.0] * 3)
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, n):
            for i in range(n):
                for j in range(n):
                    corners = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0, 0, 0]
                        p[axis], p[u], p[v] = side, i + di, j + dj
                        corners.append(tuple(p))
                    c = np.array(corners, dtype=float)
                    normal = np.cross(c[1] - c[0], c[3] - c[0])
                    if np.dot(normal, c.mean(axis=0) - centre) < 0:
                        corners.reverse()
                    quads.append([vid(p) for p in corners])
    return np.array(pts, dtype=np.float64), np.array(quads, dtype=np.int64)


def torus(nu=8, nv=6, R=2.0, r=0.7):
    """A genus-1 quad torus."""
    pts = []
    for i in range(nu):
        a = 2 * math.pi * i / nu
        for j in range(nv):
            b = 2 * math.pi * j / nv
            pts.append([(R + r * math.cos(b)) * math.cos(a), (R + r * math.cos(b)) * math.sin(a),
                        r * math.sin(b)])
    quads = []
    for i in range(nu):
        for j in range(nv):
            i1, j1 = (i + 1) % nu, (j + 1) % nv
            quads.append([i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1])
    return np.array(pts), np.array(quads)


def prism_radial():
    """Radial quad mesh of a triangular prism (tests/topology/soups.h): closed, genus 0, 9 quads."""
    p = [[math.cos(2 * math.pi * i / 3), math.sin(2 * math.pi * i / 3), z]
         for z in (0, 1) for i in range(3)]
    faces = [[0, 2, 1], [3, 4, 5], [0, 1, 4, 3], [1, 2, 5, 4], [2, 0, 3, 5]]
    pts = [np.array(q, dtype=float) for q in p]
    nv = len(pts)
    face_left = {}
    for f, fv in enumerate(faces):
        c = np.zeros(3)
        nrm = np.zeros(3)
        for i in range(len(fv)):
            a, b = pts[fv[i]], pts[fv[(i + 1) % len(fv)]]
            c += a
            nrm += np.cross(a, b)
            face_left[(fv[i], fv[(i + 1) % len(fv)])] = nv + f
        pts.append(c / len(fv) + 0.1 * nrm / np.linalg.norm(nrm))
    quads = [[e0, face_left[(e1, e0)], e1, left]
             for (e0, e1), left in sorted(face_left.items()) if e0 < e1]
    return np.array(pts), np.array(quads)


def write_obj(path, pts, quads):
    with open(path, "w") as f:
        for p in pts:
            f.write("v %.17g %.17g %.17g\n" % tuple(p))
        for q in quads:
            f.write("f %d %d %d %d\n" % tuple(int(i) + 1 for i in q))


# ---------------------------------------------------------------- checks of a hex mesh

def hex_volume(p):
    """Volume of a hex with corners p (8, 3), from its 6 faces split at their centroids."""
    c0 = p.mean(axis=0)
    vol = 0.0
    for f in HEX_FACES:
        q = p[list(f)]
        fc = q.mean(axis=0)
        for k in range(4):
            a, b = q[k], q[(k + 1) % 4]
            vol += np.dot(a - c0, np.cross(b - c0, fc - c0)) / 6.0
    return vol


def canonical(cycle):
    """An oriented quad as the rotation starting at its smallest id."""
    k = int(np.argmin(cycle))
    return tuple(int(cycle[(k + i) % 4]) for i in range(4))


def boundary_faces(hexes):
    """Hex faces used once, as canonical oriented cycles (outward)."""
    count = {}
    oriented = {}
    for h in hexes:
        for f in HEX_FACES:
            cyc = [h[i] for i in f]
            key = tuple(sorted(int(i) for i in cyc))
            count[key] = count.get(key, 0) + 1
            oriented[key] = canonical(cyc)
    return sorted(oriented[k] for k, c in count.items() if c == 1)


class HexMeshChecks:
    def assert_valid_mesh(self, in_pts, in_quads, pts, hexes, report):
        self.assertEqual(pts.dtype, np.float64)
        self.assertEqual(pts.ndim, 2)
        self.assertEqual(pts.shape[1], 3)
        self.assertIn(hexes.dtype, (np.int32, np.int64))
        self.assertEqual(hexes.shape[1], 8)
        self.assertGreater(len(hexes), 0)
        self.assertTrue(hexes.min() >= 0 and hexes.max() < len(pts))
        # every hex positive: its volume and its 8 corner Jacobians
        for h in hexes:
            p = pts[h]
            self.assertGreater(hex_volume(p), 0.0)
            for c, (a, b, d) in enumerate(CORNER_FRAMES):
                self.assertGreater(np.linalg.det(np.array([p[a] - p[c], p[b] - p[c],
                                                           p[d] - p[c]])), 0.0)
        # the boundary is the input surface: same points first, same (outward) quads
        n = len(in_pts)
        self.assertEqual(pts[:n].tobytes(), np.ascontiguousarray(in_pts, np.float64).tobytes())
        self.assertEqual(boundary_faces(hexes), sorted(canonical(q) for q in in_quads))
        # volumes add up to the volume the surface encloses
        total = sum(hex_volume(pts[h]) for h in hexes)
        enclosed = 0.0
        for q in in_quads:
            c = in_pts[q].mean(axis=0)
            for k in range(4):
                a, b = in_pts[q[k]], in_pts[q[(k + 1) % 4]]
                enclosed += np.dot(a, np.cross(b, c)) / 6.0
        self.assertAlmostEqual(total, enclosed, places=9)
        # the report
        self.assertIsInstance(report, dict)
        self.assertEqual(report["status"], "ok")
        self.assertEqual(report["message"], "")
        self.assertEqual(report["hexes"], len(hexes))
        self.assertEqual(report["points"], len(pts))
        self.assertEqual(report["scaled_jacobian"]["count_nonpositive"], 0)


class MeshTest(unittest.TestCase, HexMeshChecks):
    def test_unit_cube(self):
        pts, quads = unit_cube()
        out_pts, hexes, report = hexpeel.mesh(pts, quads)
        self.assert_valid_mesh(pts, quads, out_pts, hexes, report)
        self.assertIn("params", report)
        self.assertIn("orders_tried", report)

    def test_grid_box(self):
        pts, quads = grid_box(2)
        self.assertEqual(len(quads), 24)
        self.assertEqual(len(pts), 26)
        out_pts, hexes, report = hexpeel.mesh(pts, quads, threads=1)
        self.assert_valid_mesh(pts, quads, out_pts, hexes, report)
        self.assertGreaterEqual(len(hexes), 8)

    def test_options_and_threads_same_result(self):
        pts, quads = grid_box(2)
        a = hexpeel.mesh(pts, quads, threads=1)
        b = hexpeel.mesh(pts, quads, threads=2, sharp_angle=60.0, plan_budget=30.0)
        self.assertEqual(a[0].tobytes(), b[0].tobytes())
        self.assertTrue(np.array_equal(a[1], b[1]))

    def test_non_contiguous_and_other_dtypes(self):
        pts, quads = grid_box(2)
        ref = hexpeel.mesh(pts, quads)
        big = np.zeros((len(pts), 6))
        big[:, ::2] = pts
        strided = big[:, ::2]                       # non-contiguous float64
        self.assertFalse(strided.flags["C_CONTIGUOUS"])
        fortran = np.asfortranarray(quads.astype(np.int32))
        self.assertFalse(fortran.flags["C_CONTIGUOUS"])
        for p, q in ((strided, fortran), (pts.astype(np.float32).astype(np.float64), quads[:, :]),
                     (pts, quads.astype(np.uint16)), (pts.tolist(), quads.tolist()),
                     (pts.astype(np.int64), quads.T.copy().T)):
            got = hexpeel.mesh(p, q)
            self.assertEqual(got[0].tobytes(), ref[0].tobytes())
            self.assertTrue(np.array_equal(got[1], ref[1]))

    def test_same_as_cli_on_stairs(self):
        import meshio
        obj = os.path.join(EXAMPLES, "stairs.obj")
        surf = meshio.read(obj)
        quads = np.concatenate([c.data for c in surf.cells if c.type == "quad"])
        pts, hexes, report = hexpeel.mesh(surf.points, quads)
        with tempfile.TemporaryDirectory() as tmp:
            vtk = os.path.join(tmp, "stairs.vtk")
            run = subprocess.run([CLI, "mesh", obj, "-o", vtk, "-q"], capture_output=True,
                                 text=True)
            self.assertIn(run.returncode, (0, 5), run.stderr)
            cli = meshio.read(vtk)
        cli_hexes = np.concatenate([c.data for c in cli.cells if c.type == "hexahedron"])
        self.assertTrue(np.array_equal(hexes, cli_hexes))
        self.assertEqual(np.ascontiguousarray(cli.points, np.float64).tobytes(), pts.tobytes())
        self.assertEqual(report["hexes"], len(hexes))
        self.assertEqual(report["scaled_jacobian"]["count_nonpositive"] > 0, run.returncode == 5)
        self.assert_valid_mesh(surf.points, quads, pts, hexes, report)

    def test_gil_released_threads(self):
        pts, quads = grid_box(2)
        results = [None] * 3

        def work(i):
            results[i] = hexpeel.mesh(pts, quads, threads=1)

        threads = [threading.Thread(target=work, args=(i,)) for i in range(3)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for r in results:
            self.assertTrue(np.array_equal(r[1], results[0][1]))

    def test_gil_released_while_meshing(self):
        """Python code runs in another thread while a mesh is being made."""
        pts, quads = grid_box(14)  # 2744 hexes, some 60 ms
        span = {}

        def work():
            span["t0"] = time.perf_counter()
            span["result"] = hexpeel.mesh(pts, quads, threads=1)
            span["t1"] = time.perf_counter()

        worker = threading.Thread(target=work)
        ticks = []
        worker.start()
        while worker.is_alive():
            ticks.append(time.perf_counter())
        worker.join()
        during = [t for t in ticks if span["t0"] < t < span["t1"]]
        self.assertEqual(len(span["result"][1]), 2744)
        self.assertGreater(len(during), 1000)

    def test_docstrings(self):
        for f in (hexpeel.mesh, hexpeel.check, hexpeel.quality, hexpeel.patches, hexpeel.mesh_meshio):
            self.assertTrue(f.__doc__ and len(f.__doc__) > 80, f)
        self.assertIn("sharp_angle", hexpeel.mesh.__doc__)
        self.assertIn("VTK", hexpeel.mesh.__doc__)
        self.assertTrue(hexpeel.Error.__doc__)
        import inspect
        sig = inspect.signature(hexpeel.mesh)
        self.assertEqual(list(sig.parameters),
                         ["points", "quads", "sharp_angle", "plan_budget", "threads",
                          "repair_surface", "repair_fill"])
        self.assertEqual(sig.parameters["sharp_angle"].default, 60.0)
        self.assertTrue(hexpeel.__doc__)


class ErrorTest(unittest.TestCase):
    def assert_error(self, code, fn, *args, **kw):
        with self.assertRaises(hexpeel.Error) as cm:
            fn(*args, **kw)
        e = cm.exception
        self.assertIsInstance(e, ValueError)
        self.assertEqual(e.code, code, str(e))
        self.assertTrue(str(e).startswith(code + ": "), str(e))
        return e

    def cli_error(self, pts, quads):
        """The message of `hexpeel mesh` on this surface (after 'hexpeel: error: ')."""
        with tempfile.TemporaryDirectory() as tmp:
            obj = os.path.join(tmp, "s.obj")
            write_obj(obj, pts, quads)
            run = subprocess.run([CLI, "mesh", obj, "-o", os.path.join(tmp, "s.vtk"), "-q"],
                                 capture_output=True, text=True)
        self.assertNotEqual(run.returncode, 0)
        line = [l for l in run.stderr.splitlines() if l.startswith("hexpeel: error: ")][-1]
        return line[len("hexpeel: error: "):]

    def test_error_is_value_error(self):
        self.assertTrue(issubclass(hexpeel.Error, ValueError))

    def test_odd_quad_count(self):
        pts, quads = prism_radial()
        self.assertEqual(len(quads), 9)
        # the library's warnings come out as Python warnings (here: its chord crosses itself)
        with self.assertWarnsRegex(UserWarning, "self_intersecting_chord"):
            e = self.assert_error("odd_quad_count", hexpeel.mesh, pts, quads)
        self.assertEqual(str(e), self.cli_error(pts, quads))
        self.assertIsInstance(e.report, dict)

    def test_odd_quad_count_repaired(self):
        pts, quads = prism_radial()
        with self.assertWarnsRegex(UserWarning, "surface repaired"):
            out_pts, hexes, report = hexpeel.mesh(pts, quads, repair_surface=True)
        self.assertEqual(report["repair"]["input_quads"], 9)
        self.assertTrue(report["repair"]["input_odd"])
        self.assertEqual(report["scaled_jacobian"]["count_nonpositive"], 0)
        self.assertEqual(len(hexes), report["hexes"])
        np.testing.assert_array_equal(out_pts[: len(pts)], np.asarray(pts, dtype=float))

    def test_repair_fill(self):
        pts, quads = prism_radial()
        with self.assertWarnsRegex(UserWarning, "surface repaired"):
            _, tets, rt = hexpeel.mesh(pts, quads, repair_surface=True, repair_fill="tets")
        self.assertTrue(rt["repair"]["tet_fill"]["kept"])
        self.assertEqual(len(tets), 4 * rt["repair"]["tet_fill"]["tetrahedra"])
        with self.assertWarnsRegex(UserWarning, "surface repaired"):
            _, elim, re_ = hexpeel.mesh(pts, quads, repair_surface=True, repair_fill="elimination")
        self.assertNotIn("tet_fill", re_["repair"])
        self.assertEqual(re_["scaled_jacobian"]["count_nonpositive"], 0)
        self.assert_error("invalid_argument", hexpeel.mesh, pts, quads, repair_surface=True,
                          repair_fill="octree")

    def test_torus(self):
        pts, quads = torus()
        e = self.assert_error("nonzero_genus", hexpeel.mesh, pts, quads)
        self.assertEqual(str(e), self.cli_error(pts, quads))

    def test_bad_indices(self):
        pts, quads = unit_cube()
        for bad in (-1, 8, 2**40):
            q = quads.copy()
            q[3, 2] = bad
            e = self.assert_error("index_out_of_range", hexpeel.mesh, pts, q)
            self.assertIn("quad 3", str(e))
            self.assert_error("index_out_of_range", hexpeel.check, pts, q)
        q = quads.astype(np.uint64)
        q[0, 0] = np.uint64(2**64 - 1)
        self.assert_error("index_out_of_range", hexpeel.mesh, pts, q)

    def test_wrong_shapes_and_dtypes(self):
        pts, quads = unit_cube()
        self.assert_error("invalid_argument", hexpeel.mesh, pts[:, :2], quads)
        self.assert_error("invalid_argument", hexpeel.mesh, pts.ravel(), quads)
        self.assert_error("invalid_argument", hexpeel.mesh, pts[None], quads)
        self.assert_error("invalid_argument", hexpeel.mesh, pts, quads.ravel())
        self.assert_error("non_quad_face", hexpeel.mesh, pts, quads[:, :3])
        self.assert_error("invalid_argument", hexpeel.mesh, pts, quads.astype(np.float64))
        self.assert_error("invalid_argument", hexpeel.mesh, pts.astype(str), quads)
        self.assert_error("invalid_argument", hexpeel.mesh, pts.astype(complex), quads)
        self.assert_error("invalid_argument", hexpeel.mesh, pts, [[0, 1, 2], [0, 1]])
        self.assert_error("invalid_argument", hexpeel.mesh, "points", quads)
        self.assert_error("invalid_argument", hexpeel.mesh, None, quads)
        self.assert_error("empty_mesh", hexpeel.mesh, pts, np.zeros((0, 4), np.int64))
        self.assert_error("empty_mesh", hexpeel.mesh, pts, [])
        self.assert_error("invalid_argument", hexpeel.mesh, pts, quads, sharp_angle=0.0)
        self.assert_error("invalid_argument", hexpeel.mesh, pts, quads, sharp_angle=float("nan"))
        self.assert_error("invalid_argument", hexpeel.mesh, pts, quads, threads=-1)
        self.assert_error("invalid_argument", hexpeel.mesh, pts, quads, plan_budget=-1.0)
        self.assert_error("invalid_argument", hexpeel.quality, pts, quads)
        self.assert_error("invalid_argument", hexpeel.check, pts, quads, sharp_angle=180.0)
        with self.assertRaises(TypeError):  # options are keyword-only
            hexpeel.mesh(pts, quads, 60.0)

    def test_invalid_geometry(self):
        pts, quads = unit_cube()
        p = pts.copy()
        p[0, 0] = np.nan
        self.assert_error("non_finite_coordinate", hexpeel.mesh, p, quads)
        self.assert_error("open_boundary", hexpeel.mesh, pts, quads[:5])


class CheckQualityTest(unittest.TestCase):
    def test_check_valid(self):
        pts, quads = grid_box(2)
        d = hexpeel.check(pts, quads)
        self.assertIsInstance(d, dict)
        for key in ("status", "validation", "chords", "edges"):
            self.assertIn(key, d)
        self.assertTrue(d["status"]["ok"])
        self.assertEqual(d["status"]["code"], "ok")
        self.assertEqual(d["validation"]["quads"], 24)
        self.assertEqual(d["validation"]["genus"], 0)
        self.assertEqual(d["chords"]["count"], 6)
        self.assertEqual(d["edges"]["sharp_angle_deg"], 60.0)
        self.assertEqual(hexpeel.check(pts, quads, sharp_angle=30.0)["edges"]["sharp_angle_deg"],
                         30.0)

    def test_check_same_as_cli(self):
        import json
        pts, quads = torus()
        d = hexpeel.check(pts, quads)  # an invalid surface is a diagnosis, not an error
        self.assertFalse(d["status"]["ok"])
        self.assertEqual(d["status"]["code"], "nonzero_genus")
        self.assertEqual(d["validation"]["genus"], 1)
        with tempfile.TemporaryDirectory() as tmp:
            obj = os.path.join(tmp, "t.obj")
            js = os.path.join(tmp, "t.json")
            write_obj(obj, pts, quads)
            subprocess.run([CLI, "check", obj, "--json", js], capture_output=True)
            with open(js) as f:
                self.assertEqual(json.load(f), d)

    def test_quality(self):
        pts, quads = grid_box(2)
        out_pts, hexes, report = hexpeel.mesh(pts, quads)
        q = hexpeel.quality(out_pts, hexes)
        self.assertIsInstance(q, dict)
        for key in ("hexes", "points", "scaled_jacobian", "singular_edges", "complex",
                    "euler_characteristic", "is_ball", "topology_message", "boundary_message"):
            self.assertIn(key, q)
        for key in ("min", "mean", "max", "count_nonpositive", "degenerate", "histogram",
                    "worst"):
            self.assertIn(key, q["scaled_jacobian"])
        self.assertEqual(q["hexes"], len(hexes))
        self.assertTrue(q["is_ball"])
        self.assertEqual(q["euler_characteristic"], 1)
        self.assertEqual(q["scaled_jacobian"]["min"], report["scaled_jacobian"]["min"])
        # one unit cube hex: SJ 1
        cube, _ = unit_cube()
        q1 = hexpeel.quality(cube, np.arange(8)[None, :])
        self.assertEqual(q1["hexes"], 1)
        self.assertAlmostEqual(q1["scaled_jacobian"]["min"], 1.0)
        # mirrored: inverted
        q2 = hexpeel.quality(cube, np.array([[0, 3, 2, 1, 4, 7, 6, 5]]))
        self.assertEqual(q2["scaled_jacobian"]["count_nonpositive"], 1)
        with self.assertRaises(hexpeel.Error) as cm:
            hexpeel.quality(cube, np.array([[0, 1, 2, 3, 4, 5, 6, 8]]))
        self.assertEqual(cm.exception.code, "invalid_mesh")


class MeshioTest(unittest.TestCase, HexMeshChecks):
    def test_mesh_meshio(self):
        import meshio
        pts, quads = grid_box(2)
        surf = meshio.Mesh(pts, [("quad", quads)])
        out = hexpeel.mesh_meshio(surf, threads=1)
        self.assertIsInstance(out, meshio.Mesh)
        self.assertEqual([c.type for c in out.cells], ["hexahedron"])
        ref = hexpeel.mesh(pts, quads)
        self.assertEqual(np.asarray(out.points).tobytes(), ref[0].tobytes())
        self.assertTrue(np.array_equal(out.cells[0].data, ref[1]))
        self.assertEqual(out.hexpeel_report["hexes"], len(ref[1]))
        self.assert_valid_mesh(pts, quads, np.asarray(out.points), out.cells[0].data,
                               out.hexpeel_report)

    def test_patches_of_a_box(self):
        pts, quads = grid_box(2)
        patch = hexpeel.patches(pts, quads)
        self.assertEqual(patch.shape, (len(quads),))
        self.assertEqual(sorted(set(patch.tolist())), list(range(6)))
        # the same patch exactly when the quads face the same way (outward normal)
        normal = [tuple(np.sign(np.round(np.cross(pts[q[1]] - pts[q[0]], pts[q[3]] - pts[q[0]]))))
                  for q in quads]
        for i in range(len(quads)):
            for j in range(len(quads)):
                self.assertEqual(patch[i] == patch[j], normal[i] == normal[j], (i, j))
        # bends below the threshold do not cut: one patch at 100 degrees
        self.assertEqual(set(hexpeel.patches(pts, quads, sharp_angle=100.0).tolist()), {0})
        rp, rq = prism_radial()  # an odd count is no obstacle to patches
        self.assertEqual(len(hexpeel.patches(rp, rq)), len(rq))
        for (p, q), code in (((pts, quads[:-1]), "open_boundary"), (torus(), "nonzero_genus")):
            with self.assertRaises(hexpeel.Error) as cm:
                hexpeel.patches(p, q)
            self.assertEqual(cm.exception.code, code)

    def test_mesh_meshio_patch_sets(self):
        import meshio
        pts, quads = grid_box(2)
        out = hexpeel.mesh_meshio(meshio.Mesh(pts, [("quad", quads)]), patch_sets=True, threads=1)
        self.assertEqual([c.type for c in out.cells], ["hexahedron", "quad"])
        np.testing.assert_array_equal(out.cells[1].data, quads)
        self.assertEqual(sorted(out.cell_sets), ["patch_%d" % k for k in range(1, 7)])
        got = sorted(int(i) for k in out.cell_sets for i in out.cell_sets[k][1])
        self.assertEqual(got, list(range(len(quads))))  # every quad in exactly one patch
        for k in out.cell_sets:
            self.assertEqual(len(out.cell_sets[k][0]), 0)
            self.assertEqual(len(out.cell_sets[k][1]), 4)  # a 2 x 2 side
        # repaired: the boundary is the refined surface, found from the hexes
        rp, rq = prism_radial()
        with self.assertWarnsRegex(UserWarning, "surface repaired"):
            rep = hexpeel.mesh_meshio(meshio.Mesh(rp, [("quad", rq)]), patch_sets=True,
                                      repair_surface=True)
        bq = rep.cells[1].data
        self.assertEqual(len(bq), rep.hexpeel_report["repair"]["output_quads"])
        self.assertEqual(sum(len(v[1]) for v in rep.cell_sets.values()), len(bq))

    def test_mesh_meshio_errors(self):
        import meshio
        pts, quads = unit_cube()
        tri = meshio.Mesh(pts, [("triangle", np.array([[0, 1, 2]]))])
        with self.assertRaises(hexpeel.Error) as cm:
            hexpeel.mesh_meshio(tri)
        self.assertEqual(cm.exception.code, "invalid_argument")
        self.assertIn("triangle", str(cm.exception))
        tp, tq = torus()
        with self.assertRaises(hexpeel.Error) as cm:
            hexpeel.mesh_meshio(meshio.Mesh(tp, [("quad", tq)]))
        self.assertEqual(cm.exception.code, "nonzero_genus")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--examples", required=True)
    args, rest = ap.parse_known_args()
    CLI, EXAMPLES = args.cli, args.examples
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
