// voxfield — OpenVDB files (.vdb), the common volume file of Houdini, Blender, Unreal and most
// tools that handle volumes (Museth, "VDB: High-resolution sparse volumes with dynamic topology",
// ACM TOG 2013). Written with OpenVDB 10 itself.
//
// Frames: VDB voxel (i, j, k) is voxfield voxel (i, j, k); the grid's transform maps it to world
// units, its centre at (i, j, k) * voxel size (a field's spacing; 1 for worlds unless given).
//  * A world: an Int32 grid "materials" (0 = air, the background; solid voxels active with their
//    material), its palette and extent in the grid's metadata.
//  * A signed distance field: a Float grid of class level set — the distance to the surface
//    midway between solid and air voxel centres, so voxfield's |distance| less half a voxel (half
//    the smallest edge on anisotropic voxels): negative inside, |gradient| 1 as OpenVDB's tools
//    assume. Background: the clamp less that half voxel (or, unclamped, the largest value);
//    active where |value| < background, the inactive inside at -background (a closed level set).
//  * A vector field (vectors.h): a Vec3f grid "vectors" holding direction x strength (world-space
//    vectors, vector type invariant) and a Float grid "strength", both zero in the background and
//    active where the strength is above 0. A volume's field: texel (i, j, k) at VDB index (i, j,
//    k), the transform mapping it to the volume's voxel centre, rotation included. A world's flow
//    (vector_world.h): on the world's own lattice, texel (i, j, k) of the box at VDB voxel
//    box.begin + (i, j, k), the transform a world's (unit scale), so it lies on the world's grid.
//  * An unsigned distance field: a Float grid of class "unknown" (not "fog volume": to every tool a
//    fog volume is a density, and a distance is not one), background as above.
// Fields carry voxfield's metric, clamp, storage and domain in their metadata.
//
// Reading .vdb files is not offered: OpenVDB 10's reader aborts the process (std::terminate) or
// corrupts its heap on truncated files, so it cannot be handed untrusted bytes; docs/interop.md.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/distance.h"
#include "voxfield/vectors.h"
#include "voxfield/world.h"

namespace voxfield {

// The bytes of a .vdb file holding `world` as an Int32 grid "materials" with voxel size
// `voxel_size_units`; `extent` (united with the content) is kept in the metadata. Throws
// InvalidArgument for a voxel size that is not finite and > 0.
std::vector<std::uint8_t> encode_vdb_world(const World& world, const Box3i& extent,
                                           std::array<double, 3> voxel_size_units = {1, 1, 1});
// The bytes of a .vdb file holding `field` as one Float grid named `grid_name` (its voxel size:
// the field's spacing). Throws InvalidArgument for a field with no finite non-zero distance to
// bound its background (an unclamped field of an empty world).
std::vector<std::uint8_t> encode_vdb_field(const DistanceField& field,
                                           const std::string& grid_name = "distance");

// The bytes of a .vdb file holding a vector field's texture over `volume` as the grids "vectors"
// and "strength" (above; an rgba8 or rgba16f texture as it decodes). Throws InvalidArgument for
// an invalid volume or a texture of another resolution.
std::vector<std::uint8_t> encode_vdb_vectors(const VectorVolume& volume,
                                             const VectorTexture& texture);
// The bytes of a .vdb file holding a world's flow over `box` (WorldVectorField: the texture's
// resolution is the box's size) on the world's lattice, as encode_vdb_world places voxels.
// Throws InvalidArgument for a texture of another size.
std::vector<std::uint8_t> encode_vdb_world_vectors(const Box3i& box, const VectorTexture& texture);

}  // namespace voxfield
