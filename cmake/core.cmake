# viper_core: the ROS-free library, by stage: capture (format, shader rewrite, profile), ground truth
# (objects, tracking, boxes, flow, camera, checks), evaluation (metrics, report; the plots, which
# need OpenCV, are viper_report: evaluation.cmake).
file(GLOB VIPER_CORE_SOURCES CONFIGURE_DEPENDS
  ${PROJECT_SOURCE_DIR}/src/capture/*.cpp
  ${PROJECT_SOURCE_DIR}/src/ground_truth/*.cpp
  ${PROJECT_SOURCE_DIR}/src/evaluation/*.cpp
  ${PROJECT_SOURCE_DIR}/src/evaluation/metrics/*.cpp)
list(FILTER VIPER_CORE_SOURCES EXCLUDE REGEX "/src/evaluation/plots\\.cpp$")
add_library(viper_core ${VIPER_CORE_SOURCES})
target_include_directories(viper_core PUBLIC ${PROJECT_SOURCE_DIR}/include)
# The per-pixel kernels rely on loop vectorisation, which GCC 12 does fully only at -O3.
target_compile_options(viper_core PRIVATE -O3)
target_include_directories(viper_core SYSTEM PUBLIC ${EIGEN3_INCLUDE_DIR})
# Deliberately no OpenCV and no ROS: the capture layer preloads this library into foreign programs.
target_link_libraries(viper_core PRIVATE PkgConfig::ZSTD PkgConfig::LIBLZ4 PkgConfig::XXHASH PkgConfig::YAMLCPP)
install(TARGETS viper_core
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(DIRECTORY include/viper/ DESTINATION ${CATKIN_PACKAGE_INCLUDE_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # Unit tests of the core, by stage (the stages' folders also hold tests that run programs:
  # capture.cmake, ground_truth.cmake).
  set(VIPER_CORE_TESTS
    capture/test_capture_profile capture/test_capture_stream capture/test_capture_stream_codec
    capture/test_capture_stream_damage capture/test_camera_recovery
    capture/test_resource_census capture/test_shader_rewrite
    ground_truth/test_capture_invariants ground_truth/test_boxes ground_truth/test_camera_model
    ground_truth/test_ego_motion ground_truth/test_flow ground_truth/test_flow_from_metres
    ground_truth/test_instance_pipeline
    ground_truth/test_objects_tracking ground_truth/test_oracle ground_truth/test_semantic_overlay
    evaluation/test_eval_report evaluation/test_metrics_equivalence evaluation/test_metrics_instance_odometry
    evaluation/test_metrics_semantic_flow evaluation/test_metric_iiou)
  foreach(t ${VIPER_CORE_TESTS})
    get_filename_component(name ${t} NAME)
    catkin_add_gtest(${name} ${PROJECT_SOURCE_DIR}/test/${t}.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} viper_core gtest_main)
  endforeach()
endif()
