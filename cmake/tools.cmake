# Command-line tools of the package (run with rosrun viper NAME).
add_executable(capture_info tools/capture_info.cpp)
target_link_libraries(capture_info viper_core)
set_target_properties(capture_info PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS capture_info RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

add_executable(make_label_table tools/make_label_table.cpp)
target_link_libraries(make_label_table viper_core)
set_target_properties(make_label_table PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS make_label_table RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
