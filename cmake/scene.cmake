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
