// GLSL 330 core sources of the world's programs and a small compile/link helper. Every program
// has `in vec3 aPos` at location 0 and the uniforms uWorld, uView, uProj; fragment output
// `out vec4 fragColor`.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <string>

namespace viper {
namespace world {

/// The programs of the world.
enum class ProgramKind { kLit, kSkinned, kSky, kParticles, kGlare, kCount };

/// Number of bones in the skinned program's uBones array.
constexpr int kMaxBones = 16;
/// Number of point lights the lit programs take.
constexpr int kMaxLights = 8;

/// Compiles and links the program of `kind`. Throws std::runtime_error with the GLSL log.
GLuint buildProgram(ProgramKind kind);

}  // namespace world
}  // namespace viper
