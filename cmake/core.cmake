# viper_core: the ROS-free library (capture format, geometry, later ground truth and metrics).
file(GLOB VIPER_CORE_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/core/*.cpp)
add_library(viper_core ${VIPER_CORE_SOURCES})
target_include_directories(viper_core PUBLIC ${PROJECT_SOURCE_DIR}/include)
# The per-pixel kernels rely on loop vectorisation, which GCC 12 does fully only at -O3.
target_compile_options(viper_core PRIVATE -O3)
target_include_directories(viper_core SYSTEM PUBLIC ${EIGEN3_INCLUDE_DIR})
# Deliberately no OpenCV and no ROS: the capture layer preloads this library into foreign programs.
target_link_libraries(viper_core PRIVATE PkgConfig::ZSTD PkgConfig::XXHASH PkgConfig::YAMLCPP)
install(TARGETS viper_core
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(DIRECTORY include/viper/ DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  file(GLOB VIPER_CORE_TESTS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/core/test_*.cpp)
  foreach(t ${VIPER_CORE_TESTS})
    get_filename_component(name ${t} NAME_WE)
    catkin_add_gtest(${name} ${t} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} viper_core gtest_main)
  endforeach()
endif()
