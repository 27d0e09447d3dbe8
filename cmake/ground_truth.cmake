# Stage 3, ground truth: the nodes (instances, boxes, odometry, flow) and the checks of their cores
# against the oracles of our own programs.
# viper_ground_truth_ros: the ground-truth nodes (instances, boxes, odometry) and their nodelets.
viper_ros_library(viper_ground_truth_ros SOURCES
  src/ros/ground_truth/step_log.cpp
  src/ros/ground_truth/instances_step.cpp
  src/ros/ground_truth/boxes_step.cpp
  src/ros/ground_truth/odometry_step.cpp
  src/ros/ground_truth/instances_node.cpp
  src/ros/ground_truth/boxes_node.cpp
  src/ros/ground_truth/odometry_node.cpp
  src/ros/ground_truth/ground_truth_nodelets.cpp
  LINK viper_ros viper_core ${catkin_LIBRARIES})

foreach(node instances boxes odometry)
  viper_executable(${node} nodes/${node}_node.cpp LINK viper_ground_truth_ros)
endforeach()

if(CATKIN_ENABLE_TESTING)
  # Real captures and oracles, made at build time, for the oracle checks: the test scene, and 90
  # frames (6 s) of the world's traffic with level-of-detail swaps and occlusions.
  set(VIPER_GT_DATA ${PROJECT_BINARY_DIR}/test_data)
  function(viper_oracle_check name program profile program_args)
    set(capture ${VIPER_GT_DATA}/${name}.vcap)
    set(oracle ${VIPER_GT_DATA}/${name}.oracle)
    viper_capture_run(${capture} PROGRAM ${program} PROFILE ${PROJECT_SOURCE_DIR}/${profile} CONDITION day
      ARGS ${program_args} ORACLE ${oracle} COMMENT "Capturing ${program} for the ground-truth oracle checks")
    add_custom_target(${name}_capture DEPENDS ${capture} ${oracle})
    catkin_add_gtest(test_${name}_against_oracle test/ground_truth/test_against_oracle.cpp)
    target_link_libraries(test_${name}_against_oracle viper_core gtest_main)
    target_compile_definitions(test_${name}_against_oracle PRIVATE
      VIPER_TEST_SCENE_CAPTURE="${capture}" VIPER_TEST_SCENE_ORACLE="${oracle}")
    add_dependencies(test_${name}_against_oracle ${name}_capture)
  endfunction()
  viper_oracle_check(gt_scene test_scene config/profiles/test_scene.yaml "--frames;30;--width;320;--height;240")
  viper_oracle_check(gt_world world config/profiles/world.yaml "--frames;90;--width;480;--height;270")

  # Amodal masks: the rasteriser's rules, bad input, and the invariants on the world capture above.
  viper_gtest(test_amodal test/ground_truth/test_amodal.cpp
    DEFINITIONS
      VIPER_WORLD_CAPTURE="${VIPER_GT_DATA}/gt_world.vcap"
      VIPER_WORLD_LABELS="${PROJECT_SOURCE_DIR}/config/labels/world_labels.yaml"
      VIPER_CLASSES_CSV="${PROJECT_SOURCE_DIR}/config/viper_classes.csv"
    LINK viper_core gtest_main
    DEPENDS gt_world_capture)
  # capture_sheet --modalities on that capture: each tile drawn where its modality has values.
  viper_gtest(test_capture_sheet test/capture/test_capture_sheet.cpp
    SYSTEM_INCLUDES ${OpenCV_INCLUDE_DIRS}
    DEFINITIONS
      VIPER_CAPTURE_SHEET="$<TARGET_FILE:capture_sheet>"
      VIPER_WORLD_CAPTURE="${VIPER_GT_DATA}/gt_world.vcap"
      VIPER_WORLD_LABELS="${PROJECT_SOURCE_DIR}/config/labels/world_labels.yaml"
    LINK viper_core ${OpenCV_LIBS} gtest_main
    DEPENDS gt_world_capture capture_sheet)
  # And against GL: every tracked object of that capture drawn alone from the oracle's meshes.
  viper_gtest(test_amodal_gl test/ground_truth/test_amodal_gl.cpp test/ground_truth/oracle_truth.cpp
    DEFINITIONS
      VIPER_WORLD_CAPTURE="${VIPER_GT_DATA}/gt_world.vcap"
      VIPER_WORLD_ORACLE="${VIPER_GT_DATA}/gt_world.oracle"
      VIPER_FLOW_TRUTH_DIR="${VIPER_GT_DATA}/flow_truth"
      VIPER_WORLD_LABELS="${PROJECT_SOURCE_DIR}/config/labels/world_labels.yaml"
      VIPER_CLASSES_CSV="${PROJECT_SOURCE_DIR}/config/viper_classes.csv"
    LINK viper_core viper_gl_common gtest_main
    DEPENDS gt_world_capture)

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

# viper_flow_ros: the flow node (dense optical flow, occlusion masks, correspondences service) and
# its nodelet. Core: src/ground_truth/flow.cpp (viper_core).
viper_ros_library(viper_flow_ros SOURCES
  src/ros/ground_truth/flow_step.cpp
  src/ros/ground_truth/flow_node.cpp
  src/ros/ground_truth/flow_nodelet.cpp
  LINK viper_ground_truth_ros viper_ros viper_core ${catkin_LIBRARIES})
viper_executable(flow nodes/flow_node.cpp LINK viper_flow_ros)

if(CATKIN_ENABLE_TESTING)
  # The committed raw bag through replay.launch (instances + flow nodelets), fed and checked by
  # flow_tester; and broken frames into the flow node, checked by flow_bad_input_tester.
  viper_add_tester(flow_tester test/ros/flow_tester.cpp viper_ros viper_core)
  viper_add_tester(flow_bad_input_tester test/ros/flow_bad_input_tester.cpp)
  add_rostest(test/ros/flow_replay.test DEPENDENCIES flow_tester viper_flow_ros viper_ground_truth_ros)
  add_rostest(test/ros/flow_bad_input.test DEPENDENCIES flow_bad_input_tester flow)
  roslaunch_add_file_check(launch/replay.launch label_table:=labels.yaml bag:=raw.bag flow_wide_baseline:=2)
  roslaunch_add_file_check(launch/replay.launch label_table:=labels.yaml bag:=raw.bag export_dir:=layout)
endif()

# Flow and boxes checked against analytic truth from the world's oracle (version 2, with meshes):
# the world is captured at build time in all five conditions at 480x270 and 15 fps
# (test/ground_truth/test_flow_against_oracle.cpp, test_boxes_against_oracle.cpp).
if(CATKIN_ENABLE_TESTING)
  set(VIPER_FLOW_TRUTH_DATA ${PROJECT_BINARY_DIR}/test_data/flow_truth)
  set(VIPER_FLOW_TRUTH_FILES)
  # Ego mode and length per condition, so that the five sequences also differ in camera motion
  # (ride: lower, leaning and swaying; walk: sidewalk, step bob; the longer ones reach higher
  # speeds). Same seed: the town and traffic whose resources config/labels/world_labels.yaml labels.
  set(ego_day drive)
  set(ego_sunset ride)
  set(ego_rain walk)
  set(ego_snow drive)
  set(ego_night ride)
  set(frames_day 12)
  set(frames_sunset 12)
  set(frames_rain 12)
  set(frames_snow 24)
  set(frames_night 24)
  foreach(condition day sunset rain snow night)
    set(capture ${VIPER_FLOW_TRUTH_DATA}/world_${condition}.vcap)
    set(oracle ${VIPER_FLOW_TRUTH_DATA}/world_${condition}.oracle)
    viper_capture_run(${capture} PROGRAM world PROFILE ${PROJECT_SOURCE_DIR}/config/profiles/world.yaml
      CONDITION ${condition} ARGS --condition ${condition} --ego ${ego_${condition}} --frames ${frames_${condition}}
      --width 480 --height 270 ORACLE ${oracle} COMMENT "Capturing the world (${condition}) for the flow and box truth checks")
    list(APPEND VIPER_FLOW_TRUTH_FILES ${capture} ${oracle})
  endforeach()
  add_custom_target(flow_truth_captures DEPENDS ${VIPER_FLOW_TRUTH_FILES})

  viper_gtest(test_flow_against_oracle
    test/ground_truth/test_flow_against_oracle.cpp
    test/ground_truth/test_boxes_against_oracle.cpp
    test/ground_truth/oracle_truth.cpp
    DEFINITIONS
      VIPER_FLOW_TRUTH_DIR="${VIPER_FLOW_TRUTH_DATA}"
      VIPER_WORLD_LABELS="${PROJECT_SOURCE_DIR}/config/labels/world_labels.yaml"
      VIPER_CLASSES_CSV="${PROJECT_SOURCE_DIR}/config/viper_classes.csv"
    LINK viper_core gtest_main
    DEPENDS flow_truth_captures)
endif()
