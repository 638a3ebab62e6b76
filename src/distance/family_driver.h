// voxfield — running one of the dissertation's algorithms with a given dense solver (internal):
// the CPU's solvers, or the GPU backend's, share the problem set-up and the field assembly, so
// both produce fields the same way.
#pragma once

#include <functional>

#include "family/dense_problem.h"

namespace voxfield::detail {

using DenseSolver =
    std::function<DenseSolution(const DenseProblem&, const AlgorithmOptions&, AlgorithmStats&)>;

// compute_distance_field(world, options, algorithm, stats) with `solver` doing the dense work
// (called once per sign: to solids, then to air for signed fields). algorithm must not be kExact.
DistanceField compute_with_solver(const World& world, const DistanceOptions& options,
                                  const AlgorithmOptions& algorithm, AlgorithmStats* stats,
                                  const DenseSolver& solver);

}  // namespace voxfield::detail
