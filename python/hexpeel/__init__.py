"""hexpeel: fill a closed genus-0 all-quad surface with hexahedra.

The boundary of the hex mesh is the input surface: the same vertices (first, in input order, at
the same positions) and the same quads. numpy arrays in and out:

    import numpy as np, hexpeel
    points, hexes, report = hexpeel.mesh(points, quads)   # (N,3) float64, (M,4) int
    print(len(hexes), report["scaled_jacobian"]["min"])

Functions: mesh, check, quality, patches, mesh_meshio. Every failure raises hexpeel.Error (a ValueError)
whose str() is the CLI's message and whose .code is the status code's name. See docs/python.md.
"""

from ._hexpeel import Error, check, mesh, patches, quality

__all__ = ["Error", "mesh", "check", "quality", "patches", "mesh_meshio"]
__version__ = "0.1.0"


# Outward faces of a positive hex in VTK corner order.
_HEX_FACES = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))


def _boundary_quads(hexes):
    """The hex faces that occur once, outward, in hex then face order."""
    import numpy as np

    faces = np.asarray(hexes)[:, _HEX_FACES].reshape(-1, 4)
    _, inverse, counts = np.unique(np.sort(faces, axis=1), axis=0, return_inverse=True,
                                   return_counts=True)
    return faces[counts[inverse.reshape(-1)] == 1]


def mesh_meshio(surface, patch_sets=False, **options):
    """mesh_meshio(surface, patch_sets=False, **options) -> meshio.Mesh

    Meshes a meshio.Mesh surface: its "quad" cells (every "quad" block, in order; other cell
    blocks are ignored) over its points. Returns a meshio.Mesh with the hex points and one
    "hexahedron" cell block (VTK corner order). With patch_sets, a second block "quad" holds the
    mesh's boundary (the input quads, or the repaired surface's), and cell_sets "patch_1", ...
    the boundary quads of each patch bounded by sharp edges (hexpeel.patches; as
    `hexpeel mesh --patch-sets`). `options` are hexpeel.mesh's keyword options (sharp_angle,
    plan_budget, threads, repair_surface); the report dict is the result's attribute
    `hexpeel_report`.
    Raises hexpeel.Error (code "invalid_argument" when the mesh has no "quad" cells).
    """
    import numpy as np
    import meshio  # lazily: only this helper needs it

    blocks = [c.data for c in surface.cells if c.type == "quad"]
    if not blocks:
        types = sorted({c.type for c in surface.cells})
        raise _argument_error(
            "the meshio.Mesh has no 'quad' cells (cell types: %s)" % (", ".join(types) or "none"))
    quads = np.concatenate(blocks, axis=0)
    points = np.asarray(surface.points)
    if points.ndim == 2 and points.shape[1] == 2:  # planar meshio points: not a closed surface
        raise _argument_error("the meshio.Mesh has 2D points; a closed surface needs 3D points")
    pts, hexes, report = mesh(points, quads, **options)
    if not patch_sets:
        out = meshio.Mesh(pts, [("hexahedron", hexes)])
    else:
        repaired = (report.get("repair") or {}).get("applied", False)
        boundary = _boundary_quads(hexes) if repaired else np.asarray(quads, dtype=np.int64)
        patch = patches(pts, boundary, sharp_angle=options.get("sharp_angle", 60.0))
        sets = {"patch_%d" % (k + 1): [np.zeros(0, dtype=np.int64), np.flatnonzero(patch == k)]
                for k in range(int(patch.max()) + 1 if len(patch) else 0)}
        out = meshio.Mesh(pts, [("hexahedron", hexes), ("quad", boundary)], cell_sets=sets)
    out.hexpeel_report = report
    return out


def _argument_error(message):
    e = Error("invalid_argument: " + message)
    e.code = "invalid_argument"
    e.report = None
    return e
