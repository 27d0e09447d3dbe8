# viper_add_tester(NAME SOURCE [LIB ...]): the gtest executable a rostest (.test file) starts, built
# with the tests (not with `all`) into the package's bin folder, where rostest finds it; linked with
# the LIBs, roscpp and friends and gtest, after viper's messages are generated.
# rosbag/bag.h includes pluginlib and class_loader, which Debian installs under their own folders.
find_package(pluginlib REQUIRED)
find_package(class_loader REQUIRED)
function(viper_add_tester name source)
  add_executable(${name} EXCLUDE_FROM_ALL ${source})
  target_include_directories(${name} SYSTEM PRIVATE ${GTEST_INCLUDE_DIRS} ${pluginlib_INCLUDE_DIRS}
    ${class_loader_INCLUDE_DIRS})
  target_link_libraries(${name} ${ARGN} ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  add_dependencies(${name} viper_generate_messages_cpp)
  viper_bin_output(${name})
  if(TARGET tests)
    add_dependencies(tests ${name})
  endif()
endfunction()
