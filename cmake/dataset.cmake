# viper_dataset: ROS-free readers and writers of dataset files (VIPER's release layout, its .npz
# flow, Middlebury .flo, its PNG/JPEG images and CSV files), and the export_flow command that fills
# that layout from a bag.
pkg_check_modules(LIBZIP REQUIRED IMPORTED_TARGET libzip)
pkg_check_modules(LIBPNG REQUIRED IMPORTED_TARGET libpng)

file(GLOB VIPER_DATASET_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/dataset/*.cpp)
add_library(viper_dataset ${VIPER_DATASET_SOURCES})
target_include_directories(viper_dataset PUBLIC ${PROJECT_SOURCE_DIR}/include)
# The float16 loops vectorise only at -O3, and only when GCC 12 may execute the float operations
# of every branch (no floating-point exceptions are ever enabled here).
target_compile_options(viper_dataset PRIVATE -O3 -fno-trapping-math)
# PNG through libpng (palette indices of class images must not be expanded to colors), JPEG
# through OpenCV.
target_include_directories(viper_dataset SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(viper_dataset PRIVATE PkgConfig::LIBZIP PkgConfig::LIBPNG opencv_core opencv_imgproc opencv_imgcodecs)
set_target_properties(viper_dataset PROPERTIES
  LIBRARY_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION})
install(TARGETS viper_dataset
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

# export_flow: 32FC2 flow messages of a bag -> VIPER layout (.npz) and/or .flo files.
# rosbag/bag.h includes pluginlib and class_loader, which Debian installs under their own folders.
find_package(pluginlib REQUIRED)
find_package(class_loader REQUIRED)
add_executable(export_flow tools/export_flow.cpp)
target_include_directories(export_flow SYSTEM PRIVATE ${catkin_INCLUDE_DIRS} ${pluginlib_INCLUDE_DIRS}
  ${class_loader_INCLUDE_DIRS})
target_link_libraries(export_flow viper_dataset viper_conversions ${catkin_LIBRARIES})
set_target_properties(export_flow PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS export_flow RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(TARGET bench_flow_files)
  target_link_libraries(bench_flow_files viper_dataset)
endif()

if(CATKIN_ENABLE_TESTING)
  # Every test/dataset/test_*.cpp is a gtest. The numpy interop test runs the system python's
  # numpy (python3-numpy); the export test writes a bag and runs export_flow on it.
  file(GLOB VIPER_DATASET_TESTS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/dataset/test_*.cpp)
  foreach(t ${VIPER_DATASET_TESTS})
    get_filename_component(name ${t} NAME_WE)
    catkin_add_gtest(${name} ${t} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    if(TARGET ${name})
      target_link_libraries(${name} viper_dataset PkgConfig::LIBZIP gtest_main)
      target_compile_definitions(${name} PRIVATE
        VIPER_PYTHON="/usr/bin/python3"
        VIPER_NUMPY_INTEROP_SCRIPT="${PROJECT_SOURCE_DIR}/test/dataset/numpy_interop.py"
        VIPER_EXPORT_FLOW="$<TARGET_FILE:export_flow>")
    endif()
  endforeach()
  if(TARGET test_export_flow)
    target_include_directories(test_export_flow SYSTEM PRIVATE ${catkin_INCLUDE_DIRS} ${pluginlib_INCLUDE_DIRS}
      ${class_loader_INCLUDE_DIRS})
    target_link_libraries(test_export_flow ${catkin_LIBRARIES})
    add_dependencies(test_export_flow export_flow)
  endif()
endif()
