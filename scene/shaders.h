// GLSL 330 core sources of the scene's three programs. Every program names its matrices uWorld
// (model -> world), uView (world -> OpenGL camera) and uProj, and its position attribute aPos at
// location 0; that is what config/profiles/test_scene.yaml tells the capture layer.
#pragma once

namespace viper {
namespace scene {

/// Lambert-shaded rigid meshes.
extern const char* const kLitVertexShader;
/// Lambert-shaded tube deformed by `uniform mat4 uBones[3]` with per-vertex aBoneIds/aWeights.
extern const char* const kSkinnedVertexShader;
/// Fragment shader of the lit and skinned programs (uColor, fixed sun).
extern const char* const kLitFragmentShader;
/// Rain streaks: unlit, per-vertex alpha for blending.
extern const char* const kRainVertexShader;
extern const char* const kRainFragmentShader;

}  // namespace scene
}  // namespace viper
