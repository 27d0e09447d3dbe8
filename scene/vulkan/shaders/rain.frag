#version 450

layout(location = 0) in float vAlpha;
layout(location = 0) out vec4 fragColor;

void main() {
  fragColor = vec4(0.82, 0.86, 0.95, vAlpha);
}
