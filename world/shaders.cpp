#include "shaders.h"

#include "gl_common/shader_build.h"

#include <vector>

namespace viper {
namespace world {

namespace {
// Lighting is evaluated per vertex (llvmpipe renders 1080p on two cores only with a very short
// fragment shader); the town's large ground surfaces are tessellated so that light pools of
// street lamps and headlights still show. Lambert with hemisphere ambient, point lights, the
// ego's headlight cone, wet-road reflections, exponential fog.
const char* kLightingHeader = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aColor;
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
uniform float uTexScale;
uniform float uRoad;
uniform vec3 uCamPos;
uniform vec3 uSunDir;
uniform vec3 uSunColor;
uniform vec3 uAmbient;
uniform float uFogDensity;
uniform float uWet;
uniform vec3 uSkyHorizon;
uniform int uLightCount;
uniform vec3 uLightPos[8];
uniform vec3 uLightColor[8];
uniform vec3 uHeadPos;
uniform vec3 uHeadDir;
uniform float uHeadOn;
uniform vec3 uTint;
uniform float uEmissive;
uniform float uSnowCover;
uniform float uWindowGlow;
uniform vec3 uFogColor;
uniform vec3 uGrade;
// The fragment colour is texture.rgb * vMul + step(0.75, texture.a) * vGlow + vAdd: everything
// but the texture lookup is folded into three varyings here.
out vec3 vMul;
out vec3 vAdd;
out vec3 vGlow;
out vec2 vUv;
void shade(vec3 wp, vec3 n, vec3 objPos, vec3 color) {
  vUv = (abs(n.z) > 0.7 ? wp.xy : vec2(objPos.x + objPos.y, objPos.z)) * uTexScale;
  float up = smoothstep(0.55, 0.9, n.z);
  vec3 light = uAmbient * (0.65 + 0.35 * n.z) + uSunColor * max(dot(n, uSunDir), 0.0);
  vec3 v = normalize(uCamPos - wp);
  vec3 r = reflect(-v, n);
  vec3 spec = vec3(0.0);
  for (int i = 0; i < uLightCount; ++i) {
    vec3 l = uLightPos[i] - wp;
    float d2 = dot(l, l);
    l *= inversesqrt(d2);
    vec3 c = uLightColor[i] / (1.0 + 0.03 * d2);
    light += c * max(dot(n, l), 0.0);
    spec += c * pow(max(dot(r, l), 0.0), 16.0);
  }
  if (uHeadOn > 0.0) {
    vec3 l = uHeadPos - wp;
    float d2 = dot(l, l);
    l *= inversesqrt(d2);
    float cone = smoothstep(0.82, 0.95, dot(-l, uHeadDir));
    vec3 c = vec3(1.0, 0.95, 0.8) * uHeadOn * cone * 40.0 / (1.0 + 0.15 * d2);
    light += c * max(dot(n, l), 0.0);
    spec += c * pow(max(dot(r, l), 0.0), 16.0);
  }
  vec3 add = vec3(0.0);
  if (uRoad > 0.5 && uWet > 0.0) {
    float fresnel = pow(1.0 - max(dot(v, n), 0.0), 4.0);
    add = uWet * (fresnel * uSkyHorizon * 0.5 + spec * 2.0 +
                  uSunColor * pow(max(dot(r, uSunDir), 0.0), 60.0));
  }
  float fog = exp(-uFogDensity * length(wp - uCamPos));
  float snow = uSnowCover * up;
  vec3 lit = light + uEmissive;
  vMul = color * uTint * (1.0 - snow) * lit * fog * uGrade;
  vAdd = (vec3(0.93, 0.94, 0.97) * snow * lit + add) * fog * uGrade + uFogColor * (1.0 - fog) * uGrade;
  vGlow = uWindowGlow * (1.0 - up) * vec3(1.0, 0.8, 0.45) * fog * uGrade;
}
)";

const char* kLitVertexMain = R"(
void main() {
  vec4 wp = uWorld * vec4(aPos, 1.0);
  shade(wp.xyz, normalize(mat3(uWorld) * aNormal), aPos, aColor);
  gl_Position = uProj * uView * wp;
}
)";

const char* kSkinnedVertexMain = R"(
layout(location = 3) in vec4 aBoneIds;
layout(location = 4) in vec4 aBoneWeights;
uniform mat4 uBones[16];
void main() {
  mat4 skin = aBoneWeights.x * uBones[int(aBoneIds.x)] + aBoneWeights.y * uBones[int(aBoneIds.y)]
            + aBoneWeights.z * uBones[int(aBoneIds.z)] + aBoneWeights.w * uBones[int(aBoneIds.w)];
  vec4 posed = skin * vec4(aPos, 1.0);
  vec4 wp = uWorld * posed;
  shade(wp.xyz, normalize(mat3(uWorld) * (mat3(skin) * aNormal)), posed.xyz, aColor);
  gl_Position = uProj * uView * wp;
}
)";

// One texture lookup; lighting, snow, emission, fog and grade come folded in the varyings.
const char* kLitFragment = R"(#version 330 core
in vec3 vMul;
in vec3 vAdd;
in vec3 vGlow;
in vec2 vUv;
out vec4 fragColor;
uniform sampler2D uTex;
void main() {
  vec4 tex = texture(uTex, vUv);
  fragColor = vec4(tex.rgb * vMul + step(0.75, tex.a) * vGlow + vAdd, 1.0);
}
)";

// The sky dome sits on the far plane (z = w) and is drawn after the opaque scene.
const char* kSkyVertex = R"(#version 330 core
layout(location = 0) in vec3 aPos;
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
out vec3 vDir;
void main() {
  vDir = aPos;
  vec4 p = uProj * uView * uWorld * vec4(aPos, 1.0);
  gl_Position = p.xyww;
}
)";

const char* kSkyFragment = R"(#version 330 core
in vec3 vDir;
out vec4 fragColor;
uniform vec3 uSkyZenith;
uniform vec3 uSkyHorizon;
uniform vec3 uSunDir;
uniform vec3 uSunColor;
uniform float uSunDisc;
uniform float uStars;
uniform vec3 uGrade;
uniform vec3 uFogColor;
void main() {
  vec3 d = normalize(vDir);
  float h = clamp(d.z, 0.0, 1.0);
  vec3 c = mix(uSkyHorizon, uSkyZenith, sqrt(h));
  c = mix(uFogColor, c, smoothstep(-0.02, 0.12, d.z));
  float s = max(dot(d, uSunDir), 0.0);
  c += uSunDisc * (uSunColor * pow(s, 400.0) * 3.0 + uSunColor * pow(s, 12.0) * 0.35);
  if (uStars > 0.0) {
    vec3 g = floor(d * 300.0);
    float r = fract(sin(dot(g, vec3(12.9898, 78.233, 37.719))) * 43758.5453);
    c += uStars * step(0.9985, r) * h * vec3(0.8);
  }
  fragColor = vec4(c * uGrade, 1.0);
}
)";

// Rain streaks and snow flakes: aPos is a particle's anchor inside the box, aNormal its corner
// (x across, y along); positions wrap around the box that follows the camera.
const char* kParticleVertex = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
uniform vec3 uShift;
uniform vec3 uFall;
uniform vec3 uBox;
uniform vec2 uSize;
uniform float uSnowFlakes;
out vec2 vCorner;
void main() {
  vec3 local = mod(aPos + uFall * (0.8 + 0.4 * fract(aPos.x * 7.31)) + uShift, uBox);
  vec4 center = uWorld * vec4(local, 1.0);
  vec3 right = vec3(uView[0][0], uView[1][0], uView[2][0]);
  vec3 up = uSnowFlakes > 0.5 ? vec3(uView[0][1], uView[1][1], uView[2][1])
                              : normalize(vec3(0.08, 0.0, 1.0));
  vec3 wp = center.xyz + right * aNormal.x * uSize.x + up * aNormal.y * uSize.y;
  vCorner = aNormal.xy;
  gl_Position = uProj * uView * vec4(wp, 1.0);
}
)";

const char* kParticleFragment = R"(#version 330 core
in vec2 vCorner;
out vec4 fragColor;
uniform vec4 uParticleColor;
uniform float uSnowFlakes;
void main() {
  float a = uSnowFlakes > 0.5 ? 1.0 - smoothstep(0.5, 1.0, length(vCorner))
                              : 1.0 - abs(vCorner.x);
  fragColor = vec4(uParticleColor.rgb, uParticleColor.a * a);
}
)";

// Sun glare: a camera-facing sprite towards the sun, blended additively.
const char* kGlareVertex = R"(#version 330 core
layout(location = 0) in vec3 aPos;
uniform mat4 uWorld;
uniform mat4 uView;
uniform mat4 uProj;
out vec2 vUv;
void main() {
  vUv = aPos.yz;
  gl_Position = uProj * uView * uWorld * vec4(aPos, 1.0);
}
)";

const char* kGlareFragment = R"(#version 330 core
in vec2 vUv;
out vec4 fragColor;
uniform vec3 uGlareColor;
uniform float uGlare;
void main() {
  float r = length(vUv);
  float a = uGlare * (exp(-r * r * 9.0) * 0.9 + 0.25 * exp(-r * 3.0) +
                      0.08 * smoothstep(0.05, 0.0, abs(r - 0.55)));
  fragColor = vec4(uGlareColor, clamp(a, 0.0, 1.0));
}
)";

// For the errors: "compiling the sky vertex shader failed: ...".
const char* programName(ProgramKind kind) {
  switch (kind) {
    case ProgramKind::kLit: return "lit";
    case ProgramKind::kSkinned: return "skinned";
    case ProgramKind::kSky: return "sky";
    case ProgramKind::kParticles: return "particles";
    case ProgramKind::kGlare: return "glare";
    default: return "unknown";
  }
}
}  // namespace

GLuint buildProgram(ProgramKind kind) {
  std::string vertex = std::string(kLightingHeader) + kLitVertexMain;
  const char* fs = kLitFragment;
  if (kind == ProgramKind::kSkinned) vertex = std::string(kLightingHeader) + kSkinnedVertexMain;
  const char* vs = vertex.c_str();
  switch (kind) {
    case ProgramKind::kSky: vs = kSkyVertex, fs = kSkyFragment; break;
    case ProgramKind::kParticles: vs = kParticleVertex, fs = kParticleFragment; break;
    case ProgramKind::kGlare: vs = kGlareVertex, fs = kGlareFragment; break;
    default: break;
  }
  const gl_common::ShaderCalls calls = gl_common::linkedShaderCalls();
  const char* name = programName(kind);
  GLuint p = glCreateProgram();
  GLuint v = gl_common::compileShader(calls, GL_VERTEX_SHADER, vs, name);
  GLuint f = gl_common::compileShader(calls, GL_FRAGMENT_SHADER, fs, name);
  glAttachShader(p, v);
  glAttachShader(p, f);
  glBindAttribLocation(p, 0, "aPos");
  gl_common::linkProgram(calls, p, {v, f}, name);
  return p;
}

}  // namespace world
}  // namespace viper
