// label_resources: the labelling page of a program nobody annotated. From one capture, every
// resource its visible pixels come from (viper::ResourceCensus) with its pixel count, a few crops
// of where it shows, and a proposed class; written as a static web page (DIR/index.html, no server
// needed) where a person picks a VIPER class per resource and saves the label table YAML.
// Exit code 0 = written, 2 = usage/read/write error.
#include "command_line.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/resource_census.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    out += c;
  }
  return out + "\"";
}

std::string cropName(const viper::ResourceStats& r, size_t i) {
  return std::string("crops/") + viper::resourceKindName(r.kind) + "_" + viper::keyToHex(r.key) + "_" +
         std::to_string(i) + ".jpg";
}

// The resource's pixels in full, the rest of the crop dimmed.
cv::Mat crop(const viper::CaptureFrame& f, const viper::ResourceStats& r, const viper::ResourceSighting& s) {
  const int w = static_cast<int>(f.width), h = static_cast<int>(f.height);
  const int bw = static_cast<int>(s.x1 - s.x0 + 1), bh = static_cast<int>(s.y1 - s.y0 + 1);
  const int pad = std::max(16, std::max(bw, bh) / 4);
  const cv::Rect box = cv::Rect(static_cast<int>(s.x0) - pad, static_cast<int>(s.y0) - pad, bw + 2 * pad, bh + 2 * pad) &
                       cv::Rect(0, 0, w, h);
  cv::Mat out(box.height, box.width, CV_8UC3);
  cv::Mat mask(box.height, box.width, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < box.height; ++y) {
    for (int x = 0; x < box.width; ++x) {
      const size_t i = static_cast<size_t>(y + box.y) * f.width + static_cast<size_t>(x + box.x);
      const uint32_t id = f.draw_ids[i];
      const bool mine =
          id > 0 && id <= f.draws.size() && viper::primaryResource(f.draws[id - 1]) == std::make_pair(r.kind, r.key);
      const uint8_t* rgb = &f.color_rgb[3 * i];
      const double k = mine ? 1.0 : 0.3;
      mask.at<uint8_t>(y, x) = mine ? 255 : 0;
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(rgb[2] * k), static_cast<uint8_t>(rgb[1] * k),
                                          static_cast<uint8_t>(rgb[0] * k));
    }
  }
  const double scale = std::min(1.0, std::min(220.0 / out.cols, 160.0 / out.rows));
  if (scale < 1.0) {
    cv::resize(out, out, cv::Size(), scale, scale, cv::INTER_AREA);
    cv::resize(mask, mask, out.size(), 0, 0, cv::INTER_NEAREST);
  }
  // Its outline in yellow, so that a small part stands out of a large crop.
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(out, contours, -1, cv::Scalar(0, 230, 255), 1);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "Writes DIR/index.html: every resource (mesh, else texture, else program key) the capture's visible\n"
      "pixels come from, most pixels first, with crops, a proposed class, and a class to pick; 'Save label\n"
      "table' downloads the YAML that the instances node reads (~label_table).",
      "label_resources");
  std::string path, out_dir, previous_path, class_table_path = VIPER_CLASS_TABLE;
  size_t top = 200, crops = 3;
  uint64_t from = 0;
  app.add_option("FILE.vcap", path, "the capture")->required()->type_name("");
  app.add_option("--out", out_dir, "the folder of the page")->required()->type_name("DIR");
  app.add_option("--labels", previous_path, "a previous table, whose classes are proposed first")
      ->type_name("PREVIOUS.yaml");
  app.add_option("--class-table", class_table_path, "the classes to pick from (default: the package's "
                                                    "config/viper_classes.csv)")
      ->type_name("CSV");
  app.add_option("--top", top, "the N resources with the most pixels")->capture_default_str();
  app.add_option("--crops", crops, "crops per resource")->capture_default_str();
  app.add_option("--from", from, "skip frames numbered below N");
  app.footer("Exit status: 0 written; 2 usage, read or write error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  try {
    const viper::ClassTable classes = viper::ClassTable::load(class_table_path);
    viper::LabelTable previous;
    if (!previous_path.empty()) previous = viper::LabelTable::load(previous_path);

    // Pass 1: the census.
    viper::ResourceCensus census(crops);
    viper::MeshRegistry meshes;
    uint64_t frames = 0;
    {
      viper::CaptureReader reader(path);
      viper::CaptureFrame f;
      while (reader.next(f) == viper::CaptureReader::Status::kFrame) {
        meshes.add(f.new_meshes);
        if (f.number < from) continue;
        census.add(f, meshes);
        ++frames;
      }
    }
    std::vector<viper::ResourceStats> resources = census.resources();
    if (resources.size() > top) resources.resize(top);

    // Pass 2: the crops, frame by frame.
    fs::create_directories(out_dir + "/crops");
    std::map<uint64_t, std::vector<std::pair<size_t, size_t>>> wanted;  // frame -> (resource, sighting)
    for (size_t r = 0; r < resources.size(); ++r)
      for (size_t s = 0; s < resources[r].best.size(); ++s) wanted[resources[r].best[s].frame].push_back({r, s});
    {
      viper::CaptureReader reader(path);
      viper::CaptureFrame f;
      while (!wanted.empty() && reader.next(f) == viper::CaptureReader::Status::kFrame) {
        auto it = wanted.find(f.number);
        if (it == wanted.end()) continue;
        for (const auto& [r, s] : it->second) {
          const std::string file = out_dir + "/" + cropName(resources[r], s);
          if (!cv::imwrite(file, crop(f, resources[r], resources[r].best[s]))) throw std::runtime_error("cannot write " + file);
        }
        wanted.erase(it);
      }
    }

    // The page's data, as a script (a page opened from a file may load scripts, not fetch JSON).
    std::ostringstream js;
    js << "window.VIPER_LABELS = {\n  capture: " << jsonString(path) << ",\n  frames: " << frames
       << ",\n  total_pixels: " << census.totalPixels() << ",\n  classes: [";
    for (const viper::ClassInfo& c : classes.classes())
      js << (c.id ? "," : "") << "\n    {id: " << c.id << ", name: " << jsonString(c.name) << ", rgb: ["
         << int(c.rgb[0]) << ", " << int(c.rgb[1]) << ", " << int(c.rgb[2]) << "]}";
    js << "\n  ],\n  resources: [";
    for (size_t r = 0; r < resources.size(); ++r) {
      const viper::ResourceStats& s = resources[r];
      const viper::ClassProposal p = viper::proposeClass(s, previous_path.empty() ? nullptr : &previous);
      const Eigen::Vector3d rgb = s.meanRgb();
      char size[96];
      std::snprintf(size, sizeof(size), "[%.2f, %.2f, %.2f]", s.placed_size.x(), s.placed_size.y(), s.placed_size.z());
      js << (r ? "," : "") << "\n    {kind: " << jsonString(viper::resourceKindName(s.kind))
         << ", key: " << jsonString(viper::keyToHex(s.key)) << ", pixels: " << s.pixels << ", frames: " << s.frames
         << ", proposal: " << int(p.class_id) << ", reason: " << jsonString(p.reason) << ", rgb: [" << int(rgb.x())
         << ", " << int(rgb.y()) << ", " << int(rgb.z()) << "], size: " << size << ", crops: [";
      for (size_t c = 0; c < s.best.size(); ++c) js << (c ? ", " : "") << jsonString(cropName(s, c));
      js << "]}";
    }
    js << "\n  ]\n};\n";
    std::ofstream(out_dir + "/resources.js") << js.str();
    for (const char* file : {"index.html", "label_page.js"})
      fs::copy_file(std::string(VIPER_LABEL_PAGE_DIR) + "/" + file, out_dir + "/" + file,
                    fs::copy_options::overwrite_existing);
    std::cout << "label_resources: " << resources.size() << " resources of " << frames << " frames -> " << out_dir
              << "/index.html\n";
  } catch (const std::exception& e) {
    std::cerr << "label_resources: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
