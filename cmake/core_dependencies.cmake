# The libraries the ROS-free libraries (viper_core, viper_dataset) build on, found once for the
# catkin build (CMakeLists.txt) and for the fuzz targets' own clang build (test/fuzz/CMakeLists.txt).
find_package(Eigen3 REQUIRED)
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs)
find_package(PkgConfig REQUIRED)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)
pkg_check_modules(YAMLCPP REQUIRED IMPORTED_TARGET yaml-cpp)
pkg_check_modules(LIBZIP REQUIRED IMPORTED_TARGET libzip)
pkg_check_modules(LIBPNG REQUIRED IMPORTED_TARGET libpng)
pkg_check_modules(LIBDEFLATE REQUIRED IMPORTED_TARGET libdeflate)  # the PNG and npz writers' deflate (levels 2..12)
# ISA-L's igzip: the same writers' level 1 (libisal-dev ships no pkg-config file).
find_path(ISAL_INCLUDE_DIR isa-l/igzip_lib.h REQUIRED)
find_library(ISAL_LIBRARY isal REQUIRED)
if(NOT TARGET viper_isal)
  add_library(viper_isal INTERFACE IMPORTED)
  set_target_properties(viper_isal PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${ISAL_INCLUDE_DIR}"
                                              INTERFACE_LINK_LIBRARIES "${ISAL_LIBRARY}")
endif()
pkg_check_modules(LIBJPEG REQUIRED IMPORTED_TARGET libjpeg)  # a JPEG's size before OpenCV decodes it
pkg_check_modules(LIBLZ4 REQUIRED IMPORTED_TARGET liblz4)  # LZ4 frames of the bags written by BagFileWriter, LZ4 blocks of lz4 captures
find_package(BZip2 REQUIRED)  # and their bz2 chunks
pkg_check_modules(LIBCRYPTO REQUIRED IMPORTED_TARGET libcrypto)  # SHA-256 of the sequence markers (OpenSSL)
