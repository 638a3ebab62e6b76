// voxfield shaders — a world resident on the device (src/distance/gpu/resident_world.h): one page
// table over the chunks of a box and one brick pool of the chunks stored voxel by voxel. Every
// shader that reads a world reads it through this file. Include it after declaring the field's
// Header as `h`, the page table as `pages[]` (uints) and the brick pool, which can outgrow one
// binding, as split_buffer.glsl's windows read by `uint bricks(uint word)`.

// Material of voxel v (world coordinates, inside the page table's chunks).
uint material_at(ivec3 v) {
  const int shift = int(h.chunk_shift);
  const ivec3 rel = (v >> shift) - h.chunk_origin.xyz;
  const uint entry = pages[(rel.z * h.chunk_dims.y + rel.y) * h.chunk_dims.x + rel.x];
  if ((entry & VF_UNIFORM) != 0u) return entry & 0xFFu;  // a uniform chunk: its value
  const ivec3 l = v & int(h.chunk_edge - 1u);
  const uint index = (uint(l.z) << (2 * shift)) | (uint(l.y) << shift) | uint(l.x);
  return (bricks(entry * h.chunk_words + (index >> 2)) >> ((index & 3u) * 8u)) & 0xFFu;
}
