#include "viper/dataset/viper_submission.h"

#include "viper/dataset/middlebury_flo.h"

#include "../formats/deflate_writers.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <stdexcept>
#include <tuple>

namespace viper::dataset {
namespace {

std::string joinPath(const std::string& dir, const std::string& file) {
  return (std::filesystem::path(dir) / file).string();
}

std::vector<uint8_t> textBytes(const std::string& text) { return std::vector<uint8_t>(text.begin(), text.end()); }

// Calls `parse` on every non-empty line of `path`; a line it refuses is an error naming the file,
// the line and `format`.
void parseLines(const std::string& path, const char* format, const std::function<bool(const std::string&)>& parse) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n)
    if (!line.empty() && !parse(line))
      throw std::runtime_error(path + ":" + std::to_string(n) + ": '" + line + "' is not '" + format + "'");
}

bool parseRow(const std::string& line, SubmissionInstanceRow& row) {
  unsigned long long frame = 0;
  int consumed = 0;
  if (std::sscanf(line.c_str(), " %d , %llu , %d , %d , %lf %n", &row.sequence_id, &frame, &row.class_id,
                  &row.instance_id, &row.confidence, &consumed) != 5 ||
      static_cast<size_t>(consumed) != line.size())
    return false;
  row.frame = frame;
  return true;
}

}  // namespace

std::string submissionFrameName(int sequence_id, uint64_t frame) {
  if (sequence_id < 0 || sequence_id > 999)
    throw std::invalid_argument("submission: sequence id " + std::to_string(sequence_id) +
                                " is not in 0..999 (VIPER names it with 3 digits)");
  if (frame > 99999)
    throw std::invalid_argument("submission: frame " + std::to_string(frame) +
                                " is above 99999 (VIPER names it with 5 digits)");
  char name[16];
  std::snprintf(name, sizeof name, "%03d_%05llu", sequence_id, static_cast<unsigned long long>(frame));
  return name;
}

std::string writeSubmissionSemantic(const std::string& dir, int sequence_id, uint64_t frame, const Image8& class_ids) {
  if (class_ids.channels != 1)
    throw std::invalid_argument("submission: a semantic prediction has 1 channel of class ids, not " +
                                std::to_string(class_ids.channels));
  const std::string path = joinPath(dir, submissionFrameName(sequence_id, frame) + ".png");
  writeViperClassImage(path, class_ids, ClassPalette());
  return path;
}

std::vector<SubmissionInstanceRow> writeSubmissionInstances(const std::string& dir, int sequence_id, uint64_t frame,
                                                            const std::vector<SubmissionInstance>& instances) {
  const std::string name = submissionFrameName(sequence_id, frame);
  for (size_t i = 0; i < instances.size(); ++i) {
    const SubmissionInstance& p = instances[i];
    const Image8& first = instances.front().mask;
    if (p.mask.channels != 1 || p.mask.width != first.width || p.mask.height != first.height)
      throw std::invalid_argument("submission " + name + ": instance " + std::to_string(i) + " has a " +
                                  std::to_string(p.mask.width) + "x" + std::to_string(p.mask.height) + "x" +
                                  std::to_string(p.mask.channels) + " mask; every mask is 1 channel of the frame's size");
    if (!(p.confidence >= 0.0 && p.confidence <= 1.0))
      throw std::invalid_argument("submission " + name + ": instance " + std::to_string(i) + " has confidence " +
                                  std::to_string(p.confidence) + ", which VIPER wants in [0, 1]");
  }
  std::map<int, int> per_class;
  std::vector<SubmissionInstanceRow> rows;
  Image8 binary;
  for (const SubmissionInstance& p : instances) {
    SubmissionInstanceRow row{sequence_id, frame, p.class_id, ++per_class[p.class_id], p.confidence};
    binary = p.mask;
    for (uint8_t& v : binary.data) v = v != 0 ? 255 : 0;
    writeViperClassImage(joinPath(dir, name + "_" + std::to_string(row.class_id) + "_" +
                                            std::to_string(row.instance_id) + ".png"),
                         binary, ClassPalette());
    rows.push_back(row);
  }
  return rows;
}

std::vector<SubmissionInstanceRow> readInstancesCsv(const std::string& path) {
  std::vector<SubmissionInstanceRow> rows;
  parseLines(path, "sequence,frame,class,instance,confidence",
             [&rows](const std::string& line) { return parseRow(line, rows.emplace_back()); });
  return rows;
}

void writeInstancesCsv(const std::string& dir, int sequence_id, const std::vector<SubmissionInstanceRow>& rows) {
  const std::string path = joinPath(dir, "instances.csv");
  std::vector<SubmissionInstanceRow> all;
  if (std::filesystem::exists(path))
    for (const SubmissionInstanceRow& r : readInstancesCsv(path))
      if (r.sequence_id != sequence_id) all.push_back(r);
  all.insert(all.end(), rows.begin(), rows.end());
  std::sort(all.begin(), all.end(), [](const SubmissionInstanceRow& a, const SubmissionInstanceRow& b) {
    return std::tie(a.sequence_id, a.frame, a.class_id, a.instance_id) <
           std::tie(b.sequence_id, b.frame, b.class_id, b.instance_id);
  });
  std::string text;
  char line[96];
  for (const SubmissionInstanceRow& r : all) {
    std::snprintf(line, sizeof line, "%d,%llu,%d,%d,%.9g\n", r.sequence_id, static_cast<unsigned long long>(r.frame),
                  r.class_id, r.instance_id, r.confidence);
    text += line;
  }
  detail::writeFileAtomically(path, textBytes(text), "instances.csv");
}

std::string writeSubmissionFlow(const std::string& dir, int sequence_id, uint64_t frame, const FlowImage& flow) {
  const std::string path = joinPath(dir, submissionFrameName(sequence_id, frame) + ".flo");
  writeMiddleburyFlo(path, flow);
  return path;
}

std::string writeSubmissionOdometry(const std::string& dir, int sequence_id, const std::vector<SubmissionPose>& poses) {
  const std::string path = joinPath(dir, submissionFrameName(sequence_id, 0).substr(0, 3) + ".txt");
  std::string text;
  char line[256];
  for (const SubmissionPose& p : poses) {
    const Eigen::Quaterniond& q = p.orientation;
    std::snprintf(line, sizeof line, "%.4f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", p.timestamp_s, p.position.x(),
                  p.position.y(), p.position.z(), q.x(), q.y(), q.z(), q.w());
    text += line;
  }
  detail::writeFileAtomically(path, textBytes(text), "odometry");
  return path;
}

std::vector<SubmissionPose> readSubmissionOdometry(const std::string& path) {
  std::vector<SubmissionPose> poses;
  parseLines(path, "timestamp,tx,ty,tz,qx,qy,qz,qw", [&poses](const std::string& line) {
    double v[8];
    int consumed = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf%n", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6],
                    &v[7], &consumed) != 8 ||
        static_cast<size_t>(consumed) != line.size())
      return false;
    SubmissionPose& p = poses.emplace_back();
    p.timestamp_s = v[0];
    p.position = Eigen::Vector3d(v[1], v[2], v[3]);
    p.orientation = Eigen::Quaterniond(v[7], v[4], v[5], v[6]);
    return true;
  });
  return poses;
}

}  // namespace viper::dataset
