// The lit and (with -DSKINNED) the skinned program of vk_test_scene: test_scene's shaders with the
// camera in a uniform buffer (read at a dynamic offset), the world matrix in push constants and the
// bones in a storage buffer, as Vulkan engines keep them.
#version 450

layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
#ifdef SKINNED
layout(location = 2) in vec4 aBoneIds;
layout(location = 3) in vec4 aWeights;
#endif

// projection is OpenGL's matrix premultiplied by the Vulkan clip correction (y down, z in [0, 1]).
layout(std140, set = 0, binding = 0) uniform Camera {
  mat4 view;
  mat4 projection;
} camera;

#ifdef SKINNED
layout(std430, set = 0, binding = 1) readonly buffer Bones {
  mat4 bones[];
};
#endif

layout(push_constant) uniform Push {
  mat4 world;
} pc;

layout(location = 0) out vec3 vNormal;

void main() {
#ifdef SKINNED
  mat4 skin = aWeights.x * bones[int(aBoneIds.x)] + aWeights.y * bones[int(aBoneIds.y)]
            + aWeights.z * bones[int(aBoneIds.z)] + aWeights.w * bones[int(aBoneIds.w)];
  vNormal = mat3(pc.world) * mat3(skin) * aNormal;
  gl_Position = camera.projection * camera.view * pc.world * skin * vec4(aPos, 1.0);
#else
  vNormal = transpose(inverse(mat3(pc.world))) * aNormal;
  gl_Position = camera.projection * camera.view * pc.world * vec4(aPos, 1.0);
#endif
}
