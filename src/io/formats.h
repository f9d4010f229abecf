// The format readers and writers behind io.h, one .cpp each. Internal to src/io.
//
// Readers parse `data` (the whole file) into a CellSoup and report syntax errors naming `name`
// and the line or byte offset; io.cpp checks corner indices and builds the public types.
// Writers return the file content; io.cpp writes it atomically. The Exodus II writer is the
// exception: its library writes to a path, so it writes the file itself, atomically too.
#pragma once

#include "hexpeel/hex_mesh.h"
#include "io/hex_sides.h"
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
// `patches` (checked, may be null): the boundary groups, for the formats that carry them.
std::string write_vtk_legacy(const HexMesh& mesh, const PatchLookup* patches);
std::string write_vtu(const HexMesh& mesh, const PatchLookup* patches);
/// MEDIT: with patches, Quadrilaterals (the patch faces, reference = patch + 1).
std::string write_medit(const HexMesh& mesh, const PatchLookup* patches);
/// Gmsh 4.1: with patches, one surface entity of quads per patch, physical groups patch_k (2D)
/// and hexes (3D).
std::string write_gmsh(const HexMesh& mesh, const PatchLookup* patches);
/// Abaqus / CalculiX .inp: C3D8 elements (ELSET HEXES), NSET BOUNDARY, SURFACE BOUNDARY; with
/// patches also SURFACE PATCH_k.
std::string write_abaqus(const HexMesh& mesh, const PatchLookup* patches);
/// Exodus II: writes `path` (temporary file + rename); library errors name `path`. With
/// patches, side sets 2.. named patch_k after side set 1 "boundary".
Status write_exodus(const std::filesystem::path& path, const HexMesh& mesh, const PatchLookup* patches);

}  // namespace hexpeel::io
