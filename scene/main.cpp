// test_scene: a small plain OpenGL program (a street with cars, buildings, a skinned person and rain)
// that the capture layer is tested on. It knows nothing of capture; --oracle writes the true
// answers for tests.
#include "gl_api.h"
#include "options.h"
#include "renderer.h"
#include "world.h"

#include "gl_common/headless_egl_context.h"
#include "gl_common/ppm.h"
#include "gl_common/sanitizer_options.h"
#include "viper/ground_truth/oracle.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

namespace {

using namespace viper::scene;

// The oracle record of a mesh: positions (floats 0..2 of each interleaved vertex, what aPos reads),
// indices and, for the skinned layout, bone ids and weights (floats 6..9 and 10..13).
viper::OracleMesh toOracleMesh(const MeshData& m) {
  viper::OracleMesh o;
  o.name = m.name;
  o.indices = m.indices;
  const size_t stride = static_cast<size_t>(floatsPerVertex(m.layout));
  for (size_t v = 0; v + stride <= m.vertices.size(); v += stride) {
    o.positions_xyz.insert(o.positions_xyz.end(), m.vertices.begin() + v, m.vertices.begin() + v + 3);
    if (m.layout != VertexLayout::kSkinned) continue;
    for (size_t k = 6; k < 10; ++k) o.bone_ids.push_back(static_cast<uint32_t>(m.vertices[v + k]));
    o.bone_weights.insert(o.bone_weights.end(), m.vertices.begin() + v + 10, m.vertices.begin() + v + 14);
  }
  return o;
}

viper::OracleFrame toOracle(uint64_t number, const FrameState& s, const World& world) {
  viper::OracleFrame f;
  f.number = number;
  f.time_s = s.time_s;
  f.view = s.view;
  f.projection = s.projection;
  f.map_from_camera_body = s.map_from_camera_body;
  for (size_t i = 0; i < s.draws.size(); ++i) {
    const DrawItem& item = s.draws[i];
    viper::OracleDraw d;
    d.index = static_cast<uint32_t>(i);
    d.object_id = item.object_id;
    d.class_id = item.class_id;
    d.part = item.part;
    d.mesh = world.meshes()[item.mesh].name;
    d.world = item.world;
    d.skinned = item.program == ProgramKind::kSkinned;
    d.bones = item.bones;
    f.draws.push_back(std::move(d));
  }
  return f;
}

int run(const SceneOptions& o) {
  if (!o.dump_dir.empty()) std::filesystem::create_directories(o.dump_dir);
  viper::gl_common::HeadlessEglContext context(o.width, o.height);
  const GlApi gl = loadGlApi(o.loader);
  std::cerr << "test_scene: " << o.width << "x" << o.height << ", EGL " << context.platform() << ", GL loader "
            << glLoaderName(o.loader) << ", renderer " << reinterpret_cast<const char*>(gl.GetString(GL_RENDERER))
            << "\n";
  const World world(o.seed, static_cast<double>(o.width) / o.height);
  Renderer renderer(gl, world.meshes(), o.width, o.height);
  std::unique_ptr<viper::OracleWriter> oracle;
  if (!o.oracle_path.empty()) oracle = std::make_unique<viper::OracleWriter>(o.oracle_path, o.width, o.height);

  double total_ms = 0.0;
  for (uint64_t n = 0; n < o.frames; ++n) {
    const FrameState state = world.frame(static_cast<double>(n) / o.fps);
    const auto start = std::chrono::steady_clock::now();
    renderer.draw(state);
    if (!o.dump_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof(name), "frame_%06llu.ppm", static_cast<unsigned long long>(n));
      viper::gl_common::writePpm((std::filesystem::path(o.dump_dir) / name).string(), o.width, o.height, renderer.readColor());
    }
    if (o.benchmark) gl.Finish();  // time the rendering, not just the command submission
    context.swapBuffers();
    total_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (oracle) {
      for (const DrawItem& item : state.draws)
        if (!oracle->hasMesh(world.meshes()[item.mesh].name)) oracle->writeMesh(toOracleMesh(world.meshes()[item.mesh]));
      oracle->write(toOracle(n, state, world));
    }
  }
  if (o.benchmark)
    std::cout << "benchmark: frames=" << o.frames << " size=" << o.width << "x" << o.height
              << " mean_frame_ms=" << total_ms / o.frames << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  SceneOptions options;
  try {
    options = parseOptions(std::vector<std::string>(argv + 1, argv + argc));
  } catch (const OptionsError& e) {
    std::cerr << "test_scene: " << e.what() << "\n";
    return 2;
  }
  if (options.help) {
    std::cout << usage();
    return 0;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::cerr << "test_scene: " << e.what() << "\n";
    return 1;
  }
}
