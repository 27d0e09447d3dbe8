# Stage 4, evaluation: the evaluate node and its report, and the reference baselines it scores.

# The evaluate node + nodelet (scores perception topics against the ground truth) and its report.
# Core: src/evaluation/evaluation.cpp, src/evaluation/eval_report.cpp (viper_evaluation). docs/evaluate.md.
find_package(std_srvs REQUIRED)
find_package(opencv_apps REQUIRED)  # opencv_apps/FlowArrayStamped (Debian: libopencv-apps-dev)

# viper_plots: line plots drawn as images (OpenCV), shared by the report and the dataset statistics;
# viper_report: the report's PNG figures. Both kept out of the core.
viper_library(viper_plots SOURCES src/report/plot_image.cpp SYSTEM_INCLUDES ${OpenCV_INCLUDE_DIRS}
  LINK PUBLIC opencv_core opencv_imgproc opencv_imgcodecs)
viper_library(viper_report SOURCES src/evaluation/plots.cpp SYSTEM_INCLUDES ${OpenCV_INCLUDE_DIRS}
  LINK PUBLIC viper_evaluation viper_plots)

viper_ros_library(viper_evaluate_ros SOURCES
  src/ros/evaluation/evaluate_inputs.cpp
  src/ros/evaluation/evaluate.cpp
  src/ros/evaluation/evaluate_joins.cpp
  src/ros/evaluation/evaluate_nodelet.cpp
  SYSTEM_INCLUDES ${std_srvs_INCLUDE_DIRS} ${opencv_apps_INCLUDE_DIRS}
  LINK viper_report viper_ground_truth_ros viper_core ${catkin_LIBRARIES})
viper_executable(evaluate nodes/evaluate_node.cpp LINK viper_evaluate_ros)

if(CATKIN_ENABLE_TESTING)
  # Plain gtests: the figures, and the node's input checks.
  catkin_add_gtest(test_eval_plots test/ros/test_eval_plots.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  target_link_libraries(test_eval_plots viper_report gtest_main)
  catkin_add_gtest(test_evaluate_inputs test/ros/test_evaluate_inputs.cpp)
  target_link_libraries(test_evaluate_inputs viper_evaluate_ros gtest_main)

  # rostests: the committed raw bag through replay.launch, a fake perception made by the tester
  # (ground truth republished, or corrupted in known ways), scored by evaluate (node and nodelet).
  viper_add_tester(evaluate_tester test/ros/evaluate_tester.cpp viper_conversions)
  viper_add_tester(evaluate_bad_input_tester test/ros/evaluate_bad_input_tester.cpp)
  foreach(tester evaluate_tester evaluate_bad_input_tester)
    target_include_directories(${tester} SYSTEM PRIVATE ${std_srvs_INCLUDE_DIRS} ${opencv_apps_INCLUDE_DIRS})
  endforeach()
  set(_evaluate_test_deps evaluate_tester evaluate viper_evaluate_ros viper_flow_ros viper_ground_truth_ros)
  add_rostest(test/ros/evaluate_perfect.test DEPENDENCIES ${_evaluate_test_deps})
  add_rostest(test/ros/evaluate_corrupted.test DEPENDENCIES ${_evaluate_test_deps})
  add_rostest(test/ros/evaluate_bad_input.test DEPENDENCIES evaluate_bad_input_tester evaluate)
  roslaunch_add_file_check(launch/evaluate.launch bag:=raw.bag label_table:=labels.yaml)

  # Parity with cityscapesScripts (docs/evaluate.md): write_parity_cases writes the inputs (committed
  # under test/evaluation/data/cityscapes_parity), scripts/cityscapes_parity.py runs the reference
  # on them into reference.csv, test_cityscapes_parity scores them here and compares.
  add_executable(write_parity_cases test/evaluation/write_parity_cases.cpp)
  target_link_libraries(write_parity_cases viper_dataset)
  viper_bin_output(write_parity_cases)
  catkin_add_gtest(test_cityscapes_parity test/evaluation/test_cityscapes_parity.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  target_link_libraries(test_cityscapes_parity viper_dataset viper_core gtest_main)
endif()

# Reference baselines for the benchmark (docs/baselines.md): flow_baseline (OpenCV dense optical
# flow) and vo_baseline (monocular visual odometry), nodes + nodelets in viper_baselines_ros.
# OpenCV's config (found in CMakeLists.txt) imports every installed module; these come with libopencv-dev.
foreach(module opencv_video opencv_calib3d opencv_dnn)
  if(NOT TARGET ${module})
    message(FATAL_ERROR "baselines need ${module} (Debian: libopencv-dev, libopencv-dnn-dev)")
  endif()
endforeach()

# viper_segmentation: the segmentation baseline's network (OpenCV DNN) and its instances, no ROS.
viper_library(viper_segmentation SOURCES src/baselines/segmentation_model.cpp SYSTEM_INCLUDES ${OpenCV_INCLUDE_DIRS}
  LINK PUBLIC viper_core opencv_core opencv_imgproc opencv_dnn)

viper_ros_library(viper_baselines_ros SOURCES
  src/ros/baselines/image_input.cpp
  src/ros/baselines/flow_baseline.cpp
  src/ros/baselines/vo_baseline.cpp
  src/ros/baselines/segmentation_baseline.cpp
  src/ros/baselines/baselines_nodelets.cpp
  SYSTEM_INCLUDES ${OpenCV_INCLUDE_DIRS}
  LINK viper_segmentation viper_conversions viper_core ${catkin_LIBRARIES}
    opencv_core opencv_imgproc opencv_video opencv_calib3d)

foreach(node flow_baseline vo_baseline segmentation_baseline)
  viper_executable(${node} nodes/${node}_node.cpp LINK viper_baselines_ros)
endforeach()
if(CATKIN_ENABLE_TESTING)
  # The baselines' camera input through cv_bridge: every encoding they take, bad messages refused.
  catkin_add_gtest(test_image_input test/ros/test_image_input.cpp)
  target_link_libraries(test_image_input viper_baselines_ros gtest_main)
endif()
# The segmentation baseline's trained networks and their training logs (scripts/train_segmentation.py).
install(DIRECTORY models DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  # The committed raw bag through replay.launch + baselines.launch, fed and scored by baselines_tester.
  viper_add_tester(baselines_tester test/ros/baselines_tester.cpp viper_conversions)
  add_rostest(test/ros/baselines.test
    DEPENDENCIES baselines_tester viper_baselines_ros viper_flow_ros viper_ground_truth_ros)
  roslaunch_add_file_check(launch/baselines.launch)

  # The segmentation baseline's held-out frames: the test region of the city, three conditions,
  # generated at build time (about 30 s) from test/evaluation/data/segmentation_test_plan.yaml.
  set(VIPER_SEGMENTATION_TEST_LAYOUT ${PROJECT_BINARY_DIR}/test_data/segmentation)
  set(_segmentation_plan ${PROJECT_SOURCE_DIR}/test/evaluation/data/segmentation_test_plan.yaml)
  add_custom_command(OUTPUT ${VIPER_SEGMENTATION_TEST_LAYOUT}/test/003.done
    COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/test_data
    COMMAND $<TARGET_FILE:generate> --plan ${_segmentation_plan} --out ${VIPER_SEGMENTATION_TEST_LAYOUT}
            --outputs layout --img-format png --no-flow > ${PROJECT_BINARY_DIR}/test_data/segmentation.log
    DEPENDS generate viper_capture viper_intercept world ${_segmentation_plan}
    COMMENT "Generating the segmentation baseline's held-out frames")
  add_custom_target(segmentation_test_layout DEPENDS ${VIPER_SEGMENTATION_TEST_LAYOUT}/test/003.done)
  if(TARGET tests)
    add_dependencies(tests segmentation_test_layout)
  endif()
  set(_segmentation_defs VIPER_SEGMENTATION_TEST_LAYOUT="${VIPER_SEGMENTATION_TEST_LAYOUT}"
    VIPER_MODELS_DIR="${PROJECT_SOURCE_DIR}/models" VIPER_CLASSES_CSV="${PROJECT_SOURCE_DIR}/config/viper_classes.csv")
  catkin_add_gtest(test_segmentation_model test/evaluation/test_segmentation_model.cpp)
  target_link_libraries(test_segmentation_model viper_segmentation viper_dataset gtest_main)
  target_compile_definitions(test_segmentation_model PRIVATE ${_segmentation_defs})
  add_dependencies(test_segmentation_model segmentation_test_layout)
  # The nodelet on those frames and on bad images, checked by segmentation_baseline_tester.
  viper_add_tester(segmentation_baseline_tester test/ros/segmentation_baseline_tester.cpp viper_dataset
    viper_core opencv_core opencv_imgproc)
  target_include_directories(segmentation_baseline_tester SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  target_compile_definitions(segmentation_baseline_tester PRIVATE ${_segmentation_defs})
  add_rostest(test/ros/segmentation_baseline.test
    DEPENDENCIES segmentation_baseline_tester segmentation_test_layout segmentation_baseline viper_baselines_ros)
  roslaunch_add_file_check(launch/benchmark_baselines.launch capture:=world.vcap report_dir:=/tmp/report)
  roslaunch_add_file_check(launch/benchmark_segmentation.launch capture:=world.vcap label_table:=labels.yaml
    report_dir:=/tmp/report)
endif()
