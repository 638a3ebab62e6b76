// voxfield — simplification and draw-order optimisation through meshoptimizer (mesh_optimize.h).
#include "voxfield/mesh_optimize.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "voxfield/error.h"

namespace voxfield {

namespace {

void check(const Mesh& m, const char* who) {
  if (m.normals.size() != m.positions.size() ||
      (!m.colors.empty() && m.colors.size() != m.positions.size()) || m.indices.size() % 3 != 0)
    throw InvalidArgument(std::string(who) +
                          ": normals, colours and indices do not match the positions");
  for (const std::uint32_t i : m.indices)
    if (i >= m.positions.size())
      throw InvalidArgument(std::string(who) + ": index past the last vertex");
}

// Keeps the vertices `indices` use, in first-use order (meshoptimizer's vertex fetch order), and
// renumbers the indices to match.
void compact(Mesh& m) {
  std::vector<unsigned int> remap(m.positions.size());
  const std::size_t kept = meshopt_optimizeVertexFetchRemap(remap.data(), m.indices.data(),
                                                            m.indices.size(), m.positions.size());
  meshopt_remapIndexBuffer(m.indices.data(), m.indices.data(), m.indices.size(), remap.data());
  auto apply = [&](auto& attribute) {
    using T = typename std::decay_t<decltype(attribute)>::value_type;
    if (attribute.empty()) return;
    std::vector<T> out(kept);
    meshopt_remapVertexBuffer(out.data(), attribute.data(), attribute.size(), sizeof(T),
                              remap.data());
    attribute = std::move(out);
  };
  apply(m.positions);
  apply(m.normals);
  apply(m.colors);
}

}  // namespace

Mesh simplify_mesh(const Mesh& mesh, const SimplifyOptions& options, SimplifyStats* stats) {
  check(mesh, "simplify_mesh");
  if (!(options.triangle_ratio >= 0 && options.triangle_ratio <= 1))
    throw InvalidArgument("simplify_mesh: the triangle ratio must be in [0, 1]");
  if (!(options.max_error_units >= 0) || !std::isfinite(options.max_error_units))
    throw InvalidArgument("simplify_mesh: the error limit must be finite and >= 0");
  Mesh out = mesh;
  const float* positions = mesh.positions.empty() ? nullptr : mesh.positions.front().data();
  // meshoptimizer measures error relative to the mesh's extent (meshopt_simplifyScale).
  const float scale =
      mesh.positions.empty() ? 1.0f : meshopt_simplifyScale(positions, mesh.positions.size(), 12);
  const double limit = options.max_error_units > 0 ? options.max_error_units : 0.01 * scale;
  const std::size_t target = static_cast<std::size_t>(static_cast<double>(mesh.triangle_count()) *
                                                      options.triangle_ratio) *
                             3;
  float error = 0;
  const std::size_t count =
      mesh.indices.empty()
          ? 0
          : meshopt_simplify(out.indices.data(), mesh.indices.data(), mesh.indices.size(),
                             positions, mesh.positions.size(), 12, target,
                             static_cast<float>(scale > 0 ? limit / scale : 0),
                             meshopt_SimplifyLockBorder, &error);
  out.indices.resize(count);
  compact(out);
  if (stats)
    *stats = {mesh.triangle_count(), out.triangle_count(), static_cast<double>(error) * scale};
  return out;
}

void optimize_mesh(Mesh& mesh) {
  check(mesh, "optimize_mesh");
  if (mesh.indices.empty()) return;
  meshopt_optimizeVertexCache(mesh.indices.data(), mesh.indices.data(), mesh.indices.size(),
                              mesh.positions.size());
  compact(mesh);
}

}  // namespace voxfield
