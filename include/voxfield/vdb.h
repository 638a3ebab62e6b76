// voxfield — OpenVDB files (.vdb), the common volume file of Houdini, Blender, Unreal and most
// tools that handle volumes (Museth, "VDB: High-resolution sparse volumes with dynamic topology",
// ACM TOG 2013). Written with OpenVDB 10 itself.
//
// Frames: VDB voxel (i, j, k) is voxfield voxel (i, j, k); the grid's transform is the world's
// frame (voxel_frame.h), mapping the index to the voxel's centre, origin + R * (voxel size ⊙
// ((i, j, k) + 1/2)) — so a .vdb lines up with the meshes of the same world (and with its
// renders and rays, placed in voxel coordinates, in the identity frame). In
// the identity frame that is (i, j, k) + 1/2 (a field's: ((i, j, k) + 1/2) ⊙ spacing). Reading
// takes the frame back from the transform (any rotation and positive scale per axis; a shear or
// mirror is reported and read in the identity frame).
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
//    box.begin + (i, j, k), the transform the world's frame, so it lies on the world's grid.
//  * An unsigned distance field: a Float grid of class "unknown" (not "fog volume": to every tool a
//    fog volume is a density, and a distance is not one), background as above.
// Fields carry voxfield's metric, clamp, storage and domain in their metadata.
//
// Reading: voxfield's own parser (vdb_read*.cpp), not OpenVDB's, whose reader aborts the process
// (std::terminate) or corrupts its heap on truncated files and so cannot be handed untrusted
// bytes (docs/interop.md). It reads OpenVDB file formats 222 to 225 (OpenVDB 3 to 12): Float,
// Double, Bool, Int32 and Vec3f grids of any node configuration, uncompressed, zip or Blosc,
// with active-mask compression and half floats, shared (instanced) trees, and the affine family
// of transforms; every count, size and offset is checked against the bytes and the memory limit.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/distance.h"
#include "voxfield/vectors.h"
#include "voxfield/world.h"

namespace voxfield {

// The bytes of a .vdb file holding `world` as an Int32 grid "materials", its transform the
// world's frame; `extent` (united with the content) is kept in the metadata. Throws
// InvalidArgument for an invalid frame.
std::vector<std::uint8_t> encode_vdb_world(const World& world, const Box3i& extent);
// The bytes of a .vdb file holding `field` as one Float grid named `grid_name`, in its frame's
// world units: a field in the identity frame with its spacing as the voxel size (its values
// as they are); a field in a frame whose spacing is k times smaller than the frame's voxel size on
// every axis with its values times k. Throws InvalidArgument for a spacing out of proportion with
// the frame's voxel size (no factor makes its distances world units), or a field with no finite
// non-zero distance to bound its background (an unclamped field of an empty world).
std::vector<std::uint8_t> encode_vdb_field(const DistanceField& field,
                                           const std::string& grid_name = "distance");

// A field's .vdb written in parts (voxfield-mpi: each rank holds a slab of the field). The grid's
// background is the whole field's: the clamp's level, or unclamped the largest finite |distance|
// of any part — the largest vdb_field_background over the parts (0 for a part with none; the
// field is refused if every part has none). Each part's grid is encode_vdb_field_part's bytes,
// and VdbFieldParts joins them into the bytes encode_vdb_field writes for the whole field. The
// parts must not overlap; a leaf split between parts is joined voxel by voxel.
double vdb_field_background(const DistanceField& field);
// The refusals encode_vdb_field gives a field of `options` in `frame` whatever its values — a clamp
// that leaves no band around a level set's surface, a spacing out of proportion with the frame's
// voxel size — given before the field is computed: InvalidArgument, its message starting with
// `name` (the output's). (A field of the same options over two voxels meets them, in
// microseconds: the same code decides, so the verdict is the same.)
void check_vdb_field_output(const DistanceOptions& options, const VoxelFrame& frame,
                            const std::string& name);
std::vector<std::uint8_t> encode_vdb_field_part(const DistanceField& part, double background,
                                                const Box3i& domain,
                                                const std::string& grid_name = "distance");
class VdbFieldParts {
 public:
  // Starts from the grid of `own` (one part), as encode_vdb_field_part builds it. Throws as
  // encode_vdb_field does.
  VdbFieldParts(const DistanceField& own, double background, const Box3i& domain,
                const std::string& grid_name = "distance");
  ~VdbFieldParts();
  VdbFieldParts(const VdbFieldParts&) = delete;
  VdbFieldParts& operator=(const VdbFieldParts&) = delete;
  // Moves another part's leaves and tiles in. `part`: encode_vdb_field_part's bytes, made by this
  // library (OpenVDB's own reader parses them, which must never see bytes from elsewhere);
  // InvalidArgument, naming `name`, for a grid of another background; ResourceLimitError, naming
  // it, when the joined grid and the part's would pass the memory limit (limits.h).
  void add(std::span<const std::uint8_t> part, const std::string& name);
  // The .vdb file of the whole field.
  std::vector<std::uint8_t> finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The bytes of a .vdb file holding a vector field's texture over `volume` as the grids "vectors"
// and "strength" (above; an rgba8 or rgba16f texture as it decodes). Throws InvalidArgument for
// an invalid volume or a texture of another resolution.
std::vector<std::uint8_t> encode_vdb_vectors(const VectorVolume& volume,
                                             const VectorTexture& texture);
// The bytes of a .vdb file holding a world's flow over `box` (WorldVectorField: the texture's
// resolution is the box's size) on the world's lattice in the world's `frame`, as
// encode_vdb_world places voxels; directions are carried into the frame. Throws InvalidArgument
// for a texture of another size or an invalid frame.
std::vector<std::uint8_t> encode_vdb_world_vectors(const Box3i& box, const VectorTexture& texture,
                                                   const VoxelFrame& frame = {});

// ---------------------------------------------------------------------------------------------
// Reading

enum class VdbValueType { kFloat, kDouble, kBool, kInt32, kVec3f };
const char* vdb_value_type_name(VdbValueType t);  // "float", "double", "bool", "int32", "vec3s"

// A metadata item: its OpenVDB type name ("string", "int32", "vec3i", "double"...), the text of
// a string, the numbers of a number or vector (bools as 0 / 1); unknown types keep neither.
struct VdbMetadata {
  std::string type;
  std::string text;
  std::vector<double> numbers;
};

// A constant region of the tree: a root tile or an internal node's value slot, an axis-aligned
// cube of `edge` voxels from `origin`. Slots holding the background inactive are not listed.
struct VdbTile {
  Vec3i origin;
  std::int32_t edge = 0;
  bool active = false;
  std::array<double, 3> value{};  // components beyond the grid's are 0
};

// A leaf: leaf_edge^3 voxels from `origin`, their values in the grid's leaf values from
// `first_value` (VdbGrid::leaf_value; components interleaved, x slowest then y then z, OpenVDB's
// order), their active flags as a bit mask in the same order.
struct VdbLeaf {
  Vec3i origin;
  std::size_t first_value = 0;
  std::vector<std::uint64_t> active_bits;
};

struct VdbGrid {
  std::string name;       // without OpenVDB's "\x1e" duplicate-name suffix
  std::string type_name;  // "Tree_float_5_4_3"...
  VdbValueType value_type = VdbValueType::kFloat;
  int components = 1;       // 3 for Vec3f
  bool half_float = false;  // stored as 16-bit halves (read back as floats)
  std::string grid_class;   // "level set", "fog volume", "staggered", "unknown"
  std::string instance_of;  // the grid whose tree this one shares, if any
  // Index space to world space: world = m * (i, j, k, 1), row-major 3 x 4.
  std::array<double, 12> index_to_world{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  std::array<double, 3> voxel_size{1, 1, 1};  // world units per index step along each axis
  std::map<std::string, VdbMetadata> metadata;
  std::array<double, 3> background{};
  std::vector<int> log2_dims;  // per level, root's children first; the last is the leaves'
  int leaf_edge = 8;
  std::vector<VdbTile> tiles;
  std::vector<VdbLeaf> leaves;
  // The leaves' values, components interleaved: as floats for float and vec3s grids — their
  // values are floats in the file (halves widen to floats exactly), so doubles would only double
  // the memory — and as doubles for double, int32 and bool grids. One of the two is used.
  std::vector<float> leaf_floats;
  std::vector<double> leaf_doubles;
  // Read with VdbReadOptions::clip: the clip box, and the bounds of the tiles and leaves that lay
  // wholly outside it and were dropped unread (what stored_bounds and active_bounds still count).
  // The kept tiles and leaves may reach past the clip; world_from_vdb places only what lies in it.
  std::optional<Box3i> clip;
  Box3i dropped_stored, dropped_active;
  bool leaves_hold_floats() const {
    return value_type == VdbValueType::kFloat || value_type == VdbValueType::kVec3f;
  }
  std::size_t leaf_value_bytes() const {
    return leaves_hold_floats() ? sizeof(float) : sizeof(double);
  }
  // f(leaf_floats) or f(leaf_doubles), whichever holds the values: the one place the width is
  // chosen, so a loop over many values inside f branches once, not per value.
  template <class F>
  decltype(auto) with_leaf_values(F&& f) const {
    return leaves_hold_floats() ? f(leaf_floats) : f(leaf_doubles);
  }
  template <class F>
  decltype(auto) with_leaf_values(F&& f) {
    return leaves_hold_floats() ? f(leaf_floats) : f(leaf_doubles);
  }
  // One value (a branch per call: loops over many go through with_leaf_values).
  double leaf_value(std::size_t i) const {
    return with_leaf_values([i](const auto& values) { return static_cast<double>(values[i]); });
  }

  bool leaf_active(const VdbLeaf& leaf, int i) const {
    return (leaf.active_bits[static_cast<std::size_t>(i) >> 6] >> (i & 63)) & 1u;
  }
  // The voxels the tree stores anything but the inactive background for (tiles and leaves), and
  // the active ones; empty boxes for an empty tree. A clipped read's dropped nodes included.
  Box3i stored_bounds() const;
  Box3i active_bounds() const;
  // Every value over `box`, x fastest (voxfield's order), `components` per voxel; the
  // background where the tree stores nothing. Throws ResourceLimitError past the memory limit.
  std::vector<double> dense(const Box3i& box, std::uint64_t memory_limit_bytes = 0) const;
  // Whether each voxel over `box` is active (1) or not (0), x fastest.
  std::vector<std::uint8_t> dense_active(const Box3i& box,
                                         std::uint64_t memory_limit_bytes = 0) const;
};

struct VdbFile {
  std::uint32_t format_version = 0;
  std::uint32_t library_major = 0, library_minor = 0;
  std::map<std::string, VdbMetadata> metadata;  // the file's own
  std::vector<VdbGrid> grids;
  // What the decoded file holds in memory (trees and metadata), as the memory limit counts it.
  std::uint64_t memory_bytes() const;
};

struct VdbReadOptions {
  std::uint64_t memory_limit_bytes = 0;  // 0: the process default (limits.h)
  // Keep only the tiles and leaves that overlap this box (an MPI rank's slab): the others are
  // dropped, their values skipped undecoded (their sizes still checked against the bytes; a
  // damaged block among them goes unseen), and not held: a dropped leaf is charged to the memory
  // limit for its mask alone. An empty box keeps nothing but the topology's bounds
  // (VdbGrid::dropped_stored), the metadata and the transforms. The clip applies to every grid.
  std::optional<Box3i> clip;
};

// Parses a .vdb file's bytes; `name` names it in errors. Throws FormatError (file, offset and
// cause) for anything malformed or unsupported, ResourceLimitError when the decoded trees would
// pass the memory limit.
VdbFile decode_vdb(std::span<const std::uint8_t> bytes, const std::string& name,
                   const VdbReadOptions& options = {});
// decode_vdb on a file's contents; IoError naming the path when it cannot be read.
VdbFile read_vdb(const std::filesystem::path& path, const VdbReadOptions& options = {});

// The world a .vdb file holds, from the grid named `grid_name` when one is given (InvalidArgument
// naming the file and listing its grids when it has none of that name), else from its first grid
// of voxfield's kind "world", else its first Int32 grid, else its first grid: Int32 grids give each
// active voxel its value as the material (values outside 0..255 are refused), Bool grids material 1
// where active and true, level sets material 1 inside (value < 0, active or not), other Float /
// Double grids material 1 where active and > 0 (a fog volume's density), Vec3f grids material 1
// where active and non-zero. A palette and extent written by voxfield come back from the metadata.
// Throws FormatError naming `name`, ResourceLimitError past the memory limit.
struct VdbWorld {
  World world;
  Box3i extent;             // voxfield's recorded extent united with the content (in the clip)
  Box3i stored;             // the grid's stored_bounds(): where content may lie, clip or not
  std::string description;  // one line: format, grid, type, class, voxel size
};
VdbWorld world_from_vdb(const VdbFile& file, const std::string& name, int chunk_edge,
                        std::uint64_t memory_limit_bytes = 0, const std::string& grid_name = "");

}  // namespace voxfield
