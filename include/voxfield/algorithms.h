// voxfield — the algorithm family of the reference dissertation (Fedor 2025, "Fast GPU generation
// of distance fields from a voxel grid"), implemented on the CPU and measured against the exact
// transform.
//
// Every algorithm returns a DistanceField like compute_distance_field() does (same options:
// metric, signed, clamp, storage; nearest sites where the algorithm knows them), so results can be
// written, rendered and compared the same way. Only `exact` is exact; the others are measured by
// compare_fields().
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "voxfield/distance.h"

namespace voxfield {

enum class Algorithm {
  kExact,         // separable exact transform (distance.h)
  kBrute,         // per voxel, minimum over all sites: O(voxels x sites), small inputs only
  kBruteChunked,  // per chunk, with a one-voxel padding treated as solid (the dissertation's
                  // choice)
  kFim,           // Fast Iterative Method (Jeong & Whitaker 2008) with an active list
  kJfaSeed,       // the dissertation's jump flooding: propagates distance values, 6 neighbours
  kJfa,           // jump flooding of nearest-site coordinates, 26 neighbours (Rong & Tan 2006)
  kJfa1,          // JFA+1: one more pass with step 1 (Rong & Tan 2007)
  kJfa2,          // JFA+2: two more passes with steps 2 and 1
  kHybrid,        // JFA, then FIM from the JFA values
  kLod,           // JFA everywhere, FIM only in the chunks that meet a focus box
};

const char* algorithm_name(Algorithm a);  // "exact", "brute", "brute-chunked", "fim", ...
Algorithm parse_algorithm(const std::string& name);  // throws InvalidArgument
std::vector<Algorithm> all_algorithms();

struct AlgorithmOptions {
  Algorithm algorithm = Algorithm::kExact;
  std::optional<Box3i> focus;  // kLod: where FIM runs (required for kLod)
  // kBrute refuses inputs whose voxels x sites exceed this (it would take hours).
  double brute_max_work = 2e10;
};

struct AlgorithmStats {
  double ms = 0;             // compute time, no I/O
  int passes = 0;            // jump-flooding passes, or chunks for brute-chunked
  int iterations = 0;        // FIM sweeps over the active list
  std::int64_t updates = 0;  // voxel updates (FIM), distance evaluations (brute, JFA)
};

// Computes a field with the chosen algorithm. Throws InvalidArgument for bad options (kLod
// without a focus box, spacing with a metric that has none, kBrute on too large an input).
DistanceField compute_distance_field(const World& world, const DistanceOptions& options,
                                     const AlgorithmOptions& algorithm,
                                     AlgorithmStats* stats = nullptr);

// Error of a field against the exact one, over the voxels of the exact field's domain.
struct FieldError {
  std::int64_t voxels = 0;  // compared voxels
  // Of which not sites: air voxels for unsigned fields (solid ones are 0 for every algorithm),
  // every voxel for signed fields. Percentages are of these.
  std::int64_t air_voxels = 0;
  std::int64_t wrong = 0;      // |approx - exact| > tolerance
  std::int64_t too_large = 0;  // approx > exact + tolerance: unsafe for a ray marcher
  std::int64_t too_small = 0;  // approx < exact - tolerance
  double max_over = 0;         // max(approx - exact), >= 0
  double max_under = 0;        // max(exact - approx), >= 0
  double percent_wrong() const {
    return air_voxels ? 100.0 * static_cast<double>(wrong) / static_cast<double>(air_voxels) : 0;
  }
  double percent_unsafe() const {
    return air_voxels ? 100.0 * static_cast<double>(too_large) / static_cast<double>(air_voxels)
                      : 0;
  }
};
// Tolerance: one fixed-point step for integer storage, 1e-4 relative for f32.
FieldError compare_fields(const DistanceField& approx, const DistanceField& exact,
                          const World& world);

}  // namespace voxfield
