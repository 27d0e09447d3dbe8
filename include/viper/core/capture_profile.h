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
  /// Uniform names of the matrices (empty: not recorded for these programs).
  std::string world;
  std::string view;
  std::string projection;
  /// Name of the position attribute (empty: generic attribute location 0).
  std::string position;
  Deforming deforming = Deforming::kAuto;
};

/// A parsed profile: entries are tried in file order, the first match wins.
struct CaptureProfile {
  /// Where the profile came from (file path, or "<default>").
  std::string source;
  std::vector<ProgramProfile> programs;

  /// The first entry matching a program, or the built-in fallback (no matrices, position at
  /// location 0, deforming auto) when none does. Never null.
  const ProgramProfile* match(const std::string& vertex_source, uint64_t program_key) const;
};

/// Parses profile YAML text. `source_name` is used in error messages. Throws std::runtime_error
/// naming the source, the line and what is wrong (unknown key, wrong type, bad value).
CaptureProfile parseCaptureProfile(const std::string& yaml_text, const std::string& source_name);

/// Reads and parses a profile file. Throws std::runtime_error naming the file if it cannot be
/// read or is invalid.
CaptureProfile loadCaptureProfile(const std::string& path);

}  // namespace viper
