// Writes the player tests' dataset in VIPER's layout, damage included (viper_test_layout.h says
// what), with the package's own writers. Usage: make_viper_test_layout --out DIR (DIR is replaced).
#include "viper_test_layout.h"

#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_layout.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

namespace {

namespace fs = std::filesystem;
using namespace viper_test_layout;
using namespace viper::dataset;

std::string at(const std::string& root, const char* seq, const char* modality, uint64_t frame, const char* ext) {
  const std::string p = viperFramePath(root, "train", modality, seq, frame, ext);
  fs::create_directories(fs::path(p).parent_path());
  return p;
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

std::vector<char> readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeAll(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 || std::string(argv[1]) != "--out") {
    std::cerr << "usage: make_viper_test_layout --out DIR\n";
    return 2;
  }
  const std::string root = argv[2];
  fs::remove_all(root);
  const ClassPalette palette = {{{0, 0, 0}}, {{111, 74, 0}}, {{70, 130, 180}}, {{128, 64, 128}}};

  std::vector<ViperCameraRow> camera;
  for (uint64_t f = 0; f < kFrames001; ++f) {
    if (f != 2) writeViperColorImage(at(root, "001", "img", f, f == 7 ? "jpg" : "png"), colorImage(1, f));
    writeViperClassImage(at(root, "001", "cls", f, "png"), classImage(1, f, f == 3 ? kWidth / 2 : kWidth), palette);
    writeViperInstanceImage(at(root, "001", "inst", f, "png"), instanceImage(f));
    if (f + 1 < kFrames001) writeViperFlow(at(root, "001", "flow", f, "npz"), flowImage(f, false));
    if (f > 0) writeViperFlow(at(root, "001", "flowbw", f, "npz"), flowImage(f, true));
    std::vector<ViperBoxRow> boxes = {carBox(f)};
    writeViperBoxesCsv(at(root, "001", "bb", f, "csv"), boxes);
    camera.push_back({f, projection(), view(f)});
  }
  fs::create_directories(fs::path(root) / "train" / "camera");
  writeViperCameraCsv(viperCameraPath(root, "train", "001"), camera);

  // The damage.
  std::vector<char> npz = readAll(at(root, "001", "flow", 4, "npz"));
  npz[npz.size() / 3] ^= 0x5a;
  writeAll(at(root, "001", "flow", 4, "npz"), npz);
  std::vector<char> png = readAll(at(root, "001", "inst", 5, "png"));
  png.resize(png.size() * 2 / 3);
  writeAll(at(root, "001", "inst", 5, "png"), png);
  {
    std::ofstream bb(at(root, "001", "bb", 6, "csv"), std::ios::app);
    bb << "24,8,1,2,3\n";
  }
  {
    const std::string path = viperCameraPath(root, "train", "001");
    const std::vector<char> bytes = readAll(path);
    std::string text(bytes.begin(), bytes.end());
    text.replace(text.find("\n6,") + 3, 1, "oops");
    writeText(path, text);
  }
  writeText(at(root, "001", "flowbw", 1, "npz"), "this is not a zip archive\n");
  writeText((fs::path(at(root, "001", "img", 0, "png")).parent_path() / "README.txt").string(), "notes\n");

  camera.clear();
  for (uint64_t f = 0; f < kFrames002; ++f) {
    writeViperColorImage(at(root, "002", "img", f, "png"), colorImage(2, f));
    if (f == 1) writeText(at(root, "002", "cls", f, "png"), "not a picture\n");
    else writeViperClassImage(at(root, "002", "cls", f, "png"), classImage(2, f), {});
    camera.push_back({f, projection(), view(f)});
  }
  writeViperCameraCsv(viperCameraPath(root, "train", "002"), camera);
  std::cout << "make_viper_test_layout: wrote " << root << "\n";
  return 0;
}
