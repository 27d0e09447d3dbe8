# Ground truth of the scene's geometry: surface normals per pixel and labelled point clouds.
# Cores in viper_core (src/ground_truth/normals.cpp, labelled_cloud.cpp); docs/geometry_nodes.md.
if(CATKIN_ENABLE_TESTING)
  foreach(t test_normals test_labelled_cloud)
    viper_gtest(${t} test/ground_truth/${t}.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} LINK viper_core gtest_main)
  endforeach()
  # Normals against the oracle's triangles, on the world captures of the flow truth checks
  # (ground_truth.cmake).
  viper_gtest(test_normals_against_oracle
    test/ground_truth/test_normals_against_oracle.cpp
    test/ground_truth/oracle_truth.cpp
    DEFINITIONS VIPER_FLOW_TRUTH_DIR="${VIPER_FLOW_TRUTH_DATA}"
    LINK viper_core gtest_main
    DEPENDS flow_truth_captures)
endif()
# viper_geometry_ros: the normals, labelled cloud and amodal nodes and their nodelets, each computing only
# while its output has subscribers. Cores: src/ground_truth/normals.cpp, labelled_cloud.cpp.
viper_ros_library(viper_geometry_ros SOURCES
  src/ros/ground_truth/normals_node.cpp
  src/ros/ground_truth/labelled_cloud_node.cpp
  src/ros/ground_truth/geometry_nodelets.cpp
  src/ros/ground_truth/amodal_node.cpp
  src/ros/ground_truth/amodal_nodelet.cpp
  LINK viper_ground_truth_ros viper_ros viper_core ${catkin_LIBRARIES})
foreach(node normals labelled_cloud amodal)
  viper_executable(${node} nodes/${node}_node.cpp LINK viper_geometry_ros)
endforeach()
if(CATKIN_ENABLE_TESTING)
  # The committed raw bag through replay.launch's nodelets, fed and checked by geometry_tester.
  viper_add_tester(geometry_tester test/ros/geometry_tester.cpp)
  add_rostest(test/ros/geometry_replay.test DEPENDENCIES geometry_tester viper_geometry_ros viper_ground_truth_ros)
  roslaunch_add_file_check(launch/view_bag.launch bag:=gt.bag normals:=true)
  # The amodal node's message step on bad input; no roscore.
  catkin_add_gtest(test_amodal_message_step test/ros/test_amodal_message_step.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  target_link_libraries(test_amodal_message_step viper_geometry_ros gtest_main)
  # The amodal node on the committed raw bag, checked against the instances node's images.
  viper_add_tester(amodal_tester test/ros/amodal_tester.cpp viper_conversions)
  add_rostest(test/ros/amodal_replay.test DEPENDENCIES amodal_tester viper_geometry_ros viper_ground_truth_ros)
endif()

