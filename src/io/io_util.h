// Shared pieces of the readers and writers: the cell soup every reader fills, a text cursor that
// knows its line number, a bounds-checked binary cursor, number parsing and formatting, whole-file
// reads and atomic writes. Internal to src/io.
#pragma once

#include "hexpeel/quad_surface.h"
#include "hexpeel/status.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace hexpeel::io {

/// What a reader keeps of a cell: surface polygons (triangles, quads, polygons) and hexahedra
/// carry corners; anything else is only counted.
enum class CellKind : uint8_t { polygon, hex, other };

/// Where something was read: a line number (text) or a byte offset (binary), for messages.
struct Where {
  int64_t value = 0;  ///< 1-based line number or 0-based byte offset
  bool byte = false;  ///< true when value is a byte offset
};
inline Where at_line(int64_t line) { return {line, false}; }
inline Where at_byte(int64_t offset) { return {offset, true}; }

/// "name:37: msg" or "name: byte 1234: msg".
std::string located(const std::string& name, Where where, const std::string& msg);
Status parse_error(const std::string& name, Where where, const std::string& msg);

/// Everything a reader produces; io.cpp turns it into a PolygonSoup or a HexMesh and checks the
/// corner indices there. Corners are 0-based but unchecked (int64 so that garbage survives to the
/// check); `index_base` is added back when a message shows an index.
struct CellSoup {
  std::vector<Vec3> points;
  std::vector<CellKind> kinds;        ///< one per cell
  std::vector<int64_t> offsets{0};    ///< cell c has corners [offsets[c], offsets[c+1])
  std::vector<int64_t> corners;       ///< 0-based point indices
  std::vector<Where> where;           ///< where each cell was read
  int64_t index_base = 0;             ///< how the file numbers points (1 for OBJ, MEDIT...)

  void add_cell(CellKind kind, const int64_t* c, size_t n, Where w) {
    kinds.push_back(kind);
    corners.insert(corners.end(), c, c + n);
    offsets.push_back(static_cast<int64_t>(corners.size()));
    where.push_back(w);
  }
  /// Counted only: no corners kept.
  void add_other(Where w) { add_cell(CellKind::other, nullptr, 0, w); }
};

/// Adds a cell of VTK type `type` (12 hexahedron, 11 voxel reordered to a hexahedron, 5 triangle,
/// 9 quad, 7 polygon; anything else counted as other). False when a hexahedron, voxel, triangle
/// or quad has the wrong number of corners.
bool add_vtk_cell(CellSoup& soup, int64_t type, const int64_t* corners, size_t n, Where w);

/// Printable excerpt of a token for messages (at most 24 chars, control bytes shown as '?').
std::string quoted(std::string_view token);

/// Whole-token number parsing (a leading '+' is accepted). False on any trailing garbage.
bool parse_int(std::string_view s, int64_t& v);
bool parse_real(std::string_view s, double& v);
/// Case-insensitive equality for ASCII keywords.
bool iequals(std::string_view a, std::string_view b);

/// Reads text token by token and keeps the line number. `comment` (if not '\0') starts a comment
/// that runs to the end of the line when it begins a token.
class TextCursor {
 public:
  TextCursor(std::string_view data, const std::string& name, char comment = '\0')
      : data_(data), name_(name), comment_(comment) {}

  /// Next token, crossing line ends; false at the end of the data.
  bool next(std::string_view& tok);
  /// Next token on the current line only; false at a line end (which is not consumed).
  bool next_in_line(std::string_view& tok);
  /// Peeks at the next token without consuming it.
  bool peek(std::string_view& tok);
  /// Moves to the start of the next line.
  void skip_line();
  /// The rest of the current line (without the line end), consuming it and the line end.
  std::string_view rest_of_line();
  bool at_end();
  /// Line on which the next token starts (skips blanks and comments first).
  int64_t next_line();

  /// Next token as a number; on failure an error naming `what` and what was found.
  Status get_int(int64_t& v, std::string_view what);
  Status get_real(double& v, std::string_view what);
  /// A count: a non-negative integer of at most `max` (checked against the file size by callers).
  Status get_count(int64_t& v, std::string_view what, int64_t max);

  Status error(const std::string& msg) const { return parse_error(name_, at_line(line_), msg); }
  Status error_at(int64_t line, const std::string& msg) const {
    return parse_error(name_, at_line(line), msg);
  }
  int64_t line() const { return line_; }
  size_t pos() const { return pos_; }
  size_t remaining() const { return data_.size() - pos_; }
  std::string_view data() const { return data_; }
  const std::string& name() const { return name_; }
  /// Jumps forward (after a binary block), counting the line ends skipped.
  void jump_to(size_t pos);

 private:
  void skip_blanks(bool cross_lines);
  std::string_view data_;
  const std::string& name_;
  char comment_;
  size_t pos_ = 0;     ///< next byte to read
  int64_t line_ = 1;   ///< line of pos_
};

/// Scalar types of binary formats (PLY, VTK, VTU).
enum class Scalar : uint8_t { i8, u8, i16, u16, i32, u32, i64, u64, f32, f64 };
size_t scalar_size(Scalar s);

/// Reads fixed-size values from bytes, never past the end.
class ByteCursor {
 public:
  ByteCursor(std::string_view data, size_t pos, bool big_endian)
      : data_(data), pos_(pos), big_(big_endian) {}
  template <class T>
  bool get(T& v) {
    if (data_.size() - pos_ < sizeof(T)) return false;
    unsigned char b[sizeof(T)];
    std::memcpy(b, data_.data() + pos_, sizeof(T));
    if (big_ != (std::endian::native == std::endian::big)) {
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    }
    std::memcpy(&v, b, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  /// Any scalar type converted; integers beyond int64 saturate (they are out of range anyway).
  bool get_real(Scalar s, double& v);
  bool get_int(Scalar s, int64_t& v);
  bool skip(size_t n) {
    if (data_.size() - pos_ < n) return false;
    pos_ += n;
    return true;
  }
  size_t pos() const { return pos_; }
  size_t remaining() const { return data_.size() - pos_; }

 private:
  std::string_view data_;
  size_t pos_;
  bool big_;
};

/// Shortest text that reads back to the same double (std::to_chars), appended.
void append_real(std::string& out, double v);
/// "x y z" of a point, each coordinate as append_real writes it (no newline).
void append_point(std::string& out, const Vec3& p);
void append_int(std::string& out, int64_t v);

Status read_whole_file(const std::filesystem::path& path, std::string& out);
/// Writes to a fresh temporary file beside `path`, then renames it over `path`.
Status write_file_atomic(const std::filesystem::path& path, std::string_view bytes);
/// A name for a temporary file beside `path` (same directory, so that renaming it over `path`
/// stays on one file system): ".<file name>.tmp<pid>_<random>". The caller creates it exclusively
/// and tries another name when it exists.
std::filesystem::path temporary_path_beside(const std::filesystem::path& path);
/// Renames the finished temporary file `tmp` over `path`; on failure removes `tmp` and returns an
/// io_error naming `path`.
Status rename_over(const std::filesystem::path& tmp, const std::filesystem::path& path);

}  // namespace hexpeel::io
