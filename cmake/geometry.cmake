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
