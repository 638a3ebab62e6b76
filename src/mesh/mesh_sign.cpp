// The sign of a mesh's distance field: which voxel centres have a generalized winding number of
// at least 1/2 (Jacobson et al. 2013; winding_number.cpp), without asking every voxel.
//
// Away from the surface the winding number is harmonic, so over a region the surface does not
// enter it takes its extremes on the region's boundary (the maximum principle); off a closed
// surface it is even constant, 0 or a whole number of turns. The voxels beyond the band (at least
// two voxels wide, so a region's cells keep more than a voxel from the surface) split into
// 6-connected regions; each region's boundary voxels (next to the band or to the box's faces) are
// asked, and when every one of them is within kRegionMargin of 0, or every one within it of 1, the
// whole region takes that side. The margin covers the hierarchy's error (under 0.07) and how far
// the value can move between a boundary voxel's centre and its cell's face that far from an open
// edge (about 0.07: a half-plane's 1 / (2 pi r) over half a voxel). Inside and outside of a closed
// mesh are decided this way, each from its skin of voxels; a region whose boundary is anything
// else — the opening of a hole, overlapping sheets — is asked voxel by voxel, as are the band's.
#include <algorithm>
#include <atomic>

#include "mesh_triangles.h"
#include "voxfield/interrupt.h"
#include "voxfield/parallel.h"

namespace voxfield::detail {
namespace {

constexpr double kRegionMargin = 0.1;
constexpr std::uint32_t kNoRegion = 0xFFFFFFFFu;

}  // namespace

std::vector<std::uint8_t> inside_voxels(const WindingNumber& winding, const Box3i& box,
                                        double voxel_size,
                                        const std::vector<std::uint8_t>& near_surface,
                                        Progress& progress) {
  const Vec3i size = box.size();
  const std::size_t count = near_surface.size();
  const std::size_t plane = static_cast<std::size_t>(size.x) * size.y;
  const VoxelCentres centres{box, voxel_size};
  const auto coords = [&](std::size_t i) {
    return Vec3i{static_cast<int>(i % size.x), static_cast<int>(i / size.x % size.y),
                 static_cast<int>(i / plane)};
  };
  std::vector<std::uint8_t> inside(count, 0);

  // Regions of voxels beyond the band, labelled by a breadth-first flood (serial: a few ns a
  // voxel), with their boundary voxels.
  std::vector<std::uint32_t> region(count, kNoRegion);
  std::vector<std::uint32_t> boundary, boundary_region, queue;
  std::uint32_t regions = 0;
  const int step[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (std::size_t seed = 0; seed < count; ++seed) {
    if (near_surface[seed] || region[seed] != kNoRegion) continue;
    region[seed] = regions;
    queue.assign(1, static_cast<std::uint32_t>(seed));
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::size_t i = queue[head];
      const Vec3i c = coords(i);
      bool on_boundary = false;
      for (const auto& s : step) {
        const Vec3i n{c.x + s[0], c.y + s[1], c.z + s[2]};
        if (n.x < 0 || n.y < 0 || n.z < 0 || n.x >= size.x || n.y >= size.y || n.z >= size.z) {
          on_boundary = true;
          continue;
        }
        const std::size_t j = (static_cast<std::size_t>(n.z) * size.y + n.y) * size.x + n.x;
        if (near_surface[j]) {
          on_boundary = true;
        } else if (region[j] == kNoRegion) {
          region[j] = regions;
          queue.push_back(static_cast<std::uint32_t>(j));
        }
      }
      if (on_boundary) {
        boundary.push_back(static_cast<std::uint32_t>(i));
        boundary_region.push_back(regions);
      }
    }
    ++regions;
  }

  // Each region's boundary, asked (the hierarchical value: the margin covers its error).
  std::vector<double> value(boundary.size());
  parallel_for(boundary.size(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const Vec3i c = coords(boundary[k]);
      value[k] = winding(centres.at(c.x, c.y, c.z));
    }
  });
  std::vector<double> lo(regions, 1e300), hi(regions, -1e300);
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    lo[boundary_region[k]] = std::min(lo[boundary_region[k]], value[k]);
    hi[boundary_region[k]] = std::max(hi[boundary_region[k]], value[k]);
  }
  // 0: outside, 1: inside, 2: ask every voxel.
  std::vector<std::uint8_t> verdict(regions, 2);
  for (std::uint32_t r = 0; r < regions; ++r) {
    if (hi[r] <= 0.5 - kRegionMargin)
      verdict[r] = 0;
    else if (lo[r] >= 0.5 + kRegionMargin)
      verdict[r] = 1;
  }

  parallel_for(static_cast<std::size_t>(size.z), 1, [&](std::size_t z0, std::size_t z1) {
    for (std::size_t z = z0; z < z1; ++z) {
      if (!progress.keep_going()) return;
      for (std::size_t i = z * plane; i < (z + 1) * plane; ++i) {
        const std::uint8_t v = near_surface[i] ? 2 : verdict[region[i]];
        if (v != 2) {
          inside[i] = v;
          continue;
        }
        const Vec3i c = coords(i);
        inside[i] = winding.inside(centres.at(c.x, c.y, c.z));
      }
      progress.advance();
    }
  });
  return inside;
}

}  // namespace voxfield::detail
