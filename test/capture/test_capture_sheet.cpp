// capture_sheet --modalities on the world's capture (90 frames of traffic, 480x270): the sheet has a
// row per frame of four tiles (color, amodal masks over it, normals, scene flow), each drawn where
// its modality has values and black (or the image itself) where it has none.
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/ground_truth/label_table.h"
#include "viper/ground_truth/normals.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdlib>
#include <map>
#include <string>

namespace viper {
namespace {

bool isBlack(const cv::Vec3b& c) { return c[0] == 0 && c[1] == 0 && c[2] == 0; }

TEST(CaptureSheetModalities, TilesShowEachModalityWhereItHasValues) {
  const std::string out = ::testing::TempDir() + "capture_sheet_modalities.png";
  const std::vector<uint64_t> frames = {10, 40};
  const std::string command = std::string(VIPER_CAPTURE_SHEET) + " " + VIPER_WORLD_CAPTURE +
                              " --frames 10,40 --labels " + VIPER_WORLD_LABELS +
                              " --modalities --tile-width 480 --out " + out;
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const cv::Mat sheet = cv::imread(out, cv::IMREAD_COLOR);
  ASSERT_FALSE(sheet.empty()) << out;

  // The frames and their instance images, by the same pipeline over every frame before them.
  CaptureReader reader(VIPER_WORLD_CAPTURE);
  InstancePipeline pipeline(LabelTable::load(VIPER_WORLD_LABELS));
  std::map<uint64_t, std::pair<CaptureFrame, InstanceFrame>> wanted;
  CaptureFrame f;
  while (reader.next(f) == CaptureReader::Status::kFrame && f.number <= frames.back()) {
    InstanceFrame g = pipeline.process(f);
    if (f.number == frames[0] || f.number == frames[1]) wanted[f.number] = {f, std::move(g)};
  }
  ASSERT_EQ(wanted.size(), 2u);
  const int w = static_cast<int>(wanted.begin()->second.first.width);
  const int h = static_cast<int>(wanted.begin()->second.first.height);
  ASSERT_EQ(sheet.cols, 4 * w);
  ASSERT_EQ(sheet.rows, 2 * h);

  int row = 0;
  for (const auto& [number, fg] : wanted) {
    SCOPED_TRACE("frame " + std::to_string(number));
    const CaptureFrame& frame = fg.first;
    const InstanceFrame& truth = fg.second;
    const auto camera = chooseFrameCamera(frame);
    ASSERT_TRUE(camera);
    const std::vector<float> depth = depthMetres(frame, &*camera);
    const PixelRays rays(*camera, frame.width, frame.height);
    auto tile = [&](int k) { return sheet(cv::Rect(k * w, row * h, w, h)); };
    const cv::Mat color = tile(0), amodal = tile(1), normals = tile(2), scene = tile(3);
    size_t color_wrong = 0, visible = 0, visible_unpainted = 0, painted = 0;
    size_t surface = 0, normal_black = 0, normal_where_none = 0, normal_away = 0, normal_not_unit = 0;
    size_t ids = 0, scene_drawn = 0, scene_where_no_id = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        const uint8_t* rgb = &frame.color_rgb[3 * p];
        const cv::Vec3b c = color.at<cv::Vec3b>(y, x);
        color_wrong += c != cv::Vec3b(rgb[2], rgb[1], rgb[0]);
        // Amodal: every pixel a tracked object shows is painted over; others may be (hatching).
        const bool painted_here = amodal.at<cv::Vec3b>(y, x) != c;
        painted += painted_here;
        if (truth.instance_ids[p] > 0) {
          ++visible;
          visible_unpainted += !painted_here;
        }
        // Normals: black exactly where there is no surface (no draw or no depth); elsewhere of unit
        // length and facing the camera (n . ray < 0), within the 8 bits' rounding.
        const bool has_surface = frame.draw_ids[p] != 0 && depth[p] > 0.0f && std::isfinite(depth[p]);
        const cv::Vec3b n = normals.at<cv::Vec3b>(y, x);
        surface += has_surface;
        if (has_surface) {
          normal_black += isBlack(n);
          auto component = [](uint8_t v) { return v / 255.0 * 2.0 - 1.0; };
          const double nx = component(n[2]), ny = component(n[1]), nz = component(n[0]);
          const double rx = rays.x(x), ry = rays.y(y), rounding = 1.0 / 255.0;
          normal_away += !isBlack(n) && nx * rx + ny * ry + nz > rounding * (std::abs(rx) + std::abs(ry) + 1.0);
          normal_not_unit += !isBlack(n) && std::abs(std::sqrt(nx * nx + ny * ny + nz * nz) - 1.0) > 2.0 * rounding;
        } else {
          normal_where_none += !isBlack(n);
        }
        // Scene flow: none where no draw (the flow is undefined there).
        const bool drawn = !isBlack(scene.at<cv::Vec3b>(y, x));
        ids += frame.draw_ids[p] != 0;
        scene_drawn += drawn;
        scene_where_no_id += drawn && frame.draw_ids[p] == 0;
      }
    EXPECT_EQ(color_wrong, 0u);
    EXPECT_GT(visible, 100u);
    EXPECT_EQ(visible_unpainted, 0u) << "of " << visible << " visible object pixels";
    EXPECT_GT(painted, visible) << "occluded parts are hatched beyond what is visible";
    EXPECT_GT(surface, static_cast<size_t>(w * h / 2));
    EXPECT_EQ(normal_black, 0u) << "of " << surface;
    EXPECT_EQ(normal_where_none, 0u);
    EXPECT_EQ(normal_away, 0u);
    EXPECT_EQ(normal_not_unit, 0u);
    EXPECT_GT(scene_drawn, ids / 2) << "scene flow on " << scene_drawn << " of " << ids << " id pixels";
    EXPECT_EQ(scene_where_no_id, 0u);
    ++row;
  }
}

TEST(CaptureSheetModalities, NeedsLabels) {
  const std::string command = std::string(VIPER_CAPTURE_SHEET) + " " + VIPER_WORLD_CAPTURE +
                              " --frames 10 --modalities --out " + ::testing::TempDir() + "no_labels.png 2>/dev/null";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
}

}  // namespace
}  // namespace viper
