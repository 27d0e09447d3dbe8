# Stage 0, the programs we capture that are ours: the shared GL plumbing (gl_common), the test
# scene (test_scene) and the procedural town (world). Plain OpenGL programs: no capture code, no ROS.

# viper_gl_common: what our own OpenGL programs (test_scene, world; gl_engine/gl_legacy_program its shaders)
# share: the headless EGL context, shader compile/link with clear errors, PPM frame dumps. Plain
# EGL + GL + the standard library: no ROS, no viper_core, so the programs stay plain GL programs.
add_library(viper_gl_common STATIC
  gl_common/headless_egl_context.cpp
  gl_common/shader_build.cpp
  gl_common/ppm.cpp
)
target_include_directories(viper_gl_common PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(viper_gl_common PUBLIC PkgConfig::EGL PkgConfig::GL)

# test_scene: the plain OpenGL program the capture layer is tested on (headless EGL, no capture code;
# viper_gl_common for the EGL context, shaders and dumps, viper_core only for the oracle writer).
add_executable(test_scene
  scene/main.cpp
  scene/options.cpp
  scene/gl_api.cpp
  scene/geometry.cpp
  scene/world.cpp
  scene/shaders.cpp
  scene/renderer.cpp
)
target_link_libraries(test_scene viper_gl_common viper_core PkgConfig::EGL PkgConfig::GL)
set_target_properties(test_scene PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS test_scene RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # Runs the real binary: structure of its oracle, determinism, both GL loaders, exit codes.
  catkin_add_gtest(test_scene_run test/scene/test_scene_run.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  target_link_libraries(test_scene_run viper_core)
  target_compile_definitions(test_scene_run PRIVATE VIPER_TEST_SCENE_BIN="$<TARGET_FILE:test_scene>")
  add_dependencies(test_scene_run test_scene)
endif()

# world: the procedural town, viper's default data source (a plain OpenGL program; see docs/world.md).
file(GLOB VIPER_WORLD_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/world/*.cpp)
add_executable(world ${VIPER_WORLD_SOURCES})
target_link_libraries(world viper_gl_common viper_core PkgConfig::EGL PkgConfig::GL)
# X11 only for the optional --window mode; headless rendering needs none.
pkg_check_modules(VIPER_WORLD_X11 QUIET IMPORTED_TARGET x11)
if(VIPER_WORLD_X11_FOUND)
  target_link_libraries(world PkgConfig::VIPER_WORLD_X11)
  target_compile_definitions(world PRIVATE VIPER_WORLD_WITH_X11=1)
endif()
set_target_properties(world PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS world RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(FILES config/profiles/world.yaml DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/config/profiles)

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_world test/world/test_world.cpp test/world/world_run.cpp
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  if(TARGET test_world)
    target_link_libraries(test_world viper_core)
    target_compile_definitions(test_world PRIVATE
      VIPER_WORLD_BINARY="$<TARGET_FILE:world>"
      VIPER_CLASSES_CSV="${PROJECT_SOURCE_DIR}/config/viper_classes.csv")
    add_dependencies(test_world world)
  endif()
endif()
