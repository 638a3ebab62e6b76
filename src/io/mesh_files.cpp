// voxfield — mesh encoders. Each follows its format's reference: PLY (Turk's 1994 specification,
// binary_little_endian 1.0), OBJ (Wavefront's "Advanced Visualizer" appendix: v, vn, f a//n),
// binary STL (3D Systems: an 80-byte header, a facet count, 50 bytes per facet) and glTF 2.0
// (Khronos: a JSON chunk and a BIN chunk, each padded to 4 bytes).
#include "voxfield/mesh_files.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "voxfield/error.h"
#include "voxfield/file.h"

namespace voxfield {

namespace {

static_assert(std::endian::native == std::endian::little,
              "the encoders copy native little-endian values");

template <class T>
void put(std::vector<std::uint8_t>& out, const T& value) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

void put_text(std::vector<std::uint8_t>& out, const std::string& text) {
  out.insert(out.end(), text.begin(), text.end());
}

std::vector<std::uint8_t> ply_head(const MeshTotals& t) {
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment written by voxfield\n"
    << "element vertex " << t.vertices << "\n"
    << "property float x\nproperty float y\nproperty float z\n"
    << "property float nx\nproperty float ny\nproperty float nz\n";
  if (t.colored) h << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  h << "element face " << t.triangles << "\nproperty list uchar uint vertex_indices\nend_header\n";
  std::vector<std::uint8_t> out;
  put_text(out, h.str());
  return out;
}

std::vector<std::uint8_t> obj_head(const MeshTotals& t) {
  std::vector<std::uint8_t> out;
  put_text(out, "# written by voxfield: " + std::to_string(t.vertices) + " vertices, " +
                    std::to_string(t.triangles) + " triangles\n");
  return out;
}

std::vector<std::uint8_t> stl_head(const MeshTotals& t) {
  if (t.triangles > std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument("STL: more triangles than a binary STL can count");
  std::vector<std::uint8_t> out(80, 0);
  const char title[] = "binary STL written by voxfield";
  std::memcpy(out.data(), title, sizeof(title) - 1);  // never "solid": readers take that for ASCII
  put(out, static_cast<std::uint32_t>(t.triangles));
  return out;
}

// The .glb's chunk headers and its JSON chunk, padded to 4 bytes.
std::vector<std::uint8_t> glb_chunks(const std::string& json_text, std::uint64_t bin_bytes,
                                     bool has_bin) {
  std::string text = json_text;
  while (text.size() % 4) text.push_back(' ');
  const std::uint64_t total = 12 + 8 + text.size() + (has_bin ? 8 + bin_bytes : 0);
  if (total > std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument("glTF: the mesh passes the 4 GiB a .glb can hold");
  std::vector<std::uint8_t> out;
  put(out, std::uint32_t{0x46546C67});  // "glTF"
  put(out, std::uint32_t{2});
  put(out, static_cast<std::uint32_t>(total));
  put(out, static_cast<std::uint32_t>(text.size()));
  put(out, std::uint32_t{0x4E4F534A});  // "JSON"
  put_text(out, text);
  if (has_bin) {
    put(out, static_cast<std::uint32_t>(bin_bytes));
    put(out, std::uint32_t{0x004E4942});  // "BIN\0"
  }
  return out;
}

std::vector<std::uint8_t> glb_head(const MeshTotals& t) {
  using nlohmann::json;
  if (t.triangles == 0) {
    // glTF gives accessors, buffer views and buffers a minimum length of one: an empty mesh is
    // a scene with one node and nothing in it.
    const json empty = {{"asset", {{"version", "2.0"}, {"generator", "voxfield"}}},
                        {"scene", 0},
                        {"scenes", json::array({{{"nodes", json::array({0})}}})},
                        {"nodes", json::array({json::object()})}};
    return glb_chunks(empty.dump(), 0, false);
  }
  // One buffer: positions, normals, colours (linear RGBA as normalised 16-bit: vertex attributes
  // are 4-byte aligned, and 8 bits would band dark linear values), indices; every view's length
  // is a multiple of 4, so each starts on a 4-byte boundary with no padding.
  std::uint64_t bin = 0;
  auto view = [&](std::uint64_t bytes, json target) {
    const std::uint64_t offset = bin;
    bin += bytes;
    return json{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}};
  };
  constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963, kFloat = 5126,
                kUnsignedShort = 5123, kUnsignedInt = 5125;
  json views = json::array(), accessors = json::array(), attributes = json::object();
  const std::uint64_t n = t.vertices;
  views.push_back(view(n * 12, kArrayBuffer));
  accessors.push_back({{"bufferView", 0},
                       {"componentType", kFloat},
                       {"count", n},
                       {"type", "VEC3"},
                       {"min", t.lo},
                       {"max", t.hi}});
  attributes["POSITION"] = 0;
  views.push_back(view(n * 12, kArrayBuffer));
  accessors.push_back(
      {{"bufferView", 1}, {"componentType", kFloat}, {"count", n}, {"type", "VEC3"}});
  attributes["NORMAL"] = 1;
  if (t.colored) {
    views.push_back(view(n * 8, kArrayBuffer));
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", kUnsignedShort},
                         {"normalized", true},
                         {"count", n},
                         {"type", "VEC4"}});
    attributes["COLOR_0"] = accessors.size() - 1;
  }
  views.push_back(view(t.triangles * 12, kElementArrayBuffer));
  accessors.push_back({{"bufferView", views.size() - 1},
                       {"componentType", kUnsignedInt},
                       {"count", t.triangles * 3},
                       {"type", "SCALAR"}});
  const json doc = {
      {"asset", {{"version", "2.0"}, {"generator", "voxfield"}}},
      {"scene", 0},
      {"scenes", json::array({{{"nodes", json::array({0})}}})},
      {"nodes", json::array({{{"mesh", 0}}})},
      {"meshes", json::array({{{"primitives", json::array({{{"attributes", attributes},
                                                            {"indices", accessors.size() - 1},
                                                            {"material", 0},
                                                            {"mode", 4}}})}}})},
      // A matte material: glTF's default one is fully metallic, which viewers draw nearly black
      // under plain lights. Double-sided, since a terrain cut by its volume is an open sheet.
      {"materials", json::array({{{"name", "voxfield"},
                                  {"pbrMetallicRoughness",
                                   {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}},
                                    {"metallicFactor", 0.0},
                                    {"roughnessFactor", 0.9}}},
                                  {"doubleSided", true}}})},
      {"accessors", accessors},
      {"bufferViews", views},
      {"buffers", json::array({{{"byteLength", bin}}})},
  };
  return glb_chunks(doc.dump(), bin, true);
}

// glTF's COLOR_0 is linear; voxfield's palette colours are sRGB (IEC 61966-2-1's transfer curve).
std::uint16_t linear_u16(std::uint8_t srgb) {
  const double c = srgb / 255.0;
  const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  return static_cast<std::uint16_t>(std::lround(linear * 65535));
}

// An STL facet: its normal from the corners (the file's normals are per facet), the corners and
// an empty attribute count.
void put_facet(std::vector<std::uint8_t>& out, const std::array<float, 3>& a,
               const std::array<float, 3>& b, const std::array<float, 3>& c) {
  const double u[3] = {double{b[0]} - a[0], double{b[1]} - a[1], double{b[2]} - a[2]};
  const double v[3] = {double{c[0]} - a[0], double{c[1]} - a[1], double{c[2]} - a[2]};
  double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (double& x : n) x = l > 0 ? x / l : 0;
  put(out, std::array<float, 3>{static_cast<float>(n[0]), static_cast<float>(n[1]),
                                static_cast<float>(n[2])});
  put(out, a);
  put(out, b);
  put(out, c);
  put(out, std::uint16_t{0});
}

// OBJ's lines of a run: "v" or "vn" for vertices [first, end), or every triangle's "f".
void put_obj_lines(std::vector<std::uint8_t>& out, MeshSection section, const Mesh& m,
                   std::size_t first, std::size_t end, std::span<const std::uint32_t> global) {
  std::ostringstream os;
  os.precision(std::numeric_limits<float>::max_digits10);  // positions read back bit for bit
  if (section == MeshSection::kPositions || section == MeshSection::kNormals) {
    const bool normals = section == MeshSection::kNormals;
    const auto& values = normals ? m.normals : m.positions;
    const char* tag = normals ? "vn " : "v ";
    for (std::size_t i = first; i < end; ++i)
      os << tag << values[i][0] << ' ' << values[i][1] << ' ' << values[i][2] << '\n';
  } else {
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      os << 'f';
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t local = m.indices[3 * t + static_cast<std::size_t>(k)];
        const std::uint64_t v = std::uint64_t{global.empty() ? local : global[local]} + 1;
        os << ' ' << v << "//" << v;
      }
      os << '\n';
    }
  }
  put_text(out, os.str());
}

}  // namespace

const char* mesh_format_name(MeshFormat f) {
  switch (f) {
    case MeshFormat::kPly:
      return "ply";
    case MeshFormat::kObj:
      return "obj";
    case MeshFormat::kStl:
      return "stl";
    case MeshFormat::kGlb:
      return "glb";
  }
  return "?";
}

MeshFormat mesh_format_of(const std::filesystem::path& path) {
  const std::string ext = lowercase_extension(path);
  if (ext == ".ply") return MeshFormat::kPly;
  if (ext == ".obj") return MeshFormat::kObj;
  if (ext == ".stl") return MeshFormat::kStl;
  if (ext == ".glb") return MeshFormat::kGlb;
  throw InvalidArgument(path.string() + ": unknown mesh format '" + ext +
                        "' (expected .ply, .obj, .stl or .glb)");
}

MeshTotals mesh_totals(const Mesh& mesh) {
  MeshTotals t;
  t.vertices = mesh.vertex_count();
  t.triangles = mesh.triangle_count();
  t.colored = !mesh.colors.empty();
  if (!mesh.positions.empty()) {
    t.lo = t.hi = mesh.positions[0];
    for (const auto& p : mesh.positions)
      for (std::size_t a = 0; a < 3; ++a)
        t.lo[a] = std::min(t.lo[a], p[a]), t.hi[a] = std::max(t.hi[a], p[a]);
  }
  return t;
}

std::vector<MeshSection> mesh_file_sections(MeshFormat format, const MeshTotals& totals) {
  using S = MeshSection;
  switch (format) {
    case MeshFormat::kPly:
      return {S::kVertices, S::kTriangles};
    case MeshFormat::kObj:
      return {S::kPositions, S::kNormals, S::kTriangles};
    case MeshFormat::kStl:
      return {S::kTriangles};
    case MeshFormat::kGlb:
      if (totals.triangles == 0) return {};  // no BIN chunk
      if (totals.colored) return {S::kPositions, S::kNormals, S::kColors, S::kTriangles};
      return {S::kPositions, S::kNormals, S::kTriangles};
  }
  throw InvalidArgument("mesh: unknown format");
}

std::vector<std::uint8_t> encode_mesh_head(MeshFormat format, const MeshTotals& totals) {
  switch (format) {
    case MeshFormat::kPly:
      return ply_head(totals);
    case MeshFormat::kObj:
      return obj_head(totals);
    case MeshFormat::kStl:
      return stl_head(totals);
    case MeshFormat::kGlb:
      return glb_head(totals);
  }
  throw InvalidArgument("mesh: unknown format");
}

void encode_mesh_section(MeshFormat format, MeshSection section, const Mesh& m, std::size_t first,
                         std::size_t end, std::span<const std::uint32_t> global,
                         std::vector<std::uint8_t>& out) {
  // The run's arguments, checked as encode_mesh checks a whole mesh's arrays.
  const std::size_t n = m.vertex_count();
  if (first > end || end > n || m.normals.size() != n ||
      (!m.colors.empty() && m.colors.size() != n) || m.indices.size() % 3 != 0 ||
      (section == MeshSection::kColors && m.colors.empty() && end > first) ||
      (!global.empty() && global.size() != n))
    throw InvalidArgument("mesh: a run of vertices [" + std::to_string(first) + ", " +
                          std::to_string(end) + ") or numbers that do not match the part's " +
                          std::to_string(n) + " vertices");
  if (section == MeshSection::kTriangles)
    for (const std::uint32_t i : m.indices)
      if (i >= n)
        throw InvalidArgument("mesh: index " + std::to_string(i) + " is past the last vertex");
  const auto number = [&](std::size_t index) {
    const std::uint32_t local = m.indices[index];
    return global.empty() ? local : global[local];
  };
  if (format == MeshFormat::kObj) return put_obj_lines(out, section, m, first, end, global);
  switch (section) {
    case MeshSection::kVertices:
      out.reserve(out.size() + (end - first) * (m.colors.empty() ? 24 : 27));
      for (std::size_t i = first; i < end; ++i) {
        put(out, m.positions[i]);
        put(out, m.normals[i]);
        if (!m.colors.empty()) put(out, m.colors[i]);
      }
      return;
    case MeshSection::kPositions:
    case MeshSection::kNormals: {
      const auto& values = section == MeshSection::kPositions ? m.positions : m.normals;
      const auto* p = reinterpret_cast<const std::uint8_t*>(values.data() + first);
      out.insert(out.end(), p, p + (end - first) * 12);
      return;
    }
    case MeshSection::kColors:
      out.reserve(out.size() + (end - first) * 8);
      for (std::size_t i = first; i < end; ++i) {
        for (std::size_t c = 0; c < 3; ++c) put(out, linear_u16(m.colors[i][c]));
        put(out, std::uint16_t{65535});
      }
      return;
    case MeshSection::kTriangles:
      if (format == MeshFormat::kStl) {
        out.reserve(out.size() + 50 * m.triangle_count());
        for (std::size_t t = 0; t < m.triangle_count(); ++t)
          put_facet(out, m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]],
                    m.positions[m.indices[3 * t + 2]]);
      } else {
        out.reserve(out.size() + m.indices.size() * (format == MeshFormat::kPly ? 13 : 12) / 3);
        for (std::size_t t = 0; t < m.triangle_count(); ++t) {
          if (format == MeshFormat::kPly) out.push_back(3);
          for (std::size_t k = 0; k < 3; ++k) put(out, number(3 * t + k));
        }
      }
      return;
  }
}

std::vector<std::uint8_t> encode_mesh(const Mesh& mesh, MeshFormat format) {
  if (mesh.normals.size() != mesh.positions.size() ||
      (!mesh.colors.empty() && mesh.colors.size() != mesh.positions.size()) ||
      mesh.indices.size() % 3 != 0)
    throw InvalidArgument("mesh: normals, colours and indices do not match the positions");
  for (const std::uint32_t i : mesh.indices)
    if (i >= mesh.positions.size())
      throw InvalidArgument("mesh: index " + std::to_string(i) + " is past the last vertex");
  const MeshTotals totals = mesh_totals(mesh);
  std::vector<std::uint8_t> out = encode_mesh_head(format, totals);
  for (const MeshSection s : mesh_file_sections(format, totals))
    encode_mesh_section(format, s, mesh, 0, mesh.vertex_count(), {}, out);
  return out;
}

void write_mesh(const Mesh& mesh, const std::filesystem::path& path) {
  write_file_atomic(path, encode_mesh(mesh, mesh_format_of(path)));
}

}  // namespace voxfield
