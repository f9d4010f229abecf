// The format readers and writers behind io.h, one .cpp each. Internal to src/io.
//
// Readers parse `data` (the whole file) into a CellSoup and report syntax errors naming `name`
// and the line or byte offset; io.cpp checks corner indices and builds the public types.
// Writers return the file content; io.cpp writes it atomically. The Exodus II writer is the
// exception: its library writes to a path, so it writes the file itself, atomically too.
#pragma once

#include "hexpeel/hex_mesh.h"
#include "io/io_util.h"

#include <filesystem>
#include <string>
#include <string_view>

namespace hexpeel::io {

Status read_obj(std::string_view data, const std::string& name, CellSoup& out);
Status read_off(std::string_view data, const std::string& name, CellSoup& out);
Status read_ply(std::string_view data, const std::string& name, CellSoup& out);
Status read_medit(std::string_view data, const std::string& name, CellSoup& out);
Status read_gmsh(std::string_view data, const std::string& name, CellSoup& out);
Status read_vtk_legacy(std::string_view data, const std::string& name, CellSoup& out);
Status read_vtu(std::string_view data, const std::string& name, CellSoup& out);

std::string write_obj(const QuadSurface& surface);
std::string write_off(const QuadSurface& surface);
std::string write_vtk_legacy(const HexMesh& mesh);
std::string write_vtu(const HexMesh& mesh);
std::string write_medit(const HexMesh& mesh);
std::string write_gmsh(const HexMesh& mesh);
/// Abaqus / CalculiX .inp: C3D8 elements (ELSET HEXES), NSET BOUNDARY, SURFACE BOUNDARY.
std::string write_abaqus(const HexMesh& mesh);
/// Exodus II: writes `path` (temporary file + rename); library errors name `path`.
Status write_exodus(const std::filesystem::path& path, const HexMesh& mesh);

}  // namespace hexpeel::io
