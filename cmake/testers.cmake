# viper_add_tester(NAME SOURCE [LIB ...]): the gtest executable a rostest (.test file) starts, built
# with the tests (not with `all`) into the package's bin folder, where rostest finds it; linked with
# the LIBs, roscpp and friends and gtest, after viper's messages are generated.
function(viper_add_tester name source)
  add_executable(${name} EXCLUDE_FROM_ALL ${source})
  target_include_directories(${name} SYSTEM PRIVATE ${GTEST_INCLUDE_DIRS} ${VIPER_ROSBAG_INCLUDE_DIRS})
  target_link_libraries(${name} ${ARGN} ${catkin_LIBRARIES} ${GTEST_LIBRARIES})
  add_dependencies(${name} viper_generate_messages_cpp)
  viper_bin_output(${name})
  if(TARGET tests)
    add_dependencies(tests ${name})
  endif()
endfunction()
