// --offscreen: the HUD panel, 2D positions in normalised device coordinates from a vertex buffer.
#version 450

layout(location = 0) in vec2 aCorner;

void main() {
  gl_Position = vec4(aCorner, 0.0, 1.0);
}
