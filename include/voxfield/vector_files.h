// voxfield — vector-field files: the sources a `voxfield vectors` run reads, and the textures it
// writes for NumPy, Unreal (.fga) and Unity's VFX Graph (.vf). docs/vectors.md has the layouts.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "voxfield/npy.h"
#include "voxfield/vectors.h"

namespace voxfield {

// A sources file (JSON): {"sources": [{"position": [x, y, z], "previous": [x, y, z], "radius": r},
// ...]} for one generation, or {"frames": [{"sources": [...]}, ...]} for one step per frame.
// "previous" is optional (a stationary source). A JSON syntax error throws FormatError (the file,
// the byte offset, line and column); a value out of place throws InvalidArgument naming the file,
// the frame and the source. At most 2^20 sources in all; coordinates and radii within 1e12.
struct VectorSourceFrames {
  std::vector<std::vector<VectorSource>> frames;
  bool animated = false;  // written as {"frames": ...}
};
VectorSourceFrames parse_vector_sources(std::span<const std::uint8_t> bytes,
                                        const std::string& name);
VectorSourceFrames read_vector_sources(const std::filesystem::path& path);

// float32 a[i, j, k, c]: c = 0..2 the direction in world space, c = 3 the strength, decoded from
// the texture's storage.
NpyVolume vector_npy(const VectorTexture& texture);

// Unreal's vector-field text file: "nx,ny,nz," then the box's min and max corner (each value
// followed by a comma), then nx ny nz lines "vx,vy,vz," of direction x strength, x fastest, in the
// box's own frame (apply the volume's rotation to the actor). Unreal's importer takes at most 128
// per axis: InvalidArgument past that.
std::string encode_fga(const VectorVolume& volume, const VectorTexture& texture);

// Unity VFX Graph's vector field: "VF_V", three little-endian uint16 sizes, then float32 x, y, z
// of direction x strength per voxel, x fastest, in the box's own frame; 10 + 12 N bytes.
// InvalidArgument for an axis over 65535.
std::vector<std::uint8_t> encode_vf(const VectorVolume& volume, const VectorTexture& texture);

}  // namespace voxfield
