# Stage 1, capture: the layer (libviper_intercept.so, `capture`), its tests on our programs and on
# third-party games, and the tools that read captures (capture_info, capture_check, capture_sheet,
# label_resources, make_label_table).
# Capture layer: libviper_intercept.so (loaded into OpenGL programs with LD_PRELOAD) and the
# `capture` command that runs a program under it. Design and coverage: docs/capture_layer.md.
find_package(Threads REQUIRED)

set(VIPER_INTERCEPT_SOURCES
  src/capture/layer/gl_real.cpp
  src/capture/layer/frame_target.cpp
  src/capture/layer/scene_fbo.cpp
  src/capture/layer/frame_sink.cpp
  src/capture/layer/capture_settings.cpp
  src/capture/layer/finish_frame.cpp
  src/capture/layer/mesh_extract.cpp
  src/capture/layer/interceptor.cpp
  src/capture/layer/interceptor_resources.cpp
  src/capture/layer/interceptor_draw.cpp
  src/capture/layer/fixed_function.cpp
  src/capture/layer/hooks_gl.cpp
  src/capture/layer/hooks_legacy.cpp
  src/capture/layer/hooks_immediate.cpp
  src/capture/layer/hooks_introspection.cpp
  src/capture/layer/matrix_stack.cpp
  src/capture/layer/hooks_winsys.cpp
  src/capture/layer/pixel_transfer.cpp)
# viper_capture_layer(NAME SOURCE...): a layer loaded into the programs it captures (this one, the
# Vulkan layer): a shared library exporting only the entry points it marks, in the devel space.
function(viper_capture_layer name)
  add_library(${name} SHARED ${ARGN})
  set_target_properties(${name} PROPERTIES CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  viper_lib_output(${name})
endfunction()

# viper_sanitized_layer(NAME SOURCES SRC... [OPTIONS OPT...] [INCLUDES DIR...] [LINK LIB...]): a layer
# again with AddressSanitizer and UndefinedBehaviorSanitizer, with the capture sources of the core it
# uses compiled in, into the build folder's sanitized/ (built only for the tests that name it).
function(viper_sanitized_layer name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "SOURCES;OPTIONS;INCLUDES;LINK")
  set(sanitize -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  add_library(${name} SHARED EXCLUDE_FROM_ALL ${arg_SOURCES} ${VIPER_CAPTURE_CORE_SOURCES})
  set_target_properties(${name} PROPERTIES
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    LIBRARY_OUTPUT_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/sanitized)
  target_compile_options(${name} PRIVATE ${sanitize} -O1 ${arg_OPTIONS})
  target_link_options(${name} PRIVATE ${sanitize})
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/include ${PROJECT_SOURCE_DIR}/src/capture
    ${arg_INCLUDES})
  target_include_directories(${name} SYSTEM PRIVATE ${EIGEN3_INCLUDE_DIR})
  target_link_libraries(${name} PRIVATE PkgConfig::ZSTD PkgConfig::LIBLZ4 PkgConfig::XXHASH PkgConfig::YAMLCPP
    ${arg_LINK} Threads::Threads ${CMAKE_DL_LIBS})
endfunction()

# Only the hooked GL/EGL/GLX entry points and dlsym are exported; GL and EGL are not linked
# (the real functions are looked up at run time, past the interceptor's own symbols).
viper_capture_layer(viper_intercept ${VIPER_INTERCEPT_SOURCES})
# Of the package, only the capture stage is loaded into the program (test_stage_dependencies).
target_link_libraries(viper_intercept PRIVATE viper_capture_core Threads::Threads ${CMAKE_DL_LIBS})

add_executable(viper_capture tools/capture.cpp)
set_target_properties(viper_capture PROPERTIES OUTPUT_NAME capture)
target_compile_definitions(viper_capture PRIVATE VIPER_INTERCEPT_BUILD_PATH="$<TARGET_FILE:viper_intercept>")
target_link_libraries(viper_capture PRIVATE viper_ground_truth)  # the verdict (capture_verdict.h)
add_dependencies(viper_capture viper_intercept)

viper_install(viper_intercept)
viper_program(viper_capture)
install(DIRECTORY config/profiles DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/config)

# viper_capture_run(CAPTURE PROGRAM TARGET PROFILE FILE CONDITION C [CODEC C] [ORACLE FILE] [ARGS ARG...]
# COMMENT TEXT): the rule that captures the program TARGET (run with the ARGS, and --oracle FILE with
# ORACLE) into CAPTURE at build time, at 15 fps (test data of the later stages).
function(viper_capture_run capture)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "PROGRAM;PROFILE;CONDITION;CODEC;ORACLE;COMMENT" "ARGS")
  set(codec)
  if(arg_CODEC)
    set(codec --codec ${arg_CODEC})
  endif()
  set(oracle)
  if(arg_ORACLE)
    set(oracle --oracle ${arg_ORACLE})
  endif()
  get_filename_component(folder ${capture} DIRECTORY)
  add_custom_command(OUTPUT ${capture} ${arg_ORACLE}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${folder}
    COMMAND $<TARGET_FILE:viper_capture> ${codec} --output ${capture} --profile ${arg_PROFILE}
            --condition ${arg_CONDITION} --fps 15 -- $<TARGET_FILE:${arg_PROGRAM}> ${arg_ARGS} ${oracle}
    DEPENDS viper_capture viper_intercept ${arg_PROGRAM}
    COMMENT "${arg_COMMENT}")
endfunction()

if(CATKIN_ENABLE_TESTING)
  find_package(X11 REQUIRED)
  # viper_capture_gtest(NAME SOURCE... [viper_gtest's options]): a gtest that runs `capture`
  # (VIPER_CAPTURE_EXE) and its interceptor, from the source folder.
  function(viper_capture_gtest name)
    cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "DEFINITIONS;DEPENDS")
    viper_gtest(${name} ${arg_UNPARSED_ARGUMENTS} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
      DEFINITIONS VIPER_CAPTURE_EXE="$<TARGET_FILE:viper_capture>" ${arg_DEFINITIONS}
      DEPENDS viper_capture viper_intercept ${arg_DEPENDS})
  endfunction()

  # GL test program: knows what it draws where (test/capture/test_scene_layout.h).
  add_executable(viper_gl_test_program test/capture/gl_test_program.cpp)
  target_include_directories(viper_gl_test_program SYSTEM PRIVATE ${EIGEN3_INCLUDE_DIR})
  target_include_directories(viper_gl_test_program PRIVATE ${PROJECT_SOURCE_DIR})  # gl_common/sanitizer_options.h
  target_include_directories(viper_gl_test_program PRIVATE ${PROJECT_SOURCE_DIR})
  target_link_libraries(viper_gl_test_program PRIVATE PkgConfig::EGL PkgConfig::GL ${X11_LIBRARIES} ${CMAKE_DL_LIBS})

  # GL 4.5 test program that draws as engines do (test/capture/engine_scene.h).
  add_executable(viper_gl_engine_program test/capture/gl_engine_program.cpp)
  target_include_directories(viper_gl_engine_program SYSTEM PRIVATE ${EIGEN3_INCLUDE_DIR})
  target_link_libraries(viper_gl_engine_program PRIVATE viper_gl_common PkgConfig::EGL PkgConfig::GL)

  # GL 3.0 compatibility test program that draws as Minetest does (matrix stack, client arrays).
  add_executable(viper_gl_legacy_program test/capture/gl_legacy_program.cpp)
  target_include_directories(viper_gl_legacy_program SYSTEM PRIVATE ${EIGEN3_INCLUDE_DIR})
  target_link_libraries(viper_gl_legacy_program PRIVATE viper_gl_common PkgConfig::EGL PkgConfig::GL)

  # OpenGL 1.x program without any shader (vertex arrays, glBegin/glEnd): the layer records none of it.
  add_executable(viper_gl_fixed_function_program test/capture/gl_fixed_function_program.cpp)
  target_link_libraries(viper_gl_fixed_function_program PRIVATE viper_gl_common PkgConfig::EGL PkgConfig::GL)

  # Stress program: what real engines do (several contexts and threads, program binaries,
  # persistent mappings, indirect draws, buffers of uniforms and texels, sync objects, a context
  # destroyed mid-frame, exit() from another thread), each scenario checked by test_capture_stress.
  add_executable(viper_gl_stress_program test/capture/gl_stress_program.cpp test/capture/gl_stress_compat.cpp)
  target_include_directories(viper_gl_stress_program SYSTEM PRIVATE ${EIGEN3_INCLUDE_DIR})
  target_include_directories(viper_gl_stress_program PRIVATE ${PROJECT_SOURCE_DIR})
  target_link_libraries(viper_gl_stress_program PRIVATE PkgConfig::EGL PkgConfig::GL Threads::Threads)

  # The interceptor again, built with AddressSanitizer and UndefinedBehaviorSanitizer (with the
  # capture sources of the core it uses), for test_capture_stress to preload into the stress
  # program (`capture` preloads libasan before it; test/capture/test_capture_stress.cpp says how).
  # In a ThreadSanitizer build (scripts/sanitize.sh tsan) ASan cannot be added: the test's sanitized
  # run preloads the build's own interceptor, built with TSan.
  if(CMAKE_CXX_FLAGS MATCHES "-fsanitize=thread")
    set(VIPER_STRESS_SANITIZED_TARGET viper_intercept)
  else()
    set(VIPER_STRESS_SANITIZED_TARGET viper_intercept_asan)
  endif()
  if(VIPER_STRESS_SANITIZED_TARGET STREQUAL "viper_intercept_asan")
    viper_sanitized_layer(viper_intercept_asan SOURCES ${VIPER_INTERCEPT_SOURCES})
  endif()

  viper_capture_gtest(test_capture_stress test/capture/test_capture_stress.cpp
    INCLUDES ${PROJECT_SOURCE_DIR}/test/capture
    DEFINITIONS VIPER_INTERCEPT_ASAN_LIB="$<TARGET_FILE:${VIPER_STRESS_SANITIZED_TARGET}>"
      VIPER_GL_STRESS_PROGRAM="$<TARGET_FILE:viper_gl_stress_program>"
      VIPER_STRESS_PROFILE="${PROJECT_SOURCE_DIR}/test/capture/stress_profile.yaml"
    LINK viper_core gtest_main
    DEPENDS ${VIPER_STRESS_SANITIZED_TARGET} viper_gl_stress_program)

  # The layer's pixel format table against the driver's own bounds checks (needs a GL context).
  catkin_add_gtest(test_pixel_transfer test/capture/test_pixel_transfer.cpp src/capture/layer/pixel_transfer.cpp)
  target_include_directories(test_pixel_transfer PRIVATE ${PROJECT_SOURCE_DIR}/src/capture/layer ${PROJECT_SOURCE_DIR})
  target_link_libraries(test_pixel_transfer viper_gl_common PkgConfig::EGL PkgConfig::GL gtest_main)

  viper_capture_gtest(test_capture_legacy test/capture/test_capture_legacy.cpp src/capture/layer/matrix_stack.cpp
    INCLUDES ${PROJECT_SOURCE_DIR}/src/capture/layer
    DEFINITIONS VIPER_GL_LEGACY_PROGRAM="$<TARGET_FILE:viper_gl_legacy_program>"
      VIPER_LEGACY_PROFILE="${PROJECT_SOURCE_DIR}/test/capture/legacy_profile.yaml"
    LINK viper_core gtest_main
    DEPENDS viper_gl_legacy_program)

  viper_capture_gtest(test_capture_engine test/capture/test_capture_engine.cpp
    DEFINITIONS VIPER_GL_ENGINE_PROGRAM="$<TARGET_FILE:viper_gl_engine_program>"
      VIPER_ENGINE_PROFILE="${PROJECT_SOURCE_DIR}/test/capture/engine_profile.yaml"
    LINK viper_core gtest_main
    DEPENDS viper_gl_engine_program)

  # The real-context part of the shader rewrite test needs EGL and GL.
  if(TARGET test_shader_rewrite)
    target_link_libraries(test_shader_rewrite PkgConfig::EGL PkgConfig::GL)
  endif()

  catkin_add_gtest(test_capture_mesh test/capture/test_capture_mesh.cpp src/capture/layer/mesh_extract.cpp
    src/capture/layer/frame_sink.cpp src/capture/layer/finish_frame.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  target_include_directories(test_capture_mesh PRIVATE ${PROJECT_SOURCE_DIR}/src/capture/layer)
  target_link_libraries(test_capture_mesh viper_core Threads::Threads ${CMAKE_DL_LIBS})

  catkin_add_gtest(test_finish_frame test/capture/test_finish_frame.cpp src/capture/layer/finish_frame.cpp
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  target_include_directories(test_finish_frame PRIVATE ${PROJECT_SOURCE_DIR}/src/capture/layer)
  target_link_libraries(test_finish_frame viper_core)

  viper_capture_gtest(test_capture_run test/capture/test_capture_run.cpp
    INCLUDES ${PROJECT_SOURCE_DIR}/test/capture
    DEFINITIONS VIPER_INTERCEPT_LIB="$<TARGET_FILE:viper_intercept>"
      VIPER_GL_TEST_PROGRAM="$<TARGET_FILE:viper_gl_test_program>" VIPER_PROFILE_DIR="${PROJECT_SOURCE_DIR}/config/profiles"
    LINK viper_core
    DEPENDS viper_gl_test_program)

  # capture's verdict and --require-ids, capture_check's judged checks and the ones it cannot run.
  viper_capture_gtest(test_capture_verdict test/capture/test_capture_verdict.cpp
    DEFINITIONS VIPER_CAPTURE_CHECK_EXE="$<TARGET_FILE:capture_check>"
      VIPER_GL_TEST_PROGRAM="$<TARGET_FILE:viper_gl_test_program>"
      VIPER_GL_FIXED_FUNCTION_PROGRAM="$<TARGET_FILE:viper_gl_fixed_function_program>"
      VIPER_TEST_SCENE="$<TARGET_FILE:test_scene>" VIPER_PROFILE_DIR="${PROJECT_SOURCE_DIR}/config/profiles"
    LINK viper_core
    DEPENDS capture_check viper_gl_test_program viper_gl_fixed_function_program test_scene)
endif()

if(CATKIN_ENABLE_TESTING)
  # SuperTuxKart traced once and replayed plainly and under capture (needs supertuxkart, apitrace
  # and xvfb-run: scripts/setup.sh --test-programs, which scripts/test.sh runs).
  # Minetest captured live (needs minetest and xvfb: scripts/setup.sh --test-programs).
  viper_capture_gtest(test_minetest test/capture/test_minetest.cpp
    DEFINITIONS VIPER_PROFILE_DIR="${PROJECT_SOURCE_DIR}/config/profiles" LINK viper_core gtest_main)
  viper_capture_gtest(test_supertuxkart test/capture/test_supertuxkart.cpp SYSTEM_INCLUDES ${OpenCV_INCLUDE_DIRS}
    DEFINITIONS VIPER_PROFILE_DIR="${PROJECT_SOURCE_DIR}/config/profiles"
      VIPER_STK_LABELS="${PROJECT_SOURCE_DIR}/config/labels/supertuxkart_candela_city.yaml"
    LINK viper_core gtest_main ${OpenCV_LIBS}
    DEPENDS viper_vulkan_layer)
  # Programs the package was not written for, the fast ones (scripts/capture_corpus.sh; needs them,
  # apitrace and xvfb: scripts/setup.sh --test-programs).
  viper_capture_gtest(test_corpus test/capture/test_corpus.cpp LINK gtest_main DEPENDS capture_check)
  # Mesa's conformance suite piglit plainly and under capture (scripts/piglit_compare.sh's ci slice;
  # needs piglit, waffle-utils and xvfb: scripts/setup.sh --test-programs).
  viper_capture_gtest(test_piglit test/capture/test_piglit.cpp LINK gtest_main)
endif()

# Command-line tools of the package (run with rosrun viper NAME).
viper_executable(capture_info tools/capture_info.cpp LINK viper_core)

# capture_check: ids, matrices and meshes of a capture checked against its own depth (viper::checkReprojection).
viper_executable(capture_check tools/capture_check.cpp LINK viper_core)

# capture_sheet: a contact sheet of a capture's frames (color, ids, depth, flow, reprojection).
add_executable(capture_sheet tools/capture_sheet.cpp)
target_include_directories(capture_sheet SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(capture_sheet viper_core ${OpenCV_LIBS})
target_compile_definitions(capture_sheet PRIVATE VIPER_CLASS_TABLE="${PROJECT_SOURCE_DIR}/config/viper_classes.csv")
viper_program(capture_sheet)

# label_resources: the labelling page of a capture (tools/label_page/ is copied beside the data).
add_executable(label_resources tools/label_resources.cpp)
target_include_directories(label_resources SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(label_resources viper_core ${OpenCV_LIBS})
target_compile_definitions(label_resources PRIVATE
  VIPER_LABEL_PAGE_DIR="${PROJECT_SOURCE_DIR}/tools/label_page"
  VIPER_CLASS_TABLE="${PROJECT_SOURCE_DIR}/config/viper_classes.csv")
viper_program(label_resources)

viper_executable(make_label_table tools/make_label_table.cpp LINK viper_core)

if(CATKIN_ENABLE_TESTING)
  # The labelling page in headless Chromium, driven by Playwright (test/label_page; needs chromium,
  # node and the page driver's npm package: scripts/setup.sh --test-programs).
  viper_capture_gtest(test_label_page test/label_page/test_label_page.cpp
    DEFINITIONS VIPER_GL_TEST_PROGRAM="$<TARGET_FILE:viper_gl_test_program>"
      VIPER_LABEL_RESOURCES="$<TARGET_FILE:label_resources>" VIPER_PROFILE_DIR="${PROJECT_SOURCE_DIR}/config/profiles"
      VIPER_LABEL_PAGE_TEST_DIR="${PROJECT_SOURCE_DIR}/test/label_page"
    LINK viper_core gtest_main
    DEPENDS viper_gl_test_program label_resources)
endif()
