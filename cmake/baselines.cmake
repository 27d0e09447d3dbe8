# Reference baselines for the benchmark (docs/baselines.md): flow_baseline (OpenCV dense optical
# flow) and vo_baseline (monocular visual odometry), nodes + nodelets in viper_baselines_ros.
# OpenCV's config (found in CMakeLists.txt) imports every installed module; these come with libopencv-dev.
foreach(module opencv_video opencv_calib3d)
  if(NOT TARGET ${module})
    message(FATAL_ERROR "baselines need ${module} (Debian: libopencv-dev)")
  endif()
endforeach()

add_library(viper_baselines_ros
  src/ros/baselines/flow_baseline.cpp
  src/ros/baselines/vo_baseline.cpp
  src/ros/baselines/baselines_nodelets.cpp
)
target_include_directories(viper_baselines_ros PUBLIC ${PROJECT_SOURCE_DIR}/include)
target_include_directories(viper_baselines_ros SYSTEM PUBLIC ${catkin_INCLUDE_DIRS} ${OpenCV_INCLUDE_DIRS})
target_link_libraries(viper_baselines_ros PUBLIC viper_conversions viper_core ${catkin_LIBRARIES}
  opencv_core opencv_imgproc opencv_video opencv_calib3d)
set_target_properties(viper_baselines_ros PROPERTIES
  LIBRARY_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION})

foreach(node flow_baseline vo_baseline)
  add_executable(${node} nodes/${node}_node.cpp)
  target_link_libraries(${node} viper_baselines_ros)
  set_target_properties(${node} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
endforeach()
install(TARGETS viper_baselines_ros flow_baseline vo_baseline
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # The committed raw bag through replay.launch + baselines.launch, fed and scored by baselines_tester.
  viper_add_tester(baselines_tester test/ros/baselines_tester.cpp viper_core)
  add_rostest(test/ros/baselines.test
    DEPENDENCIES baselines_tester viper_baselines_ros viper_flow_ros viper_ground_truth_ros)
  roslaunch_add_file_check(launch/baselines.launch)
  roslaunch_add_file_check(launch/benchmark_baselines.launch capture:=world.vcap report_dir:=/tmp/report)
endif()
