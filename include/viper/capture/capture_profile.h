// Capture profile: the one piece of per-program knowledge the capture layer uses, namely which
// uniforms of which shader programs hold the world, view and projection matrices, which vertex
// attribute is the position, and which programs deform vertices. Format: docs/capture_layer.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace viper {

/// Whether a program's vertex shader moves vertices non-rigidly (skinning, cloth, ...).
enum class Deforming {
  kAuto,  ///< deforming if the vertex shader declares a `uniform mat4 NAME[N]` array
  kYes,
  kNo,
};

/// Settings for the programs one profile entry matches.
struct ProgramProfile {
  /// Matches programs whose vertex shader source contains this text (empty: any).
  std::string vertex_contains;
  /// Matches the program with this content key (0: any).
  uint64_t program_key = 0;
  /// Names of the matrices (empty: not recorded for these programs): a `uniform mat4`, or a mat4
  /// member of a uniform block (read from the buffer bound to the block at each draw), or four
  /// consecutive elements of a vec4 array, as the matrix's rows or columns (`vs_cb0[4] rows`:
  /// parseMatrixName).
  std::string world;
  std::string view;
  std::string projection;
  /// Combined matrices, named the same way, for engines that pass them instead of (or besides)
  /// the three: model-view V·W, view-projection P·V, model-view-projection P·V·W. Each draw's
  /// world and the frame's camera are recovered from them at the end of the frame
  /// (camera_recovery.h: viper::resolveFrameMatrices).
  std::string model_view;
  std::string view_projection;
  std::string model_view_projection;
  /// `world_space: true`: these programs' vertices are already in world space (world = identity),
  /// so their model-view is the view and their model-view-projection the camera's P·V.
  bool world_space = false;
  /// Name of the position attribute (empty: generic attribute location 0). `gl_Vertex`: the
  /// conventional vertex array (glVertexPointer, in a buffer or in the program's memory).
  std::string position;
  /// The matrices live in the fixed-function stack (compatibility contexts): `load_view_mult_world`
  /// says the engine loads the view into GL_MODELVIEW (glLoadMatrix, glLoadIdentity) and multiplies
  /// the world onto it (glMultMatrix, glTranslate, glRotate, glScale), as Irrlicht's OpenGL driver
  /// does. `push_world`: the program sets the camera at the bottom of the stack (glLoadIdentity,
  /// gluLookAt, glMultMatrix...), then draws each object between glPushMatrix and glPopMatrix with
  /// its world multiplied on: the view is what the bottom of the stack holds, the world what is
  /// above it (the OpenGL 1.x textbook pattern). The projection is GL_PROJECTION's. Replaces
  /// world/view/projection. Empty: not used.
  std::string matrix_stack;
  Deforming deforming = Deforming::kAuto;
  /// Per-instance world matrices of instanced draws, from instanced vertex attributes (names;
  /// empty: absent). Either a mat4 attribute (`instance_world`), or translation (vec3), rotation
  /// (unit quaternion x, y, z, w) and scale (vec3) composed as T * R * S; a missing part is the
  /// identity. When set, they replace `world` for the draws of these programs.
  std::string instance_world;
  std::string instance_translation;
  std::string instance_rotation;
  std::string instance_scale;
  /// The shader rotates by the quaternion's conjugate, v + 2 cross(cross(v, q.xyz) + q.w v, q.xyz).
  bool instance_rotation_conjugate = false;
  /// Draws of these programs are the 2D overlay (HUD, menus): never given ids or recorded.
  bool overlay = false;
  /// `fixed_function: true`: the entry is for draws made without a program (OpenGL 1.x fixed
  /// function), and matches no program. Only `matrix_stack`, `world_space` and `overlay` go with
  /// it (without `matrix_stack`, its draws have the stack's model-view as a combined matrix).
  bool fixed_function = false;

  /// True if any instance_* attribute is named.
  bool hasInstanceTransform() const {
    return !instance_world.empty() || !instance_translation.empty() || !instance_rotation.empty() ||
           !instance_scale.empty();
  }
};

/// A matrix as a profile entry names it (world, view, projection and the combined matrices).
struct MatrixName {
  /// The mat4 (a uniform, or a member of a uniform block), or the vec4 array.
  std::string name;
  /// -1: `name` is a mat4. Else the matrix is the four elements of the vec4 array `name` from this
  /// index on (a uniform array, or an array member of a uniform block).
  int first_element = -1;
  /// The four elements are the rows of the matrix (as it multiplies column vectors); else its
  /// columns. Direct3D's constant registers hold `mul(v, M)`'s M as rows this way (wined3d).
  bool rows = false;
  bool isElements() const { return first_element >= 0; }
};

/// Largest array index a matrix name may give.
constexpr int kMaxMatrixElement = 65535;

/// Parses a matrix name of a profile: `NAME` (a mat4), or `NAME[N] rows` / `NAME[N] columns` (the
/// vec4 elements N..N+3 of the array NAME, N at most kMaxMatrixElement). Throws
/// std::invalid_argument saying what is wrong with `text`.
MatrixName parseMatrixName(const std::string& text);

/// A parsed profile: entries are tried in file order, the first match wins.
struct CaptureProfile {
  /// Where the profile came from (file path, or "<default>").
  std::string source;
  std::vector<ProgramProfile> programs;
  /// The program's world is left-handed: its cameras look along +z of eye space (projection row 3
  /// is (0, 0, +1, 0), as Direct3D-style engines such as Irrlicht build them). The capture then
  /// records the mirror image of that world in z, in OpenGL's right-handed conventions: with
  /// F = diag(1, 1, -1, 1), world F W F, view F V F, projection P F and mesh positions F x, so that
  /// clip positions, and so every pixel, stay what the program drew (P V W x = P F F V F F W F F x).
  bool left_handed = false;
  /// `depth_clear_ends_scene: true`: a depth-only clear of the default framebuffer after recorded
  /// draws ends the frame's scene (engines that then draw a first-person hand or 3D HUD items, as
  /// Minetest does): color and depth are kept as they were, and the frame's later draws are
  /// neither recorded nor given ids.
  bool depth_clear_ends_scene = false;
  /// `clip_depth: zero_to_one`: the program's projections (and the combined matrices that hold
  /// one) map depth to 0..w of clip space, as Direct3D's and Vulkan's do, and something after
  /// them turns that into OpenGL's -w..w (wined3d's vertex shaders end with z = 2 z - w). The
  /// capture records them in OpenGL's conventions, Dz P with Dz = [1 0 0 0; 0 1 0 0; 0 0 2 -1;
  /// 0 0 0 1], which maps the same points to the same window depth. Default: OpenGL's -1..1.
  bool clip_depth_zero_to_one = false;

  /// Some entry names a combined matrix or world space: frames are resolved (camera_recovery.h).
  bool combinesMatrices() const;
  /// The first entry matching a program, or the built-in fallback (no matrices, position at
  /// location 0, deforming auto) when none does. Never null.
  const ProgramProfile* match(const std::string& vertex_source, uint64_t program_key) const;
  /// The entry for draws without a program (`fixed_function: true`), or the built-in one (ids
  /// recorded, projection and model-view from the matrix stack) when there is none. Never null.
  const ProgramProfile* matchFixedFunction() const;
};

/// Parses profile YAML text. `source_name` is used in error messages. Throws std::runtime_error
/// naming the source, the line and what is wrong (unknown key, wrong type, bad value).
CaptureProfile parseCaptureProfile(const std::string& yaml_text, const std::string& source_name);

/// Reads and parses a profile file. Throws std::runtime_error naming the file if it cannot be
/// read or is invalid.
CaptureProfile loadCaptureProfile(const std::string& path);

}  // namespace viper
