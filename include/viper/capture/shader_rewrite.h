// GLSL rewriting for the capture layer, as pure string functions (no OpenGL needed).
#pragma once

#include <string>

namespace viper {

/// Name of the fragment output the rewritten shader adds (draw id, primitive id, 0, 1).
constexpr const char* kIdOutputName = "viper_id_out";
/// Fragment output location (and so draw buffer index) of kIdOutputName: the last of the eight
/// draw buffers every GL 3.0 implementation has, so that a program's own outputs (G-buffers write
/// normals at 1, 2, ...) keep theirs.
constexpr int kIdOutputLocation = 7;
/// Name of the float uniform that receives draw index + 1.
constexpr const char* kDrawIdUniform = "viper_draw_id";
/// Name of the float uniform that is 1 while blending is enabled for the program's own output.
constexpr const char* kAlphaTestUniform = "viper_alpha_test";

/// Result of rewriteFragmentShader().
struct FragmentRewrite {
  /// True if the shader was rewritten; false leaves `source` empty and says why in `reason`.
  bool ok = false;
  std::string source;
  /// Name of the program's own color output (the one written to draw buffer 0).
  std::string color_output;
  /// True if that output carries an explicit `layout(location = N)` qualifier.
  bool explicit_location = false;
  /// Number of components of the color output (alpha test needs 4).
  int color_components = 4;
  /// GLSL before 1.50 writing gl_FragColor or gl_FragData: the ids to gl_FragData[kIdOutputLocation]
  /// (no output to bind; gl_PrimitiveID from GL_EXT_gpu_shader4). gl_FragColor, which goes to every
  /// draw buffer, becomes a variable written to gl_FragData[0..6], and to [7] too while the uniform
  /// viper_draw_id is 0 (no ids wanted: a draw not recorded, or into the program's own buffer 7).
  bool legacy = false;
  std::string reason;
};

/// Replaces GLSL comments by spaces, keeping newlines (so line numbers in compiler logs hold).
std::string stripGlslComments(const std::string& source);

/// Rewrites a fragment shader so that it also writes
/// `viper_id_out = vec4(viper_draw_id, gl_PrimitiveID, 0, 1)`, or `vec4(0, 0, 0, 1)` (no object)
/// when `viper_alpha_test` is set and the color's alpha is below 0.5: a mostly transparent fragment
/// of a blended draw that writes depth (blended draws that write none write no ids at all), so that
/// an id never names a surface other than the one the depth holds. The original `main` is renamed
/// `viper_original_main` and called from a new `main`. Comments are removed. The program's color
/// is its only output, or, with several outputs (multiple render targets), the one at location 0;
/// several outputs must all have explicit locations, none at kIdOutputLocation. Shaders that are
/// not GLSL >= 1.50, have no color output, outputs the rules above do not place, dual-source
/// blending (`index = 1`), or no recognisable `void main()` are refused with a reason. Shaders of
/// GLSL before 1.50 (compatibility contexts) that write `gl_FragColor` or `gl_FragData` are rewritten
/// the legacy way (FragmentRewrite::legacy), needing GL_EXT_gpu_shader4 for gl_PrimitiveID.
/// Without `primitive_ids` the id output's second component is 0 instead of gl_PrimitiveID: for
/// programs whose geometry or tessellation stage does not write gl_PrimitiveID (the fragment
/// shader's is undefined then, and llvmpipe draws nothing when it is read).
FragmentRewrite rewriteFragmentShader(const std::string& source, bool primitive_ids = true);

/// True if the (vertex) shader declares a `uniform mat4 NAME[N]` array, which the capture layer
/// takes as the sign of skinning, i.e. of a vertex shader that deforms meshes non-rigidly.
bool declaresMat4ArrayUniform(const std::string& source);

}  // namespace viper
