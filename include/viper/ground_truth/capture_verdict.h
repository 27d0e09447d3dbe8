// What a capture recorded of its program's scene, in one line: `capture` prints it after the program
// has exited (docs/capture_layer.md, "The verdict"), from the stream it just wrote.
#pragma once

#include "viper/ground_truth/capture_invariants.h"

#include <cstdint>
#include <string>

namespace viper {

/// What a capture holds, summed over its frames: how much of the scene has ids and is placed, and
/// the draws the layer could not record, by reason.
struct CaptureCoverage {
  uint64_t frames = 0;
  uint64_t scene_pixels = 0;   ///< depth below 1 or a draw id (ReprojectionCheck::scene_pixels)
  uint64_t id_pixels = 0;      ///< scene pixels with a draw id
  uint64_t placed_pixels = 0;  ///< id pixels whose draw is placed (placedMesh()) and whose primitive is in its mesh
  /// Id pixels not placed, by the first reason that applies to their draw: no mesh (none recorded,
  /// or not in the stream's mesh store); a matrix the profile names missing at the draw
  /// (kGapMatrixMissing); else world, view or projection the profile does not name.
  uint64_t no_mesh_pixels = 0, matrix_missing_pixels = 0, not_named_pixels = 0;
  /// Recorded draws, their DrawGaps, and CaptureFrame::unrecorded_draws.
  CaptureGaps gaps;
  /// Whether the stream was written with a capture profile (its header names one).
  bool profile_given = false;

  /// Adds a frame; `meshes` must already hold the frame's new meshes.
  void add(const CaptureFrame& frame, const MeshRegistry& meshes);
  /// Share of scene pixels with a draw id, and placed; 0 when there is no scene pixel.
  double idShare() const { return scene_pixels ? static_cast<double>(id_pixels) / scene_pixels : 0.0; }
  double placedShare() const { return scene_pixels ? static_cast<double>(placed_pixels) / scene_pixels : 0.0; }
};

/// A capture stream read whole: its coverage and, when it could not be read to its end marker, why.
struct CaptureReadResult {
  CaptureCoverage coverage;
  /// "" when read to the end marker; else the reader's message (frames before it are counted).
  std::string problem;
};

/// Reads every frame of the stream at `path` (with images) into a CaptureReadResult. Throws
/// std::runtime_error or CaptureFormatError only when the file cannot be opened or its header is
/// unreadable.
CaptureReadResult readCaptureCoverage(const std::string& path);

/// Why id pixels are not placed, by the reason that costs the most of them: no profile, matrices the
/// profile does not name, a matrix it names missing, or no mesh.
std::string unplacedReason(const CaptureCoverage& c);

/// The main reason for what the capture did not record: the cause that costs the most scene pixels
/// (no draw recorded at all, draws without a program, shaders not rewritten, depth without ids; or,
/// of the id pixels, no profile, matrices not named or missing, no mesh), else draws not recorded
/// that left no pixel out; "" when nothing was left out. Needs at least one frame.
std::string mainGap(const CaptureCoverage& c);

/// The verdict line (without newline): "N frames written; ids on I% of scene pixels, placed P%;
/// R draws recorded, U not; left out: REASON" (or "nothing left out"); for no frame, "0 frames
/// written: " and `why_no_frames`. A `problem` reading the stream is appended ("; the stream is
/// damaged after N frames: PROBLEM").
std::string captureVerdict(const CaptureReadResult& read, const std::string& why_no_frames);

}  // namespace viper
