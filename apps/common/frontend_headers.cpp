// The translation unit that builds the front ends' shared precompiled header (CMakeLists.txt:
// voxfield_frontend_headers): CLI11 and nlohmann/json, parsed once per build for the CLI,
// voxfield-mpi and the benchmarks. It defines nothing of its own.
