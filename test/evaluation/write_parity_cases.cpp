// Writes the inputs of the cityscapesScripts parity check (docs/evaluate.md, "Parity with the
// references"): synthetic cases for each difference of issue #19 and a realistic case made from
// the package's own ground truth (generate's VIPER layout of the test scene), each as
//   CASE/cls/F.png        ground-truth class ids (8-bit gray)
//   CASE/inst/F.png       ground-truth instances (VIPER: R = class, 256 G + B = instance id)
//   CASE/pred_cls/F.png   predicted class ids
//   CASE/pred_inst/F.txt  predicted instances, Cityscapes' format "MASK.png CLASS SCORE" per line
//   CASE/pred_inst/F_K.png  their full-frame masks (non-zero = inside)
// Usage: write_parity_cases OUT_DIR VIPER_ROOT (VIPER_ROOT: `generate --input
// bags/test_scene_raw.bag ...`'s output; its train/001 frames 0, 6, 12, 18 are used).
#include "viper/dataset/viper_images.h"
#include "viper/dataset/viper_layout.h"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

namespace {

using viper::dataset::Image8;

// Class ids of config/viper_classes.csv.
enum : uint8_t {
  kUnlabeled = 0, kSky = 2, kRoad = 3, kSidewalk = 4, kTree = 7, kBuilding = 9, kPerson = 20,
  kBicycle = 22, kCar = 24, kVan = 25, kTruck = 27, kTrailer = 28
};

struct Rng {  // a fixed generator: the same cases on every platform
  uint32_t state;
  uint32_t next(uint32_t k) { return (state = state * 1664525u + 1013904223u) / 256u % k; }
};

struct Prediction {
  uint8_t class_id = 0;
  double score = 0.0;  // k / 64: exact in binary and in the text file
  std::vector<uint8_t> mask;
};

struct Frame {
  uint32_t w = 0, h = 0;
  std::vector<uint8_t> cls, pred_cls;
  std::vector<int32_t> ids;
  std::vector<Prediction> preds;

  Frame(uint32_t width, uint32_t height, uint8_t background)
      : w(width), h(height), cls(size_t(width) * height, background), pred_cls(cls), ids(cls.size(), 0) {}
  // Ground truth (and the semantic prediction with it) of a box.
  void paint(int32_t id, uint8_t c, uint32_t x0, uint32_t y0, uint32_t bw, uint32_t bh) {
    for (uint32_t y = y0; y < y0 + bh; ++y)
      for (uint32_t x = x0; x < x0 + bw; ++x) ids[y * w + x] = id, cls[y * w + x] = pred_cls[y * w + x] = c;
  }
  void predictClass(uint8_t c, uint32_t x0, uint32_t y0, uint32_t bw, uint32_t bh) {
    for (uint32_t y = y0; y < y0 + bh; ++y)
      for (uint32_t x = x0; x < x0 + bw; ++x) pred_cls[y * w + x] = c;
  }
  void predictBox(uint8_t c, double score, uint32_t x0, uint32_t y0, uint32_t bw, uint32_t bh) {
    Prediction p{c, score, std::vector<uint8_t>(cls.size(), 0)};
    for (uint32_t y = y0; y < y0 + bh && y < h; ++y)
      for (uint32_t x = x0; x < x0 + bw && x < w; ++x) p.mask[y * w + x] = 255;
    preds.push_back(std::move(p));
  }
  // The pixels where `inside` holds, moved by (dx, dy).
  template <class Inside>
  void predictShifted(uint8_t c, double score, int dx, int dy, Inside inside) {
    Prediction p{c, score, std::vector<uint8_t>(cls.size(), 0)};
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        const int sx = int(x) - dx, sy = int(y) - dy;
        if (sx >= 0 && sy >= 0 && sx < int(w) && sy < int(h) && inside(size_t(sy) * w + size_t(sx))) p.mask[y * w + x] = 255;
      }
    preds.push_back(std::move(p));
  }
};

// Two frames of cars and people on road under sky; every prediction scored `score(k)`.
std::vector<Frame> streetCase(double (*score)(int)) {
  std::vector<Frame> frames;
  for (int f = 0; f < 2; ++f) {
    Frame fr(64, 48, kRoad);
    fr.paint(0, kSky, 0, 0, 64, 10);
    fr.paint(0, kBuilding, 44, 10, 20, 14);
    fr.paint(1, kCar, 2, 20, 20, 12);          // 240 px
    fr.paint(2, kCar, 26, 24, 14 + f, 10);     // 140 / 150 px
    fr.paint(3, kCar, 44, 30, 16, 12);         // 192 px, never predicted
    fr.paint(4, kPerson, 8, 36, 6, 20 - 8);    // 72 px: under 100, ignored
    fr.paint(5, kPerson, 50, 12, 8, 14);       // 112 px
    fr.predictBox(kCar, score(0), 2, 20, 20, 12);          // exact
    fr.predictBox(kCar, score(1), 28, 24, 14, 10);         // shifted by 2: IoU 0.75 / 0.71
    fr.predictBox(kCar, score(2), 2, 21, 20, 12);          // a duplicate of car 1
    fr.predictBox(kCar, score(3), 30, 12, 12, 8);          // on road and sky: a false positive
    fr.predictBox(kPerson, score(4), 50, 13, 8, 14);       // IoU 13/15
    fr.predictBox(kPerson, score(5), 14, 40, 10, 8);       // on road: a false positive
    fr.predictBox(kPerson, score(6), 8, 36, 6, 12);        // on the small person: ignored
    fr.predictClass(kSidewalk, 0, 44, 64, 4);
    frames.push_back(std::move(fr));
  }
  return frames;
}

double tied(int) { return 1.0; }
double distinct(int k) { return (64.0 - 5 * k) / 64; }

// Semantic: truck predicted where there is none (IoU 0, in the mean), van only on unlabeled
// pixels (no false positive: not in the mean), tree both in the ground truth and predicted.
std::vector<Frame> absentClassCase() {
  Frame fr(64, 48, kRoad);
  fr.paint(0, kSky, 0, 0, 64, 12);
  fr.paint(0, kTree, 0, 12, 10, 20);
  fr.paint(0, kUnlabeled, 54, 40, 10, 8);
  fr.predictClass(kTruck, 20, 20, 16, 10);
  fr.predictClass(kVan, 54, 40, 10, 8);
  fr.predictClass(kTree, 10, 12, 4, 20);
  fr.paint(7, kCar, 40, 20, 14, 10);
  fr.predictBox(kCar, 0.5, 40, 20, 14, 10);
  fr.predictBox(kTruck, 0.75, 20, 20, 16, 10);  // truck has no ground truth: its AP is NaN
  return {fr};
}

// Instances of unscored classes (trailer, bicycle) with and without instance ids.
std::vector<Frame> unscoredInstanceCase() {
  Frame fr(64, 48, kRoad);
  fr.paint(1, kCar, 0, 10, 20, 12);
  fr.paint(2, kTrailer, 22, 10, 20, 12);      // an instance: not void
  fr.paint(0, kTrailer, 44, 10, 20, 12);      // no instance id: void
  fr.paint(3, kBicycle, 0, 30, 14, 12);       // an instance: not void
  fr.paint(4, kPerson, 20, 30, 10, 14);
  fr.predictBox(kCar, 0.5, 0, 10, 20, 12);
  fr.predictBox(kCar, 0.875, 22, 10, 20, 12);
  fr.predictBox(kCar, 0.75, 44, 10, 20, 12);
  fr.predictBox(kPerson, 0.625, 0, 30, 14, 12);
  fr.predictBox(kPerson, 0.25, 20, 30, 10, 14);
  return {fr};
}

// Group regions: car and person pixels without an instance id, a large and a small one.
std::vector<Frame> groupCase() {
  Frame fr(64, 48, kRoad);
  fr.paint(1, kCar, 0, 0, 20, 12);
  fr.paint(0, kCar, 22, 0, 20, 12);           // car group, 240 px
  fr.paint(0, kCar, 44, 0, 6, 10);            // and 60 px more of it, elsewhere
  fr.paint(2, kPerson, 0, 20, 10, 16);
  fr.paint(0, kPerson, 12, 20, 6, 10);        // person group, 60 px: under 100
  fr.predictBox(kCar, 0.5, 0, 0, 20, 12);
  fr.predictBox(kCar, 0.875, 22, 0, 20, 12);  // the large part of the group
  fr.predictBox(kCar, 0.75, 32, 0, 10, 16);   // half on the group, the rest on road
  fr.predictBox(kCar, 0.625, 44, 0, 10, 10);  // 60 % on the group
  fr.predictBox(kCar, 0.375, 12, 20, 10, 10); // on the person group: not ignored for cars
  fr.predictBox(kPerson, 0.5, 0, 20, 10, 16);
  fr.predictBox(kPerson, 0.25, 12, 21, 10, 10);  // half on the small person group
  return {fr};
}

// The test scene's ground truth with a perception made from it: instances moved, missed,
// mislabelled, duplicated, false positives at random, scores k / 64 (ties happen); the semantic
// image moved by 2 px with a wrong box.
std::vector<Frame> realisticCase(const std::string& root) {
  std::vector<Frame> frames;
  Rng rnd{19};
  for (uint64_t f : {0, 6, 12, 18}) {
    const Image8 cls = viper::dataset::readViperClassImage(viper::dataset::viperFramePath(root, "train", "cls", "001", f, "png"));
    const Image8 inst = viper::dataset::readViperInstanceImage(viper::dataset::viperFramePath(root, "train", "inst", "001", f, "png"));
    Frame fr(cls.width, cls.height, kUnlabeled);
    fr.cls = cls.data;
    fr.ids = viper::dataset::viperInstanceIds(inst);
    for (uint32_t y = 0; y < fr.h; ++y)
      for (uint32_t x = 0; x < fr.w; ++x) fr.pred_cls[y * fr.w + x] = fr.cls[y * fr.w + (x >= 2 ? x - 2 : 0)];
    fr.predictClass(static_cast<uint8_t>(std::vector<int>{kCar, kTruck, kSidewalk, kTree}[rnd.next(4)]),
                    rnd.next(fr.w - 80), rnd.next(fr.h - 60), 80, 60);
    std::map<int32_t, uint8_t> instances;
    for (size_t i = 0; i < fr.ids.size(); ++i)
      if (fr.ids[i] > 0) instances[fr.ids[i]] = fr.cls[i];
    for (const auto& [id, c] : instances) {
      const uint32_t fate = rnd.next(100);
      if (fate < 12) continue;  // missed
      const uint8_t label = fate < 22 ? static_cast<uint8_t>(std::vector<int>{kCar, kPerson, kVan}[rnd.next(3)]) : c;
      const int dx = int(rnd.next(9)) - 4, dy = int(rnd.next(9)) - 4;
      const int32_t gid = id;
      fr.predictShifted(label, (1 + rnd.next(64)) / 64.0, dx, dy, [&](size_t i) { return fr.ids[i] == gid; });
      if (rnd.next(100) < 25)
        fr.predictShifted(label, (1 + rnd.next(64)) / 64.0, dx + 6, dy, [&](size_t i) { return fr.ids[i] == gid; });
    }
    for (int k = 0; k < 3; ++k)
      fr.predictBox(static_cast<uint8_t>(std::vector<int>{kCar, kPerson, 19}[rnd.next(3)]), (1 + rnd.next(64)) / 64.0,
                    rnd.next(fr.w - 40), rnd.next(fr.h - 40), 10 + rnd.next(30), 10 + rnd.next(30));
    frames.push_back(std::move(fr));
  }
  return frames;
}

Image8 gray(uint32_t w, uint32_t h, const std::vector<uint8_t>& v) { return Image8{w, h, 1, v}; }

void writeCase(const std::filesystem::path& dir, const std::vector<Frame>& frames) {
  for (const char* sub : {"cls", "inst", "pred_cls", "pred_inst"}) std::filesystem::create_directories(dir / sub);
  for (size_t f = 0; f < frames.size(); ++f) {
    const Frame& fr = frames[f];
    char name[32];
    std::snprintf(name, sizeof name, "%03zu", f);
    viper::dataset::writeViperClassImage(dir / "cls" / (std::string(name) + ".png"), gray(fr.w, fr.h, fr.cls), {});
    viper::dataset::writeViperClassImage(dir / "pred_cls" / (std::string(name) + ".png"), gray(fr.w, fr.h, fr.pred_cls), {});
    Image8 inst{fr.w, fr.h, 3, std::vector<uint8_t>(fr.cls.size() * 3)};
    for (size_t i = 0; i < fr.cls.size(); ++i) {
      if (fr.ids[i] < 0 || fr.ids[i] > 65535) throw std::runtime_error("instance id out of VIPER's 16 bits");
      inst.data[3 * i] = fr.cls[i], inst.data[3 * i + 1] = uint8_t(fr.ids[i] >> 8), inst.data[3 * i + 2] = uint8_t(fr.ids[i]);
    }
    viper::dataset::writeViperInstanceImage(dir / "inst" / (std::string(name) + ".png"), inst);
    std::ofstream txt(dir / "pred_inst" / (std::string(name) + ".txt"));
    for (size_t k = 0; k < fr.preds.size(); ++k) {
      const std::string mask = std::string(name) + "_" + std::to_string(k) + ".png";
      viper::dataset::writeViperClassImage(dir / "pred_inst" / mask, gray(fr.w, fr.h, fr.preds[k].mask), {});
      char score[32];
      std::snprintf(score, sizeof score, "%.17g", fr.preds[k].score);
      txt << mask << " " << int(fr.preds[k].class_id) << " " << score << "\n";
    }
    if (!txt) throw std::runtime_error((dir / "pred_inst").string() + ": cannot write " + name + ".txt");
  }
}

}  // namespace

int main(int argc, char** argv) {
  const char* usage = "usage: write_parity_cases OUT_DIR VIPER_ROOT (the cityscapesScripts parity cases; see docs/evaluate.md)\n";
  if (argc == 2 && std::string(argv[1]) == "--help") {
    std::cout << usage;
    return 0;
  }
  if (argc != 3) {
    std::cerr << usage;
    return 2;
  }
  try {
    const std::filesystem::path out = argv[1];
    writeCase(out / "ties", streetCase(tied));
    writeCase(out / "distinct_scores", streetCase(distinct));
    writeCase(out / "absent_class", absentClassCase());
    writeCase(out / "unscored_instances", unscoredInstanceCase());
    writeCase(out / "groups", groupCase());
    writeCase(out / "realistic", realisticCase(argv[2]));
  } catch (const std::exception& e) {
    std::cerr << "write_parity_cases: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
