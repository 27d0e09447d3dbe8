#include "viper/dataset/viper_sequence.h"

#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_layout.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace viper::dataset {
namespace fs = std::filesystem;
namespace {

// Lists at most this many frame numbers in one message.
constexpr size_t kListedFrames = 10;

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool extensionFits(ViperModality m, const std::string& ext) {
  switch (m) {
    case ViperModality::kImg: return ext == "png" || ext == "jpg" || ext == "jpeg";
    case ViperModality::kCls:
    case ViperModality::kInst: return ext == "png";
    case ViperModality::kFlow:
    case ViperModality::kFlowBw: return ext == "npz";
    case ViperModality::kBb: return ext == "csv";
  }
  return false;
}

std::string listFrames(const std::vector<uint64_t>& frames) {
  std::string s;
  for (size_t i = 0; i < frames.size() && i < kListedFrames; ++i) s += (i ? ", " : "") + std::to_string(frames[i]);
  if (frames.size() > kListedFrames) s += " and " + std::to_string(frames.size() - kListedFrames) + " more";
  return s;
}

std::string sizeText(uint32_t w, uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

const std::vector<ViperModality>& allViperModalities() {
  static const std::vector<ViperModality> all = {ViperModality::kImg,  ViperModality::kCls,    ViperModality::kInst,
                                                 ViperModality::kFlow, ViperModality::kFlowBw, ViperModality::kBb};
  return all;
}

const char* viperModalityName(ViperModality m) {
  switch (m) {
    case ViperModality::kImg: return "img";
    case ViperModality::kCls: return "cls";
    case ViperModality::kInst: return "inst";
    case ViperModality::kFlow: return "flow";
    case ViperModality::kFlowBw: return "flowbw";
    case ViperModality::kBb: return "bb";
  }
  return "?";
}

std::optional<ViperModality> viperModalityFromName(const std::string& name) {
  for (ViperModality m : allViperModalities())
    if (name == viperModalityName(m)) return m;
  return std::nullopt;
}

std::vector<std::string> listViperSplits(const std::string& root) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw std::runtime_error(root + ": not a folder (expected a VIPER layout root)");
  std::vector<std::string> splits;
  for (const auto& entry : fs::directory_iterator(root, ec)) {
    if (!entry.is_directory(ec)) continue;
    bool is_split = fs::is_directory(entry.path() / "camera", ec);
    for (ViperModality m : allViperModalities()) is_split = is_split || fs::is_directory(entry.path() / viperModalityName(m), ec);
    if (is_split) splits.push_back(entry.path().filename().string());
  }
  std::sort(splits.begin(), splits.end());
  return splits;
}

std::vector<std::string> listViperSequences(const std::string& root, const std::string& split) {
  std::set<std::string> seqs;
  std::error_code ec;
  const fs::path base = fs::path(root) / split;
  for (ViperModality m : allViperModalities()) {
    const fs::path dir = base / viperModalityName(m);
    if (!fs::is_directory(dir, ec)) continue;
    for (const auto& entry : fs::directory_iterator(dir, ec))
      if (entry.is_directory(ec)) seqs.insert(entry.path().filename().string());
  }
  const fs::path camera = base / "camera";
  if (fs::is_directory(camera, ec))
    for (const auto& entry : fs::directory_iterator(camera, ec))
      if (entry.is_regular_file(ec) && lower(entry.path().extension().string()) == ".csv")
        seqs.insert(entry.path().stem().string());
  return std::vector<std::string>(seqs.begin(), seqs.end());
}

ViperSequenceFiles scanViperSequence(const std::string& root, const std::string& split, const std::string& seq) {
  ViperSequenceFiles out;
  out.root = root, out.split = split, out.seq = seq;
  std::error_code ec;
  const fs::path base = fs::path(root) / split;
  for (ViperModality m : allViperModalities()) {
    const fs::path dir = base / viperModalityName(m) / seq;
    if (!fs::is_directory(dir, ec)) continue;
    std::vector<fs::path> entries;
    for (const auto& entry : fs::directory_iterator(dir, ec)) entries.push_back(entry.path());
    std::sort(entries.begin(), entries.end());
    auto& frames = out.files[m];
    for (const fs::path& p : entries) {
      const std::string name = p.filename().string();
      if (name.find(".tmp") != std::string::npos) continue;  // a writer's temporary file
      if (!fs::is_regular_file(p, ec)) {
        out.problems.push_back(p.string() + ": not a file; ignored");
        continue;
      }
      const auto parsed = parseViperFrameName(name);
      if (!parsed) {
        out.problems.push_back(p.string() + ": name is not <seq>_<frame>.<ext>; ignored");
        continue;
      }
      if (parsed->seq != seq) {
        out.problems.push_back(p.string() + ": belongs to sequence '" + parsed->seq + "', not '" + seq + "'; ignored");
        continue;
      }
      const std::string ext = lower(parsed->extension);
      if (!extensionFits(m, ext)) {
        out.problems.push_back(p.string() + ": extension '." + parsed->extension + "' is not one of " +
                               viperModalityName(m) + "'s; ignored");
        continue;
      }
      auto existing = frames.find(parsed->frame);
      if (existing != frames.end()) {
        // Both a lossless and a lossy copy of an image: the PNG wins.
        const bool new_is_png = ext == "png";
        const std::string& kept = new_is_png ? p.string() : existing->second;
        const std::string& dropped = new_is_png ? existing->second : p.string();
        out.problems.push_back(dropped + ": frame " + std::to_string(parsed->frame) + " also in " + kept + "; ignored");
        existing->second = kept;
        continue;
      }
      frames[parsed->frame] = p.string();
    }
  }
  const fs::path camera = fs::path(viperCameraPath(root, split, seq));
  if (fs::exists(camera, ec)) out.camera_csv = camera.string();
  return out;
}

std::vector<uint64_t> viperSequenceFrames(const ViperSequenceFiles& files,
                                          const std::map<uint64_t, ViperCameraRow>& camera) {
  std::set<uint64_t> frames;
  for (const auto& [m, by_frame] : files.files)
    for (const auto& [f, path] : by_frame) frames.insert(f);
  for (const auto& [f, row] : camera) frames.insert(f);
  return std::vector<uint64_t>(frames.begin(), frames.end());
}

std::vector<std::string> describeMissingFrames(const ViperSequenceFiles& files,
                                               const std::map<uint64_t, ViperCameraRow>& camera,
                                               const std::vector<uint64_t>& frames) {
  std::vector<std::string> out;
  if (frames.empty()) return out;
  const std::string where = (fs::path(files.root) / files.split).string() + ": sequence " + files.seq;
  std::vector<uint64_t> gaps;
  for (size_t i = 1; i < frames.size(); ++i)
    for (uint64_t f = frames[i - 1] + 1; f < frames[i] && gaps.size() <= kListedFrames; ++f) gaps.push_back(f);
  if (!gaps.empty()) out.push_back(where + ": frames " + listFrames(gaps) + " are missing from every modality");
  const uint64_t first = frames.front(), last = frames.back();
  for (ViperModality m : allViperModalities()) {
    if (!files.has(m)) continue;
    const auto& have = files.files.at(m);
    std::vector<uint64_t> lacking;
    for (uint64_t f : frames) {
      if (have.count(f)) continue;
      if ((m == ViperModality::kFlow && f == last) || (m == ViperModality::kFlowBw && f == first)) continue;
      lacking.push_back(f);
    }
    if (!lacking.empty())
      out.push_back((fs::path(files.root) / files.split / viperModalityName(m) / files.seq).string() +
                    ": no file for frames " + listFrames(lacking) + " (other modalities have them)");
  }
  if (!files.camera_csv.empty()) {
    std::vector<uint64_t> lacking;
    for (uint64_t f : frames)
      if (!camera.count(f)) lacking.push_back(f);
    if (!lacking.empty()) out.push_back(files.camera_csv + ": no row for frames " + listFrames(lacking));
  }
  return out;
}

ViperFrame readViperFrame(const ViperSequenceFiles& files, uint64_t frame,
                          const std::map<uint64_t, ViperCameraRow>& camera, const std::set<ViperModality>& wanted,
                          std::vector<std::string>& problems, uint32_t expected_width, uint32_t expected_height) {
  ViperFrame out;
  out.frame = frame;
  auto pathOf = [&](ViperModality m) -> const std::string* {
    if (!wanted.count(m)) return nullptr;
    const auto by_frame = files.files.find(m);
    if (by_frame == files.files.end()) return nullptr;
    const auto it = by_frame->second.find(frame);
    return it == by_frame->second.end() ? nullptr : &it->second;
  };
  auto attempt = [&](auto read) {
    try {
      read();
    } catch (const std::exception& e) {
      problems.push_back(std::string(e.what()) + "; left out");
    }
  };
  if (const std::string* p = pathOf(ViperModality::kImg)) attempt([&] { out.img = readViperColorImage(*p); });
  if (const std::string* p = pathOf(ViperModality::kCls)) attempt([&] { out.cls = readViperClassImage(*p); });
  if (const std::string* p = pathOf(ViperModality::kInst)) attempt([&] { out.inst = readViperInstanceImage(*p); });
  if (const std::string* p = pathOf(ViperModality::kFlow)) attempt([&] { out.flow = readViperFlow(*p); });
  if (const std::string* p = pathOf(ViperModality::kFlowBw)) attempt([&] { out.flowbw = readViperFlow(*p); });
  if (const std::string* p = pathOf(ViperModality::kBb))
    attempt([&] { out.boxes = readViperBoxesCsv(*p, problems); });
  const auto row = camera.find(frame);
  if (row != camera.end()) out.camera = row->second;

  // The frame's size: the one most of its images agree on.
  struct Sized {
    ViperModality modality;
    uint32_t w, h;
  };
  std::vector<Sized> sizes;
  if (out.img) sizes.push_back({ViperModality::kImg, out.img->width, out.img->height});
  if (out.cls) sizes.push_back({ViperModality::kCls, out.cls->width, out.cls->height});
  if (out.inst) sizes.push_back({ViperModality::kInst, out.inst->width, out.inst->height});
  if (out.flow) sizes.push_back({ViperModality::kFlow, out.flow->width, out.flow->height});
  if (out.flowbw) sizes.push_back({ViperModality::kFlowBw, out.flowbw->width, out.flowbw->height});
  if (sizes.empty()) return out;
  auto votes = [&](uint32_t w, uint32_t h) {
    return std::count_if(sizes.begin(), sizes.end(), [&](const Sized& s) { return s.w == w && s.h == h; });
  };
  uint32_t best_w = sizes.front().w, best_h = sizes.front().h;
  for (const Sized& s : sizes) {
    const auto v = votes(s.w, s.h), best = votes(best_w, best_h);
    const bool expected = s.w == expected_width && s.h == expected_height;
    if (v > best || (v == best && expected)) best_w = s.w, best_h = s.h;
  }
  out.width = best_w, out.height = best_h;
  std::string agreeing;
  for (const Sized& s : sizes)
    if (s.w == best_w && s.h == best_h) agreeing += std::string(agreeing.empty() ? "" : ", ") + viperModalityName(s.modality);
  for (const Sized& s : sizes) {
    if (s.w == best_w && s.h == best_h) continue;
    problems.push_back(*pathOf(s.modality) + ": size " + sizeText(s.w, s.h) + " differs from the frame's " +
                       sizeText(best_w, best_h) + " (" + agreeing + "); left out");
    switch (s.modality) {
      case ViperModality::kImg: out.img.reset(); break;
      case ViperModality::kCls: out.cls.reset(); break;
      case ViperModality::kInst: out.inst.reset(); break;
      case ViperModality::kFlow: out.flow.reset(); break;
      case ViperModality::kFlowBw: out.flowbw.reset(); break;
      case ViperModality::kBb: break;
    }
  }
  return out;
}

}  // namespace viper::dataset
