// The evaluation report as text: Markdown and CSV tables per condition and over all, and the
// running scores as YAML. Layout of every file: docs/evaluate.md.
#pragma once

#include "viper/evaluation/evaluation.h"
#include "viper/report/csv_number.h"

#include <string>
#include <vector>

namespace viper {


/// `summary.md`: the frames each metric scored, a summary table (one row per condition and one for
/// all; the columns of every metric that scored), then each scored metric's section
/// (MetricLayout::markdown). "-" where there is nothing to score.
std::string reportMarkdown(const EvaluationSummary& s);

/// `summary.csv`: one row per condition and one "all" row, every metric's MetricLayout::summary_csv
/// columns.
std::string summaryCsv(const EvaluationSummary& s);

/// The CSV file called `file` ("semantic_iou.csv", "flow_inliers.csv", ...) of a metric's layout
/// (a ReportTable or CurveFile; docs/evaluate.md has each file's columns). Throws
/// std::invalid_argument if no registered metric writes it.
std::string tableCsv(const EvaluationSummary& s, const std::string& file);

/// The running scores (headline numbers per condition and over all) as a YAML document.
std::string scoresYaml(const EvaluationSummary& s);

/// Writes summary.md, summary.csv and every metric's CSV files into `dir` (created if missing; a
/// table without ReportTable::always only if its metric scored a frame, else an earlier one is
/// removed). Returns the paths written. Throws std::runtime_error naming the file that could not be written.
std::vector<std::string> writeReportTables(const EvaluationSummary& s, const std::string& dir);

}  // namespace viper
