# Stage 1, capture, for Vulkan programs: the loader layer VK_LAYER_VIPER_capture
# (libviper_vulkan_layer.so and its manifest), which writes the same capture stream as the OpenGL
# layer. `capture` enables it for every program it runs. Design: docs/capture_layer.md, "Vulkan".
find_package(Vulkan REQUIRED)
find_program(VIPER_GLSLANG_VALIDATOR glslangValidator)
if(NOT VIPER_GLSLANG_VALIDATOR)
  message(FATAL_ERROR "glslangValidator not found: install glslang-tools (bash scripts/setup.sh does)")
endif()

set(VIPER_VULKAN_LAYER_SOURCES
  src/capture/vulkan/spirv_module.cpp
  src/capture/vulkan/vk_hooks.cpp
  src/capture/vulkan/vk_resources.cpp
  src/capture/vulkan/vk_passes.cpp
  src/capture/vulkan/vk_pipelines.cpp
  src/capture/vulkan/vk_commands.cpp
  src/capture/vulkan/vk_frame.cpp
  src/capture/layer/frame_sink.cpp
  src/capture/layer/capture_settings.cpp
  src/capture/layer/finish_frame.cpp
  src/capture/layer/mesh_extract.cpp)
add_library(viper_vulkan_layer SHARED ${VIPER_VULKAN_LAYER_SOURCES})
# Only the loader's entry points are exported; the Vulkan loader is not linked (the layer is
# called through the dispatch chain the loader gives it).
set_target_properties(viper_vulkan_layer PROPERTIES CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
viper_lib_output(viper_vulkan_layer)
target_include_directories(viper_vulkan_layer PRIVATE ${Vulkan_INCLUDE_DIRS})
# Vulkan structures are written `{VK_STRUCTURE_TYPE_...}`, the rest zeroed, as Vulkan code is.
target_compile_options(viper_vulkan_layer PRIVATE -Wno-missing-field-initializers)
find_package(SPIRV-Tools REQUIRED)
# SPIRV-Tools validates every rewritten shader before the driver sees it.
target_link_libraries(viper_vulkan_layer PRIVATE viper_capture_core SPIRV-Tools-static Threads::Threads)

# The layer's manifest, next to the library in the devel space and in the install space: `capture`
# points the loader at the folder (VK_ADD_LAYER_PATH) and enables the layer by name.
set(VIPER_VULKAN_LAYER_NAME VK_LAYER_VIPER_capture)
set(VIPER_VULKAN_LAYER_LIBRARY $<TARGET_FILE:viper_vulkan_layer>)
file(GENERATE OUTPUT ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_SHARE_DESTINATION}/vulkan/${VIPER_VULKAN_LAYER_NAME}.json
  CONTENT "{
  \"file_format_version\": \"1.1.2\",
  \"layer\": {
    \"name\": \"${VIPER_VULKAN_LAYER_NAME}\",
    \"type\": \"GLOBAL\",
    \"library_path\": \"$<TARGET_FILE:viper_vulkan_layer>\",
    \"api_version\": \"1.3.239\",
    \"implementation_version\": \"1\",
    \"description\": \"viper: records what a Vulkan program draws into a capture stream\",
    \"functions\": {
      \"vkGetInstanceProcAddr\": \"viper_vkGetInstanceProcAddr\",
      \"vkGetDeviceProcAddr\": \"viper_vkGetDeviceProcAddr\",
      \"vkNegotiateLoaderLayerInterfaceVersion\": \"vkNegotiateLoaderLayerInterfaceVersion\"
    }
  }
}
")
viper_install(viper_vulkan_layer)

if(CATKIN_ENABLE_TESTING)
  # The SPIR-V reading and rewriting, on modules glslang compiles, checked by SPIRV-Tools' validator.
  catkin_add_gtest(test_spirv_module test/capture/test_spirv_module.cpp src/capture/vulkan/spirv_module.cpp)
  target_link_libraries(test_spirv_module SPIRV-Tools-static gtest_main)
  target_include_directories(test_spirv_module PRIVATE ${PROJECT_SOURCE_DIR})
  target_compile_definitions(test_spirv_module PRIVATE VIPER_GLSLANG_VALIDATOR="${VIPER_GLSLANG_VALIDATOR}")
endif()

# `capture` enables the layer for every program it runs.
target_compile_definitions(viper_capture PRIVATE
  VIPER_VULKAN_LAYER_BUILD_PATH="${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_SHARE_DESTINATION}/vulkan")
add_dependencies(viper_capture viper_vulkan_layer)

if(CATKIN_ENABLE_TESTING)
  # The layer on our Vulkan oracle program in every way it draws, against its truth, its own
  # pictures and the Khronos validation layer (each run under xvfb-run).
  catkin_add_gtest(test_capture_vulkan test/capture/test_capture_vulkan.cpp)
  if(TARGET test_capture_vulkan)
    target_link_libraries(test_capture_vulkan viper_core gtest_main)
    target_include_directories(test_capture_vulkan PRIVATE ${PROJECT_SOURCE_DIR})
    target_compile_definitions(test_capture_vulkan PRIVATE
      VIPER_CAPTURE_BIN="$<TARGET_FILE:viper_capture>"
      VIPER_VK_TEST_SCENE_BIN="$<TARGET_FILE:vk_test_scene>"
      VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      VIPER_VULKAN_LAYER_DIR="${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_SHARE_DESTINATION}/vulkan")
    add_dependencies(test_capture_vulkan viper_capture viper_vulkan_layer viper_intercept vk_test_scene)
    # The layer again with AddressSanitizer and UndefinedBehaviorSanitizer (as viper_intercept_asan,
    # cmake/capture.cmake), with a manifest of its own, for test_capture_vulkan's sanitized run; in a
    # ThreadSanitizer tree (scripts/sanitize.sh tsan) the tree's own layer is the sanitized one.
    if(VIPER_STRESS_SANITIZED_TARGET STREQUAL "viper_intercept_asan")
      add_library(viper_vulkan_layer_asan SHARED EXCLUDE_FROM_ALL ${VIPER_VULKAN_LAYER_SOURCES} ${VIPER_CAPTURE_CORE_SOURCES})
      set_target_properties(viper_vulkan_layer_asan PROPERTIES
        CXX_VISIBILITY_PRESET hidden
        VISIBILITY_INLINES_HIDDEN ON
        LIBRARY_OUTPUT_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/sanitized)
      target_compile_options(viper_vulkan_layer_asan PRIVATE ${VIPER_SANITIZE_FLAGS} -O1 -Wno-missing-field-initializers)
      target_link_options(viper_vulkan_layer_asan PRIVATE ${VIPER_SANITIZE_FLAGS})
      target_include_directories(viper_vulkan_layer_asan PRIVATE ${PROJECT_SOURCE_DIR}/include ${PROJECT_SOURCE_DIR}/src/capture
        ${Vulkan_INCLUDE_DIRS})
      target_include_directories(viper_vulkan_layer_asan SYSTEM PRIVATE ${EIGEN3_INCLUDE_DIR})
      target_link_libraries(viper_vulkan_layer_asan PRIVATE PkgConfig::ZSTD PkgConfig::LIBLZ4 PkgConfig::XXHASH
        PkgConfig::YAMLCPP SPIRV-Tools-static Threads::Threads ${CMAKE_DL_LIBS})
      file(GENERATE OUTPUT ${CMAKE_CURRENT_BINARY_DIR}/sanitized/vulkan/${VIPER_VULKAN_LAYER_NAME}.json
        CONTENT "{
  \"file_format_version\": \"1.1.2\",
  \"layer\": {
    \"name\": \"${VIPER_VULKAN_LAYER_NAME}\",
    \"type\": \"GLOBAL\",
    \"library_path\": \"$<TARGET_FILE:viper_vulkan_layer_asan>\",
    \"api_version\": \"1.3.239\",
    \"implementation_version\": \"1\",
    \"description\": \"viper: records what a Vulkan program draws (AddressSanitizer build)\",
    \"functions\": {
      \"vkGetInstanceProcAddr\": \"viper_vkGetInstanceProcAddr\",
      \"vkGetDeviceProcAddr\": \"viper_vkGetDeviceProcAddr\",
      \"vkNegotiateLoaderLayerInterfaceVersion\": \"vkNegotiateLoaderLayerInterfaceVersion\"
    }
  }
}
")
      target_compile_definitions(test_capture_vulkan PRIVATE
        VIPER_INTERCEPT_ASAN_LIB="$<TARGET_FILE:viper_intercept_asan>"
        VIPER_VULKAN_LAYER_ASAN_DIR="${CMAKE_CURRENT_BINARY_DIR}/sanitized/vulkan")
      add_dependencies(test_capture_vulkan viper_vulkan_layer_asan viper_intercept_asan)
    endif()
  endif()
endif()
