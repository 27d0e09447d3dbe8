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
    add_custom_command(OUTPUT ${capture} ${oracle}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${VIPER_FLOW_TRUTH_DATA}
      COMMAND $<TARGET_FILE:viper_capture> --output ${capture} --profile ${PROJECT_SOURCE_DIR}/config/profiles/world.yaml
              --condition ${condition} --fps 15 -- $<TARGET_FILE:world> --condition ${condition} --ego ${ego_${condition}}
              --frames ${frames_${condition}} --width 480 --height 270 --oracle ${oracle}
      DEPENDS viper_capture viper_intercept world
      COMMENT "Capturing the world (${condition}) for the flow and box truth checks")
    list(APPEND VIPER_FLOW_TRUTH_FILES ${capture} ${oracle})
  endforeach()
  add_custom_target(flow_truth_captures DEPENDS ${VIPER_FLOW_TRUTH_FILES})

  catkin_add_gtest(test_flow_against_oracle
    test/ground_truth/test_flow_against_oracle.cpp
    test/ground_truth/test_boxes_against_oracle.cpp
    test/ground_truth/oracle_truth.cpp)
  if(TARGET test_flow_against_oracle)
    target_link_libraries(test_flow_against_oracle viper_core gtest_main)
    target_compile_definitions(test_flow_against_oracle PRIVATE
      VIPER_FLOW_TRUTH_DIR="${VIPER_FLOW_TRUTH_DATA}"
      VIPER_WORLD_LABELS="${PROJECT_SOURCE_DIR}/config/labels/world_labels.yaml"
      VIPER_CLASSES_CSV="${PROJECT_SOURCE_DIR}/config/viper_classes.csv")
    add_dependencies(test_flow_against_oracle flow_truth_captures)
  endif()
endif()
