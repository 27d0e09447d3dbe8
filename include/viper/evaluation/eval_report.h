// The evaluation report as text: Markdown and CSV tables per condition and over all, and the
// running scores as YAML. Layout of every file: docs/evaluate.md.
#pragma once

#include "viper/evaluation/evaluation.h"

#include <string>
#include <vector>

namespace viper {

/// A number as CSV and YAML carry it: the shortest text that reads back as the same double
/// ("66.66666666666667", "100", "0.5"); NaN as "" (CSV) or ".nan" (YAML, see scoresYaml).
std::string csvNumber(double v);

/// `summary.md`: every metric that has data, a table per metric with one column (or row) per
/// condition and one for all. Percentages with 2 decimals, endpoint errors with 3, rotation
/// errors with 4; "-" where there is nothing to score.
std::string reportMarkdown(const EvaluationSummary& s);

/// `summary.csv`: one row per condition and one "all" row, one column per headline number.
std::string summaryCsv(const EvaluationSummary& s);
/// `semantic_iou.csv`: condition,class_id,class_name,iou_percent for every scored class present,
/// then a "mean" row (class_id -1) per condition.
std::string semanticIouCsv(const EvaluationSummary& s);
/// `instance_ap.csv`: condition,class_id,class_name,ap_percent,ap50_percent likewise.
std::string instanceApCsv(const EvaluationSummary& s);
/// `flow.csv`: condition,input,region,frames,pixels,invalid,wauc,epe_px,outlier_percent with input
/// dense/sparse and region all/noc.
std::string flowCsv(const EvaluationSummary& s);
/// `flow_inliers.csv`: threshold_px, then one column per condition, input and region
/// ("day/dense/all"): the percentage of pixels with endpoint error <= the threshold.
std::string flowInliersCsv(const EvaluationSummary& s);
/// `odometry.csv`: condition,length_m,segments,translation_percent,rotation_deg_per_m; one row per
/// segment length, then a row with length_m "all".
std::string odometryCsv(const EvaluationSummary& s);

/// `<key>.csv` of a metric that reports through MetricScores (MetricLayout): condition,class_id,
/// class_name,<per-class key> for every listed class with a score, then a "mean" row (class_id -1)
/// with its headline numbers, per condition that it scored.
std::string metricCsv(const EvaluationSummary& s, const MetricLayout& layout);

/// The running scores (headline numbers per condition and over all) as a YAML document.
std::string scoresYaml(const EvaluationSummary& s);

/// Writes summary.md and every CSV above into `dir` (created if missing; a metric's own CSV only if
/// it scored a frame). Returns the paths
/// written. Throws std::runtime_error naming the file that could not be written.
std::vector<std::string> writeReportTables(const EvaluationSummary& s, const std::string& dir);

}  // namespace viper
