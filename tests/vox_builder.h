// Test helper: builds .vox byte streams chunk by chunk, so that tests can make exactly the
// malformed or unusual files they need.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace voxfield::test {

using Bytes = std::vector<std::uint8_t>;

inline void put32(Bytes& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
inline void put_string(Bytes& b, const std::string& s) {
  put32(b, static_cast<std::uint32_t>(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}
inline void put_dict(Bytes& b, const std::vector<std::pair<std::string, std::string>>& d) {
  put32(b, static_cast<std::uint32_t>(d.size()));
  for (const auto& [k, v] : d) {
    put_string(b, k);
    put_string(b, v);
  }
}
inline Bytes chunk(const char id[4], const Bytes& content, const Bytes& children = {}) {
  Bytes b(id, id + 4);
  put32(b, static_cast<std::uint32_t>(content.size()));
  put32(b, static_cast<std::uint32_t>(children.size()));
  b.insert(b.end(), content.begin(), content.end());
  b.insert(b.end(), children.begin(), children.end());
  return b;
}
inline Bytes size_chunk(int x, int y, int z) {
  Bytes c;
  put32(c, static_cast<std::uint32_t>(x));
  put32(c, static_cast<std::uint32_t>(y));
  put32(c, static_cast<std::uint32_t>(z));
  return chunk("SIZE", c);
}
struct V {
  int x, y, z, c;
};
inline Bytes xyzi_chunk(const std::vector<V>& voxels) {
  Bytes c;
  put32(c, static_cast<std::uint32_t>(voxels.size()));
  for (const V& v : voxels) {
    c.push_back(static_cast<std::uint8_t>(v.x));
    c.push_back(static_cast<std::uint8_t>(v.y));
    c.push_back(static_cast<std::uint8_t>(v.z));
    c.push_back(static_cast<std::uint8_t>(v.c));
  }
  return chunk("XYZI", c);
}
inline Bytes transform_chunk(
    int id, int child, int layer, const std::vector<std::pair<std::string, std::string>>& frame,
    const std::vector<std::pair<std::string, std::string>>& attributes = {}) {
  Bytes c;
  put32(c, static_cast<std::uint32_t>(id));
  put_dict(c, attributes);
  put32(c, static_cast<std::uint32_t>(child));
  put32(c, 0xFFFFFFFFu);
  put32(c, static_cast<std::uint32_t>(layer));
  put32(c, 1);
  put_dict(c, frame);
  return chunk("nTRN", c);
}
inline Bytes group_chunk(int id, const std::vector<int>& children) {
  Bytes c;
  put32(c, static_cast<std::uint32_t>(id));
  put_dict(c, {});
  put32(c, static_cast<std::uint32_t>(children.size()));
  for (int ch : children) put32(c, static_cast<std::uint32_t>(ch));
  return chunk("nGRP", c);
}
inline Bytes shape_chunk(int id, int model) {
  Bytes c;
  put32(c, static_cast<std::uint32_t>(id));
  put_dict(c, {});
  put32(c, 1);
  put32(c, static_cast<std::uint32_t>(model));
  put_dict(c, {});
  return chunk("nSHP", c);
}
inline Bytes layer_chunk(int id, bool hidden) {
  Bytes c;
  put32(c, static_cast<std::uint32_t>(id));
  if (hidden) {
    put_dict(c, {{"_hidden", "1"}});
  } else {
    put_dict(c, {});
  }
  put32(c, 0xFFFFFFFFu);
  return chunk("LAYR", c);
}
// "VOX " + version + MAIN holding `children`.
inline Bytes vox_file(const std::vector<Bytes>& children, int version = 150) {
  Bytes all;
  for (const auto& c : children) all.insert(all.end(), c.begin(), c.end());
  Bytes b{'V', 'O', 'X', ' '};
  put32(b, static_cast<std::uint32_t>(version));
  Bytes main = chunk("MAIN", {}, all);
  b.insert(b.end(), main.begin(), main.end());
  return b;
}

}  // namespace voxfield::test
