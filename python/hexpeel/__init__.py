"""hexpeel: fill a closed genus-0 all-quad surface with hexahedra.

The boundary of the hex mesh is the input surface: the same vertices (first, in input order, at
the same positions) and the same quads. numpy arrays in and out:

    import numpy as np, hexpeel
    points, hexes, report = hexpeel.mesh(points, quads)   # (N,3) float64, (M,4) int
    print(len(hexes), report["scaled_jacobian"]["min"])

Functions: mesh, check, quality, mesh_meshio. Every failure raises hexpeel.Error (a ValueError)
whose str() is the CLI's message and whose .code is the status code's name. See docs/python.md.
"""

from ._hexpeel import Error, check, mesh, quality

__all__ = ["Error", "mesh", "check", "quality", "mesh_meshio"]
__version__ = "0.1.0"


def mesh_meshio(surface, **options):
    """mesh_meshio(surface, **options) -> meshio.Mesh

    Meshes a meshio.Mesh surface: its "quad" cells (every "quad" block, in order; other cell
    blocks are ignored) over its points. Returns a meshio.Mesh with the hex points and one
    "hexahedron" cell block (VTK corner order). `options` are hexpeel.mesh's keyword options
    (sharp_angle, plan_budget, threads, repair_surface); the report dict is the result's attribute
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
    out = meshio.Mesh(pts, [("hexahedron", hexes)])
    out.hexpeel_report = report
    return out


def _argument_error(message):
    e = Error("invalid_argument: " + message)
    e.code = "invalid_argument"
    e.report = None
    return e
