# OpenVDB (Debian libopenvdb-dev) as the imported target voxfield_openvdb::openvdb. Debian ships no
# CMake package for it, and the find module it ships asks for Boost libraries it does not depend
# on; the library needs only its headers (with Boost's and Imath's headers, libboost-dev and
# libimath-dev), libopenvdb, Imath and oneTBB. Included by the build and by the installed package.
if(NOT TARGET voxfield_openvdb::openvdb)
  find_path(VOXFIELD_OPENVDB_INCLUDE_DIR openvdb/openvdb.h)
  find_library(VOXFIELD_OPENVDB_LIBRARY openvdb)
  find_package(Imath CONFIG QUIET)
  find_package(TBB QUIET)
  if(VOXFIELD_OPENVDB_INCLUDE_DIR AND VOXFIELD_OPENVDB_LIBRARY AND Imath_FOUND AND TBB_FOUND)
    add_library(voxfield_openvdb::openvdb UNKNOWN IMPORTED)
    set_target_properties(voxfield_openvdb::openvdb PROPERTIES
      IMPORTED_LOCATION "${VOXFIELD_OPENVDB_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${VOXFIELD_OPENVDB_INCLUDE_DIR}"
      INTERFACE_LINK_LIBRARIES "Imath::Imath;TBB::tbb")
  endif()
endif()
