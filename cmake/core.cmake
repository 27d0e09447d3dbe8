# The ROS-free core, one library a stage (docs/design.md): viper_capture_core (the frame record and
# its stream, the shader rewrite, the capture profile: all the capture layers load into a foreign
# program), viper_ground_truth (labels, objects, tracking, boxes, flow, camera, the checks of a
# capture) on it, viper_evaluation (the metrics and the report's tables) on that. viper_core is the
# three together. No OpenCV and no ROS: the report's PNG figures are viper_plots and viper_report
# (evaluation.cmake). test_stage_dependencies holds the stages' includes and the layers' libraries.
function(viper_core_library name)
  add_library(${name} ${ARGN})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR}/include)
  target_include_directories(${name} SYSTEM PUBLIC ${EIGEN3_INCLUDE_DIR})
  # The per-pixel kernels rely on loop vectorisation, which GCC 12 does fully only at -O3.
  target_compile_options(${name} PRIVATE -O3)
  viper_install(${name})
endfunction()

file(GLOB VIPER_CAPTURE_CORE_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/capture/*.cpp)
viper_core_library(viper_capture_core ${VIPER_CAPTURE_CORE_SOURCES})
target_link_libraries(viper_capture_core PRIVATE PkgConfig::ZSTD PkgConfig::LIBLZ4 PkgConfig::XXHASH PkgConfig::YAMLCPP)

file(GLOB VIPER_GROUND_TRUTH_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/ground_truth/*.cpp)
viper_core_library(viper_ground_truth ${VIPER_GROUND_TRUTH_SOURCES})
target_link_libraries(viper_ground_truth PUBLIC viper_capture_core PRIVATE PkgConfig::YAMLCPP)

file(GLOB VIPER_EVALUATION_SOURCES CONFIGURE_DEPENDS
  ${PROJECT_SOURCE_DIR}/src/evaluation/*.cpp
  ${PROJECT_SOURCE_DIR}/src/evaluation/metrics/*.cpp)
list(FILTER VIPER_EVALUATION_SOURCES EXCLUDE REGEX "/src/evaluation/plots\\.cpp$")
viper_core_library(viper_evaluation ${VIPER_EVALUATION_SOURCES})
target_link_libraries(viper_evaluation PUBLIC viper_ground_truth PRIVATE PkgConfig::YAMLCPP)

add_library(viper_core INTERFACE)
target_link_libraries(viper_core INTERFACE viper_capture_core viper_ground_truth viper_evaluation)
install(DIRECTORY include/viper/ DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # Unit tests of the core, by stage (the stages' folders also hold tests that run programs:
  # capture.cmake, ground_truth.cmake).
  set(VIPER_CORE_TESTS
    capture/test_capture_profile capture/test_capture_stream capture/test_capture_stream_codec
    capture/test_capture_stream_damage capture/test_camera_recovery
    capture/test_shader_rewrite
    ground_truth/test_capture_invariants ground_truth/test_resource_census ground_truth/test_boxes ground_truth/test_camera_model
    ground_truth/test_ego_motion ground_truth/test_flow ground_truth/test_flow_from_metres
    ground_truth/test_instance_pipeline ground_truth/test_ground_truth_pipeline
    ground_truth/test_objects_tracking ground_truth/test_oracle ground_truth/test_semantic_overlay
    evaluation/test_eval_report evaluation/test_metrics_equivalence evaluation/test_metrics_instance_odometry
    evaluation/test_metrics_semantic_flow evaluation/test_metric_iiou)
  foreach(t ${VIPER_CORE_TESTS})
    get_filename_component(name ${t} NAME)
    catkin_add_gtest(${name} ${PROJECT_SOURCE_DIR}/test/${t}.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} viper_core gtest_main)
  endforeach()
  # The stages' includes and the capture layers' libraries (docs/design.md, "Rules the layout keeps").
  catkin_add_gtest(test_stage_dependencies ${PROJECT_SOURCE_DIR}/test/house/test_stage_dependencies.cpp)
  target_compile_definitions(test_stage_dependencies PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    VIPER_INTERCEPT_LIB="$<TARGET_FILE:viper_intercept>" VIPER_VULKAN_LAYER_LIB="$<TARGET_FILE:viper_vulkan_layer>")
  target_link_libraries(test_stage_dependencies gtest_main)
  add_dependencies(test_stage_dependencies viper_intercept viper_vulkan_layer)
endif()
