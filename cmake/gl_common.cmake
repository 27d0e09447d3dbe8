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
