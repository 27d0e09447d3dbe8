#include "viper/dataset/coco.h"

#include "deflate_writers.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <utility>

namespace viper::dataset {
namespace {

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

CocoRle cocoRleOfBoxMask(uint32_t width, uint32_t height, int box_x, int box_y, uint32_t box_width,
                         uint32_t box_height, const uint8_t* mask) {
  CocoRle rle;
  rle.width = width;
  rle.height = height;
  const int64_t x0 = std::max<int64_t>(0, box_x), y0 = std::max<int64_t>(0, box_y);
  const int64_t x1 = std::min<int64_t>(width, int64_t{box_x} + box_width);
  const int64_t y1 = std::min<int64_t>(height, int64_t{box_y} + box_height);
  if ((x1 > x0 && y1 > y0) && mask == nullptr) throw std::invalid_argument("cocoRleOfBoxMask: no mask for a box");
  // Column-major position of each pixel inside, in order; runs from the gaps between them.
  uint64_t at = 0;      // pixels of the image before the current run
  uint32_t ones = 0;    // length of the current run of 1s
  bool in_run = false;
  auto push = [&](uint64_t n) { rle.counts.push_back(static_cast<uint32_t>(n)); };
  for (int64_t x = x0; x < x1; ++x)
    for (int64_t y = y0; y < y1; ++y) {
      const bool inside = mask[(y - box_y) * int64_t{box_width} + (x - box_x)] != 0;
      const uint64_t position = static_cast<uint64_t>(x) * height + static_cast<uint64_t>(y);
      if (inside) {
        if (in_run && position != at + ones) {  // the run ended outside the box
          push(ones);
          at += ones;
          in_run = false;
        }
        if (!in_run) {
          push(position - at);  // the 0s before
          at = position;
          ones = 0;
          in_run = true;
        }
        ++ones;
      } else if (in_run) {
        push(ones);
        at += ones;
        in_run = false;
      }
    }
  if (in_run) {
    push(ones);
    at += ones;
  }
  push(static_cast<uint64_t>(width) * height - at);  // the 0s after (maskApi always ends with them)
  // maskApi ends on the last run whatever it is: a final run of 0s of length 0 is not written.
  if (rle.counts.size() > 1 && rle.counts.back() == 0) rle.counts.pop_back();
  return rle;
}

std::string cocoRleString(const CocoRle& rle) {
  std::string s;
  for (size_t i = 0; i < rle.counts.size(); ++i) {
    int64_t x = rle.counts[i];
    if (i > 2) x -= rle.counts[i - 2];
    bool more = true;
    while (more) {
      char c = static_cast<char>(x & 0x1f);
      x >>= 5;  // arithmetic: a negative difference ends at -1
      more = (c & 0x10) ? x != -1 : x != 0;
      if (more) c |= 0x20;
      s += static_cast<char>(c + 48);
    }
  }
  return s;
}

uint64_t cocoRleArea(const CocoRle& rle) {
  uint64_t area = 0;
  for (size_t j = 1; j < rle.counts.size(); j += 2) area += rle.counts[j];
  return area;
}

std::vector<uint32_t> cocoRleBox(const CocoRle& rle) {
  if (cocoRleArea(rle) == 0 || rle.height == 0) return {0, 0, 0, 0};
  uint32_t xs = rle.width, ys = rle.height, xe = 0, ye = 0;
  uint64_t at = 0;
  for (size_t j = 0; j < rle.counts.size(); ++j) {
    const uint64_t start = at;
    at += rle.counts[j];
    if (j % 2 == 0 || rle.counts[j] == 0) continue;
    const uint64_t last = at - 1;
    const uint32_t x_first = static_cast<uint32_t>(start / rle.height), y_first = static_cast<uint32_t>(start % rle.height);
    const uint32_t x_last = static_cast<uint32_t>(last / rle.height), y_last = static_cast<uint32_t>(last % rle.height);
    xs = std::min(xs, x_first);
    xe = std::max(xe, x_last);
    if (x_first != x_last) {  // the run wraps into the next column: it spans every row
      ys = 0;
      ye = rle.height - 1;
    } else {
      ys = std::min(ys, y_first);
      ye = std::max(ye, y_last);
    }
  }
  return {xs, ys, xe - xs + 1, ye - ys + 1};
}

CocoInstancesWriter::CocoInstancesWriter(std::vector<CocoCategory> categories) : categories_(std::move(categories)) {}

int CocoInstancesWriter::addImage(const std::string& file_name, uint32_t width, uint32_t height,
                                  const std::string& sequence, int64_t frame_index) {
  images_.push_back({file_name, sequence, width, height, frame_index});
  return static_cast<int>(images_.size());
}

const CocoInstancesWriter::Image& CocoInstancesWriter::image(int image_id) const {
  if (image_id < 1 || static_cast<size_t>(image_id) > images_.size())
    throw std::invalid_argument("COCO: no image of id " + std::to_string(image_id));
  return images_[static_cast<size_t>(image_id) - 1];
}

void CocoInstancesWriter::addVisibleInstances(int image_id, const uint8_t* class_ids, const int32_t* instance_ids) {
  const Image& im = image(image_id);
  const size_t n = static_cast<size_t>(im.width) * im.height;
  if (n > 0 && (class_ids == nullptr || instance_ids == nullptr))
    throw std::invalid_argument("COCO: no class or instance ids for image " + im.file_name);
  struct Extent {
    uint32_t x0 = UINT32_MAX, y0 = UINT32_MAX, x1 = 0, y1 = 0;
    std::array<uint32_t, 256> classes{};
  };
  std::map<int32_t, Extent> objects;  // by instance id: annotations in id order
  for (uint32_t y = 0; y < im.height; ++y)
    for (uint32_t x = 0; x < im.width; ++x) {
      const size_t i = static_cast<size_t>(y) * im.width + x;
      if (instance_ids[i] == 0) continue;
      Extent& e = objects[instance_ids[i]];
      e.x0 = std::min(e.x0, x);
      e.y0 = std::min(e.y0, y);
      e.x1 = std::max(e.x1, x);
      e.y1 = std::max(e.y1, y);
      ++e.classes[class_ids[i]];
    }
  std::vector<uint8_t> mask;
  for (const auto& [id, e] : objects) {
    const uint32_t bw = e.x1 - e.x0 + 1, bh = e.y1 - e.y0 + 1;
    mask.assign(static_cast<size_t>(bw) * bh, 0);
    for (uint32_t y = e.y0; y <= e.y1; ++y)
      for (uint32_t x = e.x0; x <= e.x1; ++x)
        mask[(y - e.y0) * bw + (x - e.x0)] = instance_ids[static_cast<size_t>(y) * im.width + x] == id;
    CocoObjectMask object;
    object.category_id = static_cast<int>(std::max_element(e.classes.begin(), e.classes.end()) - e.classes.begin());
    object.track_id = id;
    object.rle = cocoRleOfBoxMask(im.width, im.height, static_cast<int>(e.x0), static_cast<int>(e.y0), bw, bh,
                                  mask.data());
    addAnnotation(image_id, object);
  }
}

void CocoInstancesWriter::addAnnotation(int image_id, const CocoObjectMask& object) {
  const Image& im = image(image_id);
  if (object.rle.width != im.width || object.rle.height != im.height)
    throw std::invalid_argument("COCO: a mask of " + std::to_string(object.rle.width) + "x" +
                                std::to_string(object.rle.height) + " px for image " + im.file_name + " of " +
                                std::to_string(im.width) + "x" + std::to_string(im.height) + " px");
  const bool known = std::any_of(categories_.begin(), categories_.end(),
                                 [&](const CocoCategory& c) { return c.id == object.category_id; });
  const uint64_t area = cocoRleArea(object.rle);
  if (!known || area == 0) {
    ++skipped_;
    return;
  }
  annotations_.push_back({image_id, object.category_id, object.track_id, cocoRleString(object.rle), area,
                          cocoRleBox(object.rle), im.height, im.width});
}

std::string CocoInstancesWriter::json() const {
  std::string out = "{\"info\": {\"description\": \"VIPER ground truth (viper ROS package)\"}, \"licenses\": [],\n";
  out += "\"images\": [";
  for (size_t i = 0; i < images_.size(); ++i) {
    const Image& im = images_[i];
    out += (i ? ",\n  " : "\n  ");
    out += "{\"id\": " + std::to_string(i + 1) + ", \"file_name\": " + jsonString(im.file_name) +
           ", \"width\": " + std::to_string(im.width) + ", \"height\": " + std::to_string(im.height) +
           ", \"sequence\": " + jsonString(im.sequence) + ", \"frame_index\": " + std::to_string(im.frame_index) + "}";
  }
  out += "],\n\"categories\": [";
  for (size_t i = 0; i < categories_.size(); ++i) {
    const CocoCategory& c = categories_[i];
    out += (i ? ",\n  " : "\n  ");
    out += "{\"id\": " + std::to_string(c.id) + ", \"name\": " + jsonString(c.name) +
           ", \"supercategory\": " + jsonString(c.supercategory) + "}";
  }
  out += "],\n\"annotations\": [";
  for (size_t i = 0; i < annotations_.size(); ++i) {
    const Annotation& a = annotations_[i];
    out += (i ? ",\n  " : "\n  ");
    out += "{\"id\": " + std::to_string(i + 1) + ", \"image_id\": " + std::to_string(a.image_id) +
           ", \"category_id\": " + std::to_string(a.category_id) + ", \"segmentation\": {\"size\": [" +
           std::to_string(a.height) + ", " + std::to_string(a.width) + "], \"counts\": " + jsonString(a.counts) +
           "}, \"area\": " + std::to_string(a.area) + ", \"bbox\": [" + std::to_string(a.box[0]) + ", " +
           std::to_string(a.box[1]) + ", " + std::to_string(a.box[2]) + ", " + std::to_string(a.box[3]) +
           "], \"iscrowd\": 0, \"track_id\": " + std::to_string(a.track_id) + "}";
  }
  out += "]}\n";
  return out;
}

void CocoInstancesWriter::write(const std::string& path) const {
  const std::string text = json();
  detail::writeFileAtomically(path, std::vector<uint8_t>(text.begin(), text.end()), "COCO JSON");
}

}  // namespace viper::dataset
