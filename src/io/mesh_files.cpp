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

std::vector<std::uint8_t> encode_ply(const Mesh& m) {
  const bool colours = !m.colors.empty();
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment written by voxfield\n"
    << "element vertex " << m.vertex_count() << "\n"
    << "property float x\nproperty float y\nproperty float z\n"
    << "property float nx\nproperty float ny\nproperty float nz\n";
  if (colours) h << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  h << "element face " << m.triangle_count()
    << "\nproperty list uchar uint vertex_indices\nend_header\n";
  std::vector<std::uint8_t> out;
  put_text(out, h.str());
  out.reserve(out.size() + m.vertex_count() * (colours ? 27 : 24) + m.triangle_count() * 13);
  for (std::size_t i = 0; i < m.vertex_count(); ++i) {
    put(out, m.positions[i]);
    put(out, m.normals[i]);
    if (colours) put(out, m.colors[i]);
  }
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    out.push_back(3);
    for (int k = 0; k < 3; ++k) put(out, m.indices[3 * t + static_cast<std::size_t>(k)]);
  }
  return out;
}

std::vector<std::uint8_t> encode_obj(const Mesh& m) {
  std::ostringstream os;
  os.precision(std::numeric_limits<float>::max_digits10);  // positions read back bit for bit
  os << "# written by voxfield: " << m.vertex_count() << " vertices, " << m.triangle_count()
     << " triangles\n";
  for (const auto& p : m.positions) os << "v " << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  for (const auto& n : m.normals) os << "vn " << n[0] << ' ' << n[1] << ' ' << n[2] << '\n';
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    os << 'f';
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t v = std::uint64_t{m.indices[3 * t + static_cast<std::size_t>(k)]} + 1;
      os << ' ' << v << "//" << v;
    }
    os << '\n';
  }
  std::vector<std::uint8_t> out;
  put_text(out, os.str());
  return out;
}

std::vector<std::uint8_t> encode_stl(const Mesh& m) {
  if (m.triangle_count() > std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument("STL: more triangles than a binary STL can count");
  std::vector<std::uint8_t> out(80, 0);
  const char title[] = "binary STL written by voxfield";
  std::memcpy(out.data(), title, sizeof(title) - 1);  // never "solid": readers take that for ASCII
  put(out, static_cast<std::uint32_t>(m.triangle_count()));
  out.reserve(out.size() + 50 * m.triangle_count());
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const auto& a = m.positions[m.indices[3 * t]];
    const auto& b = m.positions[m.indices[3 * t + 1]];
    const auto& c = m.positions[m.indices[3 * t + 2]];
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
  return out;
}

// glTF's COLOR_0 is linear; voxfield's palette colours are sRGB (IEC 61966-2-1's transfer curve).
std::uint16_t linear_u16(std::uint8_t srgb) {
  const double c = srgb / 255.0;
  const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  return static_cast<std::uint16_t>(std::lround(linear * 65535));
}

std::vector<std::uint8_t> encode_glb(const Mesh& m) {
  using nlohmann::json;
  if (m.indices.empty()) {
    // glTF gives accessors, buffer views and buffers a minimum length of one: an empty mesh is
    // a scene with one node and nothing in it.
    const json empty = {{"asset", {{"version", "2.0"}, {"generator", "voxfield"}}},
                        {"scene", 0},
                        {"scenes", json::array({{{"nodes", json::array({0})}}})},
                        {"nodes", json::array({json::object()})}};
    std::string text = empty.dump();
    while (text.size() % 4) text.push_back(' ');
    std::vector<std::uint8_t> out;
    put(out, std::uint32_t{0x46546C67});
    put(out, std::uint32_t{2});
    put(out, static_cast<std::uint32_t>(12 + 8 + text.size()));
    put(out, static_cast<std::uint32_t>(text.size()));
    put(out, std::uint32_t{0x4E4F534A});
    put_text(out, text);
    return out;
  }
  // One buffer: positions, normals, colours (linear RGBA as normalised 16-bit: vertex attributes
  // are 4-byte aligned, and 8 bits would band dark linear values), indices; each view starts on
  // a 4-byte boundary.
  std::vector<std::uint8_t> bin;
  auto view = [&](const void* data, std::size_t bytes, json target) {
    const std::size_t offset = bin.size();
    const auto* p = static_cast<const std::uint8_t*>(data);
    bin.insert(bin.end(), p, p + bytes);
    while (bin.size() % 4) bin.push_back(0);
    return json{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}};
  };
  constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963, kFloat = 5126,
                kUnsignedShort = 5123, kUnsignedInt = 5125;
  std::array<float, 3> lo{0, 0, 0}, hi{0, 0, 0};
  if (!m.positions.empty()) {
    lo = hi = m.positions[0];
    for (const auto& p : m.positions)
      for (std::size_t a = 0; a < 3; ++a)
        lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  }
  json views = json::array(), accessors = json::array(), attributes = json::object();
  const std::size_t n = m.vertex_count();
  views.push_back(view(m.positions.data(), n * 12, kArrayBuffer));
  accessors.push_back({{"bufferView", 0},
                       {"componentType", kFloat},
                       {"count", n},
                       {"type", "VEC3"},
                       {"min", lo},
                       {"max", hi}});
  attributes["POSITION"] = 0;
  views.push_back(view(m.normals.data(), n * 12, kArrayBuffer));
  accessors.push_back(
      {{"bufferView", 1}, {"componentType", kFloat}, {"count", n}, {"type", "VEC3"}});
  attributes["NORMAL"] = 1;
  if (!m.colors.empty()) {
    std::vector<std::uint16_t> rgba(4 * n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t c = 0; c < 3; ++c) rgba[4 * i + c] = linear_u16(m.colors[i][c]);
      rgba[4 * i + 3] = 65535;
    }
    views.push_back(view(rgba.data(), rgba.size() * 2, kArrayBuffer));
    accessors.push_back({{"bufferView", views.size() - 1},
                         {"componentType", kUnsignedShort},
                         {"normalized", true},
                         {"count", n},
                         {"type", "VEC4"}});
    attributes["COLOR_0"] = accessors.size() - 1;
  }
  views.push_back(view(m.indices.data(), m.indices.size() * 4, kElementArrayBuffer));
  accessors.push_back({{"bufferView", views.size() - 1},
                       {"componentType", kUnsignedInt},
                       {"count", m.indices.size()},
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
      {"buffers", json::array({{{"byteLength", bin.size()}}})},
  };
  std::string text = doc.dump();
  while (text.size() % 4) text.push_back(' ');
  const std::uint64_t total = 12 + 8 + text.size() + 8 + bin.size();
  if (total > std::numeric_limits<std::uint32_t>::max())
    throw InvalidArgument("glTF: the mesh passes the 4 GiB a .glb can hold");
  std::vector<std::uint8_t> out;
  out.reserve(total);
  put(out, std::uint32_t{0x46546C67});  // "glTF"
  put(out, std::uint32_t{2});
  put(out, static_cast<std::uint32_t>(total));
  put(out, static_cast<std::uint32_t>(text.size()));
  put(out, std::uint32_t{0x4E4F534A});  // "JSON"
  put_text(out, text);
  put(out, static_cast<std::uint32_t>(bin.size()));
  put(out, std::uint32_t{0x004E4942});  // "BIN\0"
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
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
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".ply") return MeshFormat::kPly;
  if (ext == ".obj") return MeshFormat::kObj;
  if (ext == ".stl") return MeshFormat::kStl;
  if (ext == ".glb") return MeshFormat::kGlb;
  throw InvalidArgument(path.string() + ": unknown mesh format '" + ext +
                        "' (expected .ply, .obj, .stl or .glb)");
}

std::vector<std::uint8_t> encode_mesh(const Mesh& mesh, MeshFormat format) {
  if (mesh.normals.size() != mesh.positions.size() ||
      (!mesh.colors.empty() && mesh.colors.size() != mesh.positions.size()) ||
      mesh.indices.size() % 3 != 0)
    throw InvalidArgument("mesh: normals, colours and indices do not match the positions");
  for (const std::uint32_t i : mesh.indices)
    if (i >= mesh.positions.size())
      throw InvalidArgument("mesh: index " + std::to_string(i) + " is past the last vertex");
  switch (format) {
    case MeshFormat::kPly:
      return encode_ply(mesh);
    case MeshFormat::kObj:
      return encode_obj(mesh);
    case MeshFormat::kStl:
      return encode_stl(mesh);
    case MeshFormat::kGlb:
      return encode_glb(mesh);
  }
  throw InvalidArgument("mesh: unknown format");
}

void write_mesh(const Mesh& mesh, const std::filesystem::path& path) {
  write_file_atomic(path, encode_mesh(mesh, mesh_format_of(path)));
}

}  // namespace voxfield
