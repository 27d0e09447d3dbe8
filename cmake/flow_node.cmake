# viper_flow_ros: the flow node (dense optical flow, occlusion masks, correspondences service) and
# its nodelet. Core: src/ground_truth/flow.cpp (viper_core).
add_library(viper_flow_ros
  src/ros/ground_truth/flow.cpp
  src/ros/ground_truth/flow_nodelet.cpp
)
target_include_directories(viper_flow_ros PUBLIC ${PROJECT_SOURCE_DIR}/include)
target_include_directories(viper_flow_ros SYSTEM PUBLIC ${catkin_INCLUDE_DIRS})
target_link_libraries(viper_flow_ros PUBLIC viper_ground_truth_ros viper_ros viper_core ${catkin_LIBRARIES})
add_dependencies(viper_flow_ros viper_generate_messages_cpp)
set_target_properties(viper_flow_ros PROPERTIES
  LIBRARY_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION})

add_executable(flow nodes/flow_node.cpp)
target_link_libraries(flow viper_flow_ros)
set_target_properties(flow PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS viper_flow_ros flow
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # The committed raw bag through replay.launch (instances + flow nodelets), fed and checked by
  # flow_tester; and broken frames into the flow node, checked by flow_bad_input_tester.
  viper_add_tester(flow_tester test/ros/flow_tester.cpp viper_ros viper_core)
  viper_add_tester(flow_bad_input_tester test/ros/flow_bad_input_tester.cpp)
  add_rostest(test/ros/flow_replay.test DEPENDENCIES flow_tester viper_flow_ros viper_ground_truth_ros)
  add_rostest(test/ros/flow_bad_input.test DEPENDENCIES flow_bad_input_tester flow)
  roslaunch_add_file_check(launch/replay.launch label_table:=labels.yaml bag:=raw.bag flow_wide_baseline:=2)
endif()
