// VTK XML unstructured grid (.vtu): reads points and cells, writes a hex mesh as ASCII.
//
// Reads DataArrays in format "ascii", "binary" (inline base64) and "appended" (raw or base64),
// with UInt32 or UInt64 headers, either byte order, uncompressed or zlib-compressed
// (vtkZLibDataCompressor: the format meshio writes by default). LZ4/LZMA compression is reported
// as unsupported. Several Pieces are concatenated. Base64 is decoded group by group so that the
// header and the data may be encoded separately (each with its own padding), as VTK and meshio
// do. A small tag scanner stands in for an XML parser: VTK files use no entities or CDATA.
// Claimed sizes are checked against the data present, and decompressed sizes against zlib's
// maximum ratio, before anything is allocated.
#include "io/formats.h"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <optional>

namespace hexpeel::io {

namespace {

std::optional<Scalar> vtu_type(std::string_view t) {
  if (t == "Int8") return Scalar::i8;
  if (t == "UInt8") return Scalar::u8;
  if (t == "Int16") return Scalar::i16;
  if (t == "UInt16") return Scalar::u16;
  if (t == "Int32") return Scalar::i32;
  if (t == "UInt32") return Scalar::u32;
  if (t == "Int64") return Scalar::i64;
  if (t == "UInt64") return Scalar::u64;
  if (t == "Float32") return Scalar::f32;
  if (t == "Float64") return Scalar::f64;
  return std::nullopt;
}

/// Value of attribute `key` in the inside of a tag, or empty.
std::string_view attribute(std::string_view tag, std::string_view key) {
  size_t p = 0;
  while ((p = tag.find(key, p)) != std::string_view::npos) {
    const bool starts = p > 0 && (tag[p - 1] == ' ' || tag[p - 1] == '\t' || tag[p - 1] == '\n' ||
                                  tag[p - 1] == '\r');
    size_t q = p + key.size();
    while (q < tag.size() && tag[q] == ' ') ++q;
    if (starts && q < tag.size() && tag[q] == '=') {
      ++q;
      while (q < tag.size() && tag[q] == ' ') ++q;
      if (q < tag.size() && (tag[q] == '"' || tag[q] == '\'')) {
        const size_t close = tag.find(tag[q], q + 1);
        if (close == std::string_view::npos) return {};
        return tag.substr(q + 1, close - q - 1);
      }
    }
    p += key.size();
  }
  return {};
}

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

/// Decodes base64 that may be several padded pieces in a row; false on a bad character.
bool decode_base64(std::string_view text, std::string& out) {
  out.clear();
  out.reserve(text.size() / 4 * 3);
  uint32_t acc = 0;
  int have = 0;  // sextets in acc
  for (char c : text) {
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    if (c == '=') {
      // Padding ends a group: flush whole bytes of the partial group and start afresh.
      if (have == 2) out += static_cast<char>((acc >> 4) & 0xFF);
      if (have == 3) {
        out += static_cast<char>((acc >> 10) & 0xFF);
        out += static_cast<char>((acc >> 2) & 0xFF);
      }
      acc = 0;
      have = 0;
      continue;
    }
    const int v = base64_value(c);
    if (v < 0) return false;
    acc = (acc << 6) | static_cast<uint32_t>(v);
    if (++have == 4) {
      out += static_cast<char>((acc >> 16) & 0xFF);
      out += static_cast<char>((acc >> 8) & 0xFF);
      out += static_cast<char>(acc & 0xFF);
      acc = 0;
      have = 0;
    }
  }
  return have == 0;
}

/// One DataArray of interest.
struct VtuArray {
  bool present = false;
  Scalar type = Scalar::f64;
  std::string_view format;   ///< ascii, binary or appended
  std::string_view content;  ///< text between the tags (ascii, binary)
  int64_t offset = 0;        ///< into the appended data
  int64_t line = 0;          ///< where the array starts
  int64_t components = 1;
};

/// Settings of the whole file.
struct VtuFile {
  bool big_endian = false;
  bool header64 = false;
  bool compressed = false;
  std::string_view appended;  ///< after the '_' of <AppendedData>
  bool appended_base64 = false;
};

class VtuDecoder {
 public:
  VtuDecoder(const VtuFile& file, const std::string& name) : file_(file), name_(name) {}

  /// The raw bytes of an array: decoded, the header read, decompressed.
  Status bytes(const VtuArray& a, std::string& out) {
    std::string_view raw;
    if (a.format == "binary" || (a.format == "appended" && file_.appended_base64)) {
      std::string_view text = a.content;
      if (a.format == "appended") {
        if (a.offset < 0 || a.offset > static_cast<int64_t>(file_.appended.size())) return fail(a, "offset beyond the appended data");
        text = file_.appended.substr(static_cast<size_t>(a.offset));
        const size_t end = text.find('<');
        if (end != std::string_view::npos) text = text.substr(0, end);
      }
      if (!decode_base64(text, decoded_)) return fail(a, "invalid base64 data");
      raw = decoded_;
    } else if (a.format == "appended") {
      if (a.offset < 0 || a.offset > static_cast<int64_t>(file_.appended.size())) return fail(a, "offset beyond the appended data");
      raw = file_.appended.substr(static_cast<size_t>(a.offset));
    } else {
      return fail(a, "unknown format " + quoted(a.format));
    }
    ByteCursor bc(raw, 0, file_.big_endian);
    auto header = [&](uint64_t& v) {
      if (file_.header64) return bc.get(v);
      uint32_t x;
      if (!bc.get(x)) return false;
      v = x;
      return true;
    };
    if (!file_.compressed) {
      uint64_t n = 0;
      if (!header(n)) return fail(a, "truncated data header");
      if (n > bc.remaining()) return fail(a, "header claims " + std::to_string(n) + " bytes but fewer follow");
      out.assign(raw.substr(bc.pos(), static_cast<size_t>(n)));
      return Status::success();
    }
    uint64_t blocks = 0, block_size = 0, last_size = 0;
    if (!header(blocks) || !header(block_size) || !header(last_size)) return fail(a, "truncated compression header");
    const uint64_t word = file_.header64 ? 8 : 4;
    if (blocks > bc.remaining() / word) return fail(a, "compression header claims too many blocks");
    std::vector<uint64_t> sizes(static_cast<size_t>(blocks));
    uint64_t total_in = 0;
    for (uint64_t& s : sizes) {
      if (!header(s)) return fail(a, "truncated compression header");
      total_in += std::min<uint64_t>(s, raw.size());
    }
    if (total_in > bc.remaining()) return fail(a, "compressed blocks are truncated");
    if (last_size == 0) last_size = block_size;
    if (block_size > (uint64_t{1} << 40) || last_size > block_size) return fail(a, "bad compression block size");
    // zlib never expands more than about 1032:1.
    const uint64_t limit = 1100 * total_in + 1024;
    if (blocks > 0 && ((blocks - 1) > limit / std::max<uint64_t>(block_size, 1) ||
                       (blocks - 1) * block_size + last_size > limit)) {
      return fail(a, "claimed uncompressed size is impossible for the compressed size");
    }
    out.clear();
    size_t at = bc.pos();
    for (uint64_t b = 0; b < blocks; ++b) {
      const uint64_t want = b + 1 == blocks ? last_size : block_size;
      const size_t start = out.size();
      out.resize(start + static_cast<size_t>(want));
      uLongf got = static_cast<uLongf>(want);
      const int rc = ::uncompress(reinterpret_cast<Bytef*>(out.data() + start), &got,
                                  reinterpret_cast<const Bytef*>(raw.data() + at),
                                  static_cast<uLong>(sizes[b]));
      if (rc != Z_OK || got != want) return fail(a, "zlib block " + std::to_string(b) + " does not decompress");
      at += static_cast<size_t>(sizes[b]);
    }
    return Status::success();
  }

  Status fail(const VtuArray& a, const std::string& msg) {
    return parse_error(name_, at_line(a.line), "DataArray: " + msg);
  }

 private:
  const VtuFile& file_;
  const std::string& name_;
  std::string decoded_;
};

/// Reads all values of an array as doubles or integers.
template <class T>
Status array_values(VtuDecoder& dec, const VtuFile& file, const VtuArray& a,
                    const std::string& name, std::vector<T>& out) {
  out.clear();
  if (a.format == "ascii") {
    TextCursor cur(a.content, name);
    std::string_view tok;
    while (cur.next(tok)) {
      T v{};
      bool ok;
      if constexpr (std::is_same_v<T, double>) {
        ok = parse_real(tok, v);
      } else {
        ok = parse_int(tok, v);
      }
      if (!ok) return parse_error(name, at_line(a.line + cur.line() - 1), "bad number " + quoted(tok));
      out.push_back(v);
    }
    return Status::success();
  }
  std::string bytes;
  if (Status s = dec.bytes(a, bytes); !s.ok()) return s;
  const size_t size = scalar_size(a.type);
  if (bytes.size() % size != 0) return dec.fail(a, "byte count is not a multiple of the value size");
  ByteCursor bc(bytes, 0, file.big_endian);
  out.resize(bytes.size() / size);
  for (T& v : out) {
    if constexpr (std::is_same_v<T, double>) {
      bc.get_real(a.type, v);
    } else {
      bc.get_int(a.type, v);
    }
  }
  return Status::success();
}

/// Arrays of one Piece.
struct VtuPiece {
  VtuArray points, connectivity, offsets, types;
  int64_t line = 0;
};

Status add_piece(VtuDecoder& dec, const VtuFile& file, const VtuPiece& piece,
                 const std::string& name, CellSoup& out) {
  auto missing = [&](const char* what) {
    return parse_error(name, at_line(piece.line), std::string("Piece has no ") + what + " array");
  };
  if (!piece.points.present) return missing("Points");
  if (piece.points.components != 3) {
    return parse_error(name, at_line(piece.points.line), "Points must have 3 components");
  }
  std::vector<double> xyz;
  if (Status s = array_values(dec, file, piece.points, name, xyz); !s.ok()) return s;
  if (xyz.size() % 3 != 0) return parse_error(name, at_line(piece.points.line), "Points size is not a multiple of 3");
  const int64_t base = static_cast<int64_t>(out.points.size());
  for (size_t i = 0; i < xyz.size(); i += 3) out.points.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  if (!piece.connectivity.present && !piece.offsets.present && !piece.types.present) {
    return Status::success();  // points only
  }
  if (!piece.connectivity.present) return missing("connectivity");
  if (!piece.offsets.present) return missing("offsets");
  if (!piece.types.present) return missing("types");
  std::vector<int64_t> conn, offsets, types;
  if (Status s = array_values(dec, file, piece.connectivity, name, conn); !s.ok()) return s;
  if (Status s = array_values(dec, file, piece.offsets, name, offsets); !s.ok()) return s;
  if (Status s = array_values(dec, file, piece.types, name, types); !s.ok()) return s;
  if (offsets.size() != types.size()) {
    return parse_error(name, at_line(piece.offsets.line), "offsets and types differ in length");
  }
  for (int64_t& v : conn) v = v < 0 || v > INT64_MAX - base ? -1 : v + base;
  int64_t begin = 0;
  for (size_t c = 0; c < types.size(); ++c) {
    const int64_t end = offsets[c];
    if (end < begin || end > static_cast<int64_t>(conn.size())) {
      return parse_error(name, at_line(piece.offsets.line),
                         "offset of cell " + std::to_string(c) + " is out of order or range");
    }
    const Where w = at_line(piece.connectivity.line);
    if (!add_vtk_cell(out, types[c], conn.data() + begin, static_cast<size_t>(end - begin), w)) {
      return parse_error(name, w, "cell " + std::to_string(c) + " of type " + std::to_string(types[c]) +
                                      " has " + std::to_string(end - begin) + " corners");
    }
    begin = end;
  }
  return Status::success();
}

}  // namespace

Status read_vtu(std::string_view data, const std::string& name, CellSoup& out) {
  TextCursor lines(data, name);  // only for line numbers
  VtuFile file;
  std::vector<VtuPiece> pieces;
  bool in_points = false, in_cells = false, seen_root = false, closed_root = false;
  size_t p = 0;
  while ((p = data.find('<', p)) != std::string_view::npos) {
    lines.jump_to(p);
    const int64_t line = lines.line();
    auto skip_to = [&](std::string_view end) {
      const size_t q = data.find(end, p);
      p = q == std::string_view::npos ? data.size() : q + end.size();
    };
    if (data.substr(p, 4) == "<!--") { skip_to("-->"); continue; }
    if (data.substr(p, 2) == "<?" ) { skip_to("?>"); continue; }
    if (data.substr(p, 2) == "<!") { skip_to(">"); continue; }
    const size_t close = data.find('>', p);
    if (close == std::string_view::npos) return parse_error(name, at_line(line), "unterminated tag");
    std::string_view tag = data.substr(p + 1, close - p - 1);
    p = close + 1;
    const bool closing = !tag.empty() && tag[0] == '/';
    if (closing) tag.remove_prefix(1);
    size_t name_end = 0;
    while (name_end < tag.size() && tag[name_end] != ' ' && tag[name_end] != '\n' &&
           tag[name_end] != '\t' && tag[name_end] != '\r' && tag[name_end] != '/') {
      ++name_end;
    }
    const std::string_view tag_name = tag.substr(0, name_end);
    if (tag_name == "VTKFile" && closing) closed_root = true;
    if (tag_name == "VTKFile" && !closing) {
      seen_root = true;
      if (attribute(tag, "type") != "UnstructuredGrid") {
        return Status::error(StatusCode::unsupported_format,
                             located(name, at_line(line), "VTKFile type " + quoted(attribute(tag, "type")) +
                                                              " is not supported (UnstructuredGrid is)"));
      }
      file.big_endian = attribute(tag, "byte_order") == "BigEndian";
      file.header64 = attribute(tag, "header_type") == "UInt64";
      const std::string_view compressor = attribute(tag, "compressor");
      if (!compressor.empty() && compressor != "vtkZLibDataCompressor") {
        return Status::error(StatusCode::unsupported_format,
                             located(name, at_line(line), "compressor " + quoted(compressor) +
                                                              " is not supported (zlib is)"));
      }
      file.compressed = !compressor.empty();
    } else if (!seen_root) {
      return parse_error(name, at_line(line), "expected the <VTKFile> element first");
    } else if (tag_name == "Piece") {
      if (!closing) pieces.push_back(VtuPiece{{}, {}, {}, {}, line});
    } else if (tag_name == "Points") {
      in_points = !closing;
    } else if (tag_name == "Cells") {
      in_cells = !closing;
    } else if (tag_name == "DataArray" && !closing && !pieces.empty() && (in_points || in_cells)) {
      VtuArray a;
      a.present = true;
      a.line = line;
      const auto type = vtu_type(attribute(tag, "type"));
      if (!type) return parse_error(name, at_line(line), "unknown DataArray type " + quoted(attribute(tag, "type")));
      a.type = *type;
      a.format = attribute(tag, "format");
      if (a.format.empty()) a.format = "ascii";
      if (const std::string_view nc = attribute(tag, "NumberOfComponents"); !nc.empty()) {
        if (!parse_int(nc, a.components)) return parse_error(name, at_line(line), "bad NumberOfComponents");
      }
      if (const std::string_view off = attribute(tag, "offset"); !off.empty()) {
        if (!parse_int(off, a.offset)) return parse_error(name, at_line(line), "bad offset");
      }
      if (tag.back() != '/') {
        const size_t end = data.find('<', p);
        a.content = data.substr(p, (end == std::string_view::npos ? data.size() : end) - p);
      }
      VtuPiece& piece = pieces.back();
      const std::string_view array_name = attribute(tag, "Name");
      if (in_points && !piece.points.present) piece.points = a;
      if (in_cells && array_name == "connectivity") piece.connectivity = a;
      if (in_cells && array_name == "offsets") piece.offsets = a;
      if (in_cells && array_name == "types") piece.types = a;
    } else if (tag_name == "AppendedData" && !closing) {
      file.appended_base64 = attribute(tag, "encoding") == "base64";
      const size_t underscore = data.find('_', p);
      if (underscore == std::string_view::npos) return parse_error(name, at_line(line), "AppendedData lacks its '_' marker");
      file.appended = data.substr(underscore + 1);
      break;  // raw appended bytes may contain anything
    }
  }
  if (!seen_root) return parse_error(name, at_line(1), "not a VTK XML file: no <VTKFile> element");
  if (!closed_root && file.appended.empty()) {
    lines.jump_to(data.size());
    return parse_error(name, at_line(lines.line()), "file ends before </VTKFile> (truncated?)");
  }
  VtuDecoder dec(file, name);
  for (const VtuPiece& piece : pieces) {
    if (Status s = add_piece(dec, file, piece, name, out); !s.ok()) return s;
  }
  return Status::success();
}

std::string write_vtu(const HexMesh& mesh, const PatchLookup* /*patches: none in VTK*/) {
  const int64_t np = mesh.num_points(), nh = mesh.num_hexes();
  std::string s =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
      "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"";
  append_int(s, np);
  s += "\" NumberOfCells=\"";
  append_int(s, nh);
  s += "\">\n      <Points>\n"
       "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const Vec3& p : mesh.points) {
    s += "          ";
    append_point(s, p);
    s += '\n';
  }
  s += "        </DataArray>\n      </Points>\n      <Cells>\n"
       "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const Hex& h : mesh.hexes) {
    s += "         ";
    for (int32_t v : h) (s += ' ', append_int(s, v));
    s += '\n';
  }
  s += "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (int64_t h = 1; h <= nh; ++h) {
    s += "          ";
    append_int(s, 8 * h);
    s += '\n';
  }
  s += "        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int64_t h = 0; h < nh; ++h) s += "          12\n";
  s += "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  return s;
}

}  // namespace hexpeel::io
