# The shapes of target every stage's file repeats, one call each: where a target is built (the devel
# space, where rosrun and the nodelet manager find it), how it is installed, and the package's two
# kinds of library (ROS-free, ROS layer).

# rosbag/bag.h includes pluginlib and class_loader, which Debian installs under their own folders:
# VIPER_ROSBAG_INCLUDE_DIRS, the system headers of every target that includes it.
find_package(pluginlib REQUIRED)
find_package(class_loader REQUIRED)
set(VIPER_ROSBAG_INCLUDE_DIRS ${pluginlib_INCLUDE_DIRS} ${class_loader_INCLUDE_DIRS})

# viper_lib_output(TARGET...): shared libraries into the devel space's lib folder.
function(viper_lib_output)
  set_target_properties(${ARGN} PROPERTIES
    LIBRARY_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION})
endfunction()

# viper_bin_output(TARGET...): executables into the devel space's bin folder.
function(viper_bin_output)
  set_target_properties(${ARGN} PROPERTIES
    RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
endfunction()

# viper_install(TARGET...): libraries into the package's lib folder, executables into its bin folder.
function(viper_install)
  install(TARGETS ${ARGN}
    ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
    RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endfunction()

# viper_program(TARGET...): executables users run: built into the devel space, installed.
function(viper_program)
  viper_bin_output(${ARGN})
  viper_install(${ARGN})
endfunction()

# viper_executable(NAME SOURCE... [LINK LIB...]): a node's main or a command-line tool, linked to the
# LIBs (plain signature), built into the devel space and installed.
function(viper_executable name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "LINK")
  add_executable(${name} ${arg_UNPARSED_ARGUMENTS})
  if(arg_LINK)
    target_link_libraries(${name} ${arg_LINK})
  endif()
  viper_program(${name})
endfunction()

# viper_library(NAME SOURCES SRC... [SYSTEM_INCLUDES DIR...] LINK [PUBLIC|PRIVATE] LIB... [MESSAGES]):
# a library of the package: its headers (include/) public, the DIRs as public system headers, linked
# as LINK says, built after viper's messages with MESSAGES, into the devel space, installed.
function(viper_library name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "MESSAGES" "" "SOURCES;SYSTEM_INCLUDES;LINK")
  add_library(${name} ${arg_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR}/include)
  if(arg_SYSTEM_INCLUDES)
    target_include_directories(${name} SYSTEM PUBLIC ${arg_SYSTEM_INCLUDES})
  endif()
  target_link_libraries(${name} ${arg_LINK})
  if(arg_MESSAGES)
    add_dependencies(${name} viper_generate_messages_cpp)
  endif()
  viper_lib_output(${name})
  viper_install(${name})
endfunction()

# viper_ros_library(NAME SOURCES SRC... [SYSTEM_INCLUDES DIR...] LINK LIB...): a library of the ROS
# layer: viper_library with catkin's headers first among the system ones, linked PUBLIC, after the
# messages.
function(viper_ros_library name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "SOURCES;SYSTEM_INCLUDES;LINK")
  viper_library(${name} SOURCES ${arg_SOURCES} SYSTEM_INCLUDES ${catkin_INCLUDE_DIRS} ${arg_SYSTEM_INCLUDES}
    LINK PUBLIC ${arg_LINK} MESSAGES)
endfunction()

# viper_gtest(NAME SOURCE... [WORKING_DIRECTORY DIR] [INCLUDES DIR...] [SYSTEM_INCLUDES DIR...]
# [DEFINITIONS DEF...] [LINK LIB...] [DEPENDS TARGET...]): a plain gtest (no roscore) and, where
# gtest is there to build it, its private headers (the DIRs, then the system DIRs), definitions,
# libraries (plain signature) and the targets it runs or reads.
function(viper_gtest name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "WORKING_DIRECTORY" "INCLUDES;SYSTEM_INCLUDES;DEFINITIONS;LINK;DEPENDS")
  if(arg_WORKING_DIRECTORY)
    catkin_add_gtest(${name} ${arg_UNPARSED_ARGUMENTS} WORKING_DIRECTORY ${arg_WORKING_DIRECTORY})
  else()
    catkin_add_gtest(${name} ${arg_UNPARSED_ARGUMENTS})
  endif()
  if(NOT TARGET ${name})
    return()
  endif()
  if(arg_INCLUDES)
    target_include_directories(${name} PRIVATE ${arg_INCLUDES})
  endif()
  if(arg_SYSTEM_INCLUDES)
    target_include_directories(${name} SYSTEM PRIVATE ${arg_SYSTEM_INCLUDES})
  endif()
  if(arg_DEFINITIONS)
    target_compile_definitions(${name} PRIVATE ${arg_DEFINITIONS})
  endif()
  if(arg_LINK)
    target_link_libraries(${name} ${arg_LINK})
  endif()
  if(arg_DEPENDS)
    add_dependencies(${name} ${arg_DEPENDS})
  endif()
endfunction()
