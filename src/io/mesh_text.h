// voxfield — the pieces the mesh readers share (internal): a cursor over text that reports the
// byte offset of every problem, and the growing mesh whose memory is checked as it grows.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_voxelize.h"

namespace voxfield::detail {

class TextCursor {
 public:
  TextCursor(std::span<const std::uint8_t> bytes, const std::string& name, std::size_t pos = 0)
      : text_(reinterpret_cast<const char*>(bytes.data()), bytes.size()), name_(&name), pos_(pos) {}

  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return text_.size() - pos_; }
  bool at_end() const { return pos_ >= text_.size(); }
  [[noreturn]] void fail(const std::string& what) const { throw FormatError(*name_, pos_, what); }
  [[noreturn]] void fail_at(std::size_t at, const std::string& what) const {
    throw FormatError(*name_, at, what);
  }

  // Spaces, tabs and carriage returns (not line ends).
  void skip_blanks() {
    while (pos_ < text_.size() &&
           (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\r'))
      ++pos_;
  }
  // Every kind of white space, line ends included.
  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) ++pos_;
  }
  bool at_line_end() {
    skip_blanks();
    return pos_ >= text_.size() || text_[pos_] == '\n';
  }
  void next_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    if (pos_ < text_.size()) ++pos_;
  }
  // The next run of non-space characters on this line (empty at the line's end).
  std::string_view word() {
    skip_blanks();
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    return text_.substr(start, pos_ - start);
  }
  // The next word across lines (empty only at the end of the text).
  std::string_view token() {
    skip_space();
    return word();
  }
  double number(const char* what, bool across_lines = false) {
    if (across_lines) skip_space();
    const std::size_t at = (skip_blanks(), pos_);
    const std::string_view w = word();
    double v = 0;
    const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
    if (w.empty() || r.ec != std::errc() || r.ptr != w.data() + w.size())
      fail_at(at, std::string("expected ") + what + ", found \"" + printable(w) + "\"");
    if (!std::isfinite(v)) fail_at(at, std::string(what) + " is not finite");
    return v;
  }
  std::int64_t integer(const char* what, bool across_lines = false) {
    if (across_lines) skip_space();
    const std::size_t at = (skip_blanks(), pos_);
    const std::string_view w = word();
    std::int64_t v = 0;
    const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
    if (w.empty() || r.ec != std::errc() || r.ptr != w.data() + w.size())
      fail_at(at, std::string("expected ") + what + ", found \"" + printable(w) + "\"");
    return v;
  }
  static std::string printable(std::string_view w) {
    std::string s;
    for (char c : w.substr(0, 24)) s += (c >= 32 && c < 127) ? c : '?';
    return w.size() > 24 ? s + "..." : s;
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
  std::string_view text_;
  const std::string* name_;
  std::size_t pos_;
};

// The mesh being read, with the memory limit checked each time its arrays are about to grow.
class MeshBuilder {
 public:
  MeshBuilder(const std::string& name, std::uint64_t limit) : name_(name), limit_(limit) {}

  std::size_t vertex_count() const { return mesh_.positions.size(); }
  void reserve(std::uint64_t vertices, std::uint64_t triangles) {
    check(vertices, triangles);
    mesh_.positions.reserve(vertices);
    mesh_.triangles.reserve(triangles);
  }
  void vertex(double x, double y, double z) {
    if (mesh_.positions.size() == mesh_.positions.capacity())
      check(2 * mesh_.positions.size() + 1, mesh_.triangles.capacity());
    mesh_.positions.push_back({x, y, z});
  }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (mesh_.triangles.size() == mesh_.triangles.capacity())
      check(mesh_.positions.capacity(), 2 * mesh_.triangles.size() + 1);
    mesh_.triangles.push_back({a, b, c});
  }
  TriangleMesh take() { return std::move(mesh_); }

 private:
  void check(std::uint64_t vertices, std::uint64_t triangles) const {
    require_memory(add_sat(mul_sat(vertices, 24), mul_sat(triangles, 12)), limit_, name_,
                   "the mesh (" + std::to_string(vertices) + " vertices, " +
                       std::to_string(triangles) + " triangles)");
  }
  const std::string& name_;
  std::uint64_t limit_;
  TriangleMesh mesh_;
};

// Reads PLY (ASCII or binary); mesh_read_ply.cpp.
TriangleMesh parse_ply(std::span<const std::uint8_t> bytes, const std::string& name,
                       std::uint64_t memory_limit);

}  // namespace voxfield::detail
