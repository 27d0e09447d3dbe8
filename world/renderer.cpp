#include "renderer.h"

#include "classes.h"
#include "textures.h"

#include <cmath>
#include <random>
#include <stdexcept>

namespace viper {
namespace world {

namespace {
constexpr uint32_t kParticleCount = 5000;
const Vec3 kParticleBox{40.0f, 40.0f, 16.0f};

// Uploads `data` to `buffer` and points `count` vertex attributes from `first` on at it, `size`
// floats each, interleaved in that order (one attribute: tightly packed).
void uploadAttributes(GLuint buffer, const std::vector<float>& data, GLuint first, GLint size, int count) {
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glBufferData(GL_ARRAY_BUFFER, data.size() * sizeof(float), data.data(), GL_STATIC_DRAW);
  const GLsizei stride = count > 1 ? GLsizei(count * size * sizeof(float)) : 0;
  for (int a = 0; a < count; ++a) {
    glVertexAttribPointer(first + a, size, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<void*>(a * size * sizeof(float)));
    glEnableVertexAttribArray(first + a);
  }
}

GlMatrix toGl(const Mat4& m) {
  GlMatrix g;
  for (int i = 0; i < 16; ++i) g.data()[i] = m.m[i];
  return g;
}

void uniform3(GLint loc, Vec3 v) { glUniform3f(loc, v.x, v.y, v.z); }
void uniform3(GLuint program, const char* name, Vec3 v) {
  uniform3(glGetUniformLocation(program, name), v);
}
void uniform1(GLuint program, const char* name, float v) {
  glUniform1f(glGetUniformLocation(program, name), v);
}

MeshData particleMesh(uint32_t seed, bool snow) {
  MeshData m;
  std::mt19937 rng(seed);
  auto u = [&](float hi) { return hi * float(rng() % 100000u) / 100000.0f; };
  const uint32_t count = snow ? kParticleCount : kParticleCount + kParticleCount / 2;
  for (uint32_t i = 0; i < count; ++i) {
    Vec3 anchor{u(kParticleBox.x), u(kParticleBox.y), u(kParticleBox.z)};
    uint32_t base = uint32_t(m.vertexCount());
    for (Vec3 corner : {Vec3{-1, -1, 0}, Vec3{1, -1, 0}, Vec3{1, 1, 0}, Vec3{-1, 1, 0}})
      m.addVertex(anchor, corner, {1, 1, 1});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  return m;
}
}  // namespace

void addEffectMeshes(MeshLibrary& meshes, uint32_t seed) {
  MeshData sky;
  sky.addSphere(Mat4(), {1, 1, 1}, 16, 8, {1, 1, 1});
  meshes.add("sky_dome", kSky, std::move(sky));
  meshes.add("rain_streaks", kUnlabeled, particleMesh(seed + 1, false));
  meshes.add("snow_flakes", kUnlabeled, particleMesh(seed + 2, true));
  MeshData glare;
  glare.addQuad({0, -1, -1}, {0, 1, -1}, {0, 1, 1}, {0, -1, 1}, {1, 1, 1});
  meshes.add("sun_glare", kUnlabeled, std::move(glare));
}

void Renderer::init(const MeshLibrary& meshes, int width, int height) {
  width_ = width;
  height_ = height;
  sky_mesh_ = meshes.find("sky_dome");
  rain_mesh_ = meshes.find("rain_streaks");
  snow_mesh_ = meshes.find("snow_flakes");
  glare_mesh_ = meshes.find("sun_glare");
  meshes_ = &meshes;

  for (size_t k = 0; k < programs_.size(); ++k) {
    GLuint p = buildProgram(ProgramKind(k));
    programs_[k] = p;
    Locations& l = loc_[k];
    l.world = glGetUniformLocation(p, "uWorld");
    l.view = glGetUniformLocation(p, "uView");
    l.proj = glGetUniformLocation(p, "uProj");
    l.tint = glGetUniformLocation(p, "uTint");
    l.emissive = glGetUniformLocation(p, "uEmissive");
    l.road = glGetUniformLocation(p, "uRoad");
    l.window = glGetUniformLocation(p, "uWindowGlow");
    l.tex_scale = glGetUniformLocation(p, "uTexScale");
    l.bones = glGetUniformLocation(p, "uBones");
    l.snow = glGetUniformLocation(p, "uSnowCover");
  }

  gpu_.resize(meshes.size());
  for (int i = 0; i < meshes.size(); ++i) {
    const MeshData& d = meshes.at(i).data;
    GpuMesh& g = gpu_[i];
    glGenVertexArrays(1, &g.vao);
    glBindVertexArray(g.vao);
    GLuint buffers[4];
    glGenBuffers(4, buffers);
    // Positions alone in their own buffer (what aPos reads), other attributes in others.
    uploadAttributes(buffers[0], d.positions, 0, 3, 1);
    std::vector<float> attrs;
    attrs.reserve(d.vertexCount() * 6);
    for (size_t v = 0; v < d.vertexCount(); ++v)
      attrs.insert(attrs.end(), {d.normals[3 * v], d.normals[3 * v + 1], d.normals[3 * v + 2],
                                 d.colors[3 * v], d.colors[3 * v + 1], d.colors[3 * v + 2]});
    uploadAttributes(buffers[1], attrs, 1, 3, 2);
    if (d.skinned()) {
      std::vector<float> skin;
      for (size_t v = 0; v < d.vertexCount(); ++v) {
        skin.insert(skin.end(), d.bone_ids.begin() + 4 * v, d.bone_ids.begin() + 4 * v + 4);
        skin.insert(skin.end(), d.bone_weights.begin() + 4 * v, d.bone_weights.begin() + 4 * v + 4);
      }
      uploadAttributes(buffers[2], skin, 3, 4, 2);
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[3]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, d.indices.size() * sizeof(uint32_t), d.indices.data(),
                 GL_STATIC_DRAW);
    g.index_count = GLsizei(d.indices.size());
  }
  glBindVertexArray(0);

  glGenTextures(GLsizei(textures_.size()), textures_.data());
  for (size_t c = 0; c < textures_.size(); ++c) {
    std::vector<uint8_t> px = classTexture(uint8_t(c));
    glBindTexture(GL_TEXTURE_2D, textures_[c]);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, kTextureSize, kTextureSize, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, px.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }
  glViewport(0, 0, width, height);
}

void Renderer::setFrameUniforms(GLuint p, const Mat4& view, const Mat4& proj,
                                const FrameLighting& l) {
  glUseProgram(p);
  glUniformMatrix4fv(glGetUniformLocation(p, "uView"), 1, GL_FALSE, view.m);
  glUniformMatrix4fv(glGetUniformLocation(p, "uProj"), 1, GL_FALSE, proj.m);
  const ConditionParams& c = l.cond;
  uniform3(p, "uCamPos", l.cam_pos);
  uniform3(p, "uSunDir", c.sun_dir);
  uniform3(p, "uSunColor", c.sun_color);
  uniform3(p, "uAmbient", c.ambient);
  uniform3(p, "uFogColor", c.fog_color);
  uniform1(p, "uFogDensity", c.fog_density);
  uniform3(p, "uGrade", c.grade);
  uniform1(p, "uWet", c.wet);
  uniform1(p, "uSnow", c.snow);
  uniform3(p, "uSkyHorizon", c.sky_horizon);
  uniform3(p, "uSkyZenith", c.sky_zenith);
  uniform1(p, "uSunDisc", c.sun_disc);
  uniform1(p, "uStars", c.stars);
  glUniform1i(glGetUniformLocation(p, "uLightCount"), l.light_count);
  for (int i = 0; i < l.light_count; ++i) {
    std::string n = std::to_string(i);
    uniform3(p, ("uLightPos[" + n + "]").c_str(), l.light_pos[i]);
    uniform3(p, ("uLightColor[" + n + "]").c_str(), l.light_color[i]);
  }
  uniform3(p, "uHeadPos", l.head_pos);
  uniform3(p, "uHeadDir", l.head_dir);
  uniform1(p, "uHeadOn", l.head_on);
  glUniform1i(glGetUniformLocation(p, "uTex"), 0);
}

void Renderer::beginFrame(const Mat4& view, const Mat4& proj, const FrameLighting& lighting) {
  view_ = view;
  proj_ = proj;
  lighting_ = lighting;
  const Vec3 f = lighting.cond.fog_color;
  glClearColor(f.x, f.y, f.z, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  for (GLuint p : programs_) setFrameUniforms(p, view, proj, lighting);
  current_program_ = 0;
}

void Renderer::recordDraw(uint32_t object_id, uint8_t class_id, const char* part, int mesh,
                          const Mat4& world, const std::vector<Mat4>* bones) {
  if (!record_) return;
  OracleDraw d;
  d.index = uint32_t(record_->draws.size());
  d.object_id = object_id;
  d.class_id = class_id;
  d.part = part;
  d.mesh = meshes_->at(mesh).name;
  d.world = toGl(world);
  d.skinned = bones != nullptr;
  if (bones)
    for (const Mat4& b : *bones) d.bones.push_back(toGl(b));
  record_->draws.push_back(std::move(d));
}

void Renderer::draw(const DrawRequest& r) {
  const size_t kind = size_t(r.bones ? ProgramKind::kSkinned : ProgramKind::kLit);
  const GLuint p = programs_[kind];
  const Locations& l = loc_[kind];
  if (p != current_program_) {
    glUseProgram(p);
    current_program_ = p;
  }
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, textures_[r.class_id & 31]);
  glUniform1f(l.tex_scale, 1.0f / textureMetres(r.class_id));
  glUniformMatrix4fv(l.world, 1, GL_FALSE, r.world.m);
  uniform3(l.tint, r.tint);
  glUniform1f(l.emissive, r.emissive);
  glUniform1f(l.road, r.class_id == kRoad ? 1.0f : 0.0f);
  glUniform1f(l.snow, lighting_.cond.snow * (r.class_id == kRoad ? 0.55f : 1.0f));
  glUniform1f(l.window, r.class_id == kBuilding ? 0.7f * lighting_.cond.night : 0.0f);
  if (r.bones) glUniformMatrix4fv(l.bones, GLsizei(r.bones->size()), GL_FALSE, r.bones->front().m);
  glBindVertexArray(gpu_[r.mesh].vao);
  glDrawElements(GL_TRIANGLES, gpu_[r.mesh].index_count, GL_UNSIGNED_INT, nullptr);
  recordDraw(r.object_id, r.class_id, r.part, r.mesh, r.world, r.bones);
}

void Renderer::drawSky(uint32_t object_id) {
  const GLuint p = programs_[size_t(ProgramKind::kSky)];
  glUseProgram(p);
  current_program_ = p;
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_CULL_FACE);
  Mat4 world = translation(lighting_.cam_pos) * scaling({500, 500, 500});
  glUniformMatrix4fv(loc_[size_t(ProgramKind::kSky)].world, 1, GL_FALSE, world.m);
  // Effects sample no texture, but a capture layer sees the bound one: bind their own class's.
  glBindTexture(GL_TEXTURE_2D, textures_[kSky]);
  glBindVertexArray(gpu_[sky_mesh_].vao);
  glDrawElements(GL_TRIANGLES, gpu_[sky_mesh_].index_count, GL_UNSIGNED_INT, nullptr);
  recordDraw(object_id, kSky, "dome", sky_mesh_, world, nullptr);
  glDepthFunc(GL_LESS);
}

void Renderer::drawParticles(uint32_t object_id, double t) {
  const Particles kind = lighting_.cond.particles;
  if (kind == Particles::kNone) return;
  const bool snow = kind == Particles::kSnow;
  const GLuint p = programs_[size_t(ProgramKind::kParticles)];
  glUseProgram(p);
  current_program_ = p;
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  const Vec3 origin = lighting_.cam_pos - kParticleBox * 0.5f;
  Mat4 world = translation(origin);
  glUniformMatrix4fv(loc_[size_t(ProgramKind::kParticles)].world, 1, GL_FALSE, world.m);
  glBindTexture(GL_TEXTURE_2D, textures_[kUnlabeled]);
  const float tf = float(std::fmod(t, 1000.0));
  Vec3 fall = snow ? Vec3{0.6f * tf + 0.3f * std::sin(tf), 0.2f * tf, -1.2f * tf}
                   : Vec3{0.5f * tf, 0, -9.0f * tf};
  // Shift so that particles stay put in the world while the box follows the camera.
  Vec3 shift{-origin.x, -origin.y, -origin.z};
  auto wrap = [](float v, float box) { return v - box * std::floor(v / box); };
  shift = {wrap(shift.x, kParticleBox.x), wrap(shift.y, kParticleBox.y), wrap(shift.z, kParticleBox.z)};
  uniform3(p, "uShift", shift);
  uniform3(p, "uFall", fall);
  uniform3(p, "uBox", kParticleBox);
  glUniform2f(glGetUniformLocation(p, "uSize"), snow ? 0.035f : 0.008f, snow ? 0.035f : 0.45f);
  uniform1(p, "uSnowFlakes", snow ? 1.0f : 0.0f);
  if (snow) glUniform4f(glGetUniformLocation(p, "uParticleColor"), 0.97f, 0.97f, 1.0f, 0.9f);
  else glUniform4f(glGetUniformLocation(p, "uParticleColor"), 0.75f, 0.78f, 0.85f, 0.45f);
  const int mesh = snow ? snow_mesh_ : rain_mesh_;
  glBindVertexArray(gpu_[mesh].vao);
  glDrawElements(GL_TRIANGLES, gpu_[mesh].index_count, GL_UNSIGNED_INT, nullptr);
  recordDraw(object_id, kUnlabeled, snow ? "flakes" : "streaks", mesh, world, nullptr);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

void Renderer::drawGlare(uint32_t object_id) {
  if (lighting_.cond.glare <= 0) return;
  const Vec3 s = lighting_.cond.sun_dir;
  const GLuint p = programs_[size_t(ProgramKind::kGlare)];
  glUseProgram(p);
  current_program_ = p;
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE);
  glDepthMask(GL_FALSE);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  Mat4 world = translation(lighting_.cam_pos + s * 100.0f) *
               rotationZ(std::atan2(-s.y, -s.x)) * scaling({1, 70, 70});
  glUniformMatrix4fv(loc_[size_t(ProgramKind::kGlare)].world, 1, GL_FALSE, world.m);
  glBindTexture(GL_TEXTURE_2D, textures_[kUnlabeled]);
  uniform3(p, "uGlareColor", {1.0f, 0.75f, 0.45f});
  uniform1(p, "uGlare", lighting_.cond.glare);
  glBindVertexArray(gpu_[glare_mesh_].vao);
  glDrawElements(GL_TRIANGLES, gpu_[glare_mesh_].index_count, GL_UNSIGNED_INT, nullptr);
  recordDraw(object_id, kUnlabeled, "glare", glare_mesh_, world, nullptr);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

void Renderer::readPixels(std::vector<uint8_t>& rgb) const {
  std::vector<uint8_t> rows(size_t(width_) * height_ * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  rgb.resize(rows.size());
  const size_t stride = size_t(width_) * 3;
  for (int y = 0; y < height_; ++y)
    std::copy(rows.begin() + (height_ - 1 - y) * stride, rows.begin() + (height_ - y) * stride,
              rgb.begin() + y * stride);
}

}  // namespace world
}  // namespace viper
