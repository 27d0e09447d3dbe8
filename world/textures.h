// Procedural per-class textures (RGBA8). Every class has its own texture with distinct content,
// so a texture names its class; building textures carry a window mask in alpha.
#pragma once

#include <cstdint>
#include <vector>

namespace viper {
namespace world {

/// Side length of every class texture (pixels).
constexpr int kTextureSize = 64;

/// RGBA8 pixels (kTextureSize^2) of the texture of `class_id`. Deterministic.
std::vector<uint8_t> classTexture(uint8_t class_id);

/// World metres per texture repeat for a class (uv = position / metres).
float textureMetres(uint8_t class_id);

}  // namespace world
}  // namespace viper
