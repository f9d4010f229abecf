// Exodus II (.exo, .e) of a hex mesh, through the Exodus II C library (netCDF underneath): double
// coordinates, element block 1 of type HEX8, node set 1 and side set 1, both named "boundary".
//
// HEX8 node order is VTK_HEXAHEDRON's (hex_mesh.h), so corners are written as stored, 1-based.
// The library writes to a path, not a buffer: the file is made under a temporary name beside the
// target and renamed over it only when complete; on any failure the temporary file is removed and
// the target is untouched. The library keeps process-wide state (its open files, the last error),
// so writes are serialized.
#include "io/formats.h"
#include "io/hex_sides.h"

#include <exodusII.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

namespace hexpeel::io {

namespace {

/// Exodus HEX8 sides 1..6 as VTK-order corners: 1-2-6-5, 2-3-7-6, 3-4-8-7, 1-5-8-4, 1-4-3-2,
/// 5-6-7-8 in the manual's 1-based node numbers.
constexpr SideTable kHex8Sides{{
    {0, 1, 5, 4},
    {1, 2, 6, 5},
    {2, 3, 7, 6},
    {0, 4, 7, 3},
    {0, 3, 2, 1},
    {4, 5, 6, 7},
}};

constexpr ex_entity_id kBlockId = 1;
constexpr ex_entity_id kSetId = 1;

std::mutex exodus_mutex;

/// The Exodus file being written under its temporary name: closed and removed on destruction
/// unless it was finished (closed and renamed) first.
struct TemporaryExodus {
  std::filesystem::path tmp;
  int id = -1;          ///< Exodus file id while open
  bool exists = false;  ///< true while `tmp` is ours to remove
  ~TemporaryExodus() {
    if (id >= 0) ex_close(id);
    if (exists) ::unlink(tmp.c_str());
  }
};

/// The library's last error as a Status naming the target file and the call that failed.
Status library_error(const std::filesystem::path& path, const char* call) {
  const char* msg = nullptr;
  const char* func = nullptr;
  int code = 0;
  ex_get_err(&msg, &func, &code);
  std::string reason;
  if (code > 0) {
    reason = std::strerror(code);  // a system errno
  } else {
    reason = msg != nullptr && *msg != '\0' ? msg : "unknown error";
    if (code != 0) reason += " (netCDF error " + std::to_string(code) + ")";
  }
  return Status::error(StatusCode::io_error,
                       path.string() + ": cannot write Exodus II: " + call + " failed: " + reason);
}

/// Creates the temporary file exclusively, trying fresh names while one exists.
Status create_temporary(const std::filesystem::path& path, TemporaryExodus& file) {
  for (int attempt = 0; attempt < 16; ++attempt) {
    file.tmp = temporary_path_beside(path);
    int cpu_word_size = sizeof(double);
    int io_word_size = sizeof(double);
    file.id = ex_create(file.tmp.c_str(), EX_NOCLOBBER | EX_LARGE_MODEL, &cpu_word_size,
                        &io_word_size);
    if (file.id >= 0) {
      file.exists = true;
      return Status::success();
    }
    const char* msg = nullptr;
    const char* func = nullptr;
    int code = 0;
    ex_get_err(&msg, &func, &code);
    if (code != NC_EEXIST && code != EEXIST) {
      file.exists = true;  // whatever the failed create left there is ours
      return library_error(path, "ex_create");
    }
  }
  return Status::error(StatusCode::io_error,
                       path.string() + ": cannot create a temporary file: names taken");
}

/// 0-based indices as the 1-based ids Exodus stores.
std::vector<int> one_based(const std::vector<int32_t>& ids) {
  std::vector<int> out(ids.begin(), ids.end());
  for (int& v : out) ++v;
  return out;
}

/// Coordinates, the HEX8 block and its connectivity.
Status put_mesh(const std::filesystem::path& path, int id, const HexMesh& mesh) {
  std::vector<double> x, y, z;
  x.reserve(mesh.points.size());
  y.reserve(mesh.points.size());
  z.reserve(mesh.points.size());
  for (const Vec3& p : mesh.points) {
    x.push_back(p.x());
    y.push_back(p.y());
    z.push_back(p.z());
  }
  if (ex_put_coord(id, x.data(), y.data(), z.data()) < 0) return library_error(path, "ex_put_coord");
  if (mesh.hexes.empty()) return Status::success();
  std::vector<int> conn;
  conn.reserve(mesh.hexes.size() * 8);
  for (const Hex& h : mesh.hexes) {
    for (int32_t v : h) conn.push_back(v + 1);
  }
  if (ex_put_block(id, EX_ELEM_BLOCK, kBlockId, "HEX8", mesh.num_hexes(), 8, 0, 0, 0) < 0) {
    return library_error(path, "ex_put_block");
  }
  if (ex_put_conn(id, EX_ELEM_BLOCK, kBlockId, conn.data(), nullptr, nullptr) < 0) {
    return library_error(path, "ex_put_conn");
  }
  if (ex_put_name(id, EX_ELEM_BLOCK, kBlockId, "hexes") < 0) return library_error(path, "ex_put_name");
  return Status::success();
}

/// Set `set_id` of `type` named `name`: `entries` (1-based) and, for a side set, `extra` (the
/// side numbers).
Status put_set(const std::filesystem::path& path, int id, ex_entity_type type,
               const std::vector<int>& entries, const std::vector<int>* extra,
               int64_t set_id = kSetId, const char* name = "boundary") {
  const int64_t n = static_cast<int64_t>(entries.size());
  if (ex_put_set_param(id, type, set_id, n, 0) < 0) return library_error(path, "ex_put_set_param");
  if (ex_put_set(id, type, set_id, entries.data(), extra != nullptr ? extra->data() : nullptr) < 0) {
    return library_error(path, "ex_put_set");
  }
  if (ex_put_name(id, type, set_id, name) < 0) return library_error(path, "ex_put_name");
  return Status::success();
}

/// Side set `set_id` named `name` of `sides`.
Status put_side_set(const std::filesystem::path& path, int id, const std::vector<HexSide>& sides,
                    int64_t set_id, const std::string& name) {
  std::vector<int> elements, numbers;
  elements.reserve(sides.size());
  numbers.reserve(sides.size());
  for (const HexSide& side : sides) {
    elements.push_back(side.hex + 1);
    numbers.push_back(side.side + 1);
  }
  return put_set(path, id, EX_SIDE_SET, elements, &numbers, set_id, name.c_str());
}

Status put_boundary(const std::filesystem::path& path, int id, const HexMesh& mesh,
                    const std::vector<HexSide>& sides) {
  if (sides.empty()) return Status::success();
  if (Status s = put_set(path, id, EX_NODE_SET, one_based(side_vertices(mesh, kHex8Sides, sides)),
                         nullptr);
      !s.ok()) {
    return s;
  }
  return put_side_set(path, id, sides, kSetId, "boundary");
}

}  // namespace

Status write_exodus(const std::filesystem::path& path, const HexMesh& mesh, const PatchLookup* patches) {
  if (path.filename().empty()) {
    return Status::error(StatusCode::io_error, path.string() + ": not a file name");
  }
  const std::vector<HexSide> sides = boundary_sides(mesh, kHex8Sides);
  const std::lock_guard<std::mutex> lock(exodus_mutex);
  TemporaryExodus file;
  if (Status s = create_temporary(path, file); !s.ok()) return s;
  const int64_t blocks = mesh.hexes.empty() ? 0 : 1;
  const int64_t sets = sides.empty() ? 0 : 1;
  // Side sets 2.. for the patches that hold sides (ids in patch order).
  std::vector<std::vector<HexSide>> parts;
  if (patches != nullptr && !sides.empty()) parts = patches->by_patch(mesh, kHex8Sides, sides);
  int64_t side_sets = sets;
  for (const auto& part : parts) side_sets += part.empty() ? 0 : 1;
  if (ex_put_init(file.id, "hexpeel hex mesh", 3, mesh.num_points(), mesh.num_hexes(), blocks, sets,
                  side_sets) < 0) {
    return library_error(path, "ex_put_init");
  }
  if (Status s = put_mesh(path, file.id, mesh); !s.ok()) return s;
  if (Status s = put_boundary(path, file.id, mesh, sides); !s.ok()) return s;
  for (size_t k = 0; k < parts.size(); ++k) {
    if (parts[k].empty()) continue;
    const std::string name = "patch_" + std::to_string(k + 1);
    if (Status s = put_side_set(path, file.id, parts[k], static_cast<int64_t>(k) + 2, name); !s.ok())
      return s;
  }
  const int closed = ex_close(file.id);
  file.id = -1;
  if (closed < 0) return library_error(path, "ex_close");
  file.exists = false;  // rename_over removes it itself when the rename fails
  return rename_over(file.tmp, path);
}

}  // namespace hexpeel::io
