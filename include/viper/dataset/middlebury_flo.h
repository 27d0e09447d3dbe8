// Middlebury's .flo optical-flow format (Baker et al., "A Database and Evaluation Methodology for
// Optical Flow"; flowIO.cpp of the Middlebury flow code), read by most flow tools: the tag
// "PIEH" (float32 202021.25), int32 width, int32 height, then height rows of width (u, v) float32
// pairs, all little-endian. A pixel is unknown when |u| or |v| exceeds 1e9 (or is NaN).
#pragma once

#include "viper/dataset/flow_image.h"

#include <string>

namespace viper::dataset {

/// The .flo tag: these four bytes, "PIEH", read as a little-endian float32.
constexpr float kFloTag = 202021.25f;
/// A pixel is unknown in .flo when |u| or |v| is above this (Middlebury's UNKNOWN_FLOW_THRESH).
constexpr float kFloUnknownThreshold = 1e9f;
/// What writeMiddleburyFlo stores for an unknown pixel (Middlebury's UNKNOWN_FLOW).
constexpr float kFloUnknownValue = 1e10f;

/// Writes `flow` to `path` as .flo. .flo marks unknown flow per pixel, so a pixel whose u or v is
/// not finite (or above kFloUnknownThreshold in magnitude) is written with both components
/// kFloUnknownValue; all other values are written exactly. Throws std::invalid_argument if
/// uv.size() is not 2 * width * height or a size is 0, std::runtime_error naming `path` if it
/// cannot be written.
void writeMiddleburyFlo(const std::string& path, const FlowImage& flow);

/// Reads a .flo file. Unknown pixels (|u| or |v| above kFloUnknownThreshold, or NaN) come back
/// with both components NaN; all other values exactly as stored. Throws std::runtime_error naming
/// `path` (and the byte offset) if the file is missing, shorter than its header, has a wrong tag,
/// non-positive or absurd sizes (over 2^20 per side), or a data size other than 8 * width * height.
FlowImage readMiddleburyFlo(const std::string& path);

}  // namespace viper::dataset
