// What one captured frame holds: only what a layer between an OpenGL program and its driver sees.
// No object identities, classes, instance ids or object poses: those are derived downstream.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace viper {

/// A 4x4 matrix exactly as the program passed it to OpenGL (column-major storage, OpenGL axes).
using GlMatrix = Eigen::Matrix4f;

/// DrawRecord::program_key of draws made without a program: the fixed-function pipeline.
constexpr uint64_t kFixedFunctionProgramKey = 0x6678656466756e63ull;  // "fxedfunc"


/// Which of a draw's matrices the capture profile found for the draw's program.
enum MatrixFlags : uint8_t {
  kHasWorld = 1u << 0,
  kHasView = 1u << 1,
  kHasProjection = 1u << 2,
};

/// What the capture layer could not record of a draw (DrawRecord::gaps); 0: nothing missing.
enum DrawGaps : uint8_t {
  /// The program's fragment shader was not rewritten (refused, or the rewrite did not compile):
  /// the draw wrote no ids, so its pixels keep the id of what was drawn there before.
  kGapNoIds = 1u << 0,
  /// A matrix the capture profile names for the program could not be read at this draw.
  kGapMatrixMissing = 1u << 1,
  /// No mesh: positions not extracted (not GL_TRIANGLES, not float, or not readable).
  kGapNoMesh = 1u << 2,
};

/// One draw call of a frame, as the interceptor recorded it.
struct DrawRecord {
  /// Index of the draw call within its frame (0-based). The id image stores index + 1.
  uint32_t index = 0;
  /// Content key of the mesh: hash of vertex data, index data and position layout of the draw range.
  uint64_t mesh_key = 0;
  /// Content keys of the vertex buffer holding positions and of the index buffer (0 if none).
  uint64_t vertex_buffer_key = 0;
  uint64_t index_buffer_key = 0;
  /// Content key of the shader program (hash of its original shader sources);
  /// kFixedFunctionProgramKey for a draw made without a program (OpenGL 1.x fixed function).
  uint64_t program_key = 0;
  /// Content keys of the textures bound to the program's samplers, in sampler order.
  std::vector<uint64_t> texture_keys;
  /// Matrices named by the capture profile, as passed by the program (see `matrix_flags`).
  uint8_t matrix_flags = 0;
  GlMatrix world = GlMatrix::Identity();
  GlMatrix view = GlMatrix::Identity();
  GlMatrix projection = GlMatrix::Identity();
  /// GL primitive mode (GL_TRIANGLES = 4) and number of primitives drawn.
  uint32_t primitive_mode = 4;
  uint32_t primitive_count = 0;
  /// Number of pixels of the final id image that this draw owns (0 = left no visible pixel).
  uint32_t visible_pixels = 0;
  /// DrawGaps bits: what the layer could not record of this draw (format version 2; 0 in 1).
  uint8_t gaps = 0;
  /// For draws whose vertex shader deforms vertices: clip-space position (x, y, z, w) of every
  /// vertex of the mesh after the vertex shader, indexed like the mesh's vertices. Empty if rigid.
  std::vector<float> deformed_clip_xyzw;
};

/// Object-space geometry of one mesh, sent once per mesh key.
struct MeshRecord {
  uint64_t key = 0;
  /// Vertex positions x, y, z in the mesh's own coordinates (what the program uploaded).
  std::vector<float> positions_xyz;
  /// Triangle list: three vertex indices per primitive, in primitive order (primitive id order).
  std::vector<uint32_t> indices;
};

/// One frame of a capture.
struct CaptureFrame {
  /// Frame number, counting buffer swaps from 0.
  uint64_t number = 0;
  /// Capture time in seconds (program's clock as seen at the swap; monotonic within a stream).
  double time_s = 0.0;
  /// Condition tag given by whoever ran the capture (e.g. "day", "night"); may be empty.
  std::string condition;
  uint32_t width = 0;
  uint32_t height = 0;
  /// Final color image, rgb8, row-major, top row first (width * height * 3 bytes).
  std::vector<uint8_t> color_rgb;
  /// Window-space depth of the opaque surfaces in [0, 1], top row first; 1 where nothing was drawn.
  std::vector<float> depth_window;
  /// Per pixel: index + 1 of the draw call that produced the visible surface, 0 = none.
  std::vector<uint32_t> draw_ids;
  /// Per pixel: primitive (triangle) index within that draw; meaningless where draw_ids is 0.
  std::vector<uint32_t> primitive_ids;
  std::vector<DrawRecord> draws;
  /// Draws into the scene that the layer could not record at all (no program: fixed-function;
  /// a multi or indirect draw whose shaders read gl_DrawID). Not counted: the profile's overlay
  /// draws and draws after the scene ended (depth_clear_ends_scene), which are left out by design.
  /// Format version 2; 0 when read from version 1.
  uint32_t unrecorded_draws = 0;
  /// Meshes first seen in this frame (the mesh store is the union over all earlier frames).
  std::vector<MeshRecord> new_meshes;

  size_t pixelCount() const { return static_cast<size_t>(width) * height; }
};

/// Checks sizes and consistency of a frame (image sizes match width*height, draw indices are
/// 0..n-1, every draw id in the image names an existing draw). Returns an empty string when the
/// frame is consistent, else a message saying what is wrong.
std::string validateFrame(const CaptureFrame& frame);

/// Where a frame's images are stored when not in its vectors: each pointer set stands for that
/// vector and points at width*height values (times 3 for colour) checked for size by whoever set it
/// (storage a CaptureImageSink gave, say: a message's pixels).
struct FrameImagesElsewhere {
  const uint8_t* color_rgb = nullptr;
  const float* depth_window = nullptr;
  const uint32_t* draw_ids = nullptr;
  const uint32_t* primitive_ids = nullptr;
  /// The caller checks that every draw id names a draw itself, with drawIdsProblem() and the
  /// largest id found in a pass over the ids of its own (the bridge's depth conversion).
  bool draw_id_range_later = false;
};
/// validateFrame() of a frame whose images are partly or wholly elsewhere: the images given there are
/// not size-checked again, and the draw ids are read where they are.
std::string validateFrame(const CaptureFrame& frame, const FrameImagesElsewhere& elsewhere);

/// validateFrame()'s check of the draw ids at `ids` (frame.pixelCount() of them) given their
/// `largest`: "" when it names one of the frame's draws (or none), else the first pixel whose id
/// names none, prefixed with the frame's number as validateFrame() words it.
std::string drawIdsProblem(const CaptureFrame& frame, const uint32_t* ids, uint32_t largest);

/// The primitive ids of `n` pixels with -1 where the draw id is 0 (no draw), into `out`, which may
/// be `primitives` (masked in place). Four pixels a step with SSE2.
void maskPrimitiveIds(const uint32_t* draw_ids, const uint32_t* primitives, size_t n, int32_t* out);

/// The largest of the `n` draw ids at `ids` (0 for none): whether every id names one of a frame's
/// draws, at the speed of reading them (AVX2 where the CPU has it; the baseline x86-64 has no
/// vector maximum of unsigned 32-bit values, and the plain loop stays one value at a time).
uint32_t largestDrawId(const uint32_t* ids, size_t n);

}  // namespace viper
