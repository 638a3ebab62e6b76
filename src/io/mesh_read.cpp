// Reading triangle meshes: Wavefront OBJ and OFF (text), STL (ASCII and binary) here, PLY in
// mesh_read_ply.cpp. The formats as written by the tools users have: OBJ per Wavefront's
// "Advanced Visualizer" appendix B1 (v and f statements, 1-based and negative relative indices),
// OFF per Geomview's manual (OFF/COFF/NOFF/CNOFF headers, per-vertex and per-face extras ignored),
// STL per 3D Systems' 1989 specification (an 80-byte header, a count, 50-byte facets; or the ASCII
// solid/facet/outer loop/vertex grammar).
#include <algorithm>
#include <bit>
#include <cctype>
#include <cstring>
#include <unordered_map>

#include "io/mesh_text.h"
#include "voxfield/file.h"
#include "voxfield/mesh_read.h"

namespace voxfield {
namespace {

using detail::MeshBuilder;
using detail::TextCursor;

// A polygon's corners as a fan of triangles (a convex polygon's exact split; the formats have no
// way to say a polygon is concave, and every reader here fans them alike).
void add_fan(MeshBuilder& out, const std::vector<std::uint32_t>& corners) {
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
    out.triangle(corners[0], corners[i], corners[i + 1]);
}

// `index` is 0-based; `written` is how the file wrote it, for the message.
std::uint32_t checked_index(TextCursor& in, std::size_t at, std::int64_t index,
                            std::int64_t written, std::size_t count) {
  if (index < 0 || static_cast<std::uint64_t>(index) >= count)
    in.fail_at(at, "the face names vertex " + std::to_string(written) + ", but " +
                       std::to_string(count) + " vertices were read before it");
  return static_cast<std::uint32_t>(index);
}

TriangleMesh parse_obj(std::span<const std::uint8_t> bytes, const std::string& name,
                       std::uint64_t limit) {
  TextCursor in(bytes, name);
  MeshBuilder out(name, limit);
  std::vector<std::uint32_t> corners;
  while (!in.at_end()) {
    const std::string_view keyword = in.word();
    if (keyword == "v") {
      const double x = in.number("an x coordinate"), y = in.number("a y coordinate"),
                   z = in.number("a z coordinate");
      out.vertex(x, y, z);  // an optional w, or the colours some exporters add, follow: ignored
    } else if (keyword == "f" || keyword == "fo") {
      const std::size_t face_at = in.offset() - keyword.size();
      corners.clear();
      while (!in.at_line_end()) {
        const std::size_t at = in.offset();
        // v, v/vt, v//vn or v/vt/vn: the position's index is the first number.
        const std::string_view w = in.word();
        const std::string_view first = w.substr(0, w.find('/'));
        std::int64_t index = 0;
        const auto r = std::from_chars(first.data(), first.data() + first.size(), index);
        if (first.empty() || r.ec != std::errc() || r.ptr != first.data() + first.size() ||
            index == 0)
          in.fail_at(at, "expected a vertex index (1-based, or negative from the last), found \"" +
                             TextCursor::printable(w) + "\"");
        const std::size_t count = out.vertex_count();
        // 1-based, or negative: counted back from the last vertex read.
        corners.push_back(
            checked_index(in, at, index > 0 ? index - 1 : static_cast<std::int64_t>(count) + index,
                          index, count));
      }
      if (corners.size() < 3) in.fail_at(face_at, "a face needs at least 3 vertices");
      add_fan(out, corners);
    }
    // Everything else — comments, vt, vn, groups, materials, lines, points, free-form
    // geometry — says nothing about the triangles: skipped.
    in.next_line();
  }
  return out.take();
}

// OFF: "OFF" (or COFF, NOFF, CNOFF: colours and normals after each vertex), the counts, the
// vertices, then each face as its corner count and corners (a colour may follow).
TriangleMesh parse_off(std::span<const std::uint8_t> bytes, const std::string& name,
                       std::uint64_t limit) {
  TextCursor in(bytes, name);
  MeshBuilder out(name, limit);
  const auto skip_comments = [&] {
    for (;;) {
      in.skip_space();
      if (in.at_end() || bytes[in.offset()] != '#') return;
      in.next_line();
    }
  };
  skip_comments();
  const std::string_view header = in.word();
  if (header != "OFF" && header != "COFF" && header != "NOFF" && header != "CNOFF")
    in.fail_at(0, "not an OFF file (expected OFF, COFF, NOFF or CNOFF, found \"" +
                      TextCursor::printable(header) + "\")");
  if (!in.at_line_end()) {
    const std::size_t at = in.offset();
    if (in.word() == "BINARY") in.fail_at(at, "binary OFF is not supported; save it as text");
    in.fail_at(at, "unexpected text after the OFF header");
  }
  skip_comments();
  const std::size_t counts_at = in.offset();
  const std::int64_t nv = in.integer("the vertex count"), nf = in.integer("the face count");
  if (!in.at_line_end()) in.integer("the edge count");
  // Each vertex takes at least "0 0 0\n", each face "3 0 1 2\n": counts beyond that are lies.
  if (nv < 0 || nf < 0 || static_cast<std::uint64_t>(nv) > in.remaining() / 6 ||
      static_cast<std::uint64_t>(nf) > in.remaining() / 8)
    in.fail_at(counts_at, "counts of " + std::to_string(nv) + " vertices and " +
                              std::to_string(nf) + " faces do not fit in the " +
                              std::to_string(in.remaining()) + " bytes left");
  out.reserve(static_cast<std::uint64_t>(nv), static_cast<std::uint64_t>(nf));
  in.next_line();
  for (std::int64_t i = 0; i < nv; ++i) {
    skip_comments();
    const double x = in.number("an x coordinate"), y = in.number("a y coordinate"),
                 z = in.number("a z coordinate");
    out.vertex(x, y, z);
    in.next_line();
  }
  std::vector<std::uint32_t> corners;
  for (std::int64_t f = 0; f < nf; ++f) {
    skip_comments();
    const std::size_t face_at = (in.skip_blanks(), in.offset());
    const std::int64_t n = in.integer("a face's corner count");
    if (n < 3 || static_cast<std::uint64_t>(n) > in.remaining() / 2)
      in.fail_at(face_at,
                 "a face of " + std::to_string(n) + " corners (at least 3, and no more than fit)");
    corners.clear();
    for (std::int64_t k = 0; k < n; ++k) {
      const std::size_t at = (in.skip_blanks(), in.offset());
      const std::int64_t index = in.integer("a vertex index");
      corners.push_back(checked_index(in, at, index, index, static_cast<std::size_t>(nv)));
    }
    add_fan(out, corners);
    in.next_line();
  }
  return out.take();
}

// Positions keyed by their exact bits: STL repeats a corner in every facet around it.
struct CornerKey {
  std::uint64_t x, y, z;
  bool operator==(const CornerKey&) const = default;
};
struct CornerHash {
  std::size_t operator()(const CornerKey& k) const noexcept {
    std::uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
    h = (h ^ (h >> 31) ^ k.y) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 29) ^ k.z) * 0x94D049BB133111EBull;
    return static_cast<std::size_t>(h ^ (h >> 32));
  }
};

class CornerWelder {
 public:
  explicit CornerWelder(MeshBuilder& out) : out_(out) {}
  std::uint32_t corner(double x, double y, double z) {
    // +0.0 and -0.0 are the same point.
    const CornerKey key{std::bit_cast<std::uint64_t>(x + 0.0),
                        std::bit_cast<std::uint64_t>(y + 0.0),
                        std::bit_cast<std::uint64_t>(z + 0.0)};
    const auto [it, added] =
        index_.try_emplace(key, static_cast<std::uint32_t>(out_.vertex_count()));
    if (added) out_.vertex(x, y, z);
    return it->second;
  }

 private:
  MeshBuilder& out_;
  std::unordered_map<CornerKey, std::uint32_t, CornerHash> index_;
};

TriangleMesh parse_stl_binary(std::span<const std::uint8_t> bytes, const std::string& name,
                              std::uint64_t limit, std::uint32_t count) {
  MeshBuilder out(name, limit);
  // The welder's table holds up to 3 corners a facet (about 48 bytes each): counted with the mesh.
  // The mesh (24 bytes a corner, 12 a facet) and the welder's table (about 48 bytes a corner).
  require_memory(add_sat(mul_sat(std::uint64_t{3} * count, 24 + 48), mul_sat(count, 12)), limit,
                 name, "the mesh and its corners' table (" + std::to_string(count) + " facets)");
  out.reserve(std::uint64_t{3} * count, count);
  CornerWelder weld(out);
  for (std::uint32_t f = 0; f < count; ++f) {
    const std::uint8_t* facet = bytes.data() + 84 + std::size_t{50} * f;
    std::uint32_t corner[3];
    for (int k = 0; k < 3; ++k) {
      float v[3];
      std::memcpy(v, facet + 12 + 12 * k, 12);  // after the facet's normal; little-endian hosts
      for (int a = 0; a < 3; ++a)
        if (!std::isfinite(v[a]))
          throw FormatError(name, 84 + std::uint64_t{50} * f + 12 + 12 * k + 4 * a,
                            "facet " + std::to_string(f) + " has a coordinate that is not finite");
      corner[k] = weld.corner(v[0], v[1], v[2]);
    }
    out.triangle(corner[0], corner[1], corner[2]);
  }
  return out.take();
}

TriangleMesh parse_stl_ascii(std::span<const std::uint8_t> bytes, const std::string& name,
                             std::uint64_t limit) {
  TextCursor in(bytes, name);
  MeshBuilder out(name, limit);
  // A corner takes at least "vertex 0 0 0\n" (13 bytes) and up to about 48 in the welder's table:
  // the table can cost up to 4 bytes per byte of text, charged before it grows.
  require_memory(mul_sat(bytes.size(), 4), limit, name, "the corners' table");
  CornerWelder weld(out);
  const auto expect = [&](std::string_view what) {
    const std::size_t at = (in.skip_space(), in.offset());
    const std::string_view w = in.token();
    if (w != what)
      in.fail_at(
          at, "expected \"" + std::string(what) + "\", found \"" + TextCursor::printable(w) + "\"");
  };
  std::vector<std::uint32_t> corners;
  bool any_solid = false;
  for (;;) {
    const std::size_t at = (in.skip_space(), in.offset());
    const std::string_view w = in.token();
    if (w.empty()) break;
    if (w != "solid")
      in.fail_at(at, "expected \"solid\", found \"" + TextCursor::printable(w) + "\"");
    any_solid = true;
    in.next_line();  // the solid's name
    for (;;) {
      const std::size_t fat = (in.skip_space(), in.offset());
      const std::string_view k = in.token();
      if (k == "endsolid") {
        in.next_line();
        break;
      }
      if (k != "facet")
        in.fail_at(
            fat, "expected \"facet\" or \"endsolid\", found \"" + TextCursor::printable(k) + "\"");
      const std::size_t facet_at = fat;
      in.next_line();  // its normal: recomputed from the corners by whoever needs it
      expect("outer");
      expect("loop");
      corners.clear();
      for (;;) {
        const std::size_t vat = (in.skip_space(), in.offset());
        const std::string_view v = in.token();
        if (v == "endloop") break;
        if (v != "vertex")
          in.fail_at(vat, "expected \"vertex\" or \"endloop\", found \"" +
                              TextCursor::printable(v) + "\"");
        const double x = in.number("an x coordinate"), y = in.number("a y coordinate"),
                     z = in.number("a z coordinate");
        corners.push_back(weld.corner(x, y, z));
      }
      if (corners.size() < 3) in.fail_at(facet_at, "a facet needs at least 3 vertices");
      add_fan(out, corners);
      expect("endfacet");
    }
  }
  if (!any_solid) in.fail_at(0, "an empty STL file");
  return out.take();
}

TriangleMesh parse_stl(std::span<const std::uint8_t> bytes, const std::string& name,
                       std::uint64_t limit) {
  // Binary when the size matches its count exactly — many exporters begin binary headers with
  // "solid" too, so the size decides, not the first word.
  if (bytes.size() >= 84) {
    std::uint32_t count;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (bytes.size() == 84 + std::uint64_t{50} * count)
      return parse_stl_binary(bytes, name, limit, count);
  }
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(bytes[i])) ++i;
  if (bytes.size() - i >= 5 && std::memcmp(bytes.data() + i, "solid", 5) == 0)
    return parse_stl_ascii(bytes, name, limit);
  if (bytes.size() < 84)
    throw FormatError(name, bytes.size(),
                      "too short for a binary STL (84 bytes at least) and "
                      "not ASCII STL (no \"solid\")");
  std::uint32_t count;
  std::memcpy(&count, bytes.data() + 80, 4);
  throw FormatError(name, 80,
                    "not ASCII STL (no \"solid\") and not binary STL: " + std::to_string(count) +
                        " facets need " + std::to_string(84 + std::uint64_t{50} * count) +
                        " bytes, the file has " + std::to_string(bytes.size()));
}

}  // namespace

std::optional<MeshInputFormat> mesh_input_format_of(const std::filesystem::path& path) {
  const std::string e = lowercase_extension(path);
  if (e == ".obj") return MeshInputFormat::kObj;
  if (e == ".ply") return MeshInputFormat::kPly;
  if (e == ".stl") return MeshInputFormat::kStl;
  if (e == ".off") return MeshInputFormat::kOff;
  return std::nullopt;
}

const char* mesh_input_format_name(MeshInputFormat f) {
  switch (f) {
    case MeshInputFormat::kObj:
      return "obj";
    case MeshInputFormat::kPly:
      return "ply";
    case MeshInputFormat::kStl:
      return "stl";
    case MeshInputFormat::kOff:
      return "off";
  }
  return "?";
}

TriangleMesh parse_mesh(std::span<const std::uint8_t> bytes, MeshInputFormat format,
                        const std::string& name, const MeshReadOptions& options) {
  const std::uint64_t limit = effective_memory_limit(options.memory_limit_bytes);
  switch (format) {
    case MeshInputFormat::kObj:
      return parse_obj(bytes, name, limit);
    case MeshInputFormat::kPly:
      return detail::parse_ply(bytes, name, limit);
    case MeshInputFormat::kStl:
      return parse_stl(bytes, name, limit);
    case MeshInputFormat::kOff:
      return parse_off(bytes, name, limit);
  }
  throw InvalidArgument(name + ": unknown mesh format");
}

TriangleMesh read_mesh(const std::filesystem::path& path, const MeshReadOptions& options) {
  const auto format = mesh_input_format_of(path);
  if (!format)
    throw InvalidArgument(path.string() + ": not a mesh file (expected .obj, .ply, .stl or .off)");
  const std::uint64_t limit = effective_memory_limit(options.memory_limit_bytes);
  const std::vector<std::uint8_t> bytes = read_file(path, limit);
  MeshReadOptions rest;
  rest.memory_limit_bytes = remaining_memory(limit, bytes.size());
  return parse_mesh(bytes, *format, path.string(), rest);
}

}  // namespace voxfield
