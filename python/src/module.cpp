// The voxfield Python extension (voxfield._voxfield): voxfield's errors as Python exceptions and
// the engines behind the pure-Python modules of python/voxfield/.
#include <pybind11/pybind11.h>

#include "voxfield/chunk_memory.h"
#include "voxfield/error.h"
#include "voxfield/interrupt.h"

namespace py = pybind11;

namespace voxfield::python {
void bind_ndimage(py::module_& m);
void bind_csg(py::module_& m);
void bind_mesh(py::module_& m);
void bind_vectors(py::module_& m);
void bind_vdb(py::module_& m);
void bind_world(py::module_& m);
}  // namespace voxfield::python

#if defined(VOXFIELD_HAS_CPU_CHECK)
extern "C" const char* voxfield_cpu_lacks_build_level();  // apps/common/cpu_check.cpp
#endif

PYBIND11_MODULE(_voxfield, m) {
#if defined(VOXFIELD_HAS_CPU_CHECK)
  // Before any of the engine runs: an ImportError that says why, not SIGILL.
  if (const char* why = voxfield_cpu_lacks_build_level()) throw py::import_error(why);
#endif
  m.doc() = "voxfield's C++ engine; use the voxfield package";
  // Subclasses of ValueError, MemoryError and OSError carrying voxfield's message (which names the
  // file, and for malformed files the byte offset).
  // Translators are tried last registered first: the base class goes first, so that it catches
  // only what no subclass did.
  py::register_exception<voxfield::Error>(m, "Error", PyExc_RuntimeError);
  py::register_exception<voxfield::InvalidArgument>(m, "InvalidArgument", PyExc_ValueError);
  py::register_exception<voxfield::FormatError>(m, "FormatError", PyExc_ValueError);
  py::register_exception<voxfield::ResourceLimitError>(m, "ResourceLimitError", PyExc_MemoryError);
  py::register_exception<voxfield::IoError>(m, "IoError", PyExc_OSError);
  py::register_exception<voxfield::Cancelled>(m, "Cancelled", PyExc_KeyboardInterrupt);
  voxfield::python::bind_ndimage(m);
  voxfield::python::bind_csg(m);
  voxfield::python::bind_mesh(m);
  voxfield::python::bind_vectors(m);
  voxfield::python::bind_vdb(m);
  voxfield::python::bind_world(m);
  // The cache of chunk voxel arrays kept between calls (voxfield/chunk_memory.h).
  m.def("chunk_cache_limit", &voxfield::chunk_cache_limit);
  m.def("set_chunk_cache_limit", &voxfield::set_chunk_cache_limit, py::arg("bytes"));
  m.def("trim_chunk_cache", &voxfield::trim_chunk_cache);
  m.def("chunk_memory_stats", [] {
    const voxfield::ChunkMemoryStats s = voxfield::chunk_memory_stats();
    py::dict d;
    d["cached_bytes"] = s.cached_bytes;
    d["limit_bytes"] = s.limit_bytes;
    d["reused"] = s.reused;
    d["allocated"] = s.allocated;
    return d;
  });
}
