# viper_conversions: the one converter between ROS messages and the core's types (frames, draws,
# meshes, images, poses, flow, objects, boxes) and the one image check; every ROS library links it.
# The dataset types it converts (Image8, FlowImage) are plain structs: no link to viper_dataset.
file(GLOB VIPER_CONVERSIONS_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/ros/conversions/*.cpp)
viper_ros_library(viper_conversions SOURCES ${VIPER_CONVERSIONS_SOURCES} LINK viper_core ${catkin_LIBRARIES})

if(CATKIN_ENABLE_TESTING)
  # Round trips core -> message -> core for every pair, a whole frame included; no roscore.
  foreach(t test_image_conversions test_frame_conversions test_pose_conversions test_flow_conversions
            test_object_conversions test_image_msg_pool test_ground_truth_conversions)
    catkin_add_gtest(${t} test/ros/conversions/${t}.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    target_link_libraries(${t} viper_conversions gtest_main)
  endforeach()
endif()
