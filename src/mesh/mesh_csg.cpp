// voxfield — meshing CSG models. The lattice of samples comes from the voxel compiler's pruned
// voxelisation (its voxel centres are the lattice points); the meshers then find every crossing
// on the model itself (not by interpolating two samples) and read the model's gradient there and
// at every vertex instead of differencing samples: Ju et al.'s Hermite data as the paper
// intends, from the function itself. The gradient is taken by central differences of
// the whole tape with a step far below the lattice spacing (1e-6 of it): at smooth points that is
// the exact gradient to about 1e-6; at a crease it is the mean of the two faces' normals, where
// dual contouring's other crossings pin the vertex to the crease anyway.
#include <algorithm>
#include <cmath>

#include "voxfield/csg_compile.h"
#include "voxfield/csg_mesh.h"
#include "voxfield/parallel.h"

namespace voxfield {

Mesh mesh_csg(const csg::Model& model, const CsgMeshOptions& options) {
  if (!(options.voxel_size > 0) || !std::isfinite(options.voxel_size))
    throw InvalidArgument("mesh_csg: the voxel size must be a finite number > 0");
  const csg::Bounds box = csg::box_or_bounds(model, options.box);
  const double v = options.voxel_size;
  // Voxel centres of this box are the lattice points: one spacing beyond the box on every side.
  csg::VoxelizeOptions vo;
  vo.voxel_size = v;
  vo.box = csg::Bounds{box.lo - Vec3d{1.5, 1.5, 1.5} * v, box.hi + Vec3d{1.5, 1.5, 1.5} * v};
  vo.field = true;
  vo.memory_limit_bytes = options.memory_limit_bytes;
  vo.interrupter = options.mesh.interrupter;
  const csg::Voxelized samples = csg::voxelize(model, vo);
  ScalarVolume volume{samples.dims, samples.field.data()};
  for (int a = 0; a < 3; ++a) {
    volume.origin_units[static_cast<std::size_t>(a)] = vo.box->lo[a] + v / 2;
    volume.spacing_units[static_cast<std::size_t>(a)] = v;
  }
  MeshOptions mo = options.mesh;
  mo.iso = 0;
  mo.inside_above = false;
  const csg::Tape tape = csg::compile_tape(model, options.memory_limit_bytes);
  // The exact function through an octree of cells about 8 lattice spacings wide: each query runs
  // its cell's pruned tape, equal to the whole tape there bit for bit.
  std::optional<csg::Octree> tree;
  if (options.exact_gradients) {
    csg::OctreeOptions oo;
    const Vec3d extent = vo.box->hi - vo.box->lo, centre = (vo.box->lo + vo.box->hi) * 0.5;
    const double edge = std::max({extent.x, extent.y, extent.z});
    oo.depth = std::clamp(static_cast<int>(std::ceil(std::log2(edge / (8 * v)))), 0, 8);
    oo.box =
        csg::Bounds{centre - Vec3d{1, 1, 1} * (edge / 2), centre + Vec3d{1, 1, 1} * (edge / 2)};
    oo.interrupter = options.mesh.interrupter;
    tree = csg::build_octree(tape, model, oo);
    const csg::Octree* t = &*tree;
    mo.value = [t](const std::array<double, 3>& p) { return t->exact_value({p[0], p[1], p[2]}); };
    const double h = v * 1e-6;
    mo.gradient = [t, h](const std::array<double, 3>& p) -> std::array<double, 3> {
      std::array<double, 3> g{};
      for (int a = 0; a < 3; ++a) {
        Vec3d q{p[0], p[1], p[2]};
        q[a] += h;
        const double up = t->exact_value(q);
        q[a] -= 2 * h;
        g[static_cast<std::size_t>(a)] = (up - t->exact_value(q)) / (2 * h);
      }
      return g;
    };
  }
  Mesh mesh = mesh_volume(volume, mo);
  // Colours: the paint a little inside each vertex (against its outward normal).
  mesh.colors.resize(mesh.positions.size());
  parallel_for(mesh.positions.size(), 4096, [&](std::size_t begin, std::size_t end) {
    std::vector<Vec3d> pts(end - begin);
    std::vector<double> values(pts.size());
    std::vector<std::uint8_t> mats(pts.size());
    for (std::size_t i = begin; i < end; ++i) {
      const auto& p = mesh.positions[i];
      const auto& n = mesh.normals[i];
      pts[i - begin] = Vec3d{p[0], p[1], p[2]} - Vec3d{n[0], n[1], n[2]} * (0.25 * v);
    }
    csg::evaluate(tape, pts, values, mats);
    for (std::size_t i = begin; i < end; ++i) {
      const Rgba c = model.palette[mats[i - begin]];
      mesh.colors[i] = {c.r, c.g, c.b};
    }
  });
  return mesh;
}

}  // namespace voxfield
