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
# Only the loader's entry points are exported; the Vulkan loader is not linked (the layer is
# called through the dispatch chain the loader gives it).
viper_capture_layer(viper_vulkan_layer ${VIPER_VULKAN_LAYER_SOURCES})
target_include_directories(viper_vulkan_layer PRIVATE ${Vulkan_INCLUDE_DIRS})
# Vulkan structures are written `{VK_STRUCTURE_TYPE_...}`, the rest zeroed, as Vulkan code is.
target_compile_options(viper_vulkan_layer PRIVATE -Wno-missing-field-initializers)
find_package(SPIRV-Tools REQUIRED)
# SPIRV-Tools validates every rewritten shader before the driver sees it.
target_link_libraries(viper_vulkan_layer PRIVATE viper_capture_core SPIRV-Tools-static Threads::Threads)

# The layer's manifest, next to the library in the devel space and in the install space: `capture`
# points the loader at the folder (VK_ADD_LAYER_PATH) and enables the layer by name.
# viper_vulkan_manifest(FOLDER LAYER_TARGET DESCRIPTION): the manifest VK_LAYER_VIPER_capture.json in
# FOLDER, naming LAYER_TARGET's library.
set(VIPER_VULKAN_LAYER_NAME VK_LAYER_VIPER_capture)
function(viper_vulkan_manifest folder layer description)
  file(GENERATE OUTPUT ${folder}/${VIPER_VULKAN_LAYER_NAME}.json
    CONTENT "{
  \"file_format_version\": \"1.1.2\",
  \"layer\": {
    \"name\": \"${VIPER_VULKAN_LAYER_NAME}\",
    \"type\": \"GLOBAL\",
    \"library_path\": \"$<TARGET_FILE:${layer}>\",
    \"api_version\": \"1.3.239\",
    \"implementation_version\": \"1\",
    \"description\": \"${description}\",
    \"functions\": {
      \"vkGetInstanceProcAddr\": \"viper_vkGetInstanceProcAddr\",
      \"vkGetDeviceProcAddr\": \"viper_vkGetDeviceProcAddr\",
      \"vkNegotiateLoaderLayerInterfaceVersion\": \"vkNegotiateLoaderLayerInterfaceVersion\"
    }
  }
}
")
endfunction()
viper_vulkan_manifest(${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_SHARE_DESTINATION}/vulkan viper_vulkan_layer
  "viper: records what a Vulkan program draws into a capture stream")
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
  viper_gtest(test_capture_vulkan test/capture/test_capture_vulkan.cpp INCLUDES ${PROJECT_SOURCE_DIR}
    DEFINITIONS
      VIPER_CAPTURE_BIN="$<TARGET_FILE:viper_capture>"
      VIPER_VK_TEST_SCENE_BIN="$<TARGET_FILE:vk_test_scene>"
      VIPER_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      VIPER_VULKAN_LAYER_DIR="${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_SHARE_DESTINATION}/vulkan"
    LINK viper_core gtest_main
    DEPENDS viper_capture viper_vulkan_layer viper_intercept vk_test_scene)
  if(TARGET test_capture_vulkan)
    # The layer again with AddressSanitizer and UndefinedBehaviorSanitizer (as viper_intercept_asan,
    # cmake/capture.cmake), with a manifest of its own, for test_capture_vulkan's sanitized run; in a
    # ThreadSanitizer tree (scripts/sanitize.sh tsan) the tree's own layer is the sanitized one.
    if(VIPER_STRESS_SANITIZED_TARGET STREQUAL "viper_intercept_asan")
      viper_sanitized_layer(viper_vulkan_layer_asan SOURCES ${VIPER_VULKAN_LAYER_SOURCES}
        OPTIONS -Wno-missing-field-initializers INCLUDES ${Vulkan_INCLUDE_DIRS} LINK SPIRV-Tools-static)
      viper_vulkan_manifest(${CMAKE_CURRENT_BINARY_DIR}/sanitized/vulkan viper_vulkan_layer_asan
        "viper: records what a Vulkan program draws (AddressSanitizer build)")
      target_compile_definitions(test_capture_vulkan PRIVATE
        VIPER_INTERCEPT_ASAN_LIB="$<TARGET_FILE:viper_intercept_asan>"
        VIPER_VULKAN_LAYER_ASAN_DIR="${CMAKE_CURRENT_BINARY_DIR}/sanitized/vulkan")
      add_dependencies(test_capture_vulkan viper_vulkan_layer_asan viper_intercept_asan)
    endif()
  endif()
endif()
