// The rain streaks (test_scene's rain program), blended and drawn without depth writes.
#version 450

layout(location = 0) in vec3 aPos;
layout(location = 1) in float aAlpha;

layout(std140, set = 0, binding = 0) uniform Camera {
  mat4 view;
  mat4 projection;
} camera;

layout(push_constant) uniform Push {
  mat4 world;
} pc;

layout(location = 0) out float vAlpha;

void main() {
  vAlpha = aAlpha;
  gl_Position = camera.projection * camera.view * pc.world * vec4(aPos, 1.0);
}
