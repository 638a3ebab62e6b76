// voxfield shaders — a buffer of 32-bit words larger than one storage-buffer binding may cover
// (maxStorageBufferRange: 128 MiB on lavapipe and on some integrated GPUs), bound as
// VF_SPLIT_PARTS windows of 2^shift words each (src/gpu/split_buffer.h). Word w lives in window
// w >> shift at w & (2^shift - 1). The windows are separate bindings chosen by a switch, not an
// array of descriptors: indexing such an array by a value that differs between invocations needs
// descriptor-indexing features that a switch does not.
//
// VF_SPLIT_WORDS(access, Block, name, b0, b1, b2, b3) declares the four windows (`access`:
// readonly, writeonly or empty) as buffers Block0..Block3 of arrays name0..name3 at bindings
// b0..b3. VF_SPLIT_LOAD(name, shift) then defines `uint name(uint w)`, VF_SPLIT_STORE(name, shift)
// defines `void name_store(uint w, uint value)`; `shift` is an expression the shader can read
// (a field of its parameters).

#define VF_SPLIT_WORDS(access, Block, name, b0, b1, b2, b3)                                   \
  layout(std430, set = 0, binding = b0) access buffer Block##0 { uint name##0[]; };           \
  layout(std430, set = 0, binding = b1) access buffer Block##1 { uint name##1[]; };           \
  layout(std430, set = 0, binding = b2) access buffer Block##2 { uint name##2[]; };           \
  layout(std430, set = 0, binding = b3) access buffer Block##3 { uint name##3[]; }

#define VF_SPLIT_LOAD(name, shift)                         \
  uint name(uint w) {                                      \
    const uint part = w >> (shift);                        \
    const uint j = w & ((1u << (shift)) - 1u);             \
    if (part == 0u) return name##0[j];                     \
    if (part == 1u) return name##1[j];                     \
    if (part == 2u) return name##2[j];                     \
    return name##3[j];                                     \
  }

#define VF_SPLIT_STORE(name, shift)                        \
  void name##_store(uint w, uint value) {                  \
    const uint part = w >> (shift);                        \
    const uint j = w & ((1u << (shift)) - 1u);             \
    if (part == 0u) name##0[j] = value;                    \
    else if (part == 1u) name##1[j] = value;               \
    else if (part == 2u) name##2[j] = value;               \
    else name##3[j] = value;                               \
  }
