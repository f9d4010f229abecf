// Stanford PLY: reads the vertices and faces of a polygon surface.
//
// Formats ascii, binary_little_endian and binary_big_endian. The `vertex` element must have
// scalar properties x, y, z of any numeric type; the `face` element's list property
// `vertex_indices` (or `vertex_index`) may use any count and index types. Every other element
// and property is parsed and skipped, so files with normals, colours or edges read fine.
// Element counts are checked against the bytes left before anything is allocated.
#include "io/formats.h"

#include <optional>

namespace hexpeel::io {

namespace {

struct PlyProperty {
  std::string name;
  bool list = false;
  Scalar count_type = Scalar::u8;  ///< type of a list's length
  Scalar type = Scalar::f32;       ///< type of the value (or of each list entry)
};

struct PlyElement {
  std::string name;
  int64_t count = 0;
  std::vector<PlyProperty> props;
};

std::optional<Scalar> ply_type(std::string_view t) {
  if (t == "char" || t == "int8") return Scalar::i8;
  if (t == "uchar" || t == "uint8") return Scalar::u8;
  if (t == "short" || t == "int16") return Scalar::i16;
  if (t == "ushort" || t == "uint16") return Scalar::u16;
  if (t == "int" || t == "int32") return Scalar::i32;
  if (t == "uint" || t == "uint32") return Scalar::u32;
  if (t == "int64") return Scalar::i64;
  if (t == "uint64") return Scalar::u64;
  if (t == "float" || t == "float32") return Scalar::f32;
  if (t == "double" || t == "float64") return Scalar::f64;
  return std::nullopt;
}

bool is_float(Scalar s) { return s == Scalar::f32 || s == Scalar::f64; }

/// The body values, ASCII tokens or binary scalars, behind one interface.
class PlyBody {
 public:
  PlyBody(TextCursor* text, ByteCursor* bin, const std::string& name)
      : text_(text), bin_(bin), name_(name) {}

  bool real(Scalar s, double& v) {
    if (bin_ != nullptr) return bin_->get_real(s, v);
    std::string_view t;
    return text_->next(t) && parse_real(t, v);
  }
  bool integer(Scalar s, int64_t& v) {
    if (bin_ != nullptr) return bin_->get_int(s, v);
    std::string_view t;
    if (!text_->next(t)) return false;
    if (parse_int(t, v)) return true;
    double d;  // some writers print integer properties as "3.0"
    if (!is_float(s) || !parse_real(t, d) || !(d > -9e18 && d < 9e18)) return false;
    v = static_cast<int64_t>(d);
    return true;
  }
  size_t remaining() const { return bin_ != nullptr ? bin_->remaining() : text_->remaining(); }
  Where where() const {
    return bin_ != nullptr ? at_byte(static_cast<int64_t>(bin_->pos())) : at_line(text_->line());
  }
  Status error(const std::string& msg) const { return parse_error(name_, where(), msg); }

 private:
  TextCursor* text_;
  ByteCursor* bin_;
  const std::string& name_;
};

/// Reads one item of `e`, keeping the values of properties flagged in `keep_real` (scalars) and
/// the list `keep_list` (index into props, or -1).
Status read_item(PlyBody& body, const PlyElement& e, int64_t item, double* reals,
                 std::vector<int64_t>* list, int keep_list) {
  for (size_t p = 0; p < e.props.size(); ++p) {
    const PlyProperty& prop = e.props[p];
    const std::string what =
        "property '" + prop.name + "' of " + e.name + " " + std::to_string(item);
    if (!prop.list) {
      double v;
      if (!body.real(prop.type, v)) return body.error("missing or malformed " + what);
      reals[p] = v;
      continue;
    }
    int64_t n = 0;
    if (!body.integer(prop.count_type, n)) return body.error("missing or malformed length of " + what);
    if (n < 0 || n > static_cast<int64_t>(body.remaining())) {
      return body.error("impossible length " + std::to_string(n) + " of " + what);
    }
    const bool keep = static_cast<int>(p) == keep_list;
    if (keep) list->resize(static_cast<size_t>(n));
    for (int64_t k = 0; k < n; ++k) {
      int64_t v;
      if (!body.integer(prop.type, v)) return body.error("missing or malformed entry of " + what);
      if (keep) (*list)[static_cast<size_t>(k)] = v;
    }
  }
  return Status::success();
}

}  // namespace

Status read_ply(std::string_view data, const std::string& name, CellSoup& out) {
  TextCursor cur(data, name);
  if (cur.rest_of_line() != "ply") return cur.error_at(1, "expected 'ply' on the first line");
  enum class Format { none, ascii, little, big } format = Format::none;
  std::vector<PlyElement> elements;
  bool ended = false;
  while (!ended) {
    if (cur.remaining() == 0) return cur.error("header has no end_header line");
    const int64_t line = cur.line();
    TextCursor words(cur.rest_of_line(), name);
    std::string_view kw;
    if (!words.next(kw) || kw == "comment" || kw == "obj_info") continue;
    auto bad = [&](const std::string& msg) { return cur.error_at(line, msg); };
    if (kw == "end_header") {
      ended = true;
    } else if (kw == "format") {
      std::string_view f;
      words.next(f);
      if (f == "ascii") format = Format::ascii;
      else if (f == "binary_little_endian") format = Format::little;
      else if (f == "binary_big_endian") format = Format::big;
      else return bad("unknown format " + quoted(f));
    } else if (kw == "element") {
      PlyElement e;
      std::string_view n, c;
      if (!words.next(n) || !words.next(c) || !parse_int(c, e.count) || e.count < 0) {
        return bad("expected 'element <name> <count>'");
      }
      e.name = std::string(n);
      elements.push_back(std::move(e));
    } else if (kw == "property") {
      if (elements.empty()) return bad("property before any element");
      PlyProperty p;
      std::string_view t, n;
      if (!words.next(t)) return bad("expected a property type");
      if (t == "list") {
        std::string_view ct, it;
        if (!words.next(ct) || !words.next(it) || !words.next(n)) {
          return bad("expected 'property list <count type> <index type> <name>'");
        }
        const auto ctype = ply_type(ct), itype = ply_type(it);
        if (!ctype || !itype) return bad("unknown property type in list " + quoted(n));
        p.list = true;
        p.count_type = *ctype;
        p.type = *itype;
      } else {
        const auto type = ply_type(t);
        if (!type) return bad("unknown property type " + quoted(t));
        if (!words.next(n)) return bad("expected a property name");
        p.type = *type;
      }
      p.name = std::string(n);
      elements.back().props.push_back(std::move(p));
    } else {
      return bad("unknown header keyword " + quoted(kw));
    }
  }
  if (format == Format::none) return cur.error("header has no format line");

  TextCursor text(data, name);
  text.jump_to(cur.pos());
  ByteCursor bin(data, cur.pos(), format == Format::big);
  PlyBody body(&text, format == Format::ascii ? nullptr : &bin, name);

  bool seen_vertex = false;
  std::vector<double> reals;
  std::vector<int64_t> face;
  for (const PlyElement& e : elements) {
    if (e.props.empty()) continue;  // nothing stored per item
    reals.assign(e.props.size(), 0.0);
    size_t min_item_bytes = 0;
    for (const PlyProperty& p : e.props) {
      min_item_bytes += format == Format::ascii ? 1 : scalar_size(p.list ? p.count_type : p.type);
    }
    if (e.count > static_cast<int64_t>(body.remaining() / min_item_bytes)) {
      return body.error("element '" + e.name + "' claims " + std::to_string(e.count) +
                        " items, more than the rest of the file can hold");
    }
    int x = -1, y = -1, z = -1, list = -1;
    for (size_t p = 0; p < e.props.size(); ++p) {
      const PlyProperty& prop = e.props[p];
      const int i = static_cast<int>(p);
      if (!prop.list && prop.name == "x") x = i;
      if (!prop.list && prop.name == "y") y = i;
      if (!prop.list && prop.name == "z") z = i;
      if (prop.list && (prop.name == "vertex_indices" || prop.name == "vertex_index")) list = i;
    }
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    if (is_vertex) {
      if (x < 0 || y < 0 || z < 0) {
        return Status::error(StatusCode::parse_error,
                             name + ": element 'vertex' lacks scalar property x, y or z");
      }
      seen_vertex = true;
      out.points.reserve(static_cast<size_t>(e.count));
    }
    if (is_face && list < 0) {
      return Status::error(StatusCode::parse_error,
                           name + ": element 'face' has no list property vertex_indices");
    }
    for (int64_t i = 0; i < e.count; ++i) {
      const Where w = body.where();
      if (Status s = read_item(body, e, i, reals.data(), &face, is_face ? list : -1); !s.ok()) {
        return s;
      }
      if (is_vertex) out.points.emplace_back(reals[x], reals[y], reals[z]);
      if (is_face) out.add_cell(CellKind::polygon, face.data(), face.size(), w);
    }
  }
  if (!seen_vertex) {
    return Status::error(StatusCode::parse_error, name + ": header declares no 'vertex' element");
  }
  return Status::success();
}

}  // namespace hexpeel::io
