// The vertex shader of a full-screen pass that draws without a vertex buffer (glDrawArrays of 3
// vertices): one triangle over the whole screen, its texture coordinates in `uv`. The composite
// passes of gl_test_program (--offscreen) and gl_engine_program (--offscreen 1) draw with it.
#pragma once

namespace viper {
namespace test_program {

inline const char* const kFullScreenTriangleVs = R"(#version 330 core
out vec2 uv;
void main() {
  uv = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
)";

}  // namespace test_program
}  // namespace viper
