# Finds Prizma's dependencies as Debian 12 ships them (see docs/building.md for the traps).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)

# OpenEXR 3.1: its config warns about a missing PyImath file; harmless.
find_package(OpenEXR CONFIG REQUIRED)
find_package(Eigen3 3.3 CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)

# OpenImageIO's CMake config on Debian 12 needs OpenCV headers: use pkg-config instead.
pkg_check_modules(OIIO REQUIRED IMPORTED_TARGET OpenImageIO)
# Little CMS (liblcms2-dev): the ICC profiles of PNG/TIFF/JPEG outputs, made in the image module.
pkg_check_modules(LCMS2 REQUIRED IMPORTED_TARGET lcms2)
# OpenColorIO's config sits where find_package does not look: use pkg-config.
pkg_check_modules(OCIO REQUIRED IMPORTED_TARGET OpenColorIO)
# prizma-relight -i: line editing and history (libedit-dev), inline images in sixel terminals (libsixel-dev).
pkg_check_modules(LIBEDIT REQUIRED IMPORTED_TARGET libedit)
pkg_check_modules(SIXEL REQUIRED IMPORTED_TARGET libsixel)
# Highway (libhwy-dev): run-time SIMD dispatch of the relight kernel (relight/src/relight_simd.cpp).
pkg_check_modules(HWY REQUIRED IMPORTED_TARGET libhwy)

# libnifti's CMake config points at a non-multiarch path: find the pieces by hand.
find_package(ZLIB REQUIRED)
find_path(NIFTI_INCLUDE_DIR nifti1_io.h PATH_SUFFIXES nifti REQUIRED)
find_library(NIFTI_IO_LIBRARY niftiio REQUIRED)
find_library(NIFTI_ZNZ_LIBRARY znz REQUIRED)
if(NOT TARGET prizma_nifti)
  add_library(prizma_nifti INTERFACE)
  target_include_directories(prizma_nifti SYSTEM INTERFACE ${NIFTI_INCLUDE_DIR})
  target_link_libraries(prizma_nifti INTERFACE ${NIFTI_IO_LIBRARY} ${NIFTI_ZNZ_LIBRARY} ZLIB::ZLIB m)
endif()

# OpenVDB 10 (libopenvdb-dev): Debian installs only Find modules under a path find_package does not
# search, and they look for Blosc, IlmBase and more that the shared library already links: find the
# library and header by hand; its headers need Imath's half (from OpenEXR's Imath) and TBB.
find_path(OPENVDB_INCLUDE_DIR openvdb/openvdb.h REQUIRED)
find_library(OPENVDB_LIBRARY openvdb REQUIRED)
find_package(Imath CONFIG REQUIRED)
if(NOT TARGET prizma_openvdb)
  add_library(prizma_openvdb INTERFACE)
  target_include_directories(prizma_openvdb SYSTEM INTERFACE ${OPENVDB_INCLUDE_DIR})
  target_link_libraries(prizma_openvdb INTERFACE ${OPENVDB_LIBRARY} Imath::Imath TBB::tbb)
endif()

if(PRIZMA_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(PRIZMA_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
