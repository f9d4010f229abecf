// Gmsh .msh: reads nodes and elements of format 2.2 and 4.1, ASCII and binary; writes a hex mesh
// as 4.1 ASCII.
//
// Node tags (any positive integers, in any order) are mapped to 0-based indices in file order;
// an element naming an undefined tag is an error here. Element type 2 (triangle) and 3 (quad)
// come back as surface polygons, type 5 (8-node hexahedron) as a hex; every other known type is
// counted as "other". Gmsh's hexahedron numbering (nodes 0-3 on the w=-1 face, node i+4 above
// node i) is the VTK one, so no permutation is applied. Sections other than $MeshFormat, $Nodes
// and $Elements are skipped up to their $End line. Formats 4.0 and 3.x are reported as
// unsupported. Counts are checked against the bytes left before anything is allocated.
#include "io/formats.h"

#include <algorithm>

namespace hexpeel::io {

namespace {

/// Number of nodes of a Gmsh element type (0 when unknown).
int gmsh_nodes_per_element(int64_t type) {
  static constexpr int kNodes[] = {
      0,  2,  3,  4,  4,  8,  6,  5,  3,  6,  9,  10, 27, 18, 14, 1,  8,  20, 15, 13, 9,
      10, 12, 15, 15, 21, 4,  5,  6,  20, 35, 56, 0,  0,  0,  0,  16, 25, 36};
  if (type == 92) return 64;
  if (type == 93) return 125;
  if (type < 0 || type >= static_cast<int64_t>(std::size(kNodes))) return 0;
  return kNodes[type];
}

CellKind gmsh_kind(int64_t type) {
  if (type == 2 || type == 3) return CellKind::polygon;
  if (type == 5) return CellKind::hex;
  return CellKind::other;
}

/// Numbers of a section, ASCII tokens or binary values, read through one interface.
class GmshValues {
 public:
  GmshValues(TextCursor& cur, bool binary, bool big, int64_t size_t_bytes)
      : cur_(cur), binary_(binary), big_(big), size_bytes_(size_t_bytes) {}

  Status size(int64_t& v, std::string_view what) {
    if (!binary_) return cur_.get_int(v, what);
    if (size_bytes_ == 8) return fixed<int64_t>(v, what);
    int32_t x;
    if (Status s = fixed<int32_t>(x, what); !s.ok()) return s;
    v = static_cast<uint32_t>(x);
    return Status::success();
  }
  Status integer(int64_t& v, std::string_view what) {
    if (!binary_) return cur_.get_int(v, what);
    int32_t x;
    if (Status s = fixed<int32_t>(x, what); !s.ok()) return s;
    v = x;
    return Status::success();
  }
  Status real(double& v, std::string_view what) {
    if (!binary_) return cur_.get_real(v, what);
    return fixed<double>(v, what);
  }
  /// A count that must fit in the rest of the file at `bytes` bytes (binary) or 2 (ASCII) each.
  Status check_count(int64_t n, int64_t bytes, std::string_view what) {
    const int64_t each = binary_ ? std::max<int64_t>(bytes, 1) : 2;
    if (n < 0 || n > static_cast<int64_t>(cur_.remaining()) / each) {
      return error(std::string(what) + " " + std::to_string(n) +
                   " is negative or more than the rest of the file can hold");
    }
    return Status::success();
  }
  Status error(const std::string& msg) const {
    if (binary_) return parse_error(cur_.name(), at_byte(static_cast<int64_t>(cur_.pos())), msg);
    return cur_.error(msg);
  }
  Where where() { return binary_ ? at_byte(static_cast<int64_t>(cur_.pos())) : at_line(cur_.next_line()); }
  bool binary() const { return binary_; }

 private:
  template <class T>
  Status fixed(T& v, std::string_view what) {
    ByteCursor bc(cur_.data(), cur_.pos(), big_);
    if (!bc.get(v)) return error("expected " + std::string(what) + ", found end of file");
    cur_.jump_to(bc.pos());
    return Status::success();
  }
  TextCursor& cur_;
  bool binary_;
  bool big_;
  int64_t size_bytes_;
};

/// Node tags in file order, for mapping tags to indices.
class NodeTags {
 public:
  void add(int64_t tag) {
    if (tag != static_cast<int64_t>(sorted_.size()) + 1) dense_ = false;
    sorted_.push_back({tag, static_cast<int64_t>(sorted_.size())});
  }
  /// Sorts for lookups; false if a tag repeats (its value is returned in `dup`).
  bool finish(int64_t& dup) {
    if (dense_) return true;
    std::sort(sorted_.begin(), sorted_.end());
    for (size_t i = 1; i < sorted_.size(); ++i) {
      if (sorted_[i].first == sorted_[i - 1].first) {
        dup = sorted_[i].first;
        return false;
      }
    }
    return true;
  }
  /// 0-based index of a tag, or -1.
  int64_t index(int64_t tag) const {
    if (dense_) return tag >= 1 && tag <= static_cast<int64_t>(sorted_.size()) ? tag - 1 : -1;
    const auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::pair<int64_t, int64_t>{tag, -1});
    return it != sorted_.end() && it->first == tag ? it->second : -1;
  }

 private:
  bool dense_ = true;  ///< tags are exactly 1..n in order: index = tag - 1
  std::vector<std::pair<int64_t, int64_t>> sorted_;  ///< (tag, index), sorted unless dense_
};

struct GmshReader {
  TextCursor& cur;
  GmshValues& val;
  bool v41;
  CellSoup& out;
  NodeTags tags;

  void node(int64_t tag, const double xyz[3]) {
    tags.add(tag);
    out.points.emplace_back(xyz[0], xyz[1], xyz[2]);
  }

  Status read_nodes() {
    if (val.binary() && v41) cur.skip_line();
    if (!v41) {
      int64_t n = 0;
      if (Status s = cur.get_int(n, "the number of nodes"); !s.ok()) return s;
      if (val.binary()) cur.skip_line();
      if (Status s = val.check_count(n, 4 + 24, "number of nodes"); !s.ok()) return s;
      out.points.reserve(static_cast<size_t>(n));
      for (int64_t i = 0; i < n; ++i) {
        int64_t tag;
        double xyz[3];
        if (Status s = val.integer(tag, "a node tag"); !s.ok()) return s;
        for (double& c : xyz) {
          if (Status s = val.real(c, "a node coordinate"); !s.ok()) return s;
        }
        node(tag, xyz);
      }
      return Status::success();
    }
    int64_t blocks = 0, n = 0, min_tag = 0, max_tag = 0;
    if (Status s = val.size(blocks, "the number of node blocks"); !s.ok()) return s;
    if (Status s = val.size(n, "the number of nodes"); !s.ok()) return s;
    if (Status s = val.size(min_tag, "the minimum node tag"); !s.ok()) return s;
    if (Status s = val.size(max_tag, "the maximum node tag"); !s.ok()) return s;
    if (Status s = val.check_count(blocks, 20, "number of node blocks"); !s.ok()) return s;
    if (Status s = val.check_count(n, 32, "number of nodes"); !s.ok()) return s;
    out.points.reserve(static_cast<size_t>(n));
    std::vector<int64_t> block_tags;
    for (int64_t b = 0; b < blocks; ++b) {
      int64_t dim = 0, entity = 0, parametric = 0, count = 0;
      if (Status s = val.integer(dim, "an entity dimension"); !s.ok()) return s;
      if (Status s = val.integer(entity, "an entity tag"); !s.ok()) return s;
      if (Status s = val.integer(parametric, "the parametric flag"); !s.ok()) return s;
      if (Status s = val.size(count, "the number of nodes in the block"); !s.ok()) return s;
      if (dim < 0 || dim > 3) return val.error("entity dimension must be 0 to 3");
      if (Status s = val.check_count(count, 32, "number of nodes in the block"); !s.ok()) return s;
      block_tags.resize(static_cast<size_t>(count));
      for (int64_t& t : block_tags) {
        if (Status s = val.size(t, "a node tag"); !s.ok()) return s;
      }
      const int64_t extra = parametric != 0 ? dim : 0;  // u, v, w parameters follow x y z
      for (int64_t t : block_tags) {
        double xyz[3], param;
        for (double& c : xyz) {
          if (Status s = val.real(c, "a node coordinate"); !s.ok()) return s;
        }
        for (int64_t k = 0; k < extra; ++k) {
          if (Status s = val.real(param, "a node parameter"); !s.ok()) return s;
        }
        node(t, xyz);
      }
    }
    return Status::success();
  }

  /// Maps node tags to indices and stores one element.
  Status element(int64_t type, const int64_t* node_tags, int n, Where w) {
    const CellKind kind = gmsh_kind(type);
    if (kind == CellKind::other) {
      out.add_other(w);
      return Status::success();
    }
    int64_t corners[8];
    for (int k = 0; k < n; ++k) {
      corners[k] = tags.index(node_tags[k]);
      if (corners[k] < 0) {
        return parse_error(cur.name(), w,
                           "element refers to node tag " + std::to_string(node_tags[k]) +
                               ", which no node has");
      }
    }
    out.add_cell(kind, corners, static_cast<size_t>(n), w);
    return Status::success();
  }

  Status read_elements() {
    int64_t nodes[125];
    if (!v41) {
      int64_t n = 0;
      if (Status s = cur.get_int(n, "the number of elements"); !s.ok()) return s;
      if (val.binary()) cur.skip_line();
      if (Status s = val.check_count(n, 8, "number of elements"); !s.ok()) return s;
      int64_t done = 0;
      while (done < n) {
        int64_t type = 0, count = 1, ntags = 0;
        if (val.binary()) {  // a block header: type, number of elements, number of tags
          if (Status s = val.integer(type, "an element type"); !s.ok()) return s;
          if (Status s = val.integer(count, "an element count"); !s.ok()) return s;
          if (Status s = val.integer(ntags, "a tag count"); !s.ok()) return s;
          if (count < 1 || count > n - done) return val.error("bad element block size " + std::to_string(count));
        }
        for (int64_t e = 0; e < count; ++e) {
          const Where w = val.where();
          int64_t id = 0, tag = 0;
          if (Status s = val.integer(id, "an element tag"); !s.ok()) return s;
          if (!val.binary()) {
            if (Status s = val.integer(type, "an element type"); !s.ok()) return s;
            if (Status s = val.integer(ntags, "the number of tags"); !s.ok()) return s;
          }
          if (ntags < 0 || ntags > 1000) return val.error("bad number of element tags " + std::to_string(ntags));
          for (int64_t k = 0; k < ntags; ++k) {
            if (Status s = val.integer(tag, "an element tag"); !s.ok()) return s;
          }
          const int nn = gmsh_nodes_per_element(type);
          if (nn == 0) return parse_error(cur.name(), w, "unknown element type " + std::to_string(type));
          for (int k = 0; k < nn; ++k) {
            if (Status s = val.integer(nodes[k], "an element node"); !s.ok()) return s;
          }
          if (Status s = element(type, nodes, nn, w); !s.ok()) return s;
        }
        done += count;
      }
      return Status::success();
    }
    if (val.binary()) cur.skip_line();
    int64_t blocks = 0, n = 0, min_tag = 0, max_tag = 0;
    if (Status s = val.size(blocks, "the number of element blocks"); !s.ok()) return s;
    if (Status s = val.size(n, "the number of elements"); !s.ok()) return s;
    if (Status s = val.size(min_tag, "the minimum element tag"); !s.ok()) return s;
    if (Status s = val.size(max_tag, "the maximum element tag"); !s.ok()) return s;
    if (Status s = val.check_count(blocks, 20, "number of element blocks"); !s.ok()) return s;
    for (int64_t b = 0; b < blocks; ++b) {
      int64_t dim = 0, entity = 0, type = 0, count = 0;
      if (Status s = val.integer(dim, "an entity dimension"); !s.ok()) return s;
      if (Status s = val.integer(entity, "an entity tag"); !s.ok()) return s;
      if (Status s = val.integer(type, "an element type"); !s.ok()) return s;
      if (Status s = val.size(count, "the number of elements in the block"); !s.ok()) return s;
      const int nn = gmsh_nodes_per_element(type);
      if (nn == 0) return val.error("unknown element type " + std::to_string(type));
      if (Status s = val.check_count(count, 8 * (nn + 1), "number of elements in the block"); !s.ok()) {
        return s;
      }
      for (int64_t e = 0; e < count; ++e) {
        const Where w = val.where();
        int64_t id = 0;
        if (Status s = val.size(id, "an element tag"); !s.ok()) return s;
        for (int k = 0; k < nn; ++k) {
          if (Status s = val.size(nodes[k], "an element node"); !s.ok()) return s;
        }
        if (Status s = element(type, nodes, nn, w); !s.ok()) return s;
      }
    }
    return Status::success();
  }
};

/// Skips to just after `$End<name>`; false if there is none.
bool skip_section(TextCursor& cur, std::string_view keyword) {
  const std::string end = "$End" + std::string(keyword.substr(1));
  const size_t at = cur.data().find(end, cur.pos());
  if (at == std::string_view::npos) return false;
  cur.jump_to(at + end.size());
  return true;
}

}  // namespace

Status read_gmsh(std::string_view data, const std::string& name, CellSoup& out) {
  TextCursor cur(data, name);
  std::string_view tok;
  if (!cur.next(tok) || tok != "$MeshFormat") {
    return cur.error("not a Gmsh file: expected '$MeshFormat' first");
  }
  std::string_view version;
  int64_t file_type = 0, data_size = 0;
  if (!cur.next(version)) return cur.error("expected the format version, found end of file");
  if (Status s = cur.get_int(file_type, "the file type (0 ASCII, 1 binary)"); !s.ok()) return s;
  if (Status s = cur.get_int(data_size, "the data size"); !s.ok()) return s;
  const bool v41 = version == "4.1";
  if (!v41 && version != "2.2" && version != "2.1" && version != "2.0" && version != "2") {
    return Status::error(StatusCode::unsupported_format,
                         located(name, at_line(cur.line()),
                                 "Gmsh format " + quoted(version) + " is not supported (2.2 and 4.1 are)"));
  }
  if (file_type != 0 && file_type != 1) return cur.error("file type must be 0 or 1");
  if (data_size != 4 && data_size != 8) return cur.error("data size must be 4 or 8");
  const bool binary = file_type == 1;
  bool big = false;
  if (binary) {
    cur.skip_line();
    ByteCursor bc(data, cur.pos(), false);
    int32_t one = 0;
    if (!bc.get(one)) return cur.error("binary file lacks the endianness check value");
    if (one != 1) {
      if (one != 0x01000000) return cur.error("binary endianness check value is not 1");
      big = true;
    }
    cur.jump_to(bc.pos());
  }
  if (!cur.next(tok) || tok != "$EndMeshFormat") return cur.error("expected '$EndMeshFormat'");
  GmshValues val(cur, binary, big, data_size);
  GmshReader reader{cur, val, v41, out, {}};
  bool nodes_read = false;
  while (cur.next(tok)) {
    const int64_t line = cur.line();
    if (tok.empty() || tok[0] != '$') return cur.error("expected a section keyword, found " + quoted(tok));
    if (tok == "$Nodes" || tok == "$Elements") {
      const bool nodes = tok == "$Nodes";
      if (nodes && nodes_read) return cur.error("a second $Nodes section");
      if (!nodes && !nodes_read) return cur.error("$Elements before $Nodes");
      if (Status s = nodes ? reader.read_nodes() : reader.read_elements(); !s.ok()) return s;
      if (nodes) {
        nodes_read = true;
        int64_t dup = 0;
        if (!reader.tags.finish(dup)) {
          return cur.error_at(line, "node tag " + std::to_string(dup) + " is defined twice");
        }
      }
      const std::string end = nodes ? "$EndNodes" : "$EndElements";
      if (!cur.next(tok) || tok != end) return cur.error("expected '" + end + "'");
      continue;
    }
    if (!skip_section(cur, tok)) {
      return cur.error_at(line, "section " + quoted(tok) + " has no end line");
    }
  }
  return Status::success();
}

namespace {

/// " minX minY minZ maxX maxY maxZ" of `points` (zeros for none).
void append_box(std::string& s, const std::vector<Vec3>& points, const std::vector<int32_t>* ids) {
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  bool first = true;
  auto add = [&](const Vec3& p) {
    if (first) lo = hi = p, first = false;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  };
  if (ids != nullptr)
    for (const int32_t v : *ids) add(points[v]);
  else
    for (const Vec3& p : points) add(p);
  for (int k = 0; k < 3; ++k) (s += ' ', append_real(s, lo[k]));
  for (int k = 0; k < 3; ++k) (s += ' ', append_real(s, hi[k]));
}

}  // namespace

std::string write_gmsh(const HexMesh& mesh, const PatchLookup* patches) {
  const int64_t np = mesh.num_points(), nh = mesh.num_hexes();
  const BoundaryPatches* bp = patches != nullptr ? patches->patches : nullptr;
  const int32_t npatch = bp != nullptr ? bp->count : 0;
  // The faces of each patch, in the order given, and their vertices (for the entity boxes).
  std::vector<std::vector<int32_t>> faces_of(npatch), verts_of(npatch);
  if (bp != nullptr)
    for (size_t i = 0; i < bp->faces.size(); ++i) {
      faces_of[bp->patch[i]].push_back(static_cast<int32_t>(i));
      for (const int32_t v : bp->faces[i]) verts_of[bp->patch[i]].push_back(v);
    }
  std::string s = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  if (bp != nullptr) {
    s += "$PhysicalNames\n";
    append_int(s, int64_t{npatch} + 1);
    s += '\n';
    for (int32_t k = 1; k <= npatch; ++k) s += "2 " + std::to_string(k) + " \"patch_" + std::to_string(k) + "\"\n";
    s += "3 1 \"hexes\"\n$EndPhysicalNames\n";
  }
  // One volume entity holding every node and hex, so Gmsh itself can load the file; with
  // patches, one surface entity per patch (physical group k) bounding it.
  s += "$Entities\n0 0 ";
  append_int(s, npatch);
  s += " 1\n";
  for (int32_t k = 1; k <= npatch; ++k) {
    append_int(s, k);
    append_box(s, mesh.points, &verts_of[k - 1]);
    s += " 1 " + std::to_string(k) + " 0\n";
  }
  s += '1';
  append_box(s, mesh.points, nullptr);
  if (bp == nullptr) {
    s += " 0 0\n";
  } else {
    s += " 1 1 ";
    append_int(s, npatch);
    for (int32_t k = 1; k <= npatch; ++k) s += ' ' + std::to_string(k);
    s += '\n';
  }
  s += "$EndEntities\n$Nodes\n1 ";
  append_int(s, np);
  s += np > 0 ? " 1 " : " 0 ";
  append_int(s, np);
  s += "\n3 1 0 ";
  append_int(s, np);
  s += '\n';
  for (int64_t v = 1; v <= np; ++v) (append_int(s, v), s += '\n');
  for (const Vec3& p : mesh.points) {
    append_point(s, p);
    s += '\n';
  }
  const int64_t nf = bp != nullptr ? static_cast<int64_t>(bp->faces.size()) : 0;
  s += "$EndNodes\n$Elements\n";
  append_int(s, 1 + int64_t{npatch});
  s += ' ';
  append_int(s, nh + nf);
  s += nh + nf > 0 ? " 1 " : " 0 ";
  append_int(s, nh + nf);
  s += "\n3 1 5 ";
  append_int(s, nh);
  s += '\n';
  for (int64_t h = 0; h < nh; ++h) {
    append_int(s, h + 1);
    for (int32_t v : mesh.hexes[h]) (s += ' ', append_int(s, int64_t{v} + 1));
    s += '\n';
  }
  int64_t tag = nh;
  for (int32_t k = 1; k <= npatch; ++k) {
    s += "2 " + std::to_string(k) + " 3 ";
    append_int(s, static_cast<int64_t>(faces_of[k - 1].size()));
    s += '\n';
    for (const int32_t i : faces_of[k - 1]) {
      append_int(s, ++tag);
      for (int32_t v : bp->faces[i]) (s += ' ', append_int(s, int64_t{v} + 1));
      s += '\n';
    }
  }
  s += "$EndElements\n";
  return s;
}

}  // namespace hexpeel::io
