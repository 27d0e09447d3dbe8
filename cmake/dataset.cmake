# Stage 5, dataset: VIPER's release layout (readers and writers in viper_dataset), export_flow,
# the player, the exporters (export_viper, viper_exporter) and viper_to_bag.
# viper_dataset: ROS-free readers and writers of dataset files (VIPER's release layout, its .npz
# flow, Middlebury .flo, its PNG/JPEG images and CSV files), and the export_flow command that fills
# that layout from a bag.
# (Their libraries are found in cmake/core_dependencies.cmake.)

# src/dataset by role (docs/design.md): bag/ (ROS bag files without ROS), formats/ (npy, .flo,
# float16, PNG, JPEG, zip and their deflate, atomic writes), layout/ (VIPER's release layout and its
# submission files), generation/ (dataset plans, sequence locks and markers, manifests, digests,
# the write queue), statistics/ (a library of its own: it needs the class table of
# viper_ground_truth and the line plots of viper_plots).
file(GLOB VIPER_DATASET_SOURCES CONFIGURE_DEPENDS
  ${PROJECT_SOURCE_DIR}/src/dataset/bag/*.cpp
  ${PROJECT_SOURCE_DIR}/src/dataset/formats/*.cpp
  ${PROJECT_SOURCE_DIR}/src/dataset/generation/*.cpp
  ${PROJECT_SOURCE_DIR}/src/dataset/layout/*.cpp)
# The submission files use Eigen and viper_core (poses in KITTI axes): a library of their own, below.
list(FILTER VIPER_DATASET_SOURCES EXCLUDE REGEX "/src/dataset/layout/(viper_submission|submission_poses)\\.cpp$")
# The layout writer takes the ground truth's core types (boxes, cameras, objects): a library of its
# own, below.
list(FILTER VIPER_DATASET_SOURCES EXCLUDE REGEX "/src/dataset/layout/(viper_layout_writer|viper_layout_geometry)\\.cpp$")
add_library(viper_dataset ${VIPER_DATASET_SOURCES})
target_include_directories(viper_dataset PUBLIC ${PROJECT_SOURCE_DIR}/include)
# Eigen (header-only): the KITTI labels' boxes (kitti_labels.h).
target_include_directories(viper_dataset SYSTEM PUBLIC ${EIGEN3_INCLUDE_DIR})
# The float16 loops vectorise only at -O3, and only when GCC 12 may execute the float operations
# of every branch (no floating-point exceptions are ever enabled here).
target_compile_options(viper_dataset PRIVATE -O3 -fno-trapping-math)
# PNG read through libpng (palette indices of class images must not be expanded to colors) and
# written with ISA-L and libdeflate (src/dataset/formats/deflate_writers.h); JPEG through OpenCV.
target_include_directories(viper_dataset SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
find_package(Threads REQUIRED)  # WriteQueue's workers
target_link_libraries(viper_dataset PUBLIC Threads::Threads)
target_link_libraries(viper_dataset PRIVATE PkgConfig::LIBLZ4 PkgConfig::XXHASH BZip2::BZip2 PkgConfig::LIBZIP PkgConfig::LIBDEFLATE viper_isal PkgConfig::LIBPNG PkgConfig::LIBJPEG PkgConfig::LIBCRYPTO PkgConfig::YAMLCPP opencv_core opencv_imgproc opencv_imgcodecs)
viper_lib_output(viper_dataset)
viper_install(viper_dataset)

# export_flow: 32FC2 flow messages of a bag -> VIPER layout (.npz) and/or .flo files.
add_executable(export_flow tools/export_flow.cpp)
target_include_directories(export_flow SYSTEM PRIVATE ${catkin_INCLUDE_DIRS} ${VIPER_ROSBAG_INCLUDE_DIRS})
target_link_libraries(export_flow viper_dataset viper_conversions ${catkin_LIBRARIES})
viper_program(export_flow)

# viper_dataset_statistics: a finished dataset's statistics, their CSV, PNG and Markdown report (ROS-free),
# and the dataset_statistics command (generate --merge writes them too).
viper_library(viper_dataset_statistics SOURCES src/dataset/statistics/dataset_statistics.cpp
  src/dataset/statistics/statistics_report.cpp src/dataset/statistics/statistics_plots.cpp
  LINK PUBLIC viper_dataset viper_ground_truth PRIVATE viper_plots)
add_executable(dataset_statistics tools/dataset_statistics.cpp)
target_include_directories(dataset_statistics SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
target_link_libraries(dataset_statistics viper_dataset_statistics ${catkin_LIBRARIES})
target_compile_definitions(dataset_statistics PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
viper_program(dataset_statistics)

# viper_layout_writer: ground truth (core types) into VIPER's release layout, and the layout's
# geometry (camera and box rows against poses and boxes); ROS-free. generate writes through it, and
# so do export_viper and the viper_exporter node, through ViperExporter's conversion of messages.
viper_library(viper_layout_writer SOURCES src/dataset/layout/viper_layout_writer.cpp
  src/dataset/layout/viper_layout_geometry.cpp LINK PUBLIC viper_dataset viper_ground_truth)

# viper_submission: VIPER's submission files (ROS-free; the poses in KITTI axes take the optical frame
# from viper_core), and the viper_submission command that writes them from a bag
# of predictions (docs/evaluate.md, "Submission files").
viper_library(viper_submission SOURCES src/dataset/layout/viper_submission.cpp
  src/dataset/layout/submission_poses.cpp LINK PUBLIC viper_dataset viper_core)
add_executable(viper_submission_tool tools/viper_submission.cpp)
set_target_properties(viper_submission_tool PROPERTIES OUTPUT_NAME viper_submission)
viper_program(viper_submission_tool)
target_include_directories(viper_submission_tool SYSTEM PRIVATE ${catkin_INCLUDE_DIRS} ${VIPER_ROSBAG_INCLUDE_DIRS})
target_link_libraries(viper_submission_tool viper_submission viper_evaluate_ros viper_conversions ${catkin_LIBRARIES})
add_dependencies(viper_submission_tool viper_generate_messages_cpp)

if(TARGET bench_flow_files)
  target_link_libraries(bench_flow_files viper_dataset)
endif()

if(CATKIN_ENABLE_TESTING)
  # Every test/dataset/test_*.cpp is a gtest. The numpy interop test runs the system python's
  # numpy (python3-numpy); the export test writes a bag and runs export_flow on it.
  file(GLOB VIPER_DATASET_TESTS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/dataset/test_*.cpp)
  foreach(t ${VIPER_DATASET_TESTS})
    get_filename_component(name ${t} NAME_WE)
    catkin_add_gtest(${name} ${t} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    if(TARGET ${name})
      # libxxhash: test_xxh32_streams's reference.
      target_link_libraries(${name} viper_dataset PkgConfig::LIBZIP PkgConfig::XXHASH gtest_main)
      target_compile_definitions(${name} PRIVATE
        VIPER_PYTHON="/usr/bin/python3"
        VIPER_NUMPY_INTEROP_SCRIPT="${PROJECT_SOURCE_DIR}/test/dataset/numpy_interop.py"
        VIPER_EXPORT_FLOW="$<TARGET_FILE:export_flow>")
    endif()
  endforeach()
  # test/dataset/test_viper_submission.cpp: generate's ground truth of the test bag, a bag of predictions
  # made from it, the viper_submission command on it, its files read back.
  if(TARGET test_viper_submission)
    target_include_directories(test_viper_submission SYSTEM PRIVATE ${catkin_INCLUDE_DIRS} ${VIPER_ROSBAG_INCLUDE_DIRS})
    target_link_libraries(test_viper_submission viper_submission viper_conversions ${catkin_LIBRARIES})
    target_compile_definitions(test_viper_submission PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      VIPER_GENERATE="$<TARGET_FILE:generate>" VIPER_SUBMISSION="$<TARGET_FILE:viper_submission_tool>")
    add_dependencies(test_viper_submission viper_submission_tool generate viper_generate_messages_cpp)
  endif()
  if(TARGET test_viper_submission_files)
    target_link_libraries(test_viper_submission_files viper_submission)
  endif()
  # The training formats' fixture (docs/training_formats.md): write_training_format_cases writes the
  # frames of test/dataset/training_format_cases.h, scripts/training_formats_reference.sh runs the
  # formats' reference code on them into test/dataset/data/training_formats, test_training_formats
  # checks the writers against it (OpenCV decodes the PNG files as the reference did).
  add_executable(write_training_format_cases test/dataset/write_training_format_cases.cpp)
  target_link_libraries(write_training_format_cases viper_dataset)
  viper_bin_output(write_training_format_cases)
  if(TARGET test_training_formats)
    target_include_directories(test_training_formats SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
    target_link_libraries(test_training_formats opencv_core opencv_imgcodecs)
  endif()
  if(TARGET test_export_flow)
    target_include_directories(test_export_flow SYSTEM PRIVATE ${catkin_INCLUDE_DIRS} ${VIPER_ROSBAG_INCLUDE_DIRS})
    target_link_libraries(test_export_flow ${catkin_LIBRARIES})
    add_dependencies(test_export_flow export_flow)
  endif()
endif()

# VIPER's release layout (docs/viper_layout.md): the player node + nodelet, the viper_to_bag and
# export_viper commands, their tests and benchmark. The ROS-free readers and writers (images, camera
# and box CSV, sequences) are part of viper_dataset (cmake/dataset.cmake globs src/dataset).

# test/dataset/test_viper_layout_writer.cpp: the layout writer on core types.
if(TARGET test_viper_layout_writer)
  target_link_libraries(test_viper_layout_writer viper_layout_writer)
endif()
# test/dataset/test_viper_images.cpp checks what OpenCV sees in our files.
if(TARGET test_viper_images)
  target_include_directories(test_viper_images SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  target_link_libraries(test_viper_images opencv_core opencv_imgcodecs)
endif()
# test/dataset/test_dataset_statistics.cpp: the statistics of a dataset it writes, their figures read
# back; test_generate_statistics.cpp: generate --merge on the tiny plan, counted again by the test.
foreach(t test_dataset_statistics test_generate_statistics)
  if(TARGET ${t})
    target_include_directories(${t} SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
    target_link_libraries(${t} viper_dataset_statistics opencv_imgcodecs)
    target_compile_definitions(${t} PRIVATE VIPER_CLASS_TABLE="${PROJECT_SOURCE_DIR}/config/viper_classes.csv"
      VIPER_DATASET_STATISTICS="$<TARGET_FILE:dataset_statistics>")
  endif()
endforeach()

# viper_layout_ros: layout <-> messages, the exporter, the player and the live exporter (nodes + nodelets).
viper_ros_library(viper_layout_ros SOURCES
  src/ros/dataset/viper_layout_conversions.cpp
  src/ros/dataset/viper_exporter.cpp
  src/ros/dataset/viper_bag_conversion.cpp
  src/ros/dataset/player.cpp
  src/ros/dataset/player_nodelet.cpp
  src/ros/dataset/export_roles.cpp
  src/ros/dataset/viper_exporter_node.cpp
  src/ros/dataset/viper_exporter_nodelet.cpp
  src/ros/dataset/sequence_generator.cpp
  SYSTEM_INCLUDES ${VIPER_ROSBAG_INCLUDE_DIRS} ${std_srvs_INCLUDE_DIRS}
  LINK viper_flow_ros viper_ground_truth_ros viper_geometry_ros viper_conversions viper_ros viper_core viper_dataset
    viper_layout_writer ${catkin_LIBRARIES})

viper_executable(player nodes/player_node.cpp LINK viper_layout_ros)
viper_executable(viper_exporter nodes/viper_exporter_node.cpp LINK viper_layout_ros)
viper_executable(viper_to_bag tools/viper_to_bag.cpp LINK viper_layout_ros)
viper_executable(export_viper tools/export_viper.cpp LINK viper_layout_ros)
# export_training: a ground-truth bag -> Cityscapes, COCO, KITTI files (docs/training_formats.md).
viper_executable(export_training tools/export_training.cpp LINK viper_layout_ros)
target_include_directories(export_training PRIVATE ${PROJECT_SOURCE_DIR}/tools)
target_compile_definitions(export_training PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
viper_executable(generate tools/generate.cpp LINK viper_layout_ros)
target_include_directories(viper_to_bag PRIVATE ${PROJECT_SOURCE_DIR}/tools)
target_include_directories(export_viper PRIVATE ${PROJECT_SOURCE_DIR}/tools)
target_include_directories(generate PRIVATE ${PROJECT_SOURCE_DIR}/tools)
target_compile_definitions(generate PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_link_libraries(generate viper_dataset_statistics)  # written by --merge
# Where the class table is found when the package is not on ROS_PACKAGE_PATH.
target_compile_definitions(viper_to_bag PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_compile_definitions(export_viper PRIVATE VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)
  # Plain gtest, no roscore: the converter and the exporter.
  catkin_add_gtest(test_viper_layout_conversions test/ros/test_viper_layout_conversions.cpp)
  if(TARGET test_viper_layout_conversions)
    target_link_libraries(test_viper_layout_conversions viper_layout_ros gtest_main)
  endif()
  # The export_viper command on bags written by the test.
  catkin_add_gtest(test_export_viper test/ros/test_export_viper.cpp)
  if(TARGET test_export_viper)
    target_link_libraries(test_export_viper viper_layout_ros gtest_main)
    target_compile_definitions(test_export_viper PRIVATE VIPER_EXPORT_VIPER="$<TARGET_FILE:export_viper>")
    add_dependencies(test_export_viper export_viper)
  endif()

  # The player tests' dataset (damage included), written at build time by our own writers.
  add_executable(make_viper_test_layout test/ros/make_viper_test_layout.cpp)
  target_link_libraries(make_viper_test_layout viper_dataset)
  set(VIPER_TEST_LAYOUT ${PROJECT_BINARY_DIR}/test_data/viper_layout)
  add_custom_command(OUTPUT ${VIPER_TEST_LAYOUT}/train/camera/001.csv
    COMMAND make_viper_test_layout --out ${VIPER_TEST_LAYOUT}
    DEPENDS make_viper_test_layout
    COMMENT "Writing the player tests' VIPER layout")
  add_custom_target(viper_test_layout DEPENDS ${VIPER_TEST_LAYOUT}/train/camera/001.csv)

  viper_add_tester(viper_layout_tester test/ros/viper_layout_tester.cpp viper_layout_ros)
  target_sources(viper_layout_tester PRIVATE test/ros/viper_layout_roundtrip.cpp)
  if(TARGET tests)
    add_dependencies(tests viper_test_layout)
  endif()

  set(_layout_deps viper_layout_tester viper_test_layout player viper_layout_ros)
  add_rostest(test/ros/viper_player.test ARGS layout:=${VIPER_TEST_LAYOUT} DEPENDENCIES ${_layout_deps})
  add_rostest(test/ros/viper_player_nodelet.test ARGS layout:=${VIPER_TEST_LAYOUT} DEPENDENCIES ${_layout_deps})
  add_rostest(test/ros/viper_player_loop.test ARGS layout:=${VIPER_TEST_LAYOUT} DEPENDENCIES ${_layout_deps})
  add_rostest(test/ros/viper_layout_roundtrip.test
    ARGS export_viper:=${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}/export_viper
         viper_to_bag:=${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}/viper_to_bag
         generate:=${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}/generate
    DEPENDENCIES viper_layout_tester export_viper viper_to_bag generate viper_ground_truth_ros viper_flow_ros viper_geometry_ros)

  # The same round trip on the world: 20 frames of the town (day, driving) captured at build time and
  # turned into a raw bag by capture_to_bag (cmake/capture.cmake).
  set(VIPER_WORLD_ROUNDTRIP_CAPTURE ${PROJECT_BINARY_DIR}/test_data/world_roundtrip.vcap)
  set(VIPER_WORLD_RAW_BAG ${PROJECT_BINARY_DIR}/test_data/world_raw.bag)
  set(_world_roundtrip_run PROGRAM world PROFILE ${PROJECT_SOURCE_DIR}/config/profiles/world.yaml CONDITION day
    ARGS --condition day --ego drive --frames 20 --width 480 --height 270)
  viper_capture_run(${VIPER_WORLD_ROUNDTRIP_CAPTURE} CODEC zstd ${_world_roundtrip_run}
    COMMENT "Capturing the world for the VIPER layout round trip")
  add_custom_command(OUTPUT ${VIPER_WORLD_RAW_BAG}
    COMMAND capture_to_bag ${VIPER_WORLD_ROUNDTRIP_CAPTURE} --output ${VIPER_WORLD_RAW_BAG}
    DEPENDS capture_to_bag ${VIPER_WORLD_ROUNDTRIP_CAPTURE}
    COMMENT "Converting the world capture into a raw bag")
  # The same run captured with --codec lz4 (the world is deterministic at a fixed --fps; the one
  # above is zstd): the reading test compares its frames with the zstd capture's.
  set(VIPER_WORLD_LZ4_CAPTURE ${PROJECT_BINARY_DIR}/test_data/world_roundtrip_lz4.vcap)
  viper_capture_run(${VIPER_WORLD_LZ4_CAPTURE} CODEC lz4 ${_world_roundtrip_run}
    COMMENT "Capturing the world with LZ4 for the capture reading test")
  add_custom_target(world_raw_bag DEPENDS ${VIPER_WORLD_RAW_BAG})
  add_custom_target(world_lz4_capture DEPENDS ${VIPER_WORLD_LZ4_CAPTURE})
  if(TARGET tests)
    add_dependencies(tests world_raw_bag world_lz4_capture)
  endif()
  # The capture stage's test of reading frames without their images, on this real capture and its LZ4
  # twin (the targets world_raw_bag and world_lz4_capture make them).
  catkin_add_gtest(test_capture_without_images test/capture/test_capture_without_images.cpp)
  target_link_libraries(test_capture_without_images viper_core gtest_main PkgConfig::ZSTD)
  target_compile_definitions(test_capture_without_images PRIVATE VIPER_WORLD_CAPTURE="${VIPER_WORLD_ROUNDTRIP_CAPTURE}"
    VIPER_WORLD_LZ4_CAPTURE="${VIPER_WORLD_LZ4_CAPTURE}")
  add_dependencies(test_capture_without_images world_raw_bag world_lz4_capture)
  # (Its own small .test file: the test's name is made of its arguments, and these paths would make it
  # longer than a file name may be.)
  add_rostest(test/ros/viper_layout_roundtrip_world.test
    ARGS test_data:=${PROJECT_BINARY_DIR}/test_data bin:=${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}
    DEPENDENCIES viper_layout_tester export_viper viper_to_bag generate viper_ground_truth_ros viper_flow_ros viper_geometry_ros world_raw_bag)

  # The generate command on the world's capture and its raw bag (no roscore; test/dataset/test_*.cpp
  # are gtests, above).
  if(TARGET test_generate)
    target_compile_definitions(test_generate PRIVATE
      VIPER_GENERATE="$<TARGET_FILE:generate>"
      VIPER_EXPORT_TRAINING="$<TARGET_FILE:export_training>"
      VIPER_TEST_DATA="${PROJECT_BINARY_DIR}/test_data"
      VIPER_WORLD_LABELS="${PROJECT_SOURCE_DIR}/config/labels/world_labels.yaml")
    add_dependencies(test_generate generate export_training world_raw_bag)
  endif()

  # generate --plan on the tiny preset: the world under capture, whole and sharded (and merged with its
  # statistics: test_generate_statistics).
  foreach(t test_generate_plan test_generate_statistics)
    if(TARGET ${t})
      target_compile_definitions(${t} PRIVATE VIPER_GENERATE="$<TARGET_FILE:generate>")
      add_dependencies(${t} generate dataset_statistics viper_capture viper_intercept world)
    endif()
  endforeach()
  if(TARGET test_generate_plan)
    target_link_libraries(test_generate_plan PkgConfig::YAMLCPP)
  endif()

  # Geographically disjoint splits: the world's routes of the viper preset and the tiny plan generated
  # end to end (its ground-truth bags' camera poses).
  if(TARGET test_city_splits)
    target_include_directories(test_city_splits SYSTEM PRIVATE ${catkin_INCLUDE_DIRS})
    target_link_libraries(test_city_splits ${catkin_LIBRARIES})
    target_compile_definitions(test_city_splits PRIVATE VIPER_GENERATE="$<TARGET_FILE:generate>"
      VIPER_WORLD="$<TARGET_FILE:world>")
    add_dependencies(test_city_splits generate viper_capture viper_intercept world)
  endif()

  # That bag holds what capture_bridge publishes for the same capture, message for message.
  viper_add_tester(capture_to_bag_tester test/ros/capture_to_bag_tester.cpp viper_layout_ros)
  add_rostest(test/ros/capture_to_bag.test
    ARGS capture:=${VIPER_WORLD_ROUNDTRIP_CAPTURE} bag:=${VIPER_WORLD_RAW_BAG}
    DEPENDENCIES capture_to_bag_tester capture_bridge world_raw_bag)
  # And bag_player (node and nodelet) plays that bag message for message.
  add_rostest(test/ros/bag_player.test ARGS bag:=${VIPER_WORLD_RAW_BAG}
    DEPENDENCIES capture_to_bag_tester bag_player viper_ros world_raw_bag)
  add_rostest(test/ros/bag_player.test ARGS bag:=${VIPER_WORLD_RAW_BAG} nodelet:=true
    DEPENDENCIES capture_to_bag_tester bag_player viper_ros world_raw_bag)
  # Back-pressure (~pace_topic): bag_player and capture_bridge at rate 0 feeding a slow consumer lose
  # no frame when paced; unpaced, the same consumer loses frames.
  viper_add_tester(back_pressure_tester test/ros/back_pressure_tester.cpp viper_ros)
  add_rostest(test/ros/back_pressure.test ARGS bag:=${VIPER_WORLD_RAW_BAG}
    DEPENDENCIES back_pressure_tester viper_ros world_raw_bag)
  add_rostest(test/ros/back_pressure.test ARGS bag:=${VIPER_WORLD_RAW_BAG} paced:=false
    DEPENDENCIES back_pressure_tester viper_ros world_raw_bag)
  add_rostest(test/ros/back_pressure.test ARGS capture:=${VIPER_WORLD_ROUNDTRIP_CAPTURE}
    DEPENDENCIES back_pressure_tester viper_ros world_raw_bag)
  # Overload: the ground-truth nodelets fed far faster than they go lose frames visibly, never let
  # flow span a gap, stay bounded in memory and recover.
  viper_add_tester(overload_tester test/ros/overload_tester.cpp)
  add_rostest(test/ros/overload.test ARGS bag:=${VIPER_WORLD_RAW_BAG}
    DEPENDENCIES overload_tester viper_ground_truth_ros viper_flow_ros world_raw_bag)
  # The live exporters (viper_exporter node, export_viper --live) on a full disk.
  viper_add_tester(viper_exporter_full_disk_tester test/ros/viper_exporter_full_disk_tester.cpp viper_dataset)
  add_rostest(test/ros/viper_exporter_full_disk.test ARGS bin:=${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION}
    DEPENDENCIES viper_exporter_full_disk_tester viper_exporter export_viper)
  # With ~loop it plays the bag again and again, stamps continuing: on that bag (times = stamps) and on
  # the committed test bag (recorded: its bag times span less than its stamps).
  # (console_bridge: the tf test reads tf2's warnings there.)
  viper_add_tester(bag_player_loop_tester test/ros/bag_player_loop_tester.cpp viper_layout_ros console_bridge)
  add_rostest(test/ros/bag_player_loop.test ARGS bag:=${VIPER_WORLD_RAW_BAG} nodelet:=true
    DEPENDENCIES bag_player_loop_tester bag_player viper_ros world_raw_bag)
  add_rostest(test/ros/bag_player_loop.test ARGS bag:=${PROJECT_SOURCE_DIR}/bags/test_scene_raw.bag
    DEPENDENCIES bag_player_loop_tester bag_player viper_ros)
  # ... tf included: on viper_to_bag's bag of the player tests' layout (its intact sequence 002, with
  # /tf and /tf_static), the transforms' stamps move on with /clock on every pass.
  set(VIPER_TEST_LAYOUT_BAG ${PROJECT_BINARY_DIR}/test_data/viper_layout_002.bag)
  add_custom_command(OUTPUT ${VIPER_TEST_LAYOUT_BAG}
    COMMAND viper_to_bag --root ${VIPER_TEST_LAYOUT} --out ${VIPER_TEST_LAYOUT_BAG} --sequence 002 --modalities img,camera
    DEPENDS viper_to_bag ${VIPER_TEST_LAYOUT}/train/camera/001.csv
    COMMENT "Converting the player tests' layout into a bag with tf")
  add_custom_target(viper_layout_tf_bag DEPENDS ${VIPER_TEST_LAYOUT_BAG})
  if(TARGET tests)
    add_dependencies(tests viper_layout_tf_bag)
  endif()
  add_rostest(test/ros/bag_player_loop_tf.test ARGS bag:=${VIPER_TEST_LAYOUT_BAG}
    DEPENDENCIES bag_player_loop_tester bag_player viper_ros viper_layout_tf_bag)
  # ... and names a damaged chunk, keeping what came before it.
  set(VIPER_WORLD_DAMAGED_BAG ${PROJECT_BINARY_DIR}/test_data/world_raw_damaged.bag)
  add_custom_command(OUTPUT ${VIPER_WORLD_DAMAGED_BAG}
    COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/ros/damage_file.py ${VIPER_WORLD_RAW_BAG} ${VIPER_WORLD_DAMAGED_BAG}
    DEPENDS ${VIPER_WORLD_RAW_BAG} ${PROJECT_SOURCE_DIR}/test/ros/damage_file.py
    COMMENT "Damaging a copy of the world raw bag")
  add_custom_target(world_raw_damaged_bag DEPENDS ${VIPER_WORLD_DAMAGED_BAG})
  # The damaged bag's command names the raw bag as a file, which brings the raw bag's command into
  # this target too: without the order, make -j runs capture_to_bag twice at once on the same
  # output and the bag's index comes out broken ("Error reading INDEX_DATA header").
  add_dependencies(world_raw_damaged_bag world_raw_bag)
  if(TARGET tests)
    add_dependencies(tests world_raw_damaged_bag)
  endif()
  add_rostest(test/ros/bag_player_damaged.test
    ARGS bag:=${VIPER_WORLD_DAMAGED_BAG} intact_bag:=${VIPER_WORLD_RAW_BAG}
    DEPENDENCIES capture_to_bag_tester bag_player world_raw_damaged_bag)
  roslaunch_add_file_check(launch/viper_player.launch root:=/tmp/viper)
  roslaunch_add_file_check(launch/view_bag.launch bag:=/tmp/viper/train/bag/001.bag)
endif()

# bench/bench_viper_layout.cpp (built by cmake/bench.cmake when Google Benchmark is there).
# bench/bench_bag_writer.cpp: rosbag against BagFileWriter on a ground-truth bag's messages.
if(TARGET bench_bag_writer)
  target_include_directories(bench_bag_writer SYSTEM PRIVATE ${catkin_INCLUDE_DIRS} ${VIPER_ROSBAG_INCLUDE_DIRS})
  target_link_libraries(bench_bag_writer viper_dataset ${catkin_LIBRARIES})
endif()
# bench/bench_bag_reader.cpp: rosbag::View against BagFileReader, reading a bag as bag_player does
# (its messages typed: viper_ros brings the message headers and libraries).
if(TARGET bench_bag_reader)
  # viper_dataset: the reader's side-by-side XXH32 (BM_Xxh32*), libxxhash: the one it replaces.
  target_link_libraries(bench_bag_reader viper_ros viper_dataset PkgConfig::XXHASH)
endif()
if(TARGET bench_viper_layout)
  target_link_libraries(bench_viper_layout viper_layout_ros)
endif()
