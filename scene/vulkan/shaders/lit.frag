// Lambert shading of the lit and skinned programs (test_scene's); the albedo is a fragment push
// constant after the vertex stage's world matrix.
#version 450

layout(location = 0) in vec3 vNormal;

layout(push_constant) uniform Push {
  layout(offset = 64) vec3 color;
} pc;

layout(location = 0) out vec4 fragColor;

void main() {
  vec3 sun = normalize(vec3(-0.4, -0.5, 0.75));
  float lambert = max(dot(normalize(vNormal), sun), 0.0);
  fragColor = vec4(pc.color * (0.35 + 0.65 * lambert), 1.0);
}
