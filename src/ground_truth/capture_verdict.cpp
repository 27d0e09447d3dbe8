#include "viper/ground_truth/capture_verdict.h"

#include "viper/capture/capture_stream.h"

#include <cstdio>
#include <stdexcept>

namespace viper {

namespace {

std::string percent(uint64_t part, uint64_t whole) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f%%", whole ? 100.0 * static_cast<double>(part) / whole : 0.0);
  return buffer;
}

std::string count(uint64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Draws into the scene the layer passed on unrecorded, and why it does.
std::string unrecordedDraws(uint64_t n) {
  return count(n, "draw", "draws") +
         " into the scene not recorded (immediate mode or display lists; without a program, no depth test or no "
         "fixed-function pipeline; or multi-draws whose shaders read gl_DrawID)";
}

std::string shadersNotRewritten(uint64_t n) {
  return count(n, "draw", "draws") +
         " without ids: the shader was not rewritten, or a draw without a program was made while a query counted "
         "(the layer's '[viper capture]' lines say why)";
}

}  // namespace

void CaptureCoverage::add(const CaptureFrame& frame, const MeshRegistry& meshes) {
  ++frames;
  gaps.add(frame);
  const size_t n = frame.pixelCount();
  if (frame.depth_window.size() != n || frame.draw_ids.size() != n || frame.primitive_ids.size() != n) return;
  // Per draw: its placed mesh, or the reason it has none.
  enum class Unplaced : uint8_t { kPlaced, kNoMesh, kMatrixMissing, kNotNamed };
  std::vector<const MeshRecord*> placed(frame.draws.size(), nullptr);
  std::vector<Unplaced> why(frame.draws.size(), Unplaced::kPlaced);
  for (size_t i = 0; i < frame.draws.size(); ++i) {
    const DrawRecord& d = frame.draws[i];
    placed[i] = placedMesh(d, meshes);
    if (placed[i]) continue;
    if (!d.mesh_key || !meshes.find(d.mesh_key)) why[i] = Unplaced::kNoMesh;
    else if (d.gaps & kGapMatrixMissing) why[i] = Unplaced::kMatrixMissing;
    else why[i] = Unplaced::kNotNamed;
  }
  for (size_t px = 0; px < n; ++px) {
    const uint32_t id = frame.draw_ids[px];
    if (!(frame.depth_window[px] < 1.0f) && id == 0) continue;
    ++scene_pixels;
    if (id == 0 || id > frame.draws.size()) continue;
    ++id_pixels;
    const MeshRecord* mesh = placed[id - 1];
    if (mesh && (static_cast<size_t>(frame.primitive_ids[px]) + 1) * 3 <= mesh->indices.size()) {
      ++placed_pixels;
      continue;
    }
    switch (why[id - 1]) {
      case Unplaced::kNoMesh: ++no_mesh_pixels; break;
      case Unplaced::kMatrixMissing: ++matrix_missing_pixels; break;
      case Unplaced::kNotNamed: ++not_named_pixels; break;
      case Unplaced::kPlaced: ++no_mesh_pixels; break;  // a primitive its mesh does not have
    }
  }
}

CaptureReadResult readCaptureCoverage(const std::string& path) {
  CaptureReadResult result;
  CaptureReader reader(path);
  result.coverage.profile_given = !reader.header().profile.empty() && reader.header().profile != "<default>";
  MeshRegistry meshes;
  CaptureFrame frame;
  try {
    while (reader.next(frame) == CaptureReader::Status::kFrame) {
      meshes.add(frame.new_meshes);
      result.coverage.add(frame, meshes);
    }
  } catch (const std::exception& e) {
    result.problem = e.what();
  }
  return result;
}

std::string unplacedReason(const CaptureCoverage& c) {
  if (c.not_named_pixels >= c.matrix_missing_pixels && c.not_named_pixels >= c.no_mesh_pixels) {
    if (!c.profile_given) return "no --profile, so no matrices were recorded";
    return "their draws lack world, view or projection: no entry of the profile names them for their programs";
  }
  if (c.matrix_missing_pixels >= c.no_mesh_pixels)
    return count(c.gaps.matrix_missing, "draw", "draws") + " missing a matrix the profile names";
  return count(c.gaps.no_mesh, "draw", "draws") + " without mesh (not GL_TRIANGLES, or positions not float)";
}

std::string mainGap(const CaptureCoverage& c) {
  const CaptureGaps& g = c.gaps;
  if (c.scene_pixels == 0)
    return g.draws + g.unrecorded_draws == 0 ? "nothing was drawn into the scene (no depth, no id, no draw seen)"
                                             : "no draw left depth or an id in the scene";
  if (g.draws == 0 && g.unrecorded_draws > 0)
    return "0 draws recorded: " + unrecordedDraws(g.unrecorded_draws);
  if (g.draws == 0)
    return "0 draws recorded and none seen: the scene was drawn in ways the layer does not intercept "
           "(glBegin/glEnd, display lists?)";
  if (g.no_ids == g.draws && c.id_pixels == 0) return "no shader was rewritten: " + shadersNotRewritten(g.no_ids);
  const uint64_t without_id = c.scene_pixels - c.id_pixels;
  const uint64_t not_placed = c.id_pixels - c.placed_pixels;
  if (without_id > 0 && without_id >= not_placed) {
    const std::string share = percent(without_id, c.scene_pixels) + " of scene pixels without id: ";
    if (g.unrecorded_draws > 0) return share + unrecordedDraws(g.unrecorded_draws);
    if (g.no_ids > 0) return share + shadersNotRewritten(g.no_ids);
    return share + "depth written by draws that leave no id (mostly transparent fragments, the profile's overlay, "
                   "or drawing the layer does not intercept: glBegin/glEnd, display lists)";
  }
  if (not_placed > 0) return percent(not_placed, c.scene_pixels) + " of scene pixels not placed: " + unplacedReason(c);
  if (g.unrecorded_draws > 0) return unrecordedDraws(g.unrecorded_draws) + ", leaving no pixel without id";
  if (g.no_ids > 0) return shadersNotRewritten(g.no_ids) + ", leaving no pixel without id";
  return "";
}

std::string captureVerdict(const CaptureReadResult& read, const std::string& why_no_frames) {
  const CaptureCoverage& c = read.coverage;
  std::string line;
  if (c.frames == 0) {
    line = "0 frames written: " + why_no_frames;
  } else {
    line = count(c.frames, "frame", "frames") + " written; ids on " + percent(c.id_pixels, c.scene_pixels) +
           " of scene pixels, placed " + percent(c.placed_pixels, c.scene_pixels) + "; " +
           count(c.gaps.draws, "draw", "draws") + " recorded, " + std::to_string(c.gaps.unrecorded_draws) + " not; ";
    const std::string gap = mainGap(c);
    line += gap.empty() ? "nothing left out" : "left out: " + gap;
  }
  if (!read.problem.empty())
    line += "; the stream is damaged after " + count(c.frames, "frame", "frames") + ": " + read.problem;
  return line;
}

}  // namespace viper
