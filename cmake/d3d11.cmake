# Direct3D 11 through wine: d3d11_scene.exe, a small D3D11 program of ours (test/d3d11/), built with
# mingw-w64 when it is installed and run under wine, whose wined3d turns it into OpenGL for the
# OpenGL capture layer. Without mingw-w64 neither the program nor its test is built.
# Design and findings: docs/capture_layer.md, "Direct3D 11 through wine".
find_program(VIPER_MINGW_CXX NAMES x86_64-w64-mingw32-g++-posix x86_64-w64-mingw32-g++)
if(NOT VIPER_MINGW_CXX)
  message(STATUS "x86_64-w64-mingw32-g++ not found (mingw-w64): d3d11_scene.exe and test_capture_d3d11 not built")
  return()
endif()

set(VIPER_D3D11_SCENE_EXE ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}/d3d11_scene.exe)
add_custom_command(
  OUTPUT ${VIPER_D3D11_SCENE_EXE}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}
  COMMAND ${VIPER_MINGW_CXX} -O2 -std=c++17 -Wall -Wextra -static -static-libgcc -static-libstdc++
          ${PROJECT_SOURCE_DIR}/test/d3d11/d3d11_scene.cpp -o ${VIPER_D3D11_SCENE_EXE}
          -ld3d11 -ldxgi -ld3dcompiler_47 -luuid
  DEPENDS ${PROJECT_SOURCE_DIR}/test/d3d11/d3d11_scene.cpp
  COMMENT "Building d3d11_scene.exe with mingw-w64"
  VERBATIM)
add_custom_target(d3d11_scene ALL DEPENDS ${VIPER_D3D11_SCENE_EXE})

if(CATKIN_ENABLE_TESTING)
  # d3d11_scene under wine and `capture`, against its own truth (the test skips without wine or Xvfb).
  viper_gtest(test_capture_d3d11 test/capture/test_capture_d3d11.cpp INCLUDES ${PROJECT_SOURCE_DIR}
    DEFINITIONS VIPER_CAPTURE_BIN="$<TARGET_FILE:viper_capture>" VIPER_D3D11_SCENE_EXE="${VIPER_D3D11_SCENE_EXE}"
      VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    LINK viper_core gtest_main
    DEPENDS viper_capture viper_intercept d3d11_scene)
endif()
