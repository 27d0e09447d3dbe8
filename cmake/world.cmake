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
