# c-blosc (Debian libblosc-dev) as the imported target voxfield_blosc::blosc: the compressor OpenVDB
# 4 and later use by default inside .vdb files, which voxfield's own .vdb reader decompresses
# (src/io/vdb_read_tree.cpp). Debian ships a pkg-config file but no CMake package; found by path
# so that the installed voxfield package can define the same target. Included by the build and by
# the installed package.
if(NOT TARGET voxfield_blosc::blosc)
  find_path(VOXFIELD_BLOSC_INCLUDE_DIR blosc.h)
  find_library(VOXFIELD_BLOSC_LIBRARY blosc)
  if(VOXFIELD_BLOSC_INCLUDE_DIR AND VOXFIELD_BLOSC_LIBRARY)
    add_library(voxfield_blosc::blosc UNKNOWN IMPORTED)
    set_target_properties(voxfield_blosc::blosc PROPERTIES
      IMPORTED_LOCATION "${VOXFIELD_BLOSC_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${VOXFIELD_BLOSC_INCLUDE_DIR}")
  endif()
endif()
