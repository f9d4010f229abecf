// Reading and writing files. The format is chosen by the file extension (case-insensitive).
//
// Surfaces (read): .obj  .off  .ply (ASCII, binary little/big endian)  .mesh (MEDIT, Quadrilaterals)
//                  .msh (Gmsh 2.2 and 4.1, ASCII and binary; quad elements)  .vtk (legacy, ASCII or
//                  binary, POLYDATA POLYGONS or UNSTRUCTURED_GRID cells)  .vtu (its 2D cells)
// Surfaces (write): .obj .off (for dumping intermediate surfaces)
// Hex meshes (read and write): .vtk (legacy ASCII)  .vtu (VTK XML, ASCII)  .mesh (MEDIT)
//                              .msh (Gmsh 4.1 ASCII). Reading also takes what the surface readers
//                              take: binary .vtk, binary/appended/zlib .vtu, Gmsh 2.2 and binary.
// Hex meshes (write only, for FEA): .inp (Abaqus / CalculiX: C3D8 elements, node set BOUNDARY and
//                              element-based surface BOUNDARY)  .exo .e (Exodus II: a HEX8 block,
//                              node set and side set 1 "boundary"). The boundary groups hold every
//                              hex face that occurs once in the mesh; BoundaryPatches add one
//                              group per patch (also to .msh and .mesh). See docs/formats.md.
//
// Readers never crash on any bytes: every problem comes back as a Status naming the line (or
// byte offset) and what was expected. Writers write to a temporary file beside the target and
// rename it at the end, so a failed write leaves nothing behind.
#pragma once

#include "hexpeel/hex_mesh.h"
#include "hexpeel/quad_surface.h"
#include "hexpeel/status.h"

#include <filesystem>
#include <string>

namespace hexpeel {

/// Reads the polygons of a surface file. Indices are checked against the point count. Volume
/// cells (hexahedra, e.g. of a Gmsh or VTK volume mesh) are not part of the surface: their count
/// is stored in `hexes_ignored` when given; a file with hexahedra and no faces is an error that
/// says so.
Status read_surface(const std::filesystem::path& path, PolygonSoup& out,
                    int64_t* hexes_ignored = nullptr);

/// Writes a quad surface (.obj or .off), atomically.
Status write_surface(const std::filesystem::path& path, const QuadSurface& surface);

/// Reads a hex mesh; other cell types are skipped when `others` is given (their count is added),
/// otherwise they are an error. Hex corners come back in VTK order.
Status read_hex_mesh(const std::filesystem::path& path, HexMesh& out, int64_t* others = nullptr);

/// Named groups of a hex mesh's boundary faces: face i (mesh vertex ids, any corner order; a
/// boundary face of the mesh) is in patch patch[i], 0 <= patch[i] < count.
struct BoundaryPatches {
  std::vector<Quad> faces;
  std::vector<int32_t> patch;
  int32_t count = 0;
};

/// Writes a hex mesh in the format its extension names, atomically, with full double precision.
/// With `patches`, the formats that carry boundary groups get one per patch, named patch_1 ..
/// patch_<count> (Exodus II side sets 2.., Abaqus surfaces PATCH_k, Gmsh physical surfaces of
/// quads, MEDIT quadrilaterals with reference k); .vtk and .vtu carry none. A patch face that is
/// not a boundary face of the mesh is an error.
Status write_hex_mesh(const std::filesystem::path& path, const HexMesh& mesh,
                      const BoundaryPatches* patches = nullptr);

/// Whether the extension names a format write_hex_mesh writes boundary patches into.
bool carries_boundary_patches(const std::filesystem::path& path);

/// Writes `text` to `path` atomically (temporary file + rename). Used for reports too.
Status write_text_file(const std::filesystem::path& path, const std::string& text);

/// True when the extension names a hex-mesh format we write (read_hex_mesh reads all of them but
/// .inp, .exo and .e).
bool is_hex_mesh_extension(const std::filesystem::path& path);
/// True when the extension names a surface format we read.
bool is_surface_extension(const std::filesystem::path& path);

}  // namespace hexpeel
