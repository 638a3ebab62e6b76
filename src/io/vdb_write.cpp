// voxfield — writing .vdb files with OpenVDB 10 (Museth, "VDB: High-resolution sparse volumes with
// dynamic topology", ACM TOG 2013): worlds as Int32 material grids, signed distance fields as level
// sets, unsigned ones as scalar grids (voxfield/vdb.h says what each holds and why). Each chunk of
// voxfield's grids is written as it is stored: a uniform chunk becomes a tile (OpenVDB's fill makes
// tiles where the box aligns with its nodes), so memory follows the content, not its bounding box.
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <utility>
#include <variant>

#include "byte_streams.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/vdb.h"
#include "voxfield/world.h"

namespace voxfield {
namespace {

// openvdb::initialize() registers the grid and map types; idempotent and thread-safe, called
// before every write.
void ensure_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// The transform of a voxfield frame: VDB index (i, j, k) is voxel (i, j, k), whose centre is at
// voxel coordinates (i, j, k) + 1/2, so index to world is
//   world = origin + A * ((i, j, k) + 1/2),  A = R * diag(voxel size).
// OpenVDB's matrices act on row vectors: row a is the image of index axis a (column a of A), row 3
// the translation.
openvdb::math::Transform::Ptr frame_transform(const VoxelFrame& frame) {
  frame.validate("vdb: the frame");
  const std::array<double, 12> a = frame.world_from_vox_matrix();
  const Vec3d centre0 = frame.world_from_vox({0.5, 0.5, 0.5});
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  for (int c = 0; c < 3; ++c) {
    for (int axis = 0; axis < 3; ++axis) m[axis][c] = a[4 * c + axis];
    m[3][c] = centre0[c];
  }
  return openvdb::math::Transform::createLinearTransform(m);
}

// The frame a field is written in and the factor from its values to that frame's world units. A
// field in the identity frame is written with its spacing as the voxel size (its values are in
// those units already). A field in a frame needs its spacing in proportion to the frame's voxel
// size — k * spacing = voxel size on every axis — and its values are multiplied by k; otherwise
// its Euclidean distances were measured in other proportions than the world's and no factor turns
// them into world units.
std::pair<VoxelFrame, double> field_world_units(const DistanceField& field) {
  const std::array<double, 3>& spacing = field.options.spacing;
  if (field.frame.is_identity()) {
    VoxelFrame f;
    f.voxel_size_world = {spacing[0], spacing[1], spacing[2]};
    return {f, 1.0};
  }
  const Vec3d& size = field.frame.voxel_size_world;
  const double k = size.x / spacing[0];
  for (int a = 0; a < 3; ++a) {
    if (!(std::abs(size[a] - k * spacing[a]) <= 1e-12 * size[a])) {
      char text[96];
      std::snprintf(text, sizeof text, "(%.9g, %.9g, %.9g)", spacing[0], spacing[1], spacing[2]);
      throw InvalidArgument(
          std::string("vdb: the field was measured with spacing ") + text +
          " but its world's frame is " + describe(field.frame) +
          ": a level set needs distances in the world's units — a Euclidean field measured with "
          "the voxel size as its spacing (the CLI's --spacing); Manhattan and Chebyshev "
          "distances over anisotropic voxels have no value in world units");
    }
  }
  return {field.frame, k};
}

// Grid metadata voxfield writes (beside OpenVDB's own "file_bbox_min" and so on).
constexpr const char* kKind = "voxfield_kind";  // "world", "signed distance", "unsigned distance"
constexpr const char* kPalette = "voxfield_palette";           // 256 RGBA, 8 hex digits each
constexpr const char* kExtentMin = "voxfield_extent_min";      // Vec3i, inclusive
constexpr const char* kExtentMax = "voxfield_extent_max";      // Vec3i, inclusive
constexpr const char* kMetric = "voxfield_metric";             // "euclidean", ...
constexpr const char* kMaxDistance = "voxfield_max_distance";  // double, world units; 0: no clamp
constexpr const char* kStorage = "voxfield_storage";           // "u8", "u16", "f32"
// What was taken off |distance| (half a voxel for level sets, 0 for unsigned fields).
constexpr const char* kSurfaceOffset = "voxfield_surface_offset";
constexpr const char* kDomainMin = "voxfield_domain_min";  // Vec3i, inclusive
constexpr const char* kDomainMax = "voxfield_domain_max";  // Vec3i, inclusive
constexpr const char* kFirst = "voxfield_first";  // Vec3i: the VDB index of a texture's texel 0

openvdb::Coord coord(Vec3i p) {
  return openvdb::Coord(p.x, p.y, p.z);
}
openvdb::CoordBBox bbox(const Box3i& b) {  // half-open to OpenVDB's inclusive
  return openvdb::CoordBBox(coord(b.begin), coord(b.end - Vec3i::splat(1)));
}

std::vector<std::uint8_t> write_grids(const openvdb::GridCPtrVec& grids) {
  std::vector<std::uint8_t> bytes;
  detail::ByteSink sink(bytes);
  std::ostream out(&sink);
  // A failure to grow the bytes (std::bad_alloc from the sink) is the stream's badbit, rethrown
  // here rather than returned as a file cut short.
  out.exceptions(std::ios_base::badbit);
  openvdb::io::Stream(out).write(grids);
  return bytes;
}

std::string palette_text(const Palette& p) {
  std::string s;
  s.reserve(256 * 8);
  char hex[9];
  for (const Rgba& c : p) {
    std::snprintf(hex, sizeof hex, "%02x%02x%02x%02x", c.r, c.g, c.b, c.a);
    s += hex;
  }
  return s;
}

void insert_box(openvdb::GridBase& grid, const char* min_key, const char* max_key,
                const Box3i& box) {
  if (box.empty()) return;
  const Vec3i hi = box.end - Vec3i::splat(1);
  grid.insertMeta(min_key,
                  openvdb::Vec3IMetadata(openvdb::Vec3i(box.begin.x, box.begin.y, box.begin.z)));
  grid.insertMeta(max_key, openvdb::Vec3IMetadata(openvdb::Vec3i(hi.x, hi.y, hi.z)));
}

}  // namespace

std::vector<std::uint8_t> encode_vdb_world(const World& world, const Box3i& extent) {
  ensure_initialized();
  openvdb::Int32Grid::Ptr grid = openvdb::Int32Grid::create(0);
  grid->setName("materials");
  grid->setTransform(frame_transform(world.frame));
  const Grid<std::uint8_t>& g = world.voxels;
  auto access = grid->getAccessor();
  g.for_each_chunk([&](const ChunkView<std::uint8_t>& c) {
    const Box3i box = g.bounds() ? c.box.intersect(*g.bounds()) : c.box;
    if (box.empty()) return;
    if (c.uniform()) {
      if (c.uniform_value != 0) grid->tree().fill(bbox(box), c.uniform_value, /*active=*/true);
      return;
    }
    const int e = g.chunk_edge();
    for (int z = box.begin.z; z < box.end.z; ++z)
      for (int y = box.begin.y; y < box.end.y; ++y)
        for (int x = box.begin.x; x < box.end.x; ++x) {
          const std::uint8_t m = c.voxels[static_cast<std::size_t>(x - c.box.begin.x) +
                                          static_cast<std::size_t>(e) *
                                              (static_cast<std::size_t>(y - c.box.begin.y) +
                                               static_cast<std::size_t>(e) *
                                                   static_cast<std::size_t>(z - c.box.begin.z))];
          if (m != 0) access.setValueOn(openvdb::Coord(x, y, z), m);
        }
  });
  grid->tree().prune();
  grid->insertMeta(kKind, openvdb::StringMetadata("world"));
  grid->insertMeta(kPalette, openvdb::StringMetadata(palette_text(world.palette)));
  insert_box(*grid, kExtentMin, kExtentMax, extent.unite(g.content_bounds()));
  return write_grids({grid});
}

namespace {

// How encode_vdb_field turns a field's values into the grid's: the frame and world units it is
// written in, and the surface offset of a level set.
struct FieldLevels {
  const DistanceField& field;
  bool is_signed;
  double offset;  // taken off |distance|
  VoxelFrame frame;
  double k;  // world units per unit of the field's values

  explicit FieldLevels(const DistanceField& f)
      : field(f),
        is_signed(f.options.signed_distance),
        // voxfield's signed field is the distance between voxel centres of the two kinds, so it
        // steps from -1 to +1 voxel across the surface; a level set is the distance to the surface
        // itself, which lies midway (|gradient| = 1 there too, as OpenVDB's tools assume: its
        // volume measure read half the volume before this shift). Half a voxel comes off each
        // side; on anisotropic voxels, half the smallest edge (exact across faces normal to that
        // axis).
        offset(is_signed ? 0.5 * std::min({f.options.spacing[0], f.options.spacing[1],
                                           f.options.spacing[2]})
                         : 0.0) {
    // The grid's world units: its frame's, k per unit of the field's values.
    const std::pair<VoxelFrame, double> units = field_world_units(f);
    frame = units.first;
    k = units.second;
  }
  double level(double d) const { return k * (d > 0 ? d - offset : d < 0 ? d + offset : d); }

  // Visits every stored chunk of the field within its domain with the decoded values.
  template <class OnUniform, class OnVoxel>
  void for_each_value(OnUniform&& on_uniform, OnVoxel&& on_voxel) const {
    std::visit(
        [&](const auto& values) {
          const int e = values.chunk_edge();
          values.for_each_chunk([&](const auto& c) {
            const Box3i box = c.box.intersect(field.domain);
            if (box.empty()) return;
            if (c.uniform()) {
              on_uniform(box, field.encoding.decode(static_cast<double>(c.uniform_value)));
              return;
            }
            for (int z = box.begin.z; z < box.end.z; ++z)
              for (int y = box.begin.y; y < box.end.y; ++y)
                for (int x = box.begin.x; x < box.end.x; ++x) {
                  const auto stored =
                      c.voxels[static_cast<std::size_t>(x - c.box.begin.x) +
                               static_cast<std::size_t>(e) *
                                   (static_cast<std::size_t>(y - c.box.begin.y) +
                                    static_cast<std::size_t>(e) *
                                        static_cast<std::size_t>(z - c.box.begin.z))];
                  on_voxel(Vec3i{x, y, z}, field.encoding.decode(static_cast<double>(stored)));
                }
          });
        },
        field.values);
  }
};

// The grid of `field`'s values over its domain with the given background, pruned, named and
// described as a field over `domain` (the whole field's, when `field` is a part of it).
openvdb::FloatGrid::Ptr field_grid(const DistanceField& field, double background,
                                   const Box3i& domain, const std::string& grid_name) {
  const FieldLevels f(field);
  const DistanceOptions& o = field.options;
  if (!(background > 0))
    throw InvalidArgument(
        "vdb: the field has no finite non-zero distance (an empty world?): "
        "nothing bounds its grid's background");
  const auto bg = static_cast<float>(background);
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(bg);
  grid->setName(grid_name);
  grid->setTransform(frame_transform(f.frame));
  grid->setGridClass(f.is_signed ? openvdb::GRID_LEVEL_SET : openvdb::GRID_UNKNOWN);
  auto access = grid->getAccessor();
  // Active where |d| is below the background; beyond it, the outside is the background itself
  // and (level sets) the inside is -background, inactive. Non-finite values (no site in reach)
  // read as the background.
  const auto put_voxel = [&](Vec3i p, double distance) {
    const double d = f.level(distance);
    if (!std::isfinite(d) || d >= background) return;
    if (d <= -background) {
      access.setValueOff(coord(p), -bg);
      return;
    }
    access.setValueOn(coord(p), static_cast<float>(d));
  };
  const auto put_box = [&](const Box3i& box, double distance) {
    const double d = f.level(distance);
    if (!std::isfinite(d) || d >= background) return;
    if (d <= -background) {
      grid->tree().fill(bbox(box), -bg, /*active=*/false);
      return;
    }
    grid->tree().fill(bbox(box), static_cast<float>(d), /*active=*/true);
  };
  f.for_each_value(put_box, put_voxel);
  grid->tree().prune();
  grid->insertMeta(kKind,
                   openvdb::StringMetadata(f.is_signed ? "signed distance" : "unsigned distance"));
  grid->insertMeta(kMetric, openvdb::StringMetadata(metric_name(o.metric)));
  grid->insertMeta(kMaxDistance, openvdb::DoubleMetadata(f.k * o.max_distance));
  grid->insertMeta(kSurfaceOffset, openvdb::DoubleMetadata(f.k * f.offset));
  grid->insertMeta(kStorage, openvdb::StringMetadata(storage_name(o.storage)));
  insert_box(*grid, kDomainMin, kDomainMax, domain);
  return grid;
}

}  // namespace

double vdb_field_background(const DistanceField& field) {
  const FieldLevels f(field);
  const double clamp = field.options.max_distance;
  // The clamp as the field stores it — what voxels beyond it and outside the domain read, which
  // integer storage may have lowered to its range and rounded, and f32 rounded to a float — or,
  // unclamped, the largest finite |distance| of the field.
  const double stored_clamp = std::visit(
      [&](const auto& g) { return field.encoding.decode(static_cast<double>(g.background())); },
      field.values);
  if (clamp > 0) {
    const double background = f.level(stored_clamp);
    if (!(background > 0))
      throw InvalidArgument("vdb: a clamp of " + std::to_string(clamp) +
                            " leaves no band around the surface (the level set needs more than "
                            "half a voxel)");
    return background;
  }
  double background = 0;
  const auto widen = [&](double d) {
    if (std::isfinite(d)) background = std::max(background, std::abs(f.level(d)));
  };
  f.for_each_value([&](const Box3i&, double d) { widen(d); }, [&](Vec3i, double d) { widen(d); });
  return background;
}

void check_vdb_field_output(const DistanceOptions& options, const VoxelFrame& frame,
                            const std::string& name) {
  World probe;
  probe.voxels.set({0, 0, 0}, 1);
  DistanceOptions o = options;
  o.domain = Box3i{{0, 0, 0}, {2, 1, 1}};  // one solid voxel and one empty one
  o.nearest_sites = false;
  o.interrupter = nullptr;
  DistanceField field = compute_distance_field(probe, o);
  field.frame = frame;
  try {
    (void)vdb_field_background(field);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(name + ": " + e.what());
  }
}

std::vector<std::uint8_t> encode_vdb_field(const DistanceField& field,
                                           const std::string& grid_name) {
  ensure_initialized();
  return write_grids({field_grid(field, vdb_field_background(field), field.domain, grid_name)});
}

std::vector<std::uint8_t> encode_vdb_field_part(const DistanceField& part, double background,
                                                const Box3i& domain, const std::string& grid_name) {
  ensure_initialized();
  return write_grids({field_grid(part, background, domain, grid_name)});
}

struct VdbFieldParts::Impl {
  openvdb::FloatGrid::Ptr grid;
};

VdbFieldParts::VdbFieldParts(const DistanceField& own, double background, const Box3i& domain,
                             const std::string& grid_name)
    : impl_(std::make_unique<Impl>()) {
  ensure_initialized();
  impl_->grid = field_grid(own, background, domain, grid_name);
}

VdbFieldParts::~VdbFieldParts() = default;

void VdbFieldParts::add(std::span<const std::uint8_t> part, const std::string& name) {
  // The bytes are encode_vdb_field_part's, made by this library (OpenVDB's reader must not be
  // handed bytes from elsewhere: vdb_read.cpp).
  detail::ByteSource source(part);
  std::istream in(&source);
  // Read whole: delayed loading would copy the stream to a temporary file and leave the leaves'
  // values there, out of the tree's memory use (which is charged below).
  openvdb::io::Stream stream(in, /*delayLoad=*/false);
  const openvdb::GridPtrVecPtr grids = stream.getGrids();
  openvdb::FloatGrid::Ptr other = grids && grids->size() == 1
                                      ? openvdb::gridPtrCast<openvdb::FloatGrid>(grids->front())
                                      : nullptr;
  if (!other || other->background() != impl_->grid->background())
    throw InvalidArgument(name +
                          ": not a part of this field's grid (encode_vdb_field_part's, with "
                          "the same background)");
  openvdb::FloatTree& tree = impl_->grid->tree();
  // The joined tree is the whole field's: on the rank that joins it, it is charged to the memory
  // limit as the parts come in (the nodes of the part move; the bytes of the file come after).
  require_memory(add_sat(tree.memUsage(), other->tree().memUsage()), 0, "vdb",
                 "the grid joined from the field's parts, with " + name + ",");
  // The parts' regions do not overlap (slabs of one field), and a part writes only inside its
  // own: outside it every voxel is the background, inactive (field_grid). So a tile that is not
  // that lies wholly inside the part and moves as it is. (A node that reaches past its part holds
  // the background in its slots beyond it: those are not the part's, and would overwrite the
  // other parts' nodes there.)
  const float bg = other->background();
  auto it = other->tree().cbeginValueAll();
  it.setMaxDepth(openvdb::FloatTree::ValueAllCIter::LEAF_DEPTH - 1);  // tiles only
  for (; it; ++it)
    if (it.isValueOn() || *it != bg)
      tree.addTile(it.getLevel(), it.getCoord(), *it, it.isValueOn());
  // A part's grid holds -background inactive inside its solids and the background everywhere else
  // it does not hold a value (field_grid), but OpenVDB's reader may fill a leaf's inactive voxels
  // with other values (0 beyond the domain, in leaves that reach past it, was seen): they are set
  // back.
  for (auto leaf = other->tree().beginLeaf(); leaf; ++leaf)
    for (auto v = leaf->beginValueOff(); v; ++v)
      if (*v != -bg) v.setValue(bg);
  // Leaves move whole; one that another part already holds (slabs cut off a multiple of 8, as
  // partition_slabs does when the domain has fewer chunk layers than ranks) is joined voxel by
  // voxel: the incoming part's voxels are those it wrote, active or -background.
  std::vector<openvdb::FloatTree::LeafNodeType*> stolen;
  other->tree().stealNodes(stolen);
  std::vector<std::unique_ptr<openvdb::FloatTree::LeafNodeType>> leaves(stolen.begin(),
                                                                        stolen.end());
  for (auto& leaf : leaves) {
    openvdb::FloatTree::LeafNodeType* held = tree.probeLeaf(leaf->origin());
    if (!held) {
      tree.addLeaf(leaf.get());
      (void)leaf.release();  // the tree owns it now
      continue;
    }
    for (openvdb::Index i = 0; i < openvdb::FloatTree::LeafNodeType::SIZE; ++i) {
      const bool on = leaf->isValueOn(i);
      const float v = leaf->getValue(i);
      if (on || v != bg) {
        held->setValueOnly(i, v);
        held->setActiveState(i, on);
      }
    }
  }
}

std::vector<std::uint8_t> VdbFieldParts::finish() {
  impl_->grid->tree().prune();
  return write_grids({impl_->grid});
}

namespace {

// A vector texture as the grids "vectors" (direction x strength) and "strength", both zero in the
// background, active where the strength is above 0; texel (i, j, k) at VDB index first + (i, j, k).
// `voxel_frame`, when given, carries directions taken in voxel coordinates into the world: the
// displacement p - q a direction points along becomes R * (voxel size ⊙ (p - q)), so it turns
// (and, on anisotropic voxels, bends) with the frame. Strengths are fractions of a radius and stay.
std::vector<std::uint8_t> write_vectors(const VectorTexture& texture, Vec3i first,
                                        const openvdb::math::Transform::Ptr& transform,
                                        const VoxelFrame* voxel_frame = nullptr) {
  openvdb::Vec3fGrid::Ptr vectors = openvdb::Vec3fGrid::create(openvdb::Vec3f(0.f));
  openvdb::FloatGrid::Ptr strength = openvdb::FloatGrid::create(0.f);
  vectors->setName("vectors");
  strength->setName("strength");
  // The directions are world-space already: they do not transform with the grid.
  vectors->setVectorType(openvdb::VEC_INVARIANT);
  auto put_vector = vectors->getAccessor();
  auto put_strength = strength->getAccessor();
  const Vec3i n = texture.resolution();
  std::int64_t index = 0;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i, ++index) {
        VectorTexel t = texture.get(index);
        if (!(t.strength > 0)) continue;
        if (voxel_frame && !voxel_frame->is_identity()) {
          const Vec3d d = voxel_frame->world_direction({t.x, t.y, t.z});
          const double length = d.length();
          if (length > 0) {
            t.x = static_cast<float>(d.x / length);
            t.y = static_cast<float>(d.y / length);
            t.z = static_cast<float>(d.z / length);
          }
        }
        const openvdb::Coord at(first.x + i, first.y + j, first.z + k);
        put_vector.setValueOn(at,
                              openvdb::Vec3f(t.x * t.strength, t.y * t.strength, t.z * t.strength));
        put_strength.setValueOn(at, t.strength);
      }
  for (openvdb::GridBase* g : {static_cast<openvdb::GridBase*>(vectors.get()),
                               static_cast<openvdb::GridBase*>(strength.get())}) {
    g->setTransform(transform);
    g->insertMeta(kKind, openvdb::StringMetadata("vector field"));
    g->insertMeta(kStorage, openvdb::StringMetadata(vector_storage_name(texture.storage())));
    g->insertMeta(kFirst, openvdb::Vec3IMetadata(openvdb::Vec3i(first.x, first.y, first.z)));
  }
  vectors->tree().prune();
  strength->tree().prune();
  return write_grids({vectors, strength});
}

}  // namespace

std::vector<std::uint8_t> encode_vdb_vectors(const VectorVolume& volume,
                                             const VectorTexture& texture) {
  volume.validate();
  if (texture.resolution() != volume.resolution)
    throw InvalidArgument("vdb: the texture's resolution " + to_string(texture.resolution()) +
                          " is not the volume's " + to_string(volume.resolution));
  ensure_initialized();
  // Index (i, j, k) to world: centre + R * (((i, j, k) + 1/2) * voxel - size / 2), as
  // VectorVolume::voxel_centre. OpenVDB's matrices act on row vectors: row a is the image of
  // index axis a (column a of R times that axis' voxel edge), row 3 the translation.
  const Vec3d edge = volume.voxel_size();
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  for (int c = 0; c < 3; ++c) {
    const Vec3d& row = volume.rotation[static_cast<std::size_t>(c)];  // row c of R
    double t = volume.centre[c];
    for (int a = 0; a < 3; ++a) {
      m[a][c] = row[a] * edge[a];
      t += row[a] * (0.5 * edge[a] - 0.5 * volume.size[a]);
    }
    m[3][c] = t;
  }
  return write_vectors(texture, Vec3i::splat(0),
                       openvdb::math::Transform::createLinearTransform(m));
}

std::vector<std::uint8_t> encode_vdb_world_vectors(const Box3i& box, const VectorTexture& texture,
                                                   const VoxelFrame& frame) {
  if (texture.resolution() != box.size())
    throw InvalidArgument("vdb: the texture's resolution " + to_string(texture.resolution()) +
                          " is not the box's " + to_string(box.size()));
  ensure_initialized();
  return write_vectors(texture, box.begin, frame_transform(frame), &frame);
}

}  // namespace voxfield
