# Stage 2, the bridge: captures into raw topics and bags (capture_bridge, bag_player, capture_to_bag).

# viper_ros: the capture bridge and the bag player (nodes + nodelets), their pacing (src/ros/pacing:
# replay stamps and back-pressure) and the measurement nodelets and CPU meter (src/ros/measurement).
viper_ros_library(viper_ros SOURCES
  src/ros/pacing/replay_timing.cpp
  src/ros/pacing/pace_gate.cpp
  src/ros/measurement/cpu_meter.cpp
  src/ros/bridge/capture_bridge_options.cpp
  src/ros/bridge/capture_bridge.cpp
  src/ros/bridge/capture_bridge_nodelet.cpp
  src/ros/measurement/frame_counter_nodelet.cpp
  src/ros/measurement/output_counter_nodelet.cpp
  src/ros/bridge/bag_player.cpp
  src/ros/bridge/bag_player_nodelet.cpp
  src/ros/bridge/raw_frames.cpp
  SYSTEM_INCLUDES ${VIPER_ROSBAG_INCLUDE_DIRS}
  # viper_dataset (cmake/dataset.cmake) for its bag file writer (BagWriter, raw bags).
  LINK viper_conversions viper_core viper_dataset ${catkin_LIBRARIES})

viper_executable(capture_bridge nodes/capture_bridge_node.cpp LINK viper_ros)
viper_executable(bag_player nodes/bag_player_node.cpp LINK viper_ros)
install(FILES nodelet_plugins.xml DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
install(DIRECTORY launch rviz DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
install(PROGRAMS scripts/make_test_bag.sh DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
install(FILES scripts/package_binaries.sh scripts/options.sh DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})  # make_test_bag.sh sources them

if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)
  find_package(roslaunch REQUIRED)

  # Plain gtests, no roscore.
  catkin_add_gtest(test_replay_timing test/ros/test_replay_timing.cpp)
  target_link_libraries(test_replay_timing viper_ros)
  # Every `rosrun viper X` of README.md runs as written (needs the devel space sourced).
  catkin_add_gtest(test_readme_commands test/ros/test_readme_commands.cpp)
  target_compile_definitions(test_readme_commands PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_link_libraries(test_readme_commands gtest_main)
  add_dependencies(test_readme_commands viper_capture world test_scene capture_check capture_info capture_sheet
    label_resources capture_to_bag make_label_table export_flow viper_to_bag export_viper export_training generate viper_exporter player
    dataset_statistics)

  # Test captures written by our own generator (CaptureWriter): intact, one flipped byte, truncated.
  add_executable(make_test_capture test/ros/make_test_capture.cpp)
  target_link_libraries(make_test_capture viper_core)
  set(VIPER_ROS_TEST_DATA ${PROJECT_BINARY_DIR}/test_data)
  set(VIPER_ROS_TEST_CAPTURES
    ${VIPER_ROS_TEST_DATA}/bridge_ok.vcap
    ${VIPER_ROS_TEST_DATA}/bridge_flipped.vcap
    ${VIPER_ROS_TEST_DATA}/bridge_truncated.vcap)
  add_custom_command(OUTPUT ${VIPER_ROS_TEST_CAPTURES}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${VIPER_ROS_TEST_DATA}
    COMMAND make_test_capture --output ${VIPER_ROS_TEST_DATA}/bridge_ok.vcap
    COMMAND make_test_capture --output ${VIPER_ROS_TEST_DATA}/bridge_flipped.vcap --damage flip
    COMMAND make_test_capture --output ${VIPER_ROS_TEST_DATA}/bridge_truncated.vcap --damage truncate
    DEPENDS make_test_capture
    COMMENT "Writing capture_bridge test captures")
  add_custom_target(viper_ros_test_captures DEPENDS ${VIPER_ROS_TEST_CAPTURES})
  if(TARGET tests)
    add_dependencies(tests viper_ros_test_captures)
  endif()

  # rostests: the real node / nodelet on those captures, checked by one tester.
  viper_add_tester(capture_bridge_tester test/ros/capture_bridge_tester.cpp viper_ros)
  # Throughput probe (not a test: prints frames/s delivered to another process).
  viper_add_tester(bridge_throughput test/ros/bridge_throughput.cpp viper_ros)

  set(_bridge_test_deps capture_bridge capture_bridge_tester viper_ros_test_captures)
  add_rostest(test/ros/capture_bridge.test ARGS capture:=${VIPER_ROS_TEST_DATA}/bridge_ok.vcap
    DEPENDENCIES ${_bridge_test_deps})
  add_rostest(test/ros/capture_bridge_nodelet.test ARGS capture:=${VIPER_ROS_TEST_DATA}/bridge_ok.vcap
    DEPENDENCIES ${_bridge_test_deps})
  add_rostest(test/ros/capture_bridge_damaged.test ARGS capture:=${VIPER_ROS_TEST_DATA}/bridge_flipped.vcap
    DEPENDENCIES ${_bridge_test_deps})
  add_rostest(test/ros/capture_bridge_damaged.test ARGS capture:=${VIPER_ROS_TEST_DATA}/bridge_truncated.vcap
    DEPENDENCIES ${_bridge_test_deps})
  add_rostest(test/ros/capture_bridge_start_delay.test ARGS capture:=${VIPER_ROS_TEST_DATA}/bridge_ok.vcap
    DEPENDENCIES ${_bridge_test_deps})
  add_rostest(test/ros/capture_bridge_follow.test DEPENDENCIES make_test_capture ${_bridge_test_deps})
  roslaunch_add_file_check(launch/capture_bridge.launch file:=capture.vcap)
  roslaunch_add_file_check(launch/capture_bridge.launch file:=capture.vcap nodelet:=true)
  roslaunch_add_file_check(launch/bridge_throughput.launch file:=capture.vcap)
endif()

# capture_to_bag: a capture into the raw bag capture_bridge would publish (viper::frameMessages).
add_executable(capture_to_bag tools/capture_to_bag.cpp)
target_include_directories(capture_to_bag SYSTEM PRIVATE ${VIPER_ROSBAG_INCLUDE_DIRS})
target_link_libraries(capture_to_bag viper_ros)
viper_program(capture_to_bag)

if(CATKIN_ENABLE_TESTING)
  # The command on make_test_capture's captures (above): topics, stamps and content against
  # viper::frameMessages, a truncated capture, usage. The comparison with the running bridge is the
  # rostest capture_to_bag.test (cmake/dataset.cmake, on the world).
  viper_gtest(test_capture_to_bag test/ros/test_capture_to_bag.cpp SYSTEM_INCLUDES ${VIPER_ROSBAG_INCLUDE_DIRS}
    DEFINITIONS
      VIPER_CAPTURE_TO_BAG="$<TARGET_FILE:capture_to_bag>"
      VIPER_TEST_CAPTURE_OK="${PROJECT_BINARY_DIR}/test_data/bridge_ok.vcap"
      VIPER_TEST_CAPTURE_TRUNCATED="${PROJECT_BINARY_DIR}/test_data/bridge_truncated.vcap"
    LINK viper_ros gtest_main
    DEPENDS capture_to_bag viper_ros_test_captures)
  # CaptureReader's image sink and FrameImageMessages (the bridge's): on make_test_capture's capture and
  # on the same frames as an earlier build wrote them (test/capture/data: format versions 3 and 4).
  viper_gtest(test_frame_image_messages test/ros/test_frame_image_messages.cpp
    DEFINITIONS
      VIPER_TEST_CAPTURE_OK="${PROJECT_BINARY_DIR}/test_data/bridge_ok.vcap"
      VIPER_TEST_CAPTURE_V3="${PROJECT_SOURCE_DIR}/test/capture/data/test_capture_v3_zstd.vcap"
      VIPER_TEST_CAPTURE_V4="${PROJECT_SOURCE_DIR}/test/capture/data/test_capture_v4_lz4.vcap"
    LINK viper_ros gtest_main
    DEPENDS viper_ros_test_captures)
  # test_bag_writer: BagWriter's files against rosbag's C++ and Python readers and rosbag reindex.
  # test_bag_reader: BagFileReader (bag_player's) and BagReader against rosbag::View, on rosbag's and
  # BagFileWriter's bags and the committed test bag; test_bag_reader_damage: the same readers on
  # damaged bags.
  foreach(t test_bag_writer test_bag_reader test_bag_reader_damage)
    viper_gtest(${t} test/ros/${t}.cpp SYSTEM_INCLUDES ${VIPER_ROSBAG_INCLUDE_DIRS}
      DEFINITIONS VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}" LINK viper_ros gtest_main)
  endforeach()
endif()
