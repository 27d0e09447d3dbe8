#include "viper/evaluation/eval_report.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace viper {
namespace {

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string yamlKey(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string yamlNumber(double v) {
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  return csvNumber(v);
}

// Every column of a report: each condition, then all.
std::vector<const ConditionSummary*> columns(const EvaluationSummary& s) {
  std::vector<const ConditionSummary*> c;
  for (const ConditionSummary& cs : s.conditions) c.push_back(&cs);
  c.push_back(&s.all);
  return c;
}

struct FlowRow {
  const char* input;
  const char* region;
  const FlowSummary ConditionSummary::*member;
};
const FlowRow kFlowRows[] = {{"dense", "all", &ConditionSummary::flow_all},
                             {"dense", "noc", &ConditionSummary::flow_noc},
                             {"sparse", "all", &ConditionSummary::sparse_all},
                             {"sparse", "noc", &ConditionSummary::sparse_noc}};

std::string markdownRow(const std::vector<std::string>& cells) {
  std::string row = "|";
  for (const std::string& c : cells) row += " " + c + " |";
  return row + "\n";
}

std::string markdownHeader(const std::vector<std::string>& cells, size_t left_aligned) {
  std::string rule = "|";
  for (size_t i = 0; i < cells.size(); ++i) rule += i < left_aligned ? "---|" : "---:|";
  return markdownRow(cells) + rule + "\n";
}

// A per-class table: one row per class scored anywhere, then the mean.
std::string classTable(const EvaluationSummary& s, const std::vector<bool>& evaluated,
                       const std::vector<double> ConditionSummary::*per_class, double ConditionSummary::*mean) {
  const auto cols = columns(s);
  std::vector<std::string> header = {"class"};
  for (const ConditionSummary* c : cols) header.push_back(c->condition);
  std::string out = markdownHeader(header, 1);
  for (size_t k = 0; k < s.class_names.size(); ++k) {
    if (k >= evaluated.size() || !evaluated[k]) continue;
    bool any = false;
    std::vector<std::string> row = {s.class_names[k]};
    for (const ConditionSummary* c : cols) {
      const double v = k < (c->*per_class).size() ? (c->*per_class)[k] : NAN;
      any = any || std::isfinite(v);
      row.push_back(fixed(v, 2));
    }
    if (any) out += markdownRow(row);
  }
  std::vector<std::string> row = {"**mean**"};
  for (const ConditionSummary* c : cols) row.push_back("**" + fixed(c->*mean, 2) + "**");
  return out + markdownRow(row);
}

std::string classCsv(const EvaluationSummary& s, const std::vector<bool>& evaluated, const std::string& header,
                     const std::vector<const std::vector<double> ConditionSummary::*>& per_class,
                     const std::vector<double ConditionSummary::*>& means, uint64_t ConditionSummary::*frames) {
  std::string out = header + "\n";
  for (const ConditionSummary* c : columns(s)) {
    if (c->*frames == 0) continue;
    for (size_t k = 0; k < s.class_names.size(); ++k) {
      if (k >= evaluated.size() || !evaluated[k]) continue;
      bool any = false;
      std::string values;
      for (const auto member : per_class) {
        const double v = k < (c->*member).size() ? (c->*member)[k] : NAN;
        any = any || std::isfinite(v);
        values += "," + csvNumber(v);
      }
      if (any) out += csvField(c->condition) + "," + std::to_string(k) + "," + csvField(s.class_names[k]) + values + "\n";
    }
    out += csvField(c->condition) + ",-1,mean";
    for (const auto member : means) out += "," + csvNumber(c->*member);
    out += "\n";
  }
  return out;
}

// The metrics reporting through MetricScores that scored a frame.
std::vector<const MetricLayout*> scoredPlugins(const EvaluationSummary& s) {
  std::vector<const MetricLayout*> out;
  for (const MetricLayout& m : s.layouts)
    if (s.all.scoresOf(m.key).frames > 0) out.push_back(&m);
  return out;
}

double headlineValue(const ConditionSummary& c, const MetricLayout& m, const ReportColumn& col) {
  const MetricScores& scores = c.scoresOf(m.key);
  const auto it = scores.values.find(col.key);
  return it == scores.values.end() ? NAN : it->second;
}

double classValue(const ConditionSummary& c, const MetricLayout& m, size_t k) {
  const std::vector<double>& v = c.scoresOf(m.key).per_class;
  return k < v.size() ? v[k] : NAN;
}

// A metric's section: its per-class table (one row per class scored anywhere, then the mean).
std::string pluginMarkdown(const EvaluationSummary& s, const MetricLayout& m) {
  std::string out = "## " + m.title + "\n\n";
  if (!m.note.empty()) out += m.note + "\n\n";
  if (m.per_class.key.empty() || m.headline.empty()) return out;
  const auto cols = columns(s);
  std::vector<std::string> header = {"class"};
  for (const ConditionSummary* c : cols) header.push_back(c->condition);
  out += markdownHeader(header, 1);
  for (size_t k = 0; k < s.class_names.size(); ++k) {
    if (k >= m.classes.size() || !m.classes[k]) continue;
    bool any = false;
    std::vector<std::string> row = {s.class_names[k]};
    for (const ConditionSummary* c : cols) {
      const double v = classValue(*c, m, k);
      any = any || std::isfinite(v);
      row.push_back(fixed(v, m.per_class.decimals));
    }
    if (any) out += markdownRow(row);
  }
  std::vector<std::string> row = {"**mean**"};
  for (const ConditionSummary* c : cols)
    row.push_back("**" + fixed(headlineValue(*c, m, m.headline[0]), m.headline[0].decimals) + "**");
  return out + markdownRow(row);
}

void writeFile(const std::filesystem::path& path, const std::string& text, std::vector<std::string>& written) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw std::runtime_error(path.string() + ": cannot open for writing");
  f << text;
  f.close();
  if (!f) throw std::runtime_error(path.string() + ": write failed");
  written.push_back(path.string());
}

}  // namespace

std::string csvNumber(double v) {
  if (std::isnan(v)) return "";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

std::string reportMarkdown(const EvaluationSummary& s) {
  const ConditionSummary& all = s.all;
  const bool semantic = all.semantic_frames > 0, instances = all.instance_frames > 0,
             dense = all.flow_all.present(), sparse = all.sparse_all.present(), odometry = all.odometry_poses > 0;
  const std::vector<const MetricLayout*> plugins = scoredPlugins(s);
  std::ostringstream md;
  md << "# Evaluation report\n\n";
  md << "Frames scored: semantic " << all.semantic_frames << ", instances " << all.instance_frames
     << ", dense flow " << all.flow_all.frames << ", sparse flow " << all.sparse_all.frames << ", odometry poses "
     << all.odometry_poses << ".\n\n";
  if (!(semantic || instances || dense || sparse || odometry || !plugins.empty())) {
    md << "Nothing was scored: no prediction topic delivered a frame that met its ground truth.\n";
    return md.str();
  }

  md << "## Summary\n\n";
  std::vector<std::string> header = {"condition"};
  if (semantic) header.push_back("mIoU %");
  if (instances) header.insert(header.end(), {"AP %", "AP50 %"});
  if (dense) header.insert(header.end(), {"flow EPE px", "flow WAUC %", "flow Fl %"});
  if (sparse) header.insert(header.end(), {"sparse EPE px", "sparse WAUC %"});
  if (odometry) header.insert(header.end(), {"VO translation %", "VO rotation deg/m"});
  for (const MetricLayout* m : plugins)
    for (const ReportColumn& col : m->headline) header.push_back(col.label);
  md << markdownHeader(header, 1);
  for (const ConditionSummary* c : columns(s)) {
    const bool is_all = c == &s.all;
    std::vector<std::string> row = {is_all ? "**all**" : c->condition};
    if (semantic) row.push_back(fixed(c->mean_iou, 2));
    if (instances) row.insert(row.end(), {fixed(c->ap, 2), fixed(c->ap50, 2)});
    if (dense) row.insert(row.end(), {fixed(c->flow_all.epe_px, 3), fixed(c->flow_all.wauc, 2),
                                      fixed(c->flow_all.outlier_percent, 2)});
    if (sparse) row.insert(row.end(), {fixed(c->sparse_all.epe_px, 3), fixed(c->sparse_all.wauc, 2)});
    if (odometry) row.insert(row.end(), {fixed(c->odometry.translation_percent, 2),
                                         fixed(c->odometry.rotation_deg_per_m, 4)});
    for (const MetricLayout* m : plugins)
      for (const ReportColumn& col : m->headline) row.push_back(fixed(headlineValue(*c, *m, col), col.decimals));
    md << markdownRow(row);
  }
  md << "\n";

  if (semantic) {
    md << "## Semantic segmentation: IoU % per class\n\n";
    md << classTable(s, s.semantic_eval, &ConditionSummary::iou, &ConditionSummary::mean_iou) << "\n";
  }
  if (instances) {
    md << "## Instance segmentation: AP % per class (IoU 0.50:0.05:0.95, Cityscapes)\n\n";
    md << classTable(s, s.instance_eval, &ConditionSummary::class_ap, &ConditionSummary::ap) << "\n";
    md << "## Instance segmentation: AP50 % per class\n\n";
    md << classTable(s, s.instance_eval, &ConditionSummary::class_ap50, &ConditionSummary::ap50) << "\n";
  }
  if (dense || sparse) {
    md << "## Optical flow\n\n";
    md << "`all`: every pixel with ground-truth flow; `noc`: those visible in the next frame. Fl: endpoint error "
          "> 3 px and > 5 % of the true motion (KITTI). Sparse: one pixel per flow vector.\n\n";
    md << markdownHeader({"condition", "input", "region", "frames", "pixels", "WAUC %", "EPE px", "Fl %",
                          "invalid"},
                         3);
    for (const ConditionSummary* c : columns(s))
      for (const FlowRow& r : kFlowRows) {
        const FlowSummary& f = c->*(r.member);
        if (!f.present()) continue;
        md << markdownRow({c == &s.all ? "**all**" : c->condition, r.input, r.region, std::to_string(f.frames),
                           std::to_string(f.pixels), fixed(f.wauc, 2), fixed(f.epe_px, 3),
                           fixed(f.outlier_percent, 2), std::to_string(f.invalid)});
      }
    md << "\n![flow inlier rate over threshold](flow_inliers.png)\n\n";
  }
  if (odometry) {
    md << "## Visual odometry (KITTI)\n\n";
    md << markdownHeader({"condition", "poses", "sequences", "path m", "segments", "translation %",
                          "rotation deg/m"},
                         1);
    for (const ConditionSummary* c : columns(s)) {
      if (c->odometry_poses == 0) continue;
      md << markdownRow({c == &s.all ? "**all**" : c->condition, std::to_string(c->odometry_poses),
                         std::to_string(c->odometry_sequences), fixed(c->odometry_path_m, 1),
                         std::to_string(c->odometry.segments), fixed(c->odometry.translation_percent, 2),
                         fixed(c->odometry.rotation_deg_per_m, 4)});
    }
    md << "\n### By segment length\n\n";
    md << markdownHeader({"condition", "length m", "segments", "translation %", "rotation deg/m"}, 1);
    for (const ConditionSummary* c : columns(s)) {
      const OdometryScores& o = c->odometry;
      for (size_t i = 0; i < o.lengths_m.size(); ++i) {
        if (o.segments_per_length[i] == 0) continue;
        md << markdownRow({c == &s.all ? "**all**" : c->condition, csvNumber(o.lengths_m[i]),
                           std::to_string(o.segments_per_length[i]), fixed(o.translation_percent_by_length[i], 2),
                           fixed(o.rotation_deg_per_m_by_length[i], 4)});
      }
    }
    if (all.odometry.segments == 0)
      md << "\nNo segment: the ground-truth path (" << fixed(all.odometry_path_m, 1)
         << " m) is shorter than the shortest segment length.\n";
    md << "\n![VO error over segment length](odometry_errors.png)\n";
  }
  for (const MetricLayout* m : plugins) md << "\n" << pluginMarkdown(s, *m);
  return md.str();
}

std::string summaryCsv(const EvaluationSummary& s) {
  std::string out =
      "condition,semantic_frames,mean_iou,instance_frames,ap,ap50,"
      "flow_frames,flow_wauc,flow_epe_px,flow_outlier_percent,flow_noc_wauc,flow_noc_epe_px,flow_noc_outlier_percent,"
      "sparse_frames,sparse_vectors,sparse_wauc,sparse_epe_px,sparse_outlier_percent,"
      "sparse_noc_wauc,sparse_noc_epe_px,sparse_noc_outlier_percent,"
      "odometry_poses,odometry_path_m,odometry_segments,odometry_translation_percent,odometry_rotation_deg_per_m\n";
  auto n = [](double v) { return "," + csvNumber(v); };
  auto u = [](uint64_t v) { return "," + std::to_string(v); };
  for (const ConditionSummary* c : columns(s)) {
    out += csvField(c->condition) + u(c->semantic_frames) + n(c->mean_iou) + u(c->instance_frames) + n(c->ap) +
           n(c->ap50) + u(c->flow_all.frames) + n(c->flow_all.wauc) + n(c->flow_all.epe_px) +
           n(c->flow_all.outlier_percent) + n(c->flow_noc.wauc) + n(c->flow_noc.epe_px) +
           n(c->flow_noc.outlier_percent) + u(c->sparse_all.frames) + u(c->sparse_vectors) + n(c->sparse_all.wauc) +
           n(c->sparse_all.epe_px) + n(c->sparse_all.outlier_percent) + n(c->sparse_noc.wauc) +
           n(c->sparse_noc.epe_px) + n(c->sparse_noc.outlier_percent) + u(c->odometry_poses) +
           n(c->odometry_path_m) + u(c->odometry.segments) + n(c->odometry.translation_percent) +
           n(c->odometry.rotation_deg_per_m) + "\n";
  }
  return out;
}

std::string semanticIouCsv(const EvaluationSummary& s) {
  return classCsv(s, s.semantic_eval, "condition,class_id,class_name,iou_percent", {&ConditionSummary::iou},
                  {&ConditionSummary::mean_iou}, &ConditionSummary::semantic_frames);
}

std::string instanceApCsv(const EvaluationSummary& s) {
  return classCsv(s, s.instance_eval, "condition,class_id,class_name,ap_percent,ap50_percent",
                  {&ConditionSummary::class_ap, &ConditionSummary::class_ap50},
                  {&ConditionSummary::ap, &ConditionSummary::ap50}, &ConditionSummary::instance_frames);
}

std::string flowCsv(const EvaluationSummary& s) {
  std::string out = "condition,input,region,frames,pixels,invalid,wauc,epe_px,outlier_percent\n";
  for (const ConditionSummary* c : columns(s))
    for (const FlowRow& r : kFlowRows) {
      const FlowSummary& f = c->*(r.member);
      if (!f.present()) continue;
      out += csvField(c->condition) + "," + r.input + "," + r.region + "," + std::to_string(f.frames) + "," +
             std::to_string(f.pixels) + "," + std::to_string(f.invalid) + "," + csvNumber(f.wauc) + "," +
             csvNumber(f.epe_px) + "," + csvNumber(f.outlier_percent) + "\n";
    }
  return out;
}

std::string flowInliersCsv(const EvaluationSummary& s) {
  std::vector<const FlowSummary*> series;
  std::string out = "threshold_px";
  for (const ConditionSummary* c : columns(s))
    for (const FlowRow& r : kFlowRows) {
      const FlowSummary& f = c->*(r.member);
      if (!f.present()) continue;
      series.push_back(&f);
      out += "," + csvField(c->condition + "/" + r.input + "/" + r.region);
    }
  out += "\n";
  for (size_t i = 0; i < s.curve_thresholds_px.size(); ++i) {
    out += csvNumber(s.curve_thresholds_px[i]);
    for (const FlowSummary* f : series) out += "," + csvNumber(i < f->inlier_percent.size() ? f->inlier_percent[i] : NAN);
    out += "\n";
  }
  return out;
}

std::string odometryCsv(const EvaluationSummary& s) {
  std::string out = "condition,length_m,segments,translation_percent,rotation_deg_per_m\n";
  for (const ConditionSummary* c : columns(s)) {
    if (c->odometry_poses == 0) continue;
    const OdometryScores& o = c->odometry;
    for (size_t i = 0; i < o.lengths_m.size(); ++i)
      out += csvField(c->condition) + "," + csvNumber(o.lengths_m[i]) + "," + std::to_string(o.segments_per_length[i]) +
             "," + csvNumber(o.translation_percent_by_length[i]) + "," + csvNumber(o.rotation_deg_per_m_by_length[i]) +
             "\n";
    out += csvField(c->condition) + ",all," + std::to_string(o.segments) + "," + csvNumber(o.translation_percent) +
           "," + csvNumber(o.rotation_deg_per_m) + "\n";
  }
  return out;
}

std::string metricCsv(const EvaluationSummary& s, const MetricLayout& m) {
  std::string out = "condition,class_id,class_name," + m.per_class.key + "\n";
  for (const ConditionSummary* c : columns(s)) {
    if (c->scoresOf(m.key).frames == 0) continue;
    for (size_t k = 0; k < s.class_names.size(); ++k) {
      const double v = k < m.classes.size() && m.classes[k] ? classValue(*c, m, k) : NAN;
      if (std::isfinite(v))
        out += csvField(c->condition) + "," + std::to_string(k) + "," + csvField(s.class_names[k]) + "," +
               csvNumber(v) + "\n";
    }
    out += csvField(c->condition) + ",-1,mean";
    for (const ReportColumn& col : m.headline) out += "," + csvNumber(headlineValue(*c, m, col));
    out += "\n";
  }
  return out;
}

std::string scoresYaml(const EvaluationSummary& s) {
  std::ostringstream y;
  auto block = [&](const ConditionSummary& c, const std::string& indent) {
    if (c.semantic_frames > 0)
      y << indent << "semantic: {frames: " << c.semantic_frames << ", mean_iou: " << yamlNumber(c.mean_iou) << "}\n";
    if (c.instance_frames > 0)
      y << indent << "instances: {frames: " << c.instance_frames << ", ap: " << yamlNumber(c.ap)
        << ", ap50: " << yamlNumber(c.ap50) << "}\n";
    for (const auto& [key, all, noc] : {std::tuple<const char*, const FlowSummary*, const FlowSummary*>{
                                            "flow", &c.flow_all, &c.flow_noc},
                                        {"flow_sparse", &c.sparse_all, &c.sparse_noc}}) {
      if (!all->present()) continue;
      y << indent << key << ": {frames: " << all->frames << ", pixels: " << all->pixels
        << ", wauc: " << yamlNumber(all->wauc) << ", epe_px: " << yamlNumber(all->epe_px)
        << ", outlier_percent: " << yamlNumber(all->outlier_percent) << ", noc_wauc: " << yamlNumber(noc->wauc)
        << ", noc_epe_px: " << yamlNumber(noc->epe_px) << ", noc_outlier_percent: "
        << yamlNumber(noc->outlier_percent) << "}\n";
    }
    if (c.odometry_poses > 0)
      y << indent << "odometry: {poses: " << c.odometry_poses << ", path_m: " << yamlNumber(c.odometry_path_m)
        << ", segments: " << c.odometry.segments << ", translation_percent: "
        << yamlNumber(c.odometry.translation_percent)
        << ", rotation_deg_per_m: " << yamlNumber(c.odometry.rotation_deg_per_m) << "}\n";
    for (const MetricLayout& m : s.layouts) {
      const MetricScores& scores = c.scoresOf(m.key);
      if (scores.frames == 0) continue;
      y << indent << m.key << ": {frames: " << scores.frames;
      for (const ReportColumn& col : m.headline) y << ", " << col.key << ": " << yamlNumber(headlineValue(c, m, col));
      y << "}\n";
    }
  };
  y << "all:\n";
  block(s.all, "  ");
  y << "conditions:" << (s.conditions.empty() ? " {}" : "") << "\n";
  for (const ConditionSummary& c : s.conditions) {
    y << "  " << yamlKey(c.condition) << ":\n";
    block(c, "    ");
  }
  return y.str();
}

std::vector<std::string> writeReportTables(const EvaluationSummary& s, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create the report folder: " + ec.message());
  const std::filesystem::path d(dir);
  std::vector<std::string> written;
  writeFile(d / "summary.md", reportMarkdown(s), written);
  writeFile(d / "summary.csv", summaryCsv(s), written);
  writeFile(d / "semantic_iou.csv", semanticIouCsv(s), written);
  writeFile(d / "instance_ap.csv", instanceApCsv(s), written);
  writeFile(d / "flow.csv", flowCsv(s), written);
  writeFile(d / "flow_inliers.csv", flowInliersCsv(s), written);
  writeFile(d / "odometry.csv", odometryCsv(s), written);
  // A metric's own table is written when it scored something; otherwise one of an earlier report
  // is removed.
  for (const MetricLayout& m : s.layouts) {
    if (m.per_class.key.empty()) continue;
    const std::filesystem::path path = d / (m.key + ".csv");
    std::error_code ec;
    if (s.all.scoresOf(m.key).frames > 0) writeFile(path, metricCsv(s, m), written);
    else std::filesystem::remove(path, ec);
  }
  return written;
}

}  // namespace viper
