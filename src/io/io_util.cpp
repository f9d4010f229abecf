// Shared reader/writer helpers: tokenizing with line numbers, bounds-checked binary access,
// number parsing and shortest round-trip formatting, whole-file reads and atomic writes.
//
// Guarantees: no function here reads past the data it was given or loops without consuming
// input, so the format readers built on it cannot crash or hang on arbitrary bytes. Atomic writes
// create a uniquely named temporary file in the target directory (O_EXCL) and rename it over the
// target; on any failure the temporary file is removed and the target is left untouched.
#include "io/io_util.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <limits>
#include <random>
#include <system_error>

namespace hexpeel::io {

std::string located(const std::string& name, Where where, const std::string& msg) {
  if (where.byte) return name + ": byte " + std::to_string(where.value) + ": " + msg;
  return name + ":" + std::to_string(where.value) + ": " + msg;
}

Status parse_error(const std::string& name, Where where, const std::string& msg) {
  return Status::error(StatusCode::parse_error, located(name, where, msg));
}

bool add_vtk_cell(CellSoup& soup, int64_t type, const int64_t* corners, size_t n, Where w) {
  switch (type) {
    case 12:  // VTK_HEXAHEDRON: our own order
      if (n != 8) return false;
      soup.add_cell(CellKind::hex, corners, n, w);
      return true;
    case 11: {  // VTK_VOXEL: corners in x-fastest lattice order
      if (n != 8) return false;
      const int64_t h[8] = {corners[0], corners[1], corners[3], corners[2],
                            corners[4], corners[5], corners[7], corners[6]};
      soup.add_cell(CellKind::hex, h, 8, w);
      return true;
    }
    case 5:  // VTK_TRIANGLE
    case 9:  // VTK_QUAD
      if (n != (type == 5 ? 3u : 4u)) return false;
      soup.add_cell(CellKind::polygon, corners, n, w);
      return true;
    case 7:  // VTK_POLYGON
      soup.add_cell(CellKind::polygon, corners, n, w);
      return true;
    default:
      soup.add_other(w);
      return true;
  }
}

std::string quoted(std::string_view token) {
  std::string s = "'";
  const size_t n = std::min<size_t>(token.size(), 24);
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    s += (c >= 32 && c < 127) ? static_cast<char>(c) : '?';
  }
  if (token.size() > n) s += "...";
  return s + "'";
}

bool parse_int(std::string_view s, int64_t& v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_real(std::string_view s, double& v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// TextCursor

static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

void TextCursor::skip_blanks(bool cross_lines) {
  while (pos_ < data_.size()) {
    const char c = data_[pos_];
    if (is_blank(c)) {
      ++pos_;
    } else if (c == '\n') {
      if (!cross_lines) return;
      ++pos_;
      ++line_;
    } else if (comment_ != '\0' && c == comment_) {
      while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
    } else {
      return;
    }
  }
}

bool TextCursor::next(std::string_view& tok) {
  skip_blanks(true);
  if (pos_ >= data_.size()) return false;
  const size_t start = pos_;
  while (pos_ < data_.size() && !is_blank(data_[pos_]) && data_[pos_] != '\n') ++pos_;
  tok = data_.substr(start, pos_ - start);
  return true;
}

bool TextCursor::next_in_line(std::string_view& tok) {
  skip_blanks(false);
  if (pos_ >= data_.size() || data_[pos_] == '\n') return false;
  const size_t start = pos_;
  while (pos_ < data_.size() && !is_blank(data_[pos_]) && data_[pos_] != '\n') ++pos_;
  tok = data_.substr(start, pos_ - start);
  return true;
}

bool TextCursor::peek(std::string_view& tok) {
  const size_t p = pos_;
  const int64_t l = line_;
  const bool found = next(tok);
  pos_ = p;
  line_ = l;
  return found;
}

void TextCursor::skip_line() {
  while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
  if (pos_ < data_.size()) {
    ++pos_;
    ++line_;
  }
}

std::string_view TextCursor::rest_of_line() {
  const size_t start = pos_;
  while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
  std::string_view s = data_.substr(start, pos_ - start);
  if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
  if (pos_ < data_.size()) {
    ++pos_;
    ++line_;
  }
  return s;
}

bool TextCursor::at_end() {
  skip_blanks(true);
  return pos_ >= data_.size();
}

int64_t TextCursor::next_line() {
  skip_blanks(true);
  return line_;
}

void TextCursor::jump_to(size_t pos) {
  if (pos > data_.size()) pos = data_.size();
  for (size_t i = pos_; i < pos; ++i) line_ += data_[i] == '\n';
  if (pos > pos_) pos_ = pos;
}

Status TextCursor::get_int(int64_t& v, std::string_view what) {
  std::string_view tok;
  if (!next(tok)) return error("expected " + std::string(what) + ", found end of file");
  if (!parse_int(tok, v)) {
    return error("expected " + std::string(what) + " (an integer), found " + quoted(tok));
  }
  return Status::success();
}

Status TextCursor::get_real(double& v, std::string_view what) {
  std::string_view tok;
  if (!next(tok)) return error("expected " + std::string(what) + ", found end of file");
  if (!parse_real(tok, v)) {
    return error("expected " + std::string(what) + " (a number), found " + quoted(tok));
  }
  return Status::success();
}

Status TextCursor::get_count(int64_t& v, std::string_view what, int64_t max) {
  if (Status s = get_int(v, what); !s.ok()) return s;
  if (v < 0) return error(std::string(what) + " is negative (" + std::to_string(v) + ")");
  if (v > max) {
    return error(std::string(what) + " " + std::to_string(v) +
                 " is more than the rest of the file can hold");
  }
  return Status::success();
}

// ---------------------------------------------------------------------------------------------
// Binary scalars

size_t scalar_size(Scalar s) {
  switch (s) {
    case Scalar::i8: case Scalar::u8: return 1;
    case Scalar::i16: case Scalar::u16: return 2;
    case Scalar::i32: case Scalar::u32: case Scalar::f32: return 4;
    case Scalar::i64: case Scalar::u64: case Scalar::f64: return 8;
  }
  return 1;
}

bool ByteCursor::get_real(Scalar s, double& v) {
  switch (s) {
    case Scalar::f32: { float f; if (!get(f)) return false; v = f; return true; }
    case Scalar::f64: return get(v);
    case Scalar::u64: { uint64_t u; if (!get(u)) return false; v = static_cast<double>(u); return true; }
    default: { int64_t i; if (!get_int(s, i)) return false; v = static_cast<double>(i); return true; }
  }
}

bool ByteCursor::get_int(Scalar s, int64_t& v) {
  switch (s) {
    case Scalar::i8: { int8_t x; if (!get(x)) return false; v = x; return true; }
    case Scalar::u8: { uint8_t x; if (!get(x)) return false; v = x; return true; }
    case Scalar::i16: { int16_t x; if (!get(x)) return false; v = x; return true; }
    case Scalar::u16: { uint16_t x; if (!get(x)) return false; v = x; return true; }
    case Scalar::i32: { int32_t x; if (!get(x)) return false; v = x; return true; }
    case Scalar::u32: { uint32_t x; if (!get(x)) return false; v = x; return true; }
    case Scalar::i64: return get(v);
    case Scalar::u64: {
      uint64_t x;
      if (!get(x)) return false;
      v = x > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())
              ? std::numeric_limits<int64_t>::max() : static_cast<int64_t>(x);
      return true;
    }
    case Scalar::f32: case Scalar::f64: {
      // Integers stored as floating point: accepted when they are whole numbers in range.
      double d;
      if (!get_real(s, d)) return false;
      v = (d == d && d > -9.0e18 && d < 9.0e18) ? static_cast<int64_t>(d) : -1;
      return true;
    }
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Formatting

void append_point(std::string& out, const Vec3& p) {
  append_real(out, p.x());
  out += ' ';
  append_real(out, p.y());
  out += ' ';
  append_real(out, p.z());
}

void append_real(std::string& out, double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out.append(buf, r.ptr);
}

void append_int(std::string& out, int64_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out.append(buf, r.ptr);
}

// ---------------------------------------------------------------------------------------------
// Files

Status read_whole_file(const std::filesystem::path& path, std::string& out) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    return Status::error(StatusCode::io_error, path.string() + ": is a directory, not a file");
  }
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    return Status::error(StatusCode::io_error,
                         path.string() + ": cannot open for reading: " + std::strerror(errno));
  }
  out.clear();
  char buf[1 << 16];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof(buf), f)) > 0) out.append(buf, n);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) return Status::error(StatusCode::io_error, path.string() + ": read error");
  return Status::success();
}

std::filesystem::path temporary_path_beside(const std::filesystem::path& path) {
  std::random_device rd;
  std::string name = ".";
  name += path.filename().string();
  name += ".tmp";
  name += std::to_string(::getpid());
  name += '_';
  name += std::to_string(rd());
  return path.parent_path() / name;
}

Status rename_over(const std::filesystem::path& tmp, const std::filesystem::path& path) {
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(tmp.c_str());
    return Status::error(StatusCode::io_error,
                         path.string() + ": cannot rename the temporary file over it: " + reason);
  }
  return Status::success();
}

Status write_file_atomic(const std::filesystem::path& path, std::string_view bytes) {
  auto fail = [&](const std::string& what) {
    return Status::error(StatusCode::io_error, path.string() + ": " + what);
  };
  if (path.filename().empty()) return fail("not a file name");
  std::filesystem::path tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 16 && fd < 0; ++attempt) {
    tmp = temporary_path_beside(path);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) return fail(std::string("cannot create a temporary file: ") + std::strerror(errno));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      const std::string reason = std::strerror(errno);
      ::close(fd);
      ::unlink(tmp.c_str());
      return fail("write failed: " + reason);
    }
    done += static_cast<size_t>(w);
  }
  if (::close(fd) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(tmp.c_str());
    return fail("write failed: " + reason);
  }
  return rename_over(tmp, path);
}

}  // namespace hexpeel::io
