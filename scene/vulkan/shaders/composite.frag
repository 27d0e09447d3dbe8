// --offscreen: copies the scene's offscreen colour pixel for pixel onto the swapchain image.
#version 450

layout(set = 0, binding = 0) uniform sampler2D scene;
layout(location = 0) out vec4 fragColor;

void main() {
  fragColor = texelFetch(scene, ivec2(gl_FragCoord.xy), 0);
}
