#include "shaders.h"

namespace viper {
namespace scene {

const char* const kLitVertexShader = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
out vec3 vNormal;
void main() {
  vNormal = transpose(inverse(mat3(uWorld))) * aNormal;
  gl_Position = uProj * uView * uWorld * vec4(aPos, 1.0);
}
)";

const char* const kSkinnedVertexShader = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec4 aBoneIds;
layout(location = 3) in vec4 aWeights;
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
uniform mat4 uBones[3];
out vec3 vNormal;
void main() {
  mat4 skin = aWeights.x * uBones[int(aBoneIds.x)] + aWeights.y * uBones[int(aBoneIds.y)]
            + aWeights.z * uBones[int(aBoneIds.z)] + aWeights.w * uBones[int(aBoneIds.w)];
  vNormal = mat3(uWorld) * mat3(skin) * aNormal;
  gl_Position = uProj * uView * uWorld * skin * vec4(aPos, 1.0);
}
)";

const char* const kLitFragmentShader = R"(#version 330 core
in vec3 vNormal;
uniform vec3 uColor;
out vec4 fragColor;
void main() {
  vec3 sun = normalize(vec3(-0.4, -0.5, 0.75));
  float lambert = max(dot(normalize(vNormal), sun), 0.0);
  fragColor = vec4(uColor * (0.35 + 0.65 * lambert), 1.0);
}
)";

const char* const kRainVertexShader = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in float aAlpha;
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
out float vAlpha;
void main() {
  vAlpha = aAlpha;
  gl_Position = uProj * uView * uWorld * vec4(aPos, 1.0);
}
)";

const char* const kRainFragmentShader = R"(#version 330 core
in float vAlpha;
out vec4 fragColor;
void main() {
  fragColor = vec4(0.82, 0.86, 0.95, vAlpha);
}
)";

}  // namespace scene
}  // namespace viper
