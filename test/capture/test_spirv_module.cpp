// The Vulkan layer's SPIR-V reading and rewriting, on modules glslangValidator compiles from GLSL
// as real programs ship them, each rewritten module checked by SPIRV-Tools' validator.
#include "src/capture/vulkan/spirv_module.h"

#include <gtest/gtest.h>
#include <spirv-tools/libspirv.hpp>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace viper {
namespace capture {
namespace vulkan {
namespace {

// GLSL -> SPIR-V words with the glslangValidator found at configure time (Vulkan 1.2 target).
std::vector<uint32_t> compile(const std::string& stage, const std::string& glsl, const char* env = "vulkan1.2") {
  const std::string dir = ::testing::TempDir();
  const std::string source = dir + "/shader." + stage, binary = dir + "/shader.spv";
  std::ofstream(source) << glsl;
  const std::string command = std::string(VIPER_GLSLANG_VALIDATOR) + " -V --target-env " + env + " -o " + binary + " " +
                              source + " > " + dir + "/glslang.log 2>&1";
  if (std::system(command.c_str()) != 0) {
    std::ifstream log(dir + "/glslang.log");
    ADD_FAILURE() << "glslangValidator failed:\n" << std::string(std::istreambuf_iterator<char>(log), {});
    return {};
  }
  std::ifstream in(binary, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::vector<uint32_t> words(bytes.size() / 4);
  std::memcpy(words.data(), bytes.data(), words.size() * 4);
  return words;
}

std::string validate(const std::vector<uint32_t>& words, spv_target_env env = SPV_ENV_VULKAN_1_2) {
  spvtools::SpirvTools tools(env);
  std::string messages;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t&, const char* m) {
    messages += m;
    messages += "\n";
  });
  return tools.Validate(words) ? "" : "invalid: " + messages;
}

std::string disassemble(const std::vector<uint32_t>& words) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
  std::string text;
  tools.Disassemble(words, &text, SPV_BINARY_TO_TEXT_OPTION_NO_HEADER);
  return text;
}

const char* kVertex = R"(#version 450
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal_in;
layout(location = 0) out vec3 normal;
layout(push_constant) uniform Push { mat4 world; } pc;
layout(set = 0, binding = 0) uniform Camera { mat4 view; mat4 projection; } camera;
layout(set = 1, binding = 3, row_major) uniform Extra { vec4 tint; mat4 shadow; } extra;
void main() {
  normal = mat3(pc.world) * normal_in + extra.tint.xyz * 0.0;
  gl_Position = camera.projection * camera.view * pc.world * vec4(position, 1.0);
}
)";

TEST(SpirvModule, ReflectsMatricesAndInputsByTheirNames) {
  const std::vector<uint32_t> words = compile("vert", kVertex);
  ASSERT_FALSE(words.empty());
  const ModuleReflection r = reflectModule(words);
  ASSERT_TRUE(r.valid) << r.problem;
  EXPECT_EQ(r.entry_points.at("main"), 0u);  // vertex
  const BlockMember world = r.members.at("world");
  EXPECT_TRUE(world.push_constant);
  EXPECT_EQ(world.offset, 0u);
  EXPECT_EQ(world.matrix_stride, 16u);
  EXPECT_EQ(world.columns, 4u);
  EXPECT_EQ(world.rows, 4u);
  EXPECT_FALSE(world.row_major);
  EXPECT_EQ(r.push_constant_end, 64u);
  const BlockMember projection = r.members.at("projection");
  EXPECT_FALSE(projection.push_constant);
  EXPECT_EQ(projection.set, 0u);
  EXPECT_EQ(projection.binding, 0u);
  EXPECT_EQ(projection.offset, 64u);
  const BlockMember shadow = r.members.at("shadow");
  EXPECT_EQ(shadow.set, 1u);
  EXPECT_EQ(shadow.binding, 3u);
  EXPECT_EQ(shadow.offset, 16u);
  EXPECT_TRUE(shadow.row_major);
  EXPECT_EQ(r.members.at("tint").matrix_stride, 0u);
  EXPECT_EQ(r.input_locations.at("position"), 0u);
  EXPECT_EQ(r.input_locations.at("normal_in"), 1u);
  EXPECT_NE(r.names_text.find("Camera\n"), std::string::npos);
}

TEST(SpirvModule, BadInputIsReportedNotRead) {
  EXPECT_FALSE(reflectModule({}).valid);
  EXPECT_FALSE(reflectModule({1, 2, 3, 4, 5, 6}).valid);
  std::vector<uint32_t> words = compile("vert", kVertex);
  ASSERT_FALSE(words.empty());
  words.resize(words.size() - 3);  // the last instruction cut short
  const ModuleReflection r = reflectModule(words);
  EXPECT_FALSE(r.valid);
  EXPECT_NE(r.problem.find("runs past"), std::string::npos) << r.problem;
  std::string why;
  EXPECT_TRUE(addIdOutput(words, "main", IdOutput{1, 64}, why).empty());
  EXPECT_FALSE(why.empty());
}

struct FragmentCase {
  const char* name;
  const char* glsl;
  uint32_t location;
  uint32_t push_offset;
};

// Shaders as programs write them: with and without their own push constants, discarding,
// reading gl_PrimitiveID themselves, several outputs, early returns.
const FragmentCase kFragments[] = {
    {"own_push_block", R"(#version 450
layout(location = 0) in vec3 normal;
layout(location = 0) out vec4 color;
layout(push_constant) uniform Push { mat4 world; vec4 tint; } pc;
void main() { if (normal.x > 2.0) discard; color = vec4(normal, 1.0) * pc.tint; }
)",
     1, 80},
    {"no_push_constants", R"(#version 450
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;
layout(location = 1) out vec4 normal_out;
layout(set = 0, binding = 1) uniform sampler2D albedo;
void main() { color = texture(albedo, uv); if (color.a < 0.5) return; normal_out = vec4(uv, 0.0, 1.0); }
)",
     2, 0},
    {"reads_primitive_id", R"(#version 450
layout(location = 0) out vec4 color;
void main() { color = vec4(float(gl_PrimitiveID % 7) / 7.0); }
)",
     1, 128},
    // SuperTuxKart's skybox.frag: a push-constant block and no integer type anywhere (the layer's
    // members need one declared before the block).
    {"push_block_without_integers", R"(#version 450
layout(push_constant) uniform Constants { mat4 m_inverse_projection_view_matrix; } u_push_constants;
layout(location = 0) in vec2 f_uv;
layout(binding = 0) uniform samplerCube f_skybox_texture;
layout(location = 0) out vec4 o_color;
void main() {
  vec2 uv = 2.0f * f_uv - 1.0f;
  vec4 front = u_push_constants.m_inverse_projection_view_matrix * vec4(uv, -1.0, 1.0);
  vec4 back = u_push_constants.m_inverse_projection_view_matrix * vec4(uv, 1.0, 1.0);
  o_color = texture(f_skybox_texture, back.xyz / back.w - front.xyz / front.w);
}
)",
     1, 64},
    {"no_outputs_at_all", R"(#version 450
void main() {}
)",
     0, 4},
};

class FragmentRewrite : public ::testing::TestWithParam<FragmentCase> {};

TEST_P(FragmentRewrite, GivesAValidModuleThatWritesTheIdsAndKeepsTheProgramsOwnInterface) {
  const FragmentCase& c = GetParam();
  for (const char* env : {"vulkan1.0", "vulkan1.2"}) {
    SCOPED_TRACE(env);
    const std::vector<uint32_t> words = compile("frag", c.glsl, env);
    ASSERT_FALSE(words.empty());
    ASSERT_EQ(validate(words), "");
    std::string why;
    const std::vector<uint32_t> out = addIdOutput(words, "main", IdOutput{c.location, c.push_offset}, why);
    ASSERT_FALSE(out.empty()) << why;
    EXPECT_EQ(validate(out), "") << disassemble(out);
    const std::string text = disassemble(out);
    EXPECT_NE(text.find("Location " + std::to_string(c.location)), std::string::npos) << text;
    EXPECT_NE(text.find("Offset " + std::to_string(c.push_offset)), std::string::npos) << text;
    EXPECT_NE(text.find("Offset " + std::to_string(c.push_offset + 4)), std::string::npos) << text;
    EXPECT_NE(text.find("BuiltIn PrimitiveId"), std::string::npos) << text;
    // The program's own declarations stay: every line of the original is in the new module.
    const ModuleReflection before = reflectModule(words), after = reflectModule(out);
    ASSERT_TRUE(after.valid) << after.problem;
    EXPECT_EQ(before.entry_points, after.entry_points);
    for (const auto& [name, member] : before.members) {
      ASSERT_TRUE(after.members.count(name)) << name;
      EXPECT_EQ(after.members.at(name).offset, member.offset) << name;
    }
    EXPECT_EQ(before.input_locations, after.input_locations);
  }
}

TEST_P(FragmentRewrite, FromAUniformBufferOfTheLayersOwnWhenPushConstantsAreFull) {
  const FragmentCase& c = GetParam();
  const std::vector<uint32_t> words = compile("frag", c.glsl, "vulkan1.2");
  ASSERT_FALSE(words.empty());
  std::string why;
  const std::vector<uint32_t> out = addIdOutput(words, "main", IdOutput{c.location, 0, 7}, why);
  ASSERT_FALSE(out.empty()) << why;
  EXPECT_EQ(validate(out), "") << disassemble(out);
  const std::string text = disassemble(out);
  EXPECT_NE(text.find("DescriptorSet 7"), std::string::npos) << text;
  const ModuleReflection before = reflectModule(words), after = reflectModule(out);
  EXPECT_EQ(before.push_constant_end, after.push_constant_end);  // the program's push constants untouched
}

INSTANTIATE_TEST_SUITE_P(Shaders, FragmentRewrite, ::testing::ValuesIn(kFragments),
                         [](const ::testing::TestParamInfo<FragmentCase>& info) { return std::string(info.param.name); });

TEST(SpirvModule, RefusesWhatItCannotRewriteAndSaysWhy) {
  std::string why;
  EXPECT_TRUE(addIdOutput(compile("vert", kVertex), "main", IdOutput{0, 64}, why).empty());
  EXPECT_NE(why.find("not a fragment shader"), std::string::npos) << why;

  const std::vector<uint32_t> two_outputs = compile("frag", kFragments[1].glsl);
  EXPECT_TRUE(addIdOutput(two_outputs, "main", IdOutput{1, 0}, why).empty());
  EXPECT_NE(why.find("output location 1"), std::string::npos) << why;
  EXPECT_TRUE(addIdOutput(two_outputs, "other", IdOutput{2, 0}, why).empty());
  EXPECT_NE(why.find("no entry point \"other\""), std::string::npos) << why;

  // The layer's words must come after the shader's own push constants.
  EXPECT_TRUE(addIdOutput(compile("frag", kFragments[0].glsl), "main", IdOutput{1, 64}, why).empty());
  EXPECT_NE(why.find("push constants reach offset 64"), std::string::npos) << why;

  const std::vector<uint32_t> dual = compile("frag", R"(#version 450
layout(location = 0, index = 0) out vec4 color;
layout(location = 0, index = 1) out vec4 weight;
void main() { color = vec4(1.0); weight = vec4(0.5); }
)");
  EXPECT_TRUE(addIdOutput(dual, "main", IdOutput{1, 0}, why).empty());
  EXPECT_NE(why.find("dual-source"), std::string::npos) << why;
}

}  // namespace
}  // namespace vulkan
}  // namespace capture
}  // namespace viper
