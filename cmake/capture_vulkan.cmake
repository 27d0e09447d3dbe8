# Stage 1, capture, for Vulkan programs: the loader layer VK_LAYER_VIPER_capture
# (libviper_vulkan_layer.so and its manifest), which writes the same capture stream as the OpenGL
# layer. `capture` enables it for every program it runs. Design: docs/capture_layer.md, "Vulkan".
find_package(Vulkan REQUIRED)
find_program(VIPER_GLSLANG_VALIDATOR glslangValidator)
if(NOT VIPER_GLSLANG_VALIDATOR)
  message(FATAL_ERROR "glslangValidator not found: install glslang-tools (bash scripts/setup.sh does)")
endif()

add_library(viper_vulkan_layer SHARED
  src/capture/vulkan/spirv_module.cpp
  src/capture/vulkan/vk_hooks.cpp
  src/capture/vulkan/vk_frame.cpp
  src/capture/layer/frame_sink.cpp
  src/capture/layer/capture_settings.cpp
  src/capture/layer/finish_frame.cpp
  src/capture/layer/mesh_extract.cpp)
# Only the loader's entry points are exported; the Vulkan loader is not linked (the layer is
# called through the dispatch chain the loader gives it).
set_target_properties(viper_vulkan_layer PROPERTIES
  CXX_VISIBILITY_PRESET hidden
  VISIBILITY_INLINES_HIDDEN ON
  LIBRARY_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION})
target_include_directories(viper_vulkan_layer PRIVATE ${Vulkan_INCLUDE_DIRS})
# Vulkan structures are written `{VK_STRUCTURE_TYPE_...}`, the rest zeroed, as Vulkan code is.
target_compile_options(viper_vulkan_layer PRIVATE -Wno-missing-field-initializers)
find_package(SPIRV-Tools REQUIRED)
# SPIRV-Tools validates every rewritten shader before the driver sees it.
target_link_libraries(viper_vulkan_layer PRIVATE viper_core SPIRV-Tools-static Threads::Threads)

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
install(TARGETS viper_vulkan_layer LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

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
  endif()
endif()
