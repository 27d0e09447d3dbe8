// OpenGL 4.5 core stress program for the capture layer: what real engines do and the other test
// programs do not, one scenario at a time (stress_scene.h says what each draws where):
//   mdi          glMultiDrawElementsIndirect (two commands) and a base-instance draw, instanced
//                attributes (divisor 1);
//   persistent   vertices in a glBufferStorage persistent + coherent mapping, rewritten every frame
//                into one of three regions, each fenced (glFenceSync / glClientWaitSync);
//   ubo_tbo      view and projection in a uniform buffer, world and colour in a texture buffer;
//                its uniforms listed by introspection in every form, printed;
//   binary       glGetProgramBinary, then glProgramBinary into a new program (linked from source
//                where the binary is refused, as the GL allows);
//   threads      a shared context on a second thread uploads each frame's vertices and draws into
//                a framebuffer object of its own while the main thread draws the previous frame's
//                upload; mid-frame the main thread draws in a third, unshared context and returns;
//   destroy      mid-frame (frame 2), the context and its surface are destroyed and made again,
//                and the frame is drawn again from the start;
//   exit_thread  a second thread calls exit() while the main thread is in the middle of a frame;
//   blend_depth  an opaque background, then the objects blended (GL_SRC_ALPHA, ONE_MINUS) with
//                depth writes on, each with a left part of alpha 0.3 (x < -0.4 of its quad);
//   window_queries  (compatibility profile) the window's properties asked in every glGet form,
//                its attachments and status, printed each frame; in frame 2 a framebuffer object
//                of its own deleted while bound;
//   extension_names (compatibility profile) the EXT/ARB names of core functions from
//                eglGetProcAddress (glBindFramebufferEXT back to the default framebuffer after an
//                offscreen pass, glDrawRangeElementsEXT) and a GL_ALPHA texture updated from
//                memory that ends at an unreadable page;
//   depth_prepass the objects drawn depth only (colour masked), then at equal depth with depth
//                writes off, opaque, then blended (its colour added again);
//   fixed_function (compatibility profile) the objects drawn without a program, OpenGL 1.x style:
//                client vertex arrays, the matrix stack, glColor; alpha and stencil tests on one,
//                an occlusion query counting another;
//   combined_matrices a world-space background with a view-projection alone, two objects with
//                model-view and projection, two with a model-view-projection alone;
//   all          each of them in turn (a fresh context each).
// Every GL call is followed by glGetError: an error the program did not cause ends it (exit 3).
// In frame 1 it causes one itself (glEnable of a bad enum) and checks after the frame's calls
// that glGetError still reports exactly that one.
//   gl_stress_program --scenario NAME [--out FILE] [--frames N] [--draw-through-exit 1]
// --draw-through-exit 1 (exit_thread): the main thread draws on while exit() runs, unchecked.
// --out: the program's own read-back of its last frame (RGBA, bottom row first). Exit 0.
// Display: Mesa's surfaceless platform, else the first EGL device (a GPU driver without Mesa);
// pbuffers of 64x64 (stress_scene.h). Prints the renderer.
#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include "gl_common/sanitizer_options.h"
#include "gl_stress_support.h"
#include "stress_scene.h"

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace ss = viper::stress_scene;

namespace {

using namespace viper::stress_program;

// The start of the scenarios that draw the objects with one colour program: their surface made and
// current, the program (kUniformVs, kColourFs), the quad.
struct ColourScene {
  Surface s;
  GLuint p = 0;
  Quad q;
};

ColourScene makeColourScene() {
  ColourScene c;
  c.s = makeSurface(ss::kSize);
  makeCurrent(c.s);
  c.p = program(kUniformVs, kColourFs);
  c.q = makeQuad();
  return c;
}

// ---- scenarios ----

void mdi(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kInstancedVs, kVaryingFs);
  makeQuad(ss::kHalf);  // stays bound: the instance attributes go into its vertex array
  struct Instance {
    float offset[3], colour[4];
  };
  std::vector<Instance> instances(8);
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector2f c = ss::cellCentre(k);
    instances[k] = Instance{{c.x(), c.y(), 0.0f}, {0, 0, 0, 0}};
    std::memcpy(instances[k].colour, ss::colour(k).data(), 16);
  }
  GLuint ib = 0, indirect = 0;
  GL(glGenBuffers(1, &ib));
  GL(glBindBuffer(GL_ARRAY_BUFFER, ib));
  GL(glBufferData(GL_ARRAY_BUFFER, instances.size() * sizeof(Instance), instances.data(), GL_STATIC_DRAW));
  GL(glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Instance), nullptr));
  GL(glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(Instance), reinterpret_cast<void*>(12)));
  for (GLuint a : {1u, 2u}) {
    GL(glEnableVertexAttribArray(a));
    GL(glVertexAttribDivisor(a, 1));
  }
  // {count, instances, first index, base vertex, base instance}: objects 0-3, then 4-5.
  const GLuint commands[10] = {6, 4, 0, 0, 0, 6, 2, 0, 0, 4};
  GL(glGenBuffers(1, &indirect));
  GL(glBindBuffer(GL_DRAW_INDIRECT_BUFFER, indirect));
  GL(glBufferData(GL_DRAW_INDIRECT_BUFFER, sizeof(commands), commands, GL_STATIC_DRAW));
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    setMatrix(p, "u_view", ss::view(f));
    setMatrix(p, "u_proj", ss::projection());
    GL(glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_SHORT, nullptr, 2, 0));
    GL(glDrawElementsInstancedBaseInstance(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr, 2, 6));  // objects 6-7
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

void persistent(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kUniformVs, kColourFs);
  constexpr int kRegions = 3, kVertices = 4 * 6;  // 4 objects of two triangles
  constexpr size_t kRegionBytes = kVertices * 3 * sizeof(float);
  const GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
  GLuint vao = 0, vbo = 0;
  GL(glGenVertexArrays(1, &vao));
  GL(glBindVertexArray(vao));
  GL(glGenBuffers(1, &vbo));
  GL(glBindBuffer(GL_ARRAY_BUFFER, vbo));
  GL(glBufferStorage(GL_ARRAY_BUFFER, kRegions * kRegionBytes, nullptr, flags));
  auto* mapped = static_cast<float*>(GLV(glMapBufferRange(GL_ARRAY_BUFFER, 0, kRegions * kRegionBytes, flags)));
  if (!mapped) die("no persistent mapping");
  GL(glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr));
  GL(glEnableVertexAttribArray(0));
  GLsync fences[kRegions] = {nullptr, nullptr, nullptr};
  for (int f = 0; f < frames; ++f) {
    const int r = f % kRegions;
    if (fences[r]) {  // the GPU is done with what this region held three frames ago
      GLenum w;
      while ((w = GLV(glClientWaitSync(fences[r], GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000ull))) == GL_TIMEOUT_EXPIRED) {
      }
      if (w == GL_WAIT_FAILED) die("glClientWaitSync failed");
      GL(glDeleteSync(fences[r]));
    }
    float* v = mapped + r * kVertices * 3;
    const float corners[6][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, -1}, {1, 1}, {-1, 1}};
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2f c = ss::cellCentre(k, ss::frameShift(f));
      for (int i = 0; i < 6; ++i, v += 3) {
        v[0] = c.x() + ss::kHalf * corners[i][0];
        v[1] = c.y() + ss::kHalf * corners[i][1];
        v[2] = 0.0f;
      }
    }
    beginFrame(f);
    GL(glUseProgram(p));
    setMatrix(p, "u_world", Eigen::Matrix4f::Identity());
    setMatrix(p, "u_view", ss::view(f));
    setMatrix(p, "u_proj", ss::projection());
    for (int k = 0; k < 4; ++k) {
      setColour(p, k);
      GL(glDrawArrays(GL_TRIANGLES, r * kVertices + 6 * k, 6));
    }
    fences[r] = GLV(glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0));
    endFrame(s, f, frames, out);
  }
  for (GLsync fence : fences)
    if (fence) GL(glDeleteSync(fence));
  GL(glUnmapBuffer(GL_ARRAY_BUFFER));
  destroy(s);
}

// What a program learns of its uniforms by introspection, in every form (printed as one line
// "introspect: ...", which the test compares with a run without the layer): counts, names, types,
// sizes and block indices by index, indices by name, a block's uniforms, and the same through the
// program interface queries.
void printIntrospection(GLuint p) {
  GLint n = 0, longest = 0;
  GL(glGetProgramiv(p, GL_ACTIVE_UNIFORMS, &n));
  GL(glGetProgramiv(p, GL_ACTIVE_UNIFORM_MAX_LENGTH, &longest));
  std::string line = "introspect: " + std::to_string(n) + " uniforms, longest " + std::to_string(longest) + ":";
  std::vector<GLuint> all;
  for (GLint i = 0; i < n; ++i) {
    char name[64] = "", name2[64] = "";
    GLsizei length = 0;
    GLint size = 0;
    GLenum type = 0;
    GL(glGetActiveUniform(p, static_cast<GLuint>(i), sizeof(name), &length, &size, &type, name));
    GL(glGetActiveUniformName(p, static_cast<GLuint>(i), sizeof(name2), nullptr, name2));
    line += std::string(" ") + name + "/" + name2 + "/" + std::to_string(type) + "/" + std::to_string(size);
    all.push_back(static_cast<GLuint>(i));
  }
  std::vector<GLint> blocks(all.size());
  GL(glGetActiveUniformsiv(p, static_cast<GLsizei>(all.size()), all.data(), GL_UNIFORM_BLOCK_INDEX, blocks.data()));
  line += "; blocks";
  for (GLint b : blocks) line += " " + std::to_string(b);
  const char* const names[3] = {"s_proj", "u_object", "u_objects"};
  GLuint indices[3];
  GL(glGetUniformIndices(p, 3, names, indices));
  line += "; indices " + std::to_string(indices[0]) + " " + std::to_string(indices[1]) + " " + std::to_string(indices[2]);
  GLint in_block = 0;
  GL(glGetActiveUniformBlockiv(p, 0, GL_UNIFORM_BLOCK_ACTIVE_UNIFORMS, &in_block));
  std::vector<GLint> block_indices(static_cast<size_t>(in_block));
  GL(glGetActiveUniformBlockiv(p, 0, GL_UNIFORM_BLOCK_ACTIVE_UNIFORM_INDICES, block_indices.data()));
  line += "; block 0:";
  for (GLint i : block_indices) line += " " + std::to_string(i);
  GLint resources = 0, max_name = 0;
  GL(glGetProgramInterfaceiv(p, GL_UNIFORM, GL_ACTIVE_RESOURCES, &resources));
  GL(glGetProgramInterfaceiv(p, GL_UNIFORM, GL_MAX_NAME_LENGTH, &max_name));
  line += "; resources " + std::to_string(resources) + ", longest " + std::to_string(max_name) + ":";
  for (GLint i = 0; i < resources; ++i) {
    char name[64] = "";
    GL(glGetProgramResourceName(p, GL_UNIFORM, static_cast<GLuint>(i), sizeof(name), nullptr, name));
    const GLenum prop = GL_BLOCK_INDEX;
    GLint block = 0;
    GL(glGetProgramResourceiv(p, GL_UNIFORM, static_cast<GLuint>(i), 1, &prop, 1, nullptr, &block));
    line += std::string(" ") + name + "/" + std::to_string(block);
  }
  line += "; index of u_object " + std::to_string(GLV(glGetProgramResourceIndex(p, GL_UNIFORM, "u_object")));
  const GLenum props[2] = {GL_NUM_ACTIVE_VARIABLES, GL_ACTIVE_VARIABLES};
  GLint variables[8] = {0};
  GLsizei written = 0;
  GL(glGetProgramResourceiv(p, GL_UNIFORM_BLOCK, 0, 2, props, 8, &written, variables));
  line += "; block variables";
  for (GLsizei i = 0; i < written; ++i) line += " " + std::to_string(variables[i]);
  std::printf("%s\n", line.c_str());
}

void uboTbo(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kBlockVs, kVaryingFs);
  GL(glUniformBlockBinding(p, GLV(glGetUniformBlockIndex(p, "Camera")), 2));
  printIntrospection(p);
  const Quad q = makeQuad();
  GLuint ubo = 0, tbo = 0, tex = 0;
  GL(glGenBuffers(1, &ubo));
  GL(glBindBuffer(GL_UNIFORM_BUFFER, ubo));
  GL(glBufferData(GL_UNIFORM_BUFFER, 128, nullptr, GL_DYNAMIC_DRAW));
  GL(glGenBuffers(1, &tbo));
  GL(glBindBuffer(GL_TEXTURE_BUFFER, tbo));
  GL(glBufferData(GL_TEXTURE_BUFFER, 4 * 5 * 16, nullptr, GL_DYNAMIC_DRAW));
  GL(glGenTextures(1, &tex));
  GL(glActiveTexture(GL_TEXTURE3));
  GL(glBindTexture(GL_TEXTURE_BUFFER, tex));
  GL(glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, tbo));
  GL(glUseProgram(p));
  GL(glUniform1i(GLV(glGetUniformLocation(p, "u_objects")), 3));
  for (int f = 0; f < frames; ++f) {
    const Eigen::Matrix4f view = ss::view(f), proj = ss::projection();
    GL(glBindBuffer(GL_UNIFORM_BUFFER, ubo));
    GL(glBufferSubData(GL_UNIFORM_BUFFER, 0, 64, view.data()));
    GL(glBufferSubData(GL_UNIFORM_BUFFER, 64, 64, proj.data()));
    GL(glBindBufferBase(GL_UNIFORM_BUFFER, 2, ubo));
    for (int k = 0; k < 4; ++k) {
      GL(glBufferSubData(GL_TEXTURE_BUFFER, k * 80, 64, ss::world(k).data()));
      GL(glBufferSubData(GL_TEXTURE_BUFFER, k * 80 + 64, 16, ss::colour(k).data()));
    }
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) {
      GL(glUniform1i(GLV(glGetUniformLocation(p, "u_object")), k));
      GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr));
    }
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

void binary(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  GLint formats = 0;
  GL(glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats));
  const GLuint from_source = program(kUniformVs, kColourFs);
  GLint length = 0;
  GL(glGetProgramiv(from_source, GL_PROGRAM_BINARY_LENGTH, &length));
  std::vector<uint8_t> bytes(static_cast<size_t>(std::max(length, 1)));
  GLenum format = 0;
  GLsizei written = 0;
  GL(glGetProgramBinary(from_source, length, &written, &format, bytes.data()));
  GL(glDeleteProgram(from_source));
  // As a shader cache does: the stored binary first; where it is refused, the source.
  const GLuint p = GLV(glCreateProgram());
  GLint linked = 0;
  if (written > 0) {
    GL(glProgramBinary(p, format, bytes.data(), written));
    GL(glGetProgramiv(p, GL_LINK_STATUS, &linked));
  }
  std::printf("binary_formats=%d binary_bytes=%d binary_loaded=%d\n", formats, written, linked);
  if (!linked) linkFromSource(p, kUniformVs, kColourFs);
  const Quad q = makeQuad();
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) drawObject(p, k, f);
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

/// The uploads the loader thread made for one frame: its vertices (4 quads) and their fence.
struct Upload {
  GLuint vbo = 0;
  GLsync fence = nullptr;
};

/// A channel of uploads from the loader thread to the main thread.
struct Uploads {
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<Upload> ready;
  bool stop = false;
  void push(const Upload& u) {
    std::lock_guard<std::mutex> lock(mutex);
    ready.push_back(u);
    changed.notify_all();
  }
  Upload pop() {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [&] { return !ready.empty(); });
    const Upload u = ready.front();
    ready.pop_front();
    changed.notify_all();
    return u;
  }
  /// The loader waits while two uploads are ahead of the main thread.
  bool waitForRoom() {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [&] { return ready.size() < 2 || stop; });
    return !stop;
  }
};

/// The loader thread: a shared context of its own (its own small pbuffer), each frame's vertices
/// in a new buffer, the objects' textures updated, and a draw into a framebuffer object of its own.
void loader(EGLContext share, GLuint* textures, int frames, Uploads* uploads) {
  Surface s = makeSurface(16, share);
  makeCurrent(s);
  GLuint fbo = 0, target = 0;
  GL(glGenTextures(1, &target));
  GL(glBindTexture(GL_TEXTURE_2D, target));
  GL(glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 16, 16));
  GL(glGenFramebuffers(1, &fbo));
  GL(glBindFramebuffer(GL_FRAMEBUFFER, fbo));
  GL(glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target, 0));
  if (GLV(glCheckFramebufferStatus(GL_FRAMEBUFFER)) != GL_FRAMEBUFFER_COMPLETE) die("loader framebuffer incomplete");
  const GLuint p = program(kUniformVs, kColourFs);
  const Quad q = makeQuad();
  for (int f = 0; f < frames && uploads->waitForRoom(); ++f) {
    std::vector<float> v;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2f c = ss::cellCentre(k, ss::frameShift(f));
      static const float kCorners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& corner : kCorners)
        v.insert(v.end(), {c.x() + ss::kHalf * corner[0], c.y() + ss::kHalf * corner[1], 0.0f});
    }
    Upload u;
    GL(glGenBuffers(1, &u.vbo));
    GL(glBindBuffer(GL_ARRAY_BUFFER, u.vbo));
    GL(glBufferData(GL_ARRAY_BUFFER, v.size() * sizeof(float), v.data(), GL_STATIC_DRAW));
    for (int k = 0; k < 4; ++k) {
      std::vector<uint8_t> texels(4 * 4 * 4);
      for (size_t i = 0; i < texels.size(); ++i) texels[i] = static_cast<uint8_t>(ss::colour(k)[i % 4] * 255.0f + 0.5f);
      GL(glBindTexture(GL_TEXTURE_2D, textures[k]));
      GL(glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 4, 4, GL_RGBA, GL_UNSIGNED_BYTE, texels.data()));
    }
    // Something drawn on this thread too (an impostor, a generated texture) while the main thread draws.
    GL(glBindFramebuffer(GL_FRAMEBUFFER, fbo));
    GL(glViewport(0, 0, 16, 16));
    GL(glClear(GL_COLOR_BUFFER_BIT));
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    drawObject(p, f % 4, f);
    u.fence = GLV(glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0));
    GL(glFlush());
    uploads->push(u);
  }
  destroy(s);
}

void threads(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint p = program(kUniformVs, kTexturedFs);
  GLuint textures[4];
  GL(glGenTextures(4, textures));
  for (GLuint t : textures) {
    GL(glBindTexture(GL_TEXTURE_2D, t));
    GL(glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 4, 4, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr));
    GL(glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST));
    GL(glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST));
  }
  GL(glFinish());  // the textures exist before the loader's context uses them
  const Quad q = makeQuad();  // its index buffer; the loader's buffers give the vertices
  Uploads uploads;
  std::thread load(loader, s.context, textures, frames, &uploads);
  // A third context, not shared, used mid-frame (a tool window, a second view).
  Surface other = makeSurface(32);
  GLuint other_program = 0;
  Quad other_quad;
  GLuint previous_vbo = 0;
  for (int f = 0; f < frames; ++f) {
    const Upload u = uploads.pop();
    GL(glWaitSync(u.fence, 0, GL_TIMEOUT_IGNORED));
    GL(glDeleteSync(u.fence));
    GL(glBindVertexArray(q.vao));
    GL(glBindBuffer(GL_ARRAY_BUFFER, u.vbo));
    GL(glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr));
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glActiveTexture(GL_TEXTURE0));
    for (int k = 0; k < 4; ++k) {
      if (k == 2) {  // mid-frame: a draw in the other context, then back
        makeCurrent(other);
        if (!other_program) {
          other_program = program(kUniformVs, kColourFs);
          other_quad = makeQuad();
        }
        GL(glViewport(0, 0, 32, 32));
        GL(glClearColor(1, 1, 1, 1));
        GL(glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT));
        GL(glUseProgram(other_program));
        GL(glBindVertexArray(other_quad.vao));
        drawObject(other_program, 5, f);
        uint8_t pixel[4] = {0, 0, 0, 0};
        GL(glReadPixels(16, 16, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, pixel));
        if (pixel[0] != 255) die("the other context's image is wrong");
        makeCurrent(s);
      }
      GL(glBindTexture(GL_TEXTURE_2D, textures[k]));
      // Vertices of object k are 4 .. 4k + 3 of the upload: base vertex, world = identity.
      setMatrix(p, "u_world", Eigen::Matrix4f::Identity());
      setMatrix(p, "u_view", ss::view(f));
      setMatrix(p, "u_proj", ss::projection());
      GL(glDrawElementsBaseVertex(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr, 4 * k));
    }
    endFrame(s, f, frames, out);
    if (previous_vbo) GL(glDeleteBuffers(1, &previous_vbo));
    previous_vbo = u.vbo;
  }
  {
    std::lock_guard<std::mutex> lock(uploads.mutex);
    uploads.stop = true;
    uploads.changed.notify_all();
  }
  load.join();
  for (const Upload& u : uploads.ready) {
    GL(glDeleteSync(u.fence));
    GL(glDeleteBuffers(1, &u.vbo));
  }
  makeCurrent(other);
  destroy(other);
  makeCurrent(s);
  destroy(s);
}

void destroyMidFrame(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  GLuint p = program(kUniformVs, kColourFs);
  Quad q = makeQuad();
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) {
      if (f == 2 && k == 2) {  // the context is lost: everything made again, the frame drawn again
        destroy(s);
        s = makeSurface(ss::kSize);
        makeCurrent(s);
        p = program(kUniformVs, kColourFs);
        q = makeQuad();
        std::printf("context made again in frame %d\n", f);
        beginFrame(f);
        GL(glUseProgram(p));
        GL(glBindVertexArray(q.vao));
        for (int j = 0; j < k; ++j) drawObject(p, j, f);
      }
      drawObject(p, k, f);
    }
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

/// Another thread calls exit() while the main thread is in the middle of a frame (its context
/// current, two of its four draws made, after `frames` frames swapped), where the main thread
/// stays; with --draw-through-exit 1 it draws on meanwhile (checking nothing: the driver is torn
/// down under it, and a swap may fail).
void exitThread(int frames, const std::string& out) {
  auto [s, p, q] = makeColourScene();
  static std::atomic<bool> written{false}, parked{false};
  std::thread exiter([] {
    while (!written.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    g_exiting = true;
    while (!parked.load() && !g_draw_through_exit) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::printf("exit() from another thread\n");
    std::fflush(stdout);
    std::exit(0);
  });
  exiter.detach();
  for (int f = 0;; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    for (int k = 0; k < 4; ++k) {
      if (f == frames && k == 2 && !g_draw_through_exit) {
        parked = true;
        for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      drawObject(p, k, f);
    }
    endFrame(s, f, frames, out);
    if (f == frames - 1) {
      written = true;
      while (!g_exiting) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
}

// Blended draws that write depth (alpha 0.3 in a part of each object): the capture's ids must
// follow the depth there (id 0, not the background's id under the object's depth).
void blendDepth(int frames, const std::string& out) {
  Surface s = makeSurface(ss::kSize);
  makeCurrent(s);
  const GLuint background = program(kUniformVs, kColourFs);
  const GLuint veiled = program(kLocalXVs, kVeiledFs);
  const Quad q = makeQuad();
  Eigen::Affine3f behind = Eigen::Affine3f::Identity();
  behind.translate(Eigen::Vector3f(0.0f, 0.0f, ss::kBackgroundZ));
  behind.scale(Eigen::Vector3f(0.95f, 0.95f, 1.0f));
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glUseProgram(background));
    setMatrix(background, "u_world", behind.matrix());
    setMatrix(background, "u_view", ss::view(f));
    setMatrix(background, "u_proj", ss::projection());
    GL(glUniform4f(GLV(glGetUniformLocation(background, "u_colour")), 0.5f, 0.5f, 0.5f, 1.0f));
    GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr));
    GL(glUseProgram(veiled));
    setMatrix(veiled, "u_view", ss::view(f));
    setMatrix(veiled, "u_proj", ss::projection());
    GL(glEnable(GL_BLEND));
    GL(glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA));
    GL(glDepthMask(GL_TRUE));
    for (int k = 0; k < 4; ++k) {
      setMatrix(veiled, "u_world", ss::world(k));
      setColour(veiled, k);
      GL(glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_SHORT, nullptr));
    }
    GL(glDisable(GL_BLEND));
    endFrame(s, f, frames, out);
  }
  (void)q;
  destroy(s);
}

// A depth pre-pass engine: the objects first with their colour masked (depth only), then again at
// equal depth with depth writes off, opaque, and a third time blended over that (a texture layer).
// The ids are those of the pre-pass, which decided what is visible.
void depthPrepass(int frames, const std::string& out) {
  auto [s, p, q] = makeColourScene();
  for (int f = 0; f < frames; ++f) {
    beginFrame(f);
    GL(glUseProgram(p));
    GL(glBindVertexArray(q.vao));
    GL(glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE));
    for (int k = 0; k < 4; ++k) drawObject(p, k, f);
    GL(glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE));
    GL(glDepthMask(GL_FALSE));
    GL(glDepthFunc(GL_EQUAL));
    for (int k = 0; k < 4; ++k) drawObject(p, k, f);
    GL(glEnable(GL_BLEND));
    GL(glBlendFunc(GL_ONE, GL_ONE));
    for (int k = 0; k < 4; ++k) drawObject(p, k, f);  // its colour again, added
    GL(glDisable(GL_BLEND));
    GL(glDepthMask(GL_TRUE));
    GL(glDepthFunc(GL_LESS));
    endFrame(s, f, frames, out);
  }
  destroy(s);
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenario, out;
  int frames = ss::kFrames;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--scenario") scenario = v;
    else if (a == "--out") out = v;
    else if (a == "--frames") frames = std::atoi(v.c_str());
    else if (a == "--draw-through-exit") g_draw_through_exit = v == "1";
    else die("unknown option " + a);
  }
  if (frames < 3) die("--frames must be at least 3");
  const std::vector<std::pair<std::string, std::function<void(int, const std::string&)>>> scenarios = {
      {"mdi", mdi},         {"persistent", persistent},     {"ubo_tbo", uboTbo},          {"binary", binary},
      {"threads", threads}, {"destroy", destroyMidFrame}, {"exit_thread", exitThread}, {"blend_depth", blendDepth},
      {"window_queries", windowQueries}, {"extension_names", extensionNames}, {"depth_prepass", depthPrepass},
      {"fixed_function", fixedFunction}, {"combined_matrices", combinedMatrices}};
  bool found = false;
  for (const auto& s : scenarios) {
    if (scenario != "all" && scenario != s.first) continue;
    found = true;
    std::printf("scenario %s\n", s.first.c_str());
    std::fflush(stdout);
    s.second(frames, out);
  }
  if (!found) die("unknown scenario '" + scenario + "'");
  std::fflush(stdout);
  return 0;
}
