// voxfield — generated scenes: terrain with caves and towers, and random spheres.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "noise.h"
#include "voxfield/scene.h"

namespace voxfield {
namespace {

using detail::fbm2;
using detail::fbm3;
using detail::hash3;
using detail::unit;

enum Material : std::uint8_t {
  kAir = 0,
  kGrass = 1,
  kDirt = 2,
  kStone = 3,
  kSand = 4,
  kBrick = 5,
  kRoof = 6,
  kSnow = 7,
  kMoss = 8,
};

void set_terrain_palette(Palette& p) {
  p[kGrass] = {92, 156, 64, 255};
  p[kDirt] = {122, 88, 58, 255};
  p[kStone] = {124, 124, 130, 255};
  p[kSand] = {214, 196, 140, 255};
  p[kBrick] = {168, 74, 52, 255};
  p[kRoof] = {62, 66, 96, 255};
  p[kSnow] = {236, 238, 244, 255};
  p[kMoss] = {70, 110, 62, 255};
}

void require_size(const SceneOptions& o) {
  for (int k = 0; k < 3; ++k) {
    if (o.size[k] < 1 || o.size[k] > (1 << 16)) {
      throw InvalidArgument("scene size " + to_string(o.size) + " must be 1..65536 on every axis");
    }
  }
  // Generation fills every chunk before collapsing the uniform ones: refuse sizes that cannot fit
  // in this machine's memory, instead of running into the out-of-memory killer.
  const double bytes = static_cast<double>(Box3i::from_size(o.size).volume());
  const double physical =
      static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  if (physical > 0 && bytes > physical) {
    throw InvalidArgument("scene size " + to_string(o.size) + " needs " +
                          std::to_string(bytes / 1e9) + " GB while generating; this machine has " +
                          std::to_string(physical / 1e9) + " GB");
  }
}

// All chunks covering [0, size).
std::vector<Vec3i> chunks_of(const World& w, Vec3i size) {
  std::vector<Vec3i> out;
  const Vec3i hi = w.voxels.chunk_of(size - Vec3i::splat(1));
  for (int z = 0; z <= hi.z; ++z)
    for (int y = 0; y <= hi.y; ++y)
      for (int x = 0; x <= hi.x; ++x) out.push_back({x, y, z});
  return out;
}

struct Tower {
  bool present = false;
  int cx = 0, cy = 0;     // centre column
  int half = 0;           // half width: walls at |dx| == half or |dy| == half
  int base = 0, top = 0;  // wall z range [base, top)
};

class Terrain {
 public:
  explicit Terrain(const SceneOptions& o)
      : o_(o), horizontal_(std::max(o.size.x, o.size.y)), cell_(std::max(32, horizontal_ / 6)) {}

  // Surface height (first air voxel above ground) of column (x, y).
  int height(int x, int y) const {
    const double f = 3.0 / horizontal_;
    const double n = fbm2(o_.seed, x * f, y * f, 5);
    return static_cast<int>(std::lround(o_.size.z * std::clamp(0.52 + 0.75 * n, 0.08, 0.92)));
  }
  int water_level() const { return static_cast<int>(o_.size.z * 0.36); }

  Tower tower_of_cell(int gx, int gy) const {
    Tower t;
    const std::uint64_t h = hash3(o_.seed ^ 0x70E7ull, gx, gy, 0);
    if (unit(h) < 0.45) return t;
    const int scale = std::max(1, cell_ / 32);
    t.half = (3 + static_cast<int>(unit(hash3(h, 1, 0, 0)) * 4)) * scale;
    const int margin = t.half + 2;
    const int span = cell_ - 2 * margin;
    if (span <= 0) return t;
    t.cx = gx * cell_ + margin + static_cast<int>(unit(hash3(h, 2, 0, 0)) * span);
    t.cy = gy * cell_ + margin + static_cast<int>(unit(hash3(h, 3, 0, 0)) * span);
    if (t.cx >= o_.size.x || t.cy >= o_.size.y) return t;
    const int ground = height(t.cx, t.cy);
    if (ground <= water_level()) return t;  // no towers in the water
    t.base = ground - 2;
    t.top = ground + (8 + static_cast<int>(unit(hash3(h, 4, 0, 0)) * 14)) * scale;
    t.present = true;
    return t;
  }

  // Material of voxel (x, y, z) given its column's height and tower.
  std::uint8_t material(int x, int y, int z, int h, const Tower& t) const {
    if (t.present) {
      const int dx = std::abs(x - t.cx), dy = std::abs(y - t.cy);
      const int ring = std::max(dx, dy);
      if (ring <= t.half && z >= t.base) {
        if (z < t.top) {
          const bool wall = ring == t.half;
          const bool door = dy == t.half && dx <= 1 && z < t.base + 5 && y > t.cy;
          const bool window = wall && (z - t.base) % 6 == 4 && (dx == 0 || dy == 0);
          if (wall && !door && !window) return kBrick;
          return z == t.base ? kStone : kAir;  // hollow inside, stone floor
        }
        // Pyramid roof: one step in per voxel up.
        if (ring <= t.half - (z - t.top) + 1) return kRoof;
        return kAir;
      }
    }
    if (z >= h) return kAir;
    // Caves: thin sheets where a 3-D noise crosses zero, kept below the surface crust.
    if (z > 1 && z < h - 4) {
      const double f = 4.0 / horizontal_;
      const double n = fbm3(o_.seed ^ 0xCA7Eull, x * f, y * f, z * f * 1.6, 3);
      if (std::abs(n) < 0.03) return kAir;
      if (std::abs(n) < 0.036) return kMoss;  // cave walls
    }
    const int depth = h - 1 - z;
    if (h <= water_level() + 1) return depth < 3 ? kSand : kStone;
    if (depth == 0) return h > o_.size.z * 0.70 ? kSnow : kGrass;
    if (depth < 4) return kDirt;
    return kStone;
  }

  int cell() const { return cell_; }

 private:
  SceneOptions o_;
  int horizontal_;
  int cell_;
};

}  // namespace

World make_terrain(const SceneOptions& o, Interrupter* interrupter) {
  require_size(o);
  World world(o.chunk_edge, Box3i::from_size(o.size));
  set_terrain_palette(world.palette);
  const Terrain terrain(o);
  const int e = o.chunk_edge;
  const std::vector<Vec3i> chunks = chunks_of(world, o.size);
  Progress progress(interrupter, "terrain scene", static_cast<std::int64_t>(chunks.size()));
  world.voxels.generate_chunks(chunks, [&](Vec3i c, std::uint8_t* out) {
    if (!progress.advance()) {  // cancelled: the world is discarded, any content will do
      std::fill(out, out + static_cast<std::size_t>(e) * e * e, kAir);
      return;
    }
    const Vec3i lo{c.x * e, c.y * e, c.z * e};
    for (int y = 0; y < e; ++y)
      for (int x = 0; x < e; ++x) {
        const int wx = lo.x + x, wy = lo.y + y;
        const int h = terrain.height(wx, wy);
        const Tower t = terrain.tower_of_cell(wx / terrain.cell(), wy / terrain.cell());
        for (int z = 0; z < e; ++z) {
          out[(static_cast<std::size_t>(z) * e + y) * e + x] =
              terrain.material(wx, wy, lo.z + z, h, t);
        }
      }
  });
  progress.throw_if_cancelled();
  return world;
}

World make_spheres(const SceneOptions& o, double solid_fraction, Interrupter* interrupter) {
  require_size(o);
  if (!(solid_fraction > 0 && solid_fraction < 1)) {
    throw InvalidArgument("solid fraction must be in (0, 1), got " +
                          std::to_string(solid_fraction));
  }
  struct Sphere {
    int cx, cy, cz, r;
    std::uint8_t material;
  };
  std::vector<Sphere> spheres;
  const double target = solid_fraction * static_cast<double>(Box3i::from_size(o.size).volume());
  const int min_edge = std::min({o.size.x, o.size.y, o.size.z});
  const int r_min = std::max(1, min_edge / 40), r_max = std::max(r_min, min_edge / 10);
  double covered = 0;
  for (std::uint64_t i = 0; covered < target && i < 1000000; ++i) {
    const std::uint64_t h = hash3(o.seed ^ 0x5FE7Eull, static_cast<std::int64_t>(i), 0, 0);
    Sphere s;
    s.r = r_min + static_cast<int>(unit(hash3(h, 0, 0, 0)) * (r_max - r_min + 1));
    s.cx = static_cast<int>(unit(hash3(h, 1, 0, 0)) * o.size.x);
    s.cy = static_cast<int>(unit(hash3(h, 2, 0, 0)) * o.size.y);
    s.cz = static_cast<int>(unit(hash3(h, 3, 0, 0)) * o.size.z);
    s.material = static_cast<std::uint8_t>(1 + (h >> 56) % 8);
    spheres.push_back(s);
    covered += 4.0 / 3.0 * 3.14159265358979 * s.r * s.r * s.r;
  }
  World world(o.chunk_edge, Box3i::from_size(o.size));
  set_terrain_palette(world.palette);
  const int e = o.chunk_edge;
  const std::vector<Vec3i> chunks = chunks_of(world, o.size);
  Progress progress(interrupter, "spheres scene", static_cast<std::int64_t>(chunks.size()));
  world.voxels.generate_chunks(chunks, [&](Vec3i c, std::uint8_t* out) {
    const Box3i box = world.voxels.chunk_box(c);
    std::fill(out, out + static_cast<std::size_t>(e) * e * e, kAir);
    if (!progress.advance()) return;  // cancelled: the world is discarded
    for (const Sphere& s : spheres) {
      const Box3i sb = Box3i::from_inclusive({s.cx - s.r, s.cy - s.r, s.cz - s.r},
                                             {s.cx + s.r, s.cy + s.r, s.cz + s.r});
      const Box3i part = sb.intersect(box);
      if (part.empty()) continue;
      const std::int64_t r2 = std::int64_t{s.r} * s.r;
      for (int z = part.begin.z; z < part.end.z; ++z)
        for (int y = part.begin.y; y < part.end.y; ++y)
          for (int x = part.begin.x; x < part.end.x; ++x) {
            const std::int64_t dx = x - s.cx, dy = y - s.cy, dz = z - s.cz;
            if (dx * dx + dy * dy + dz * dz <= r2) {
              out[(static_cast<std::size_t>(z - box.begin.z) * e + (y - box.begin.y)) * e +
                  (x - box.begin.x)] = s.material;
            }
          }
    }
  });
  progress.throw_if_cancelled();
  return world;
}

World make_scene(std::string_view name, const SceneOptions& options, Interrupter* interrupter) {
  if (name == "terrain") return make_terrain(options, interrupter);
  if (name == "spheres") return make_spheres(options, 0.10, interrupter);
  throw InvalidArgument("unknown scene \"" + std::string(name) + "\" (known: terrain, spheres)");
}

}  // namespace voxfield
