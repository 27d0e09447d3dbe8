# Command-line tools of the package (run with rosrun viper NAME).
add_executable(capture_info tools/capture_info.cpp)
target_link_libraries(capture_info viper_core)
set_target_properties(capture_info PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS capture_info RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# capture_check: ids, matrices and meshes of a capture checked against its own depth (viper::checkReprojection).
add_executable(capture_check tools/capture_check.cpp)
target_link_libraries(capture_check viper_core)
set_target_properties(capture_check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS capture_check RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# capture_sheet: a contact sheet of a capture's frames (color, ids, depth, flow, reprojection).
add_executable(capture_sheet tools/capture_sheet.cpp)
target_include_directories(capture_sheet SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(capture_sheet viper_core ${OpenCV_LIBS})
set_target_properties(capture_sheet PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS capture_sheet RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

add_executable(make_label_table tools/make_label_table.cpp)
target_link_libraries(make_label_table viper_core)
set_target_properties(make_label_table PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS make_label_table RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# capture_to_bag: a capture into the raw bag capture_bridge would publish (viper::frameMessages).
# rosbag/bag.h includes pluginlib and class_loader, which Debian installs under their own folders.
find_package(pluginlib REQUIRED)
find_package(class_loader REQUIRED)
add_executable(capture_to_bag tools/capture_to_bag.cpp)
target_include_directories(capture_to_bag SYSTEM PRIVATE ${pluginlib_INCLUDE_DIRS} ${class_loader_INCLUDE_DIRS})
target_link_libraries(capture_to_bag viper_ros)
set_target_properties(capture_to_bag PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS capture_to_bag RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # The command on make_test_capture's captures (cmake/ros.cmake): topics, stamps and content against
  # viper::frameMessages, a truncated capture, usage. The comparison with the running bridge is the
  # rostest capture_to_bag.test (cmake/viper_layout.cmake, on the world).
  catkin_add_gtest(test_capture_to_bag test/ros/test_capture_to_bag.cpp)
  if(TARGET test_capture_to_bag)
    target_include_directories(test_capture_to_bag SYSTEM PRIVATE ${pluginlib_INCLUDE_DIRS} ${class_loader_INCLUDE_DIRS})
    target_link_libraries(test_capture_to_bag viper_ros gtest_main)
    target_compile_definitions(test_capture_to_bag PRIVATE
      VIPER_CAPTURE_TO_BAG="$<TARGET_FILE:capture_to_bag>"
      VIPER_TEST_CAPTURE_OK="${PROJECT_BINARY_DIR}/test_data/bridge_ok.vcap"
      VIPER_TEST_CAPTURE_TRUNCATED="${PROJECT_BINARY_DIR}/test_data/bridge_truncated.vcap")
    add_dependencies(test_capture_to_bag capture_to_bag viper_ros_test_captures)
  endif()
endif()
