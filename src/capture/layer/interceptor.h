// State and behaviour of the capture layer; the exported GL/EGL/GLX functions (hooks_*.cpp)
// forward to the real driver through this class.
#pragma once

#include "frame_sink.h"
#include "frame_target.h"
#include "gl_real.h"
#include "matrix_stack.h"
#include "mesh_extract.h"
#include "viper/capture/camera_recovery.h"
#include "viper/capture/capture_profile.h"

#include <atomic>
#include <deque>
#include "viper/capture/shader_rewrite.h"

#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace viper {
namespace capture {

// How a draw now meets the depth image, from one read of the depth state: whether it writes depth
// (its mask on and the depth test enabled: without the test the GL writes no depth either), and
// whether it only shades surfaces an earlier pass put there (mask off, the test passing at equal
// depth only: the colour passes of a depth pre-pass engine and the layers it blends over them,
// whose ids would only repeat the pass that decided what is visible, which keeps them).
struct DepthUse {
  bool writes = false;
  bool shades_decided = false;
};
DepthUse depthUse(const RealGl& g);

/// What the interceptor knows about one shader object.
struct ShaderInfo {
  GLenum type = 0;
  std::string original;
  FragmentRewrite rewrite;  ///< rewrite.ok: the driver holds the rewritten source
};

/// Where a matrix the profile names lives: a default-block uniform, or a member of a uniform block
/// (read from the buffer bound to the block's binding point at each draw); or four vec4 elements of
/// an array (MatrixName::isElements), of the default block (their locations) or of a uniform block
/// (offset and matrix_stride: the first element's and the array's stride).
struct MatrixSource {
  GLint location = -1;               ///< default-block uniform
  GLint element_locations[4] = {-1, -1, -1, -1};  ///< default-block vec4 array elements
  GLuint block = GL_INVALID_INDEX;   ///< uniform block index
  GLint offset = 0;                  ///< bytes into the block
  GLint matrix_stride = 16;          ///< bytes between columns (rows if row_major)
  bool row_major = false;            ///< rows, not columns, are matrix_stride apart (or the elements)
  bool found() const { return location >= 0 || element_locations[0] >= 0 || block != GL_INVALID_INDEX; }
};

/// Instanced vertex attributes (locations, -1 = absent) that place each instance of a draw.
struct InstanceTransform {
  GLint world = -1;  ///< mat4: four consecutive locations, one column each
  GLint translation = -1, rotation = -1, scale = -1;
  bool rotation_conjugate = false;
  bool any() const { return world >= 0 || translation >= 0 || rotation >= 0 || scale >= 0; }
};

/// What the interceptor knows about one linked program.
struct ProgramInfo {
  uint64_t key = 0;
  bool rewritten = false;   ///< fragment shader writes viper_id_out
  bool deforming = false;   ///< gl_Position is captured with transform feedback
  bool own_feedback = false;  ///< the program set its own transform feedback varyings
  bool has_geometry_stage = false;
  bool overlay = false;     ///< the profile says: 2D overlay (HUD, menus), never recorded
  /// A shader reads gl_InstanceID, gl_BaseInstance or gl_DrawID: instanced and multi draws are
  /// issued as the program made them (one record for all instances).
  bool reads_draw_parameters = false;
  GLint loc_draw_id = -1, loc_alpha_test = -1;
  MatrixSource world, view, projection;
  MatrixSource model_view, view_projection, model_view_projection;
  bool world_space = false;  ///< the profile says: vertices in world space (world = identity)
  /// A combined matrix or world space: its records are finished at the end of the frame, when
  /// the frame's camera is recovered (resolveCombined).
  bool combined = false;
  InstanceTransform instance;
  bool matrix_stack = false;           ///< matrices from the fixed-function stack (matrix_stack.h)
  bool stack_push_world = false;       ///< matrix_stack: push_world (else load_view_mult_world)
  uint8_t expected_matrices = 0;       ///< MatrixFlags the profile names for this program
  GLint position_attrib = 0;
  bool vertex_array_position = false;  ///< positions from the conventional array (glVertexPointer)
  std::vector<GLint> sampler_locations;
  std::vector<GLenum> sampler_targets;
  /// The layer's own uniforms (viper_draw_id, viper_alpha_test): their active-uniform indices,
  /// ascending, hidden from the program's introspection (hooks_introspection.cpp), and the longest
  /// name of the program's own uniforms (GL_ACTIVE_UNIFORM_MAX_LENGTH without ours, with its 0).
  std::vector<GLuint> hidden_uniforms;
  GLint visible_uniform_max_length = 0;
  float alpha_test_value = -1.0f;  ///< last value set, to skip redundant glUniform calls
};

/// Shadow copy of a buffer object's contents.
struct BufferShadow {
  std::vector<uint8_t> data;
  uint64_t version = 0;
  uint64_t key = 0;
  uint64_t key_version = ~0ull;
  // Active write mapping (glMapBuffer*), copied into `data` at unmap.
  void* map_pointer = nullptr;
  size_t map_offset = 0, map_length = 0;
  /// The mapping is persistent (glBufferStorage + GL_MAP_PERSISTENT_BIT): it stays while the
  /// program draws, and its memory, not `data`, holds what the GPU reads.
  bool map_persistent = false;
};

/// Draw call arguments, normalised.
struct DrawCall {
  GLenum mode = GL_TRIANGLES;
  GLsizei count = 0;
  GLint first = 0;             ///< non-indexed draws
  bool indexed = false;
  GLenum index_type = 0;
  size_t index_offset = 0;     ///< bytes into the element buffer
  GLint base_vertex = 0;
  GLsizei instances = 1;
  GLuint base_instance = 0;
  bool immediate = false;      ///< glBegin: its vertices are known at glEnd (count 0 until then)
};

/// A draw whose deformed vertices are being captured by transform feedback (read at the swap).
struct PendingDeform {
  uint32_t draw_index;
  GLuint buffer;
  uint32_t vertices;
};

/// What the layer keeps per GL context: its substitute framebuffer, the GL state it tracks (which
/// the GL keeps per context too), the frame being recorded from the context's draws (written at its
/// swap), and its own objects that contexts do not share. Threads drawing in contexts of their own
/// (loader threads, several windows) so never mix their draws, and a context destroyed mid-frame
/// takes its unfinished frame with it.
struct ContextState {
  std::unique_ptr<FrameTarget> target;
  bool current = false;    ///< current on a thread now
  bool destroyed = false;  ///< eglDestroyContext while current: dropped when released

  CaptureFrame frame;  ///< being recorded
  std::vector<PendingDeform> pending_deform;
  std::vector<GLuint> feedback_buffers;
  GLuint feedback_object = 0;  ///< transform feedback objects are never shared
  /// Vertex range of the draw in flight's mesh (copied: the mesh cache is shared by all contexts
  /// and may be cleared by another thread's swap meanwhile).
  bool last_mesh = false;
  uint32_t last_mesh_first = 0, last_mesh_vertices = 0;
  void setLastMesh(const ExtractedMesh& m) {
    last_mesh = true;
    last_mesh_first = static_cast<uint32_t>(m.first_vertex);
    last_mesh_vertices = static_cast<uint32_t>(m.vertex_count);
  }
  /// This frame's matrices as the programs gave them, of every recorded draw, where the profile
  /// has combined matrices (camera_recovery.h), resolved at the swap (resolveCombined).
  struct DrawMatricesEntry {
    uint32_t index;
    bool deferred;             ///< a combined program's draw: its record is finished then
    uint8_t expected;          ///< its program's expected_matrices
    DrawMatrices matrices;
  };
  std::vector<DrawMatricesEntry> frame_matrices;
  ModelViewTracker modelview;
  std::vector<uint32_t> stack_draws;  ///< this frame's draws with world and view from the stack
  bool last_recorded = false;

  GLuint current_program = 0;
  ProgramInfo* current_program_info = nullptr;
  GLuint active_unit = 0;
  std::unordered_map<uint64_t, GLuint> unit_bindings;  ///< (unit << 32 | target) -> texture
  bool blend_dirty = true;
  bool ids_write = true;  ///< write mask last set on the id attachment
  bool blend0_enabled = false;
  bool base_instance_draws = false;  ///< GL >= 4.2 (glDraw*BaseInstance)
  /// A context with the fixed-function pipeline (compatibility profile, or before OpenGL 3.1),
  /// whose draws without a program are recorded (fixed_function.cpp).
  bool fixed_function = false;
  bool fixed_function_noted = false;  ///< fixed_function and counting_queries known (at the first make-current)
  /// The context has program pipelines (GL 4.1, ARB_separate_shader_objects) and ARB vertex
  /// programs: a draw with program 0 may be a pipeline's, or transformed by an ARB program.
  bool program_pipelines = false, arb_vertex_programs = false;
  /// Query targets of the context's GL (occlusion, primitives, pipeline statistics): a draw made
  /// while one of them is active gets no id pass (it would count in the program's query).
  std::vector<GLenum> counting_queries;
  /// The id pass (fixed_function.cpp): its program (0: not made yet), made once per context.
  GLuint id_program = 0;
  GLint id_program_draw_id = -1;
  bool id_program_failed = false;
  /// Draw id (index + 1) the id pass of the draw in flight writes; 0: no id pass.
  float id_pass_value = 0.0f;
  /// glNewList's mode while the program makes a display list (0: none). Its draws are then not
  /// recorded, and no id pass goes into the list; the layer's state for its id buffer (draw
  /// buffers, the blending that clears its ids) does, before each of them, as the list's draws
  /// need it when it is called. (Without it in the lists, FooBillard++'s balls, drawn from lists
  /// that set blending, changed under the layer: scripts/capture_corpus.sh --program
  /// foobillardplus; why the id buffer's state changes the program's colour there is not pinned
  /// down.) With GL_COMPILE, matrix calls are not tracked (they run when the list is called).
  GLenum compiling_list = 0;
  /// A glBegin/glEnd without a program being recorded: its record and the vertices (x, y, z, w).
  struct Immediate {
    bool active = false;
    GLenum mode = 0;
    uint32_t record = 0;
    std::vector<float> vertices;
  } immediate;
  /// What the id pass changed, restored after it.
  struct IdPassSaved {
    GLboolean color_masks[kIdDrawBuffer][4];
    GLint depth_func = GL_LESS;
    bool stencil_test = false, alpha_test = false;
  } id_pass_saved;
};

/// The capture layer (one per process).
class Interceptor {
 public:
  static Interceptor& instance();
  /// The interceptor where it captures (an output was given and nothing failed), else null: the
  /// exported functions then only forward to the driver.
  static Interceptor* active() {
    Interceptor& i = instance();
    return i.enabled() ? &i : nullptr;
  }
  /// Writes what is queued and closes the stream; capture stops.
  void shutdown();
  bool enabled() const { return enabled_.load(std::memory_order_relaxed); }

  // Window system.
  /// Before the calling thread's context changes (or is released): frames still being read
  /// asynchronously from the current one are handed over, and its read-back buffers left free.
  void beforeMakeCurrent();
  void onMakeCurrent(void* context, int width, int height);
  /// eglDestroyContext / glXDestroyContext: what the layer kept for the context is dropped (its
  /// GL objects went with it), at once or, if it is current, when it is released.
  void contextDestroyed(void* context);
  /// At a buffer swap of a surface of `width` x `height`; `offscreen` for pbuffers.
  void beforeSwap(int width, int height, bool offscreen);

  // Shaders and programs.
  void shaderSource(GLuint shader, GLsizei count, const GLchar* const* strings, const GLint* lengths);
  void compileShader(GLuint shader);
  void linkProgram(GLuint program);
  void useProgram(GLuint program);
  void transformFeedbackVaryings(GLuint program);

  // Framebuffers.
  void bindFramebuffer(GLenum target, GLuint fb);
  /// After glDeleteFramebuffers: a deleted framebuffer the program had bound leaves the default
  /// one (ours) bound in its place, as the GL binds the real one; our ids for it are dropped.
  void framebuffersDeleted(GLsizei n, const GLuint* names);
  /// Before the program's glBlitFramebuffer (FrameTarget::programBlitToWindow).
  void blitFramebuffer(GLint src_x0, GLint src_y0, GLint src_x1, GLint src_y1, GLint dst_x0, GLint dst_y0,
                       GLint dst_x1, GLint dst_y1, GLbitfield mask);
  void drawBuffer(GLenum buf);
  void drawBuffers(GLsizei n, const GLenum* bufs);
  void readBuffer(GLenum buf);
  void clear(GLbitfield mask);
  /// glAccum: the accumulation buffer is the window's alone (giveUp).
  void accum(GLenum op, GLfloat value);
  /// The calling thread's context draws as without the layer from now on (FrameTarget::giveUp),
  /// said once with `why`.
  void giveUp(const char* why);
  /// Around a glGet* of `pname`: where it is state of the window's framebuffer (GL_DOUBLEBUFFER,
  /// GL_SAMPLES, GL_DEPTH_BITS...) and the program has its default framebuffer bound, the real
  /// default framebuffer is bound for the query (true: endWindowQuery() after it), so that the
  /// program hears the window's answer, not our substitute's.
  bool beginWindowQuery(GLenum pname);
  /// The same around a query of the framebuffer bound to `target` (glGetFramebufferAttachment-
  /// Parameteriv, glGetFramebufferParameteriv, glCheckFramebufferStatus) where the program has its
  /// default framebuffer bound there.
  bool beginWindowFramebufferQuery(GLenum target);
  /// Our framebuffer bound again where the program has its default framebuffer.
  void endWindowQuery();
  /// After a glGet*: the answer the program would have without the layer, where ours differs
  /// (framebuffer bindings: 0 for ours; the draw and read buffers it selected; no program binary
  /// formats). False where the driver's answer stands.
  bool overrideQuery(GLenum pname, GLint64& value);
  void blendStateChanged(bool blend_enabled_known, bool blend_enabled);
  /// After glColorMask, which sets the mask of every draw buffer, ours too: ours back to what the
  /// layer decides (a depth pre-pass masks its colour, and its ids decide what is visible).
  void colorMaskChanged();

  // Buffers and textures.
  void bufferData(GLenum target, GLuint name, GLsizeiptr size, const void* data);
  void bufferSubData(GLenum target, GLuint name, GLintptr offset, GLsizeiptr size, const void* data);
  void mapped(GLenum target, void* pointer, GLintptr offset, GLsizeiptr length, GLbitfield access);
  void beforeUnmap(GLenum target);
  void copyBufferSubData(GLenum read_target, GLenum write_target, GLintptr read_offset, GLintptr write_offset,
                         GLsizeiptr size);
  void deleteBuffers(GLsizei n, const GLuint* names);
  void activeTexture(GLenum unit) { cx().active_unit = unit - GL_TEXTURE0; }
  void bindTexture(GLenum target, GLuint name);
  void texImage(GLenum target, GLint level, GLsizei w, GLsizei h, GLenum format, GLenum type, const void* pixels,
                bool sub, GLint x, GLint y);
  /// glCompressedTex(Sub)Image2D: `bytes` of compressed data (keyed as they are).
  void compressedTexImage(GLenum target, GLint level, GLsizei w, GLsizei h, GLenum format, GLsizei bytes,
                          const void* data, bool sub, GLint x, GLint y);
  void deleteTextures(GLsizei n, const GLuint* names);

  /// The fixed-function model-view stack as the program builds it (hooks_legacy.cpp).
  ModelViewTracker& modelView() { return cx().modelview; }

  /// Called around every draw: `before` returns true if the draw is recorded.
  bool beforeDraw(const DrawCall& call);
  void afterDraw(const DrawCall& call);
  /// True if an instanced draw is to be issued one instance at a time (instance k as base
  /// instance + k), so that every instance gets its own draw id and record. Only when that cannot
  /// change what is drawn: no shader reads gl_InstanceID/gl_BaseInstance/gl_DrawID, every
  /// instanced attribute advances once per instance, and the context has base-instance draws.
  bool splitsInstances(const DrawCall& call);
  /// Multi and indirect draws are issued as the single draws they stand for (each recorded) unless
  /// a shader of the current program reads gl_DrawID (or no draw would be recorded anyway).
  bool decomposesMultiDraw();
  /// Before a display list (glCallList(s)) or an immediate-mode draw with a program, `what`: not
  /// recorded, counted in the frame's unrecorded draws; without a program, its ids cleared where
  /// it writes depth, with one, ids off (logged once).
  void beforeUnrecordableDraw(const char* what);
  /// glBegin (before the GL's): without a program, recorded as a draw without a program whose
  /// vertices (immediateVertex) are known at glEnd; with one, as beforeUnrecordableDraw.
  void beginImmediate(GLenum mode);
  void immediateVertex(float x, float y, float z, float w) {
    ContextState& c = cx();
    if (c.immediate.active) c.immediate.vertices.insert(c.immediate.vertices.end(), {x, y, z, w});
  }
  /// glEnd (after the GL's): the recorded draw's mesh from its vertices, and its id pass (the same
  /// vertices again between glBegin and glEnd).
  void endImmediate();
  /// glNewList (its mode) and glEndList (0).
  void newList(GLenum mode) { cx().compiling_list = mode; }
  /// A display list is being made with GL_COMPILE: the matrix calls run later, if at all.
  bool compilingOnly() { return cx().compiling_list == 0x1300; }
  /// After a recorded draw without a program that writes depth: true if its ids are to be
  /// written by drawing it again (the same call, issued by the caller, then endIdPass()) with the
  /// layer's id program, the program's colour buffers masked, at equal depth without depth writes.
  bool beginIdPass();
  void endIdPass();
  /// Before a multi or indirect draw passed through whole: ids off for it (logged once).
  void beforeUndecomposedDraw(const char* what);
  /// `size` bytes of the bound draw indirect buffer at `offset` (false if unknown).
  bool readIndirect(size_t offset, void* out, size_t size);
  void bufferStorage(GLenum target, GLuint name, GLsizeiptr size, const void* data);
  /// After the program cleared buffers with glClearBuffer*: ids follow its depth and color clears.
  void clearBuffer(GLenum buffer, GLint drawbuffer);
  /// Our id attachment of the default framebuffer back to 0 (no draw), draw buffers as they were.
  void clearDefaultIds(FrameTarget& t);
  /// The layer's uniforms of `program` and the longest of its own uniform names (see ProgramInfo),
  /// for the introspection hooks; false for a program the layer did not link.
  bool hiddenUniforms(GLuint program, std::vector<GLuint>& hidden, GLint& visible_max_length);
  /// glProgramParameteri: a program made separable (GL_PROGRAM_SEPARABLE), which the GL answers only
  /// once linked.
  void programParameter(GLuint program, GLenum pname, GLint value);
  /// glProgramBinary: refused (logged once), so that the program links from source, which we rewrite.
  void programBinary(GLuint program);

 private:
  Interceptor();
  ~Interceptor();
  FrameTarget* target();
  /// The calling thread's current context's state (a state of the thread's own when none is current).
  ContextState& cx();
  ProgramInfo* currentProgram();
  GLuint boundBuffer(GLenum target);
  uint64_t bufferKey(GLuint name);
  void recordMesh(const DrawCall& call, const ProgramInfo& program, DrawRecord& record);
  /// Mesh positions mirrored in z for `handedness: left` (nothing otherwise).
  void mirrorForProfile(ExtractedMesh& mesh) const;
  /// A mesh whose vertices or indices are in the program's memory (client-side arrays): extracted
  /// at every draw (the memory may change between draws).
  void recordClientMesh(const DrawCall& call, const PositionLayout& layout, GLuint vbo, const uint8_t* client_vertices,
                        GLuint ibo, DrawRecord& record);
  /// World, view and projection from the fixed-function stack (`push_world`: the view is the
  /// bottom of the stack, the world what is above it); world and view only where the driver's
  /// model-view equals what the layer tracked (else logged once).
  void readMatrixStack(DrawRecord& record, bool push_world);
  /// At the end of a frame: draws from the matrix stack whose loaded matrix is not the frame's view
  /// (the one most of them loaded) get their world re-expressed against it, W = V^-1 V_d W_d:
  /// Irrlicht loads view x world as one matrix for the first draw after 2D drawing.
  void oneStackView();
  /// Where the profile has combined matrices: the draw's matrices as given, kept for the end of
  /// the frame (and the record finished then for a program with combined matrices).
  void keepDrawMatrices(const ProgramInfo& p, const DrawRecord& record, const DrawMatrices& combined);
  /// At the end of a frame: the frame's camera and each deferred draw's world, view and projection
  /// from the kept matrices (resolveFrameMatrices); what it could not find is said once.
  void resolveCombined();
  void captureDeformed(const DrawCall& call);
  void readDeformed();
  uint64_t textureKey(GLenum target, GLuint unit);
  /// The content key of an upload into the texture bound to `target` on the active unit: the
  /// texture's key (level 0), or combined with it (sub-image updates).
  void storeTextureKey(GLenum target, GLint level, bool sub, uint64_t key);
  /// Whether the draw about to be made goes into the frame's scene (default framebuffer or a scene
  /// framebuffer object) with a program that is recorded.
  bool recordable();
  /// viper_draw_id of the current program (rewritten) to `value`: index + 1 of a recorded draw, 0
  /// into a framebuffer whose draw buffer 7 is the program's (the rewritten shader then writes
  /// there what the original would).
  void setDrawId(float value);
  /// A draw made while a display list is being made: not recorded (counted if it runs now).
  bool notRecordedInList();
  /// beforeSceneDraw() of a draw without a program (fixed_function.cpp).
  bool beforeFixedFunctionDraw(const DrawCall& call, FrameTarget* t, FrameTarget::ProgramFbo* scene_fbo);
  /// A draw without a program writes its colour to every draw buffer, ours too: where it writes
  /// depth, its ids are cleared to 0 (until an id pass writes them), else left as they are.
  void clearIdsUnderFixedFunction(FrameTarget* t, FrameTarget::ProgramFbo* scene_fbo, bool writes_depth);
  /// The context's id program (0 if it cannot be made, said once).
  GLuint idProgram();
  /// The fixed-function context's state: recordable draws without a program, queries that count.
  void noteFixedFunction(ContextState& c);
  /// The record's matrices as the profile wants them (the mirror image in z for left-handed
  /// programs), and the gap when one the profile names is missing.
  void finishMatrices(uint8_t expected_matrices, DrawRecord& r) const;
  /// A projection (or a combined matrix holding one) as read, into OpenGL's clip depth where the
  /// profile says `clip_depth: zero_to_one` (Dz P); unchanged otherwise.
  void toGlClipDepth(GlMatrix& projection) const;
  /// beforeDraw() of a draw into the scene's framebuffer (ours, or `scene_fbo`).
  bool beforeSceneDraw(const DrawCall& call, FrameTarget* t, FrameTarget::ProgramFbo* scene_fbo);
  /// Copies bytes of a buffer as the GPU will read them now (a persistent mapping's memory, else
  /// our shadow copy); false if the range is not known.
  bool readBufferBytes(GLuint name, size_t offset, size_t size, void* out);
  bool readMatrix(const MatrixSource& source, GlMatrix& out);
  /// The world matrix of instance `call.base_instance` from the program's instanced attributes.
  bool readInstanceWorld(const InstanceTransform& t, const DrawCall& call, GlMatrix& out);
  bool readAttribute(GLint location, const DrawCall& call, float out[4]);
  /// Once per distinct message: to stderr, prefixed.
  void logOnce(const std::string& message);

  std::atomic<bool> enabled_{false};
  bool closed_ = false;  ///< shut down: the stream is closed, nothing more is written (lifecycle_mutex_)
  /// Held by a swap while it writes a frame and by shutdown(): a thread that calls exit() while
  /// another renders closes the stream between two frames.
  std::mutex lifecycle_mutex_;
  std::string output_path_, condition_;
  uint64_t frame_limit_ = 0;    ///< frames to write (0: until the program ends)
  uint64_t skip_frames_ = 0;    ///< VIPER_CAPTURE_SKIP: swaps before the first written frame
  bool start_on_scene_ = false; ///< VIPER_CAPTURE_START_ON_SCENE: first written frame has a camera
  uint64_t frames_written_ = 0;
  CaptureProfile profile_;
  /// What draws without a program are recorded as (the profile's `fixed_function` entry).
  ProgramInfo fixed_function_;
  bool combines_ = false;  ///< profile_.combinesMatrices()
  std::unique_ptr<FrameSink> sink_;
  double start_s_ = 0.0;

  std::mutex mutex_;  // guards the resource maps (programs may upload from loader threads)
  std::unordered_map<GLuint, ShaderInfo> shaders_;
  std::unordered_map<GLuint, ProgramInfo> programs_;
  std::unordered_set<GLuint> programs_with_own_feedback_;
  std::unordered_set<GLuint> separable_programs_;  ///< glProgramParameteri(GL_PROGRAM_SEPARABLE, true)
  std::unordered_map<GLuint, BufferShadow> buffers_;
  std::unordered_map<GLuint, uint64_t> texture_keys_;
  std::unordered_map<void*, std::unique_ptr<ContextState>> contexts_;  // guarded by mutex_
  std::unordered_map<uint64_t, ExtractedMesh> mesh_cache_;
  std::unordered_set<uint64_t> emitted_meshes_;

  double fixed_fps_ = 0.0; ///< VIPER_CAPTURE_FPS: frame time = number / fps (0: monotonic clock)
  std::unordered_set<std::string> logged_;

  // Frame being recorded.
  uint64_t frame_number_ = 0;
  // Asynchronous read-back (VIPER_CAPTURE_READBACK=async): frames read into the target's
  // pixel-pack buffers, handed to the sink once their fence has signalled (at the next swap).
  bool async_readback_ = false;
  bool readback_decided_ = false;  ///< auto: decided at the first written frame, from GL_RENDERER
  /// shutdown() registered with atexit (at the first make-current, after the driver's own handlers)
  std::atomic<bool> exit_hook_{false};
  bool async_exit_hook_ = false;  ///< and again at the first asynchronous read
  struct PendingFrame {
    FrameTarget* target;
    GLsync fence;
    CaptureFrame frame;
    RawImages raw;
  };
  std::deque<PendingFrame> pending_frames_;
  /// Waits for the fences of the pending frames of the current context (all but the newest
  /// `keep`) and pushes them to the sink in order.
  void pushPending(size_t keep);
  /// The target to the surface's size, the pending frames handed over first if it changes.
  void resizeTarget(FrameTarget& t, int width, int height);
  struct {
    uint64_t frames = 0;
    double present_s = 0, push_wait_s = 0;
    double deform_s = 0;  ///< of present_s: reading the deformed vertices (waits for the frame)
    double pixel_reads_s = 0;  ///< of present_s: the glReadPixels calls (the last target's)
    uint64_t synchronous_reads = 0;  ///< asynchronous read-back asked for, no buffer free
  } stats_;  // printed at exit when VIPER_CAPTURE_STATS is set
};

}  // namespace capture
}  // namespace viper
