// capture_sheet: a contact sheet of chosen frames of a capture, one row a frame: the color image,
// the draw ids (a color per draw), the depth, the flow to the next frame (hue = direction,
// brightness = length), and where each id pixel's triangle reprojects (capture_check's test:
// green within 0.5 px, red beyond, grey: no placement recorded, black: no id). With --labels, the
// ground truth instead: color, semantic classes, instances (a color per track), depth, flow. With
// --labels and --modalities, the ground truth beyond VIPER's: color, the amodal masks over it,
// normals, scene flow to the next frame.
// Exit code 0 = written, 1 = a frame was not found, 2 = usage/read/write error.
#include "command_line.h"
#include "viper/ground_truth/amodal.h"
#include "viper/ground_truth/amodal_overlay.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/capture_invariants.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/flow.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/normals.h"
#include "viper/ground_truth/scene_flow.h"
#include "viper/ground_truth/semantic_overlay.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace {

// Per draw of `f`, the track id of its object in `truth` (0: none, or no truth).
std::vector<int32_t> trackIdsPerDraw(const viper::CaptureFrame& f, const viper::InstanceFrame* truth) {
  std::vector<int32_t> ids(f.draws.size(), 0);
  if (truth)
    for (const viper::TrackedObject& o : truth->objects)
      for (uint32_t d : o.object.draws)
        if (d < ids.size()) ids[d] = std::max(o.track_id, 0);
  return ids;
}

cv::Mat colorImage(const viper::CaptureFrame& f) {
  cv::Mat rgb(static_cast<int>(f.height), static_cast<int>(f.width), CV_8UC3,
              const_cast<uint8_t*>(f.color_rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

// A color per id, spread over consecutive ids.
cv::Vec3b idColor(uint32_t id) {
  const uint32_t h = id * 2654435761u;
  return cv::Vec3b(64 + (h & 0xbf), 64 + ((h >> 8) & 0xbf), 64 + ((h >> 16) & 0xbf));
}

cv::Mat idImage(const viper::CaptureFrame& f) {
  cv::Mat out(static_cast<int>(f.height), static_cast<int>(f.width), CV_8UC3, cv::Scalar(0, 0, 0));
  for (size_t i = 0; i < f.draw_ids.size(); ++i)
    if (f.draw_ids[i]) out.at<cv::Vec3b>(static_cast<int>(i / f.width), static_cast<int>(i % f.width)) = idColor(f.draw_ids[i]);
  return out;
}

cv::Mat depthImage(const viper::CaptureFrame& f) {
  const auto camera = viper::chooseFrameCamera(f);
  const std::vector<float> d = viper::depthMetres(f, camera ? &*camera : nullptr);
  cv::Mat gray(static_cast<int>(f.height), static_cast<int>(f.width), CV_8UC1, cv::Scalar(0));
  for (size_t i = 0; i < d.size(); ++i) {
    if (!(d[i] > 0.0f)) continue;  // no surface: black
    // Log scale from 1 m (bright) to 1000 m (dark).
    const double t = std::clamp(std::log10(static_cast<double>(d[i])) / 3.0, 0.0, 1.0);
    gray.data[i] = static_cast<uint8_t>(255.0 - 235.0 * t);
  }
  cv::Mat out;
  cv::applyColorMap(gray, out, cv::COLORMAP_INFERNO);
  for (size_t i = 0; i < d.size(); ++i)
    if (!(d[i] > 0.0f)) out.at<cv::Vec3b>(static_cast<int>(i / f.width), static_cast<int>(i % f.width)) = cv::Vec3b(0, 0, 0);
  return out;
}

cv::Mat flowImage(const viper::FlowField& flow) {
  const int w = static_cast<int>(flow.width), h = static_cast<int>(flow.height);
  cv::Mat hsv(h, w, CV_8UC3, cv::Scalar(0, 0, 0));
  double max_len = 1e-6;
  for (size_t i = 0; i < flow.uv.size() / 2; ++i)
    if (!std::isnan(flow.uv[2 * i])) max_len = std::max(max_len, static_cast<double>(std::hypot(flow.uv[2 * i], flow.uv[2 * i + 1])));
  for (size_t i = 0; i < flow.uv.size() / 2; ++i) {
    const float u = flow.uv[2 * i], v = flow.uv[2 * i + 1];
    if (std::isnan(u) || std::isnan(v)) continue;
    const double angle = std::atan2(-v, u);  // up is 90 degrees
    const double hue = (angle < 0 ? angle + 2 * M_PI : angle) / (2 * M_PI) * 180.0;
    const double len = std::sqrt(std::hypot(u, v) / max_len);  // square root: small motions visible
    hsv.at<cv::Vec3b>(static_cast<int>(i / flow.width), static_cast<int>(i % flow.width)) =
        cv::Vec3b(static_cast<uint8_t>(hue), 255, static_cast<uint8_t>(60 + 195 * len));
  }
  cv::Mat out;
  cv::cvtColor(hsv, out, cv::COLOR_HSV2BGR);
  return out;
}

cv::Mat semanticImage(const viper::InstanceFrame& g, const viper::CaptureFrame& f, const viper::ClassTable& classes) {
  cv::Mat rgb(static_cast<int>(f.height), static_cast<int>(f.width), CV_8UC3);
  viper::colorizeClasses(g.semantic.data(), g.semantic.size(), classes, rgb.data);
  cv::cvtColor(rgb, rgb, cv::COLOR_RGB2BGR);
  return rgb;
}

cv::Mat instanceImage(const viper::InstanceFrame& g, const viper::CaptureFrame& f) {
  cv::Mat out(static_cast<int>(f.height), static_cast<int>(f.width), CV_8UC3, cv::Scalar(0, 0, 0));
  for (size_t i = 0; i < g.instance_ids.size(); ++i) {
    const int32_t id = g.instance_ids[i];
    if (id > 0) out.at<cv::Vec3b>(static_cast<int>(i / f.width), static_cast<int>(i % f.width)) = idColor(static_cast<uint32_t>(id));
  }
  for (size_t i = 0; i < g.boundaries.size(); ++i)
    if (g.boundaries[i]) out.at<cv::Vec3b>(static_cast<int>(i / f.width), static_cast<int>(i % f.width)) = cv::Vec3b(255, 255, 255);
  return out;
}

// What a step could not do on a frame (objects or draws left out of its tile), on stderr.
void reportProblems(const char* step, const viper::CaptureFrame& f, const viper::StepProblems& problems) {
  for (const viper::StepProblem& p : problems)
    std::cerr << "capture_sheet: frame " << f.number << ", " << step << ": " << p.text << "\n";
}

// The amodal masks (paintAmodalOverlay) blended over the color image where a mask is.
cv::Mat amodalImage(const viper::CaptureFrame& f, const viper::InstanceFrame& g, const viper::MeshRegistry& meshes) {
  viper::AmodalStep step;
  viper::FrameAmodal amodal;
  viper::StepProblems problems;
  step.process(f, g.objects, g.instance_ids.data(), meshes, amodal, problems);
  reportProblems("amodal", f, problems);
  cv::Mat overlay(static_cast<int>(f.height), static_cast<int>(f.width), CV_8UC3, cv::Scalar(0, 0, 0));
  viper::paintAmodalOverlay(amodal, g.instance_ids.data(), overlay.data);
  cv::cvtColor(overlay, overlay, cv::COLOR_RGB2BGR);
  const cv::Mat color = colorImage(f);
  cv::Mat out;
  cv::addWeighted(color, 0.35, overlay, 0.65, 0.0, out);
  cv::Mat painted;
  cv::inRange(overlay, cv::Scalar(0, 0, 0), cv::Scalar(0, 0, 0), painted);
  color.copyTo(out, painted);  // no mask: the image as it is
  return out;
}

// Normals in the optical frame as 0.5 * (n + 1) in r, g, b; black where there is none (NaN).
cv::Mat normalsImage(const viper::CaptureFrame& f, const viper::MeshRegistry& meshes) {
  const auto camera = viper::chooseFrameCamera(f);
  const std::vector<float> depth = viper::depthMetres(f, camera ? &*camera : nullptr);
  viper::GroundTruthInput in;
  in.frame = f;
  in.draw_ids = f.draw_ids.data();
  in.primitive_ids = f.primitive_ids.size() == f.pixelCount() ? f.primitive_ids.data() : nullptr;
  in.depth_m = depth.data();
  std::vector<float> n(3 * f.pixelCount());
  viper::StepProblems problems;
  viper::NormalsStep().process(in, camera, meshes, n.data(), problems);
  reportProblems("normals", f, problems);
  cv::Mat out(static_cast<int>(f.height), static_cast<int>(f.width), CV_8UC3, cv::Scalar(0, 0, 0));
  for (size_t i = 0; i < f.pixelCount(); ++i) {
    const float* v = &n[3 * i];
    if (std::isnan(v[0])) continue;
    auto c = [](float x) { return static_cast<uint8_t>(std::lround(std::clamp(0.5f * (x + 1.0f), 0.0f, 1.0f) * 255.0f)); };
    out.at<cv::Vec3b>(static_cast<int>(i / f.width), static_cast<int>(i % f.width)) = cv::Vec3b(c(v[2]), c(v[1]), c(v[0]));
  }
  return out;
}

// Scene flow's length sqrt(dx^2 + dy^2 + dz^2) through viridis, on a square-root scale up to the
// 99th percentile of the frame's moving pixels (dark violet: still in the world, yellow: that length
// or more); black where there is none.
cv::Mat sceneFlowImage(const viper::CaptureFrame& a, const viper::CaptureFrame& b, const std::vector<int32_t>& a_to_b,
                       const viper::MeshRegistry& meshes, const viper::FlowField& flow) {
  cv::Mat out(static_cast<int>(a.height), static_cast<int>(a.width), CV_8UC3, cv::Scalar(0, 0, 0));
  const auto camera_a = viper::chooseFrameCamera(a), camera_b = viper::chooseFrameCamera(b);
  if (!camera_a || !camera_b) return out;
  const std::vector<float> xyzd =
      viper::computeSceneFlow(a, b, a_to_b, meshes, viper::opticalMotion(camera_a->view, camera_b->view), flow);
  std::vector<float> length(a.pixelCount(), std::nanf("")), moving;
  for (size_t i = 0; i < length.size(); ++i) {
    const float* v = &xyzd[viper::kSceneFlowChannels * i];
    if (std::isnan(v[0])) continue;
    length[i] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (length[i] > 1e-3f) moving.push_back(length[i]);
  }
  // The scale's top: the 99th percentile of what moves (over 1 mm), so that a few fast pixels do
  // not darken the rest.
  float max_len = 1e-3f;
  if (!moving.empty()) {
    auto top = moving.begin() + static_cast<std::ptrdiff_t>(0.99 * (moving.size() - 1));
    std::nth_element(moving.begin(), top, moving.end());
    max_len = std::max(max_len, *top);
  }
  cv::Mat gray(out.size(), CV_8UC1, cv::Scalar(0));
  for (size_t i = 0; i < length.size(); ++i)
    if (!std::isnan(length[i])) gray.data[i] = static_cast<uint8_t>(std::lround(255.0f * std::sqrt(std::min(length[i] / max_len, 1.0f))));
  cv::applyColorMap(gray, out, cv::COLORMAP_VIRIDIS);
  for (size_t i = 0; i < length.size(); ++i)
    if (std::isnan(length[i])) out.at<cv::Vec3b>(static_cast<int>(i / a.width), static_cast<int>(i % a.width)) = cv::Vec3b(0, 0, 0);
  return out;
}

cv::Mat reprojectionImage(const viper::CaptureFrame& f, const viper::MeshRegistry& meshes) {
  std::vector<float> distance;
  viper::checkReprojection(f, meshes, &distance);
  cv::Mat out(static_cast<int>(f.height), static_cast<int>(f.width), CV_8UC3, cv::Scalar(0, 0, 0));
  for (size_t i = 0; i < distance.size() && i < f.draw_ids.size(); ++i) {
    if (!f.draw_ids[i]) continue;  // no id: black
    const float d = distance[i];
    out.at<cv::Vec3b>(static_cast<int>(i / f.width), static_cast<int>(i % f.width)) =
        std::isnan(d) ? cv::Vec3b(128, 128, 128) : d <= 0.5f ? cv::Vec3b(60, 200, 60) : cv::Vec3b(40, 40, 230);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "A contact sheet of chosen frames of a capture, one row per frame: color, draw ids, depth, flow to the\n"
      "next frame, reprojection check; with --labels: color, semantic classes, instances, depth, flow; with\n"
      "--labels --modalities: color, amodal masks over it, normals, scene flow.",
      "capture_sheet");
  std::string path, out_path;
  std::vector<uint64_t> frames;
  int tile_width = 320;
  std::string labels_path, class_table_path = VIPER_CLASS_TABLE;
  bool modalities = false;
  app.add_option("FILE.vcap", path, "the capture")->required()->type_name("");
  app.add_option("--frames", frames, "the frames, one row each (each needs the next one for its flow)")
      ->required()
      ->delimiter(',')
      ->type_name("N[,N...]");
  app.add_option("--out", out_path, "the sheet to write")->required()->type_name("SHEET.png");
  app.add_option("--tile-width", tile_width, "width of each image in the sheet, px (at least 32)")
      ->capture_default_str();
  app.add_option("--labels", labels_path, "a label table: the ground truth instead (classes, instances)")
      ->type_name("LABELS.yaml");
  app.add_option("--class-table", class_table_path,
                 "with --labels, the classes' colors (default: the package's config/viper_classes.csv)")
      ->type_name("CSV");
  app.add_flag("--modalities", modalities,
               "with --labels, the ground truth beyond VIPER's instead: color, amodal masks over it (visible part\n"
               "filled, occluded part hatched), normals (0.5 (n + 1) as r g b), scene flow's length (viridis)");
  app.footer("Exit status: 0 written; 1 a frame (or the frame after it) is not in the capture; 2 usage, read or\n"
             "write error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  if (modalities && labels_path.empty()) {
    std::cerr << "capture_sheet: --modalities needs --labels (the amodal masks are the tracked objects')\n";
    return 2;
  }
  tile_width = std::max(32, tile_width);
  std::set<uint64_t> wanted(frames.begin(), frames.end());
  std::vector<cv::Mat> rows;
  try {
    viper::CaptureReader reader(path);
    viper::MeshRegistry meshes;
    viper::CaptureFrame frame, previous;
    bool have_previous = false;
    std::unique_ptr<viper::InstancePipeline> pipeline;
    std::unique_ptr<viper::ClassTable> classes;
    viper::InstanceFrame truth, previous_truth;
    if (!labels_path.empty()) {
      classes = std::make_unique<viper::ClassTable>(viper::ClassTable::load(class_table_path));
      pipeline = std::make_unique<viper::InstancePipeline>(viper::LabelTable::load(labels_path));
    }
    while (reader.next(frame) == viper::CaptureReader::Status::kFrame && !wanted.empty()) {
      meshes.add(frame.new_meshes);
      if (pipeline) pipeline->process(frame, truth);  // every frame, so that tracks carry over
      if (have_previous && wanted.count(previous.number) && frame.number == previous.number + 1) {
        const auto camera = viper::chooseFrameCamera(frame);
        // Draws associate by their objects' track ids where the ground truth is computed (as the flow
        // node's do), else by mesh and placement alone.
        const std::vector<int32_t> a_to_b =
            viper::associateDraws(previous, trackIdsPerDraw(previous, pipeline ? &previous_truth : nullptr), frame,
                                  trackIdsPerDraw(frame, pipeline ? &truth : nullptr));
        const viper::FlowField flow =
            viper::computeFlow(previous, frame, a_to_b, viper::depthMetres(frame, camera ? &*camera : nullptr), meshes);
        std::vector<cv::Mat> tiles =
            modalities ? std::vector<cv::Mat>{colorImage(previous), amodalImage(previous, previous_truth, meshes),
                                              normalsImage(previous, meshes),
                                              sceneFlowImage(previous, frame, a_to_b, meshes, flow)}
            : pipeline ? std::vector<cv::Mat>{colorImage(previous), semanticImage(previous_truth, previous, *classes),
                                              instanceImage(previous_truth, previous), depthImage(previous), flowImage(flow)}
                       : std::vector<cv::Mat>{colorImage(previous), idImage(previous), depthImage(previous),
                                              flowImage(flow), reprojectionImage(previous, meshes)};
        const double scale = static_cast<double>(tile_width) / previous.width;
        for (cv::Mat& t : tiles) cv::resize(t, t, cv::Size(), scale, scale, cv::INTER_AREA);
        cv::Mat row;
        cv::hconcat(tiles, row);
        rows.push_back(row);
        wanted.erase(previous.number);
      }
      previous = frame;
      if (pipeline) std::swap(previous_truth, truth);
      have_previous = true;
    }
  } catch (const std::exception& e) {
    std::cerr << "capture_sheet: " << e.what() << "\n";
    return 2;
  }
  if (rows.empty()) {
    std::cerr << "capture_sheet: none of the frames (each needs the next one for its flow) is in " << path << "\n";
    return 1;
  }
  cv::Mat sheet;
  cv::vconcat(rows, sheet);
  if (!cv::imwrite(out_path, sheet)) {
    std::cerr << "capture_sheet: cannot write " << out_path << "\n";
    return 2;
  }
  if (!wanted.empty()) {
    std::cerr << "capture_sheet: frame " << *wanted.begin() << " (or its next frame) not in " << path << "\n";
    return 1;
  }
  return 0;
}
