# Stage 0, the programs we capture that are ours: the shared GL plumbing (gl_common), the test
# scene (test_scene, and vk_test_scene its Vulkan twin) and the procedural town (world). Plain OpenGL
# and Vulkan programs: no capture code, no ROS.

# viper_gl_common: what our own OpenGL programs (test_scene, world; gl_engine/gl_legacy_program its shaders)
# share: the headless EGL context, shader compile/link with clear errors, PPM frame dumps. Plain
# EGL + GL + the standard library: no ROS, no viper_core, so the programs stay plain GL programs.
add_library(viper_gl_common STATIC
  gl_common/headless_egl_context.cpp
  gl_common/shader_build.cpp
  gl_common/ppm.cpp
)
target_include_directories(viper_gl_common PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(viper_gl_common PUBLIC PkgConfig::EGL PkgConfig::GL)

# viper_test_scene_world: what test_scene and vk_test_scene share, so both draw and describe the same
# scene: the command line, the meshes, the world's animation and the oracle records. No graphics API
# (options.h names the GL loader enum, a header-only use); viper_core only for the oracle writer.
add_library(viper_test_scene_world STATIC
  scene/options.cpp
  scene/geometry.cpp
  scene/world.cpp
  scene/frame_output.cpp
)
target_include_directories(viper_test_scene_world PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(viper_test_scene_world PUBLIC viper_core)

# test_scene: the plain OpenGL program the capture layer is tested on (headless EGL, no capture code;
# viper_gl_common for the EGL context, shaders and dumps).
add_executable(test_scene
  scene/main.cpp
  scene/gl_api.cpp
  scene/shaders.cpp
  scene/renderer.cpp
)
target_link_libraries(test_scene viper_test_scene_world viper_gl_common viper_core PkgConfig::EGL PkgConfig::GL)
viper_program(test_scene)

if(CATKIN_ENABLE_TESTING)
  # Runs the real binary: structure of its oracle, determinism, both GL loaders, exit codes.
  catkin_add_gtest(test_scene_run test/scene/test_scene_run.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  target_link_libraries(test_scene_run viper_core)
  target_compile_definitions(test_scene_run PRIVATE VIPER_TEST_SCENE_BIN="$<TARGET_FILE:test_scene>")
  add_dependencies(test_scene_run test_scene)
endif()

# vk_test_scene: test_scene's scene drawn with Vulkan into an X window's swapchain (xcb), the program the
# Vulkan capture layer is tested on; its oracle equals test_scene's. Shaders are GLSL in
# scene/vulkan/shaders/, compiled to SPIR-V headers at build time (debug names kept: the layer reads them).
find_package(Vulkan REQUIRED)
pkg_check_modules(XCB REQUIRED IMPORTED_TARGET xcb)
find_program(VIPER_GLSLANG_VALIDATOR glslangValidator)
if(NOT VIPER_GLSLANG_VALIDATOR)
  message(FATAL_ERROR "glslangValidator not found: vk_test_scene compiles its shaders with it "
                      "(Debian: apt-get install glslang-tools, or scripts/setup.sh)")
endif()
set(VIPER_VK_SHADER_DIR ${CMAKE_CURRENT_BINARY_DIR}/vk_test_scene_shaders)
set(VIPER_VK_SHADER_HEADERS)
# name|source|array|defines: scene.vert serves the lit and (SKINNED) the skinned program.
foreach(shader
    "scene_lit_vert|scene.vert|kSceneLitVert|"
    "scene_skinned_vert|scene.vert|kSceneSkinnedVert|-DSKINNED"
    "lit_frag|lit.frag|kLitFrag|"
    "rain_vert|rain.vert|kRainVert|"
    "rain_frag|rain.frag|kRainFrag|"
    "composite_vert|composite.vert|kCompositeVert|"
    "composite_frag|composite.frag|kCompositeFrag|"
    "hud_vert|hud.vert|kHudVert|"
    "hud_frag|hud.frag|kHudFrag|")
  string(REPLACE "|" ";" fields "${shader}")
  list(GET fields 0 name)
  list(GET fields 1 source)
  list(GET fields 2 array)
  list(GET fields 3 defines)
  set(header ${VIPER_VK_SHADER_DIR}/${name}.spv.h)
  add_custom_command(OUTPUT ${header}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${VIPER_VK_SHADER_DIR}
    COMMAND ${VIPER_GLSLANG_VALIDATOR} --quiet -V --target-env vulkan1.2 ${defines} --vn ${array} -o ${header}
            ${PROJECT_SOURCE_DIR}/scene/vulkan/shaders/${source}
    DEPENDS ${PROJECT_SOURCE_DIR}/scene/vulkan/shaders/${source}
    COMMENT "glslangValidator: ${source} ${defines} -> ${name}.spv.h"
    VERBATIM)
  list(APPEND VIPER_VK_SHADER_HEADERS ${header})
endforeach()
add_executable(vk_test_scene
  scene/vulkan/main.cpp
  scene/vulkan/vk_options.cpp
  scene/vulkan/vk_context.cpp
  scene/vulkan/vk_pipelines.cpp
  scene/vulkan/vk_renderer.cpp
  scene/vulkan/vk_renderer_frame.cpp
  gl_common/ppm.cpp  # the PPM writer alone: viper_gl_common would link EGL and GL into a Vulkan program
  ${VIPER_VK_SHADER_HEADERS}
)
target_include_directories(vk_test_scene PRIVATE ${VIPER_VK_SHADER_DIR})
# Vulkan structs are written `VkXxxCreateInfo info{VK_STRUCTURE_TYPE_...};`: the rest zero on purpose.
target_compile_options(vk_test_scene PRIVATE -Wno-missing-field-initializers)
target_link_libraries(vk_test_scene viper_test_scene_world Vulkan::Vulkan PkgConfig::XCB)
viper_program(vk_test_scene)

if(CATKIN_ENABLE_TESTING)
  # Runs vk_test_scene under a private Xvfb in every mode, with the Khronos validation layer, against
  # test_scene: same oracle, nearly the same pictures.
  catkin_add_gtest(test_vk_scene_run test/scene/test_vk_scene_run.cpp WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  if(TARGET test_vk_scene_run)
    target_link_libraries(test_vk_scene_run viper_core)
    target_compile_definitions(test_vk_scene_run PRIVATE
      VIPER_VK_TEST_SCENE_BIN="$<TARGET_FILE:vk_test_scene>" VIPER_TEST_SCENE_BIN="$<TARGET_FILE:test_scene>")
    add_dependencies(test_vk_scene_run vk_test_scene test_scene)
  endif()
endif()

# world: the procedural town, viper's default data source (a plain OpenGL program; see docs/world.md).
file(GLOB VIPER_WORLD_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/world/*.cpp)
add_executable(world ${VIPER_WORLD_SOURCES})
target_link_libraries(world viper_gl_common viper_core PkgConfig::EGL PkgConfig::GL)
# X11 only for the optional --window mode; headless rendering needs none.
pkg_check_modules(VIPER_WORLD_X11 QUIET IMPORTED_TARGET x11)
if(VIPER_WORLD_X11_FOUND)
  target_link_libraries(world PkgConfig::VIPER_WORLD_X11)
  target_compile_definitions(world PRIVATE VIPER_WORLD_WITH_X11=1)
endif()
viper_program(world)
install(FILES config/profiles/world.yaml DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/config/profiles)

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_world test/world/test_world.cpp test/world/world_run.cpp
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  if(TARGET test_world)
    target_link_libraries(test_world viper_core)
    target_compile_definitions(test_world PRIVATE
      VIPER_WORLD_BINARY="$<TARGET_FILE:world>"
      VIPER_CLASSES_CSV="${PROJECT_SOURCE_DIR}/config/viper_classes.csv")
    add_dependencies(test_world world)
  endif()
endif()
