# viper_ground_truth_ros: the ground-truth nodes (instances, boxes, odometry) and their nodelets.
add_library(viper_ground_truth_ros
  src/ros/ground_truth/instances.cpp
  src/ros/ground_truth/boxes.cpp
  src/ros/ground_truth/odometry.cpp
  src/ros/ground_truth/ground_truth_nodelets.cpp
)
target_include_directories(viper_ground_truth_ros PUBLIC ${PROJECT_SOURCE_DIR}/include)
target_include_directories(viper_ground_truth_ros SYSTEM PUBLIC ${catkin_INCLUDE_DIRS})
target_link_libraries(viper_ground_truth_ros PUBLIC viper_ros viper_core ${catkin_LIBRARIES})
add_dependencies(viper_ground_truth_ros viper_generate_messages_cpp)
set_target_properties(viper_ground_truth_ros PROPERTIES
  LIBRARY_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION})

foreach(node instances boxes odometry)
  add_executable(${node} nodes/${node}_node.cpp)
  target_link_libraries(${node} viper_ground_truth_ros)
  set_target_properties(${node} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
  install(TARGETS ${node} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endforeach()
install(TARGETS viper_ground_truth_ros
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # Real captures and oracles, made at build time, for the oracle checks: the test scene, and 90
  # frames (6 s) of the world's traffic with level-of-detail swaps and occlusions.
  set(VIPER_GT_DATA ${PROJECT_BINARY_DIR}/test_data)
  function(viper_oracle_check name program profile program_args)
    set(capture ${VIPER_GT_DATA}/${name}.vcap)
    set(oracle ${VIPER_GT_DATA}/${name}.oracle)
    add_custom_command(OUTPUT ${capture} ${oracle}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${VIPER_GT_DATA}
      COMMAND $<TARGET_FILE:viper_capture> --output ${capture} --profile ${PROJECT_SOURCE_DIR}/${profile}
              --condition day --fps 15 -- $<TARGET_FILE:${program}> ${program_args} --oracle ${oracle}
      DEPENDS viper_capture viper_intercept ${program}
      COMMENT "Capturing ${program} for the ground-truth oracle checks")
    add_custom_target(${name}_capture DEPENDS ${capture} ${oracle})
    catkin_add_gtest(test_${name}_against_oracle test/ground_truth/test_against_oracle.cpp)
    target_link_libraries(test_${name}_against_oracle viper_core gtest_main)
    target_compile_definitions(test_${name}_against_oracle PRIVATE
      VIPER_TEST_SCENE_CAPTURE="${capture}" VIPER_TEST_SCENE_ORACLE="${oracle}")
    add_dependencies(test_${name}_against_oracle ${name}_capture)
  endfunction()
  viper_oracle_check(gt_scene test_scene config/profiles/test_scene.yaml "--frames;30;--width;320;--height;240")
  viper_oracle_check(gt_world world config/profiles/world.yaml "--frames;90;--width;480;--height;270")

  # The committed raw bag through replay.launch's nodelets, fed and checked by replay_tester.
  # SuperTuxKart live through replay.launch's nodelets (needs scripts/setup.sh --test-programs).
  viper_add_tester(supertuxkart_tester test/ros/supertuxkart_tester.cpp)
  add_rostest(test/ros/supertuxkart_live.test DEPENDENCIES supertuxkart_tester viper_ground_truth_ros viper_flow_ros
    viper_capture viper_intercept capture_check)
  viper_add_tester(replay_tester test/ros/replay_tester.cpp)
  add_rostest(test/ros/replay_bag.test DEPENDENCIES replay_tester viper_ground_truth_ros)

  viper_add_tester(bad_input_tester test/ros/bad_input_tester.cpp)
  add_rostest(test/ros/bad_input.test DEPENDENCIES bad_input_tester viper_ground_truth_ros)
  roslaunch_add_file_check(launch/replay.launch label_table:=labels.yaml bag:=raw.bag)
  roslaunch_add_file_check(launch/world_live.launch)
endif()
