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
target_compile_definitions(capture_sheet PRIVATE VIPER_CLASS_TABLE="${PROJECT_SOURCE_DIR}/config/viper_classes.csv")
set_target_properties(capture_sheet PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS capture_sheet RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# label_resources: the labelling page of a capture (tools/label_page/ is copied beside the data).
add_executable(label_resources tools/label_resources.cpp)
target_include_directories(label_resources SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(label_resources viper_core ${OpenCV_LIBS})
target_compile_definitions(label_resources PRIVATE
  VIPER_LABEL_PAGE_DIR="${PROJECT_SOURCE_DIR}/tools/label_page"
  VIPER_CLASS_TABLE="${PROJECT_SOURCE_DIR}/config/viper_classes.csv")
set_target_properties(label_resources PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS label_resources RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

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

if(CATKIN_ENABLE_TESTING)
  # The labelling page in headless Chromium, driven by Playwright (test/label_page; needs chromium,
  # node and the page driver's npm package: scripts/setup.sh --test-programs).
  catkin_add_gtest(test_label_page test/label_page/test_label_page.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  if(TARGET test_label_page)
    target_compile_definitions(test_label_page PRIVATE
      VIPER_CAPTURE_EXE="$<TARGET_FILE:viper_capture>"
      VIPER_GL_TEST_PROGRAM="$<TARGET_FILE:viper_gl_test_program>"
      VIPER_LABEL_RESOURCES="$<TARGET_FILE:label_resources>"
      VIPER_PROFILE_DIR="${PROJECT_SOURCE_DIR}/config/profiles"
      VIPER_LABEL_PAGE_TEST_DIR="${PROJECT_SOURCE_DIR}/test/label_page")
    target_link_libraries(test_label_page viper_core gtest_main)
    add_dependencies(test_label_page viper_capture viper_intercept viper_gl_test_program label_resources)
  endif()
endif()
