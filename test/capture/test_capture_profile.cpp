// Capture profile parsing: entries, matching, defaults, and errors that name the file.
#include "viper/capture/capture_profile.h"

#include <gtest/gtest.h>

#include <stdexcept>


using namespace viper;

namespace {

// What parsing `yaml` as "bad.yaml" throws, or "no error".
std::string message(const std::string& yaml) {
  try {
    parseCaptureProfile(yaml, "bad.yaml");
  } catch (const std::runtime_error& e) {
    return std::string(e.what());
  }
  return std::string("no error");
}

}  // namespace

TEST(CaptureProfile, ParsesEntriesAndMatchesInOrder) {
  const CaptureProfile p = parseCaptureProfile(R"(
programs:
  - vertex_contains: uBones
    world: uWorld
    position: aPos
    deforming: true
  - program_key: 0x10
    view: uV
    deforming: false
  - world: uModel
    view: uView
    projection: uProj
)",
                                               "test.yaml");
  ASSERT_EQ(p.programs.size(), 3u);
  EXPECT_EQ(p.programs[0].deforming, Deforming::kYes);
  EXPECT_EQ(p.programs[1].program_key, 16u);
  EXPECT_EQ(p.match("uniform mat4 uBones[4];", 16)->world, "uWorld");
  EXPECT_EQ(p.match("plain", 16)->view, "uV");
  const ProgramProfile* other = p.match("plain", 17);
  EXPECT_EQ(other->world, "uModel");
  EXPECT_EQ(other->projection, "uProj");
  EXPECT_EQ(other->deforming, Deforming::kAuto);
  EXPECT_EQ(other->position, "");
}

TEST(CaptureProfile, EmptyProfileFallsBackToDefaults) {
  const CaptureProfile p = parseCaptureProfile("", "empty.yaml");
  EXPECT_TRUE(p.programs.empty());
  const ProgramProfile* m = p.match("anything", 1);
  ASSERT_NE(m, nullptr);
  EXPECT_TRUE(m->world.empty());
  EXPECT_EQ(m->deforming, Deforming::kAuto);
}

TEST(CaptureProfile, ShippedProfileLoads) {
  const CaptureProfile p = loadCaptureProfile("config/profiles/viper_scene.yaml");
  ASSERT_EQ(p.programs.size(), 2u);
  EXPECT_EQ(p.match("uniform mat4 uBones[8];", 0)->deforming, Deforming::kYes);
  EXPECT_EQ(p.match("uniform mat4 uWorld;", 0)->position, "aPos");
}

TEST(CaptureProfile, ErrorsNameTheFileAndTheProblem) {
  const std::string unknown = message("programs:\n  - wrold: uWorld\n");
  EXPECT_NE(unknown.find("bad.yaml:2"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("wrold"), std::string::npos) << unknown;
  EXPECT_NE(message("programs: [a, b]").find("must be a map"), std::string::npos);
  EXPECT_NE(message("programs:\n  - deforming: maybe\n").find("auto, true or false"), std::string::npos);
  EXPECT_NE(message("programs:\n  - program_key: xyz\n").find("program_key"), std::string::npos);
  EXPECT_NE(message("programs:\n  - world: [1, 2]\n").find("'world' must be a string"), std::string::npos);
  EXPECT_NE(message("progams: []\n").find("unknown top-level key"), std::string::npos);
  EXPECT_NE(message("programs: [\n").find("not valid YAML"), std::string::npos);
  EXPECT_NE(message("programs: [\n").find("bad.yaml"), std::string::npos);
}

TEST(CaptureProfile, SuperTuxKartProfile) {
  const CaptureProfile p = loadCaptureProfile("config/profiles/supertuxkart.yaml");
  EXPECT_TRUE(p.left_handed);
  // A mesh shader of the game (sp_pass.vert): matrices in the Matrices block, instances placed by
  // origin, rotation and scale attributes.
  const ProgramProfile* mesh = p.match("layout(location = 8) in vec3 i_origin;\nuniform mat4 x;", 0);
  EXPECT_EQ(mesh->view, "u_view_matrix");
  EXPECT_EQ(mesh->instance_translation, "i_origin");
  EXPECT_TRUE(mesh->instance_rotation_conjugate);
  EXPECT_EQ(mesh->deforming, Deforming::kNo);
  EXPECT_TRUE(mesh->hasInstanceTransform());
  EXPECT_EQ(p.match("uniform samplerBuffer skinning_tex; in vec3 i_origin;", 0)->deforming, Deforming::kYes);
  EXPECT_EQ(p.match("uniform vec3 wind_direction; in vec3 i_origin;", 0)->deforming, Deforming::kYes);
  EXPECT_TRUE(p.match("uniform vec2 center;\nuniform vec2 size;", 0)->overlay);
  EXPECT_FALSE(p.match("in vec3 Position; void main() { gl_Position = vec4(Position, 1.); }", 0)->overlay);
}

TEST(CaptureProfile, EngineKeysAndTheirErrors) {
  const CaptureProfile p = parseCaptureProfile(R"(
handedness: left
programs:
  - instance_world: iModel
    overlay: false
  - vertex_contains: hud
    overlay: yes
)",
                                               "engine.yaml");
  EXPECT_TRUE(p.left_handed);
  EXPECT_EQ(p.programs[0].instance_world, "iModel");
  EXPECT_TRUE(p.programs[1].overlay);
  EXPECT_FALSE(parseCaptureProfile("programs: []\n", "x").left_handed);
  EXPECT_NE(message("handedness: up\n").find("left or right"), std::string::npos);
  EXPECT_NE(message("programs:\n  - overlay: maybe\n").find("'overlay' must be true or false"), std::string::npos);
  EXPECT_NE(message("programs:\n  - instance_world: a\n    instance_scale: b\n").find("exclude each other"),
            std::string::npos);
}

TEST(CaptureProfile, MatrixStackKey) {
  const CaptureProfile p = parseCaptureProfile("programs:\n  - matrix_stack: load_view_mult_world\n    position: gl_Vertex\n",
                                               "stack.yaml");
  EXPECT_EQ(p.programs[0].matrix_stack, "load_view_mult_world");
  EXPECT_EQ(p.programs[0].position, "gl_Vertex");
  EXPECT_NE(message("programs:\n  - matrix_stack: yes\n").find("must be load_view_mult_world or push_world, got 'yes'"),
            std::string::npos);
  EXPECT_NE(message("programs:\n  - matrix_stack: load_view_mult_world\n    view: v\n").find("exclude each other"),
            std::string::npos);
}

TEST(CaptureProfile, FixedFunctionEntry) {
  const CaptureProfile p = parseCaptureProfile(
      "programs:\n  - vertex_contains: a\n  - fixed_function: true\n    matrix_stack: load_view_mult_world\n", "ff.yaml");
  // It matches draws without a program only, and programs never match it.
  EXPECT_EQ(p.matchFixedFunction(), &p.programs[1]);
  EXPECT_EQ(p.match("b", 0)->vertex_contains, "");
  EXPECT_FALSE(p.match("b", 0)->fixed_function);
  const CaptureProfile none = parseCaptureProfile("programs:\n  - vertex_contains: a\n", "none.yaml");
  EXPECT_TRUE(none.matchFixedFunction()->fixed_function);
  EXPECT_EQ(none.matchFixedFunction()->matrix_stack, "");
  EXPECT_NE(message("programs:\n  - fixed_function: true\n    world: u_world\n").find("only matrix_stack, world_space and overlay"),
            std::string::npos);
  EXPECT_NE(message("programs:\n  - fixed_function: maybe\n").find("'fixed_function' must be true or false"),
            std::string::npos);
}

TEST(CaptureProfile, CombinedMatrixKeys) {
  const CaptureProfile p = parseCaptureProfile(
      "programs:\n  - vertex_contains: a\n    model_view: mv\n    projection: p\n"
      "  - vertex_contains: b\n    view_projection: vp\n    world_space: true\n"
      "  - model_view_projection: mvp\n",
      "combined.yaml");
  EXPECT_TRUE(p.combinesMatrices());
  EXPECT_EQ(p.match("a", 0)->model_view, "mv");
  EXPECT_TRUE(p.match("b", 0)->world_space);
  EXPECT_EQ(p.match("c", 0)->model_view_projection, "mvp");
  EXPECT_FALSE(parseCaptureProfile("programs:\n  - world: w\n", "plain.yaml").combinesMatrices());
  EXPECT_NE(message("programs:\n  - world_space: true\n    world: w\n").find("no world or instance_* with it"),
            std::string::npos);
  EXPECT_NE(message("programs:\n  - matrix_stack: load_view_mult_world\n    model_view: mv\n").find("exclude each other"),
            std::string::npos);
  EXPECT_NE(message("programs:\n  - world_space: sometimes\n").find("'world_space' must be true or false"),
            std::string::npos);
}

TEST(CaptureProfile, MinetestProfile) {
  const CaptureProfile p = loadCaptureProfile("config/profiles/minetest.yaml");
  EXPECT_TRUE(p.left_handed);
  const ProgramProfile* nodes = p.match("#define mWorldViewProj gl_ModelViewProjectionMatrix\nuniform mat4 mWorld;", 0);
  EXPECT_EQ(nodes->matrix_stack, "load_view_mult_world");
  EXPECT_EQ(nodes->position, "gl_Vertex");
}

TEST(CaptureProfile, MatrixNamesOfVec4ArrayElementsAndClipDepth) {
  const MatrixName mat4 = parseMatrixName("uBones[3]");  // a mat4 array element stays a mat4's name
  EXPECT_FALSE(mat4.isElements());
  EXPECT_EQ(mat4.name, "uBones[3]");
  const MatrixName rows = parseMatrixName("vs_cb0[4] rows");
  EXPECT_EQ(rows.name, "vs_cb0");
  EXPECT_EQ(rows.first_element, 4);
  EXPECT_TRUE(rows.rows);
  const MatrixName columns = parseMatrixName("Camera.regs[0] columns");
  EXPECT_EQ(columns.name, "Camera.regs");
  EXPECT_EQ(columns.first_element, 0);
  EXPECT_FALSE(columns.rows);
  for (const char* bad : {"vs_cb0[4] sideways", "vs_cb0 rows", "[4] rows", "vs_cb0[] rows", "vs_cb0[-1] rows",
                          "vs_cb0[4x] rows", "vs_cb0[65536] rows", "vs_cb0[4] rows extra", "vs_cb0[4 rows"})
    EXPECT_THROW(parseMatrixName(bad), std::invalid_argument) << bad;

  const CaptureProfile p = loadCaptureProfile("config/profiles/d3d11_scene.yaml");
  EXPECT_TRUE(p.left_handed);
  EXPECT_TRUE(p.clip_depth_zero_to_one);
  const ProgramProfile* cb = p.match("layout(std140, binding = 15) uniform block_vs_cb0 { vec4 vs_cb0[13]; };", 0);
  EXPECT_EQ(cb->world, "vs_cb0[0] rows");
  EXPECT_EQ(cb->projection, "vs_cb0[8] rows");
  EXPECT_FALSE(parseCaptureProfile("programs: []\n", "plain.yaml").clip_depth_zero_to_one);
  EXPECT_NE(message("clip_depth: reversed\n").find("'clip_depth' must be zero_to_one or minus_one_to_one"),
            std::string::npos);
  EXPECT_NE(message("programs:\n  - view: regs[2] diagonally\n").find("'view': 'regs[2] diagonally' is neither"),
            std::string::npos);
  EXPECT_NE(message("programs:\n  - projection: regs[x] rows\n").find("must be an array element"), std::string::npos);
}

TEST(CaptureProfile, MissingFileIsNamed) {
  try {
    loadCaptureProfile("/nonexistent/profile.yaml");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/profile.yaml"), std::string::npos);
  }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
