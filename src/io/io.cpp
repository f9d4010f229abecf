// The public entry points of io.h: picks the format from the file extension, runs its reader or
// writer, and turns a reader's CellSoup into a PolygonSoup or a HexMesh.
//
// Every corner index is checked here against the point count, so the formats only parse. The
// result is built only when the whole file was read without error: a failed read leaves `out`
// empty rather than half filled.
#include "hexpeel/io.h"

#include "io/formats.h"

#include <limits>

namespace hexpeel {

namespace {

using io::CellKind;
using io::CellSoup;

using Reader = Status (*)(std::string_view, const std::string&, CellSoup&);
using HexWriter = std::string (*)(const HexMesh&, const io::PatchLookup*);

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return ext;
}

Reader surface_reader(const std::string& ext) {
  if (ext == ".obj") return io::read_obj;
  if (ext == ".off") return io::read_off;
  if (ext == ".ply") return io::read_ply;
  if (ext == ".mesh") return io::read_medit;
  if (ext == ".msh") return io::read_gmsh;
  if (ext == ".vtk") return io::read_vtk_legacy;
  if (ext == ".vtu") return io::read_vtu;
  return nullptr;
}

Reader hex_reader(const std::string& ext) {
  if (ext == ".mesh") return io::read_medit;
  if (ext == ".msh") return io::read_gmsh;
  if (ext == ".vtk") return io::read_vtk_legacy;
  if (ext == ".vtu") return io::read_vtu;
  return nullptr;
}

constexpr const char* kSurfaceExtensions = ".obj .off .ply .mesh .msh .vtk .vtu";
constexpr const char* kHexExtensions = ".vtk .vtu .mesh .msh";
constexpr const char* kHexOutputExtensions = ".vtk .vtu .mesh .msh .inp .exo .e";

/// The writer of a hex-mesh output format that returns the file content, or nullptr.
HexWriter hex_text_writer(const std::string& ext) {
  if (ext == ".vtk") return io::write_vtk_legacy;
  if (ext == ".vtu") return io::write_vtu;
  if (ext == ".mesh") return io::write_medit;
  if (ext == ".msh") return io::write_gmsh;
  if (ext == ".inp") return io::write_abaqus;
  return nullptr;
}

/// Exodus II, which its library writes to a path.
bool is_exodus_extension(const std::string& ext) { return ext == ".exo" || ext == ".e"; }

Status unsupported(const std::filesystem::path& path, const char* what, const char* list) {
  return Status::error(StatusCode::unsupported_format,
                       path.string() + ": unknown " + what + " file extension '" +
                           path.extension().string() + "' (supported: " + list + ")");
}

/// Reads and parses the whole file with `reader`.
Status parse_file(const std::filesystem::path& path, Reader reader, CellSoup& soup) {
  std::string data;
  if (Status s = io::read_whole_file(path, data); !s.ok()) return s;
  if (data.empty()) return Status::error(StatusCode::empty_mesh, path.string() + ": file is empty");
  return reader(data, path.string(), soup);
}

/// A 0-based index as the file numbers it (kept as is where adding the base would overflow).
int64_t in_file_numbering(int64_t v, int64_t base) {
  return v > std::numeric_limits<int64_t>::max() - base ? v : v + base;
}

/// Checks the corners of cell c; on failure, an error of `code` naming the cell's location.
Status check_corners(const CellSoup& soup, int64_t n, size_t c, const std::string& name,
                     const char* what, StatusCode code) {
  for (int64_t k = soup.offsets[c]; k < soup.offsets[c + 1]; ++k) {
    const int64_t v = soup.corners[k];
    if (v < 0 || v >= n) {
      return Status::error(
          code, io::located(name, soup.where[c],
                            std::string(what) + " " + std::to_string(c) + " refers to vertex " +
                                std::to_string(in_file_numbering(v, soup.index_base)) + " but only " +
                                std::to_string(n) + " vertices exist" +
                                (soup.index_base ? " (numbered from " +
                                                       std::to_string(soup.index_base) + ")"
                                                 : "")));
    }
  }
  return Status::success();
}

}  // namespace

bool is_hex_mesh_extension(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return hex_text_writer(ext) != nullptr || is_exodus_extension(ext);
}

bool is_surface_extension(const std::filesystem::path& path) {
  return surface_reader(lower_extension(path)) != nullptr;
}

Status read_surface(const std::filesystem::path& path, PolygonSoup& out, int64_t* hexes_ignored) {
  out = PolygonSoup{};
  if (hexes_ignored != nullptr) *hexes_ignored = 0;
  const Reader reader = surface_reader(lower_extension(path));
  if (reader == nullptr) return unsupported(path, "surface", kSurfaceExtensions);
  CellSoup soup;
  if (Status s = parse_file(path, reader, soup); !s.ok()) return s;
  const std::string name = path.string();
  if (soup.points.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max()) ||
      soup.corners.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    return Status::error(StatusCode::parse_error, name + ": more than 2^31 points or corners");
  }
  const int64_t n = static_cast<int64_t>(soup.points.size());
  PolygonSoup result;
  int64_t hexes = 0;
  for (size_t c = 0; c < soup.kinds.size(); ++c) {
    if (soup.kinds[c] == CellKind::hex) ++hexes;
    if (soup.kinds[c] != CellKind::polygon) continue;
    if (Status s = check_corners(soup, n, c, name, "face", StatusCode::index_out_of_range); !s.ok()) {
      return s;
    }
    for (int64_t k = soup.offsets[c]; k < soup.offsets[c + 1]; ++k) {
      result.indices.push_back(static_cast<int32_t>(soup.corners[k]));
    }
    result.offsets.push_back(static_cast<int32_t>(result.indices.size()));
  }
  if (result.num_faces() == 0) {
    if (hexes > 0) {
      return Status::error(StatusCode::empty_mesh,
                           name + ": the file holds " + std::to_string(hexes) +
                               " hexahedra and no surface faces: give the quad surface to mesh "
                               "(e.g. the boundary of this hex mesh as .obj)");
    }
    return Status::error(StatusCode::empty_mesh, name + ": the file holds no surface faces");
  }
  result.points = std::move(soup.points);
  out = std::move(result);
  if (hexes_ignored != nullptr) *hexes_ignored = hexes;
  return Status::success();
}

Status read_hex_mesh(const std::filesystem::path& path, HexMesh& out, int64_t* others) {
  out = HexMesh{};
  const std::string ext = lower_extension(path);
  const Reader reader = hex_reader(ext);
  if (reader == nullptr) return unsupported(path, "hex mesh", kHexExtensions);
  CellSoup soup;
  if (Status s = parse_file(path, reader, soup); !s.ok()) return s;
  const std::string name = path.string();
  if (soup.points.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    return Status::error(StatusCode::parse_error, name + ": more than 2^31 points");
  }
  const int64_t n = static_cast<int64_t>(soup.points.size());
  HexMesh result;
  int64_t skipped = 0;
  for (size_t c = 0; c < soup.kinds.size(); ++c) {
    if (soup.kinds[c] != CellKind::hex) {
      if (others == nullptr) {
        return Status::error(StatusCode::invalid_mesh,
                             io::located(name, soup.where[c], "cell is not a hexahedron"));
      }
      ++skipped;
      continue;
    }
    if (Status s = check_corners(soup, n, c, name, "hexahedron", StatusCode::invalid_mesh); !s.ok()) {
      return s;
    }
    Hex h;
    for (int k = 0; k < 8; ++k) h[k] = static_cast<int32_t>(soup.corners[soup.offsets[c] + k]);
    result.hexes.push_back(h);
  }
  if (result.hexes.empty()) {
    return Status::error(StatusCode::empty_mesh, name + ": the file holds no hexahedra");
  }
  result.points = std::move(soup.points);
  if (others != nullptr) *others += skipped;
  out = std::move(result);
  return Status::success();
}

Status write_surface(const std::filesystem::path& path, const QuadSurface& surface) {
  const std::string ext = lower_extension(path);
  if (ext == ".obj") return io::write_file_atomic(path, io::write_obj(surface));
  if (ext == ".off") return io::write_file_atomic(path, io::write_off(surface));
  return unsupported(path, "surface output", ".obj .off");
}

Status write_hex_mesh(const std::filesystem::path& path, const HexMesh& mesh,
                      const BoundaryPatches* patches) {
  const std::string ext = lower_extension(path);
  const HexWriter writer = hex_text_writer(ext);
  if (writer == nullptr && !is_exodus_extension(ext))
    return unsupported(path, "hex mesh output", kHexOutputExtensions);
  io::PatchLookup lookup;
  if (patches != nullptr)
    if (Status s = io::make_patch_lookup(mesh, *patches, lookup); !s.ok())
      return Status::error(s.code, path.string() + ": " + s.message);
  const io::PatchLookup* p = patches != nullptr ? &lookup : nullptr;
  if (writer != nullptr) return io::write_file_atomic(path, writer(mesh, p));
  return io::write_exodus(path, mesh, p);
}

bool carries_boundary_patches(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".mesh" || ext == ".msh" || ext == ".inp" || is_exodus_extension(ext);
}

Status write_text_file(const std::filesystem::path& path, const std::string& text) {
  return io::write_file_atomic(path, text);
}

}  // namespace hexpeel
