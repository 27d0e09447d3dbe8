#include "viper/evaluation/eval_report.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

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

// A number as a column shows it: Markdown with its decimals, CSV exactly; counts as whole numbers.
std::string number(double v, const ReportColumn& col, bool markdown) {
  if (col.decimals == ReportColumn::kCount)
    return std::isfinite(v) ? std::to_string(static_cast<uint64_t>(v)) : (markdown ? "-" : "");
  if (!markdown || col.decimals == ReportColumn::kShortest) return csvNumber(v);
  return fixed(v, col.decimals);
}

double rowValue(const ReportRow& row, const std::string& key) {
  const auto it = row.values.find(key);
  return it == row.values.end() ? NAN : it->second;
}

std::string cell(const ReportRow& row, const ReportColumn& col, bool markdown) {
  const auto text = row.text.find(col.key);
  if (text != row.text.end()) return markdown ? text->second : csvField(text->second);
  return number(rowValue(row, col.key), col, markdown);
}

bool scored(const EvaluationSummary& s, const MetricLayout& m) { return s.all.scoresOf(m.key).frames > 0; }

// The metrics sharing m's section and files: its group in registration order, or m alone.
std::vector<const MetricLayout*> groupOf(const EvaluationSummary& s, const MetricLayout& m) {
  if (m.group.empty()) return {&m};
  std::vector<const MetricLayout*> out;
  for (const MetricLayout& o : s.layouts)
    if (o.group == m.group) out.push_back(&o);
  return out;
}

bool leadsGroup(const EvaluationSummary& s, const MetricLayout& m) { return groupOf(s, m).front() == &m; }

bool groupScored(const EvaluationSummary& s, const MetricLayout& m) {
  for (const MetricLayout* g : groupOf(s, m))
    if (scored(s, *g)) return true;
  return false;
}

const ReportTable* tableNamed(const MetricLayout& m, const std::string& name) {
  for (const ReportTable& t : m.tables)
    if (t.name == name) return &t;
  return nullptr;
}

double classValue(const ConditionSummary& c, const MetricLayout& m, const std::string& key, size_t k) {
  const auto& per_class = c.scoresOf(m.key).per_class;
  const auto it = per_class.find(key);
  return it != per_class.end() && k < it->second.size() ? it->second[k] : NAN;
}

bool listed(const MetricLayout& m, size_t k) { return k < m.classes.size() && m.classes[k]; }

// Markdown: one row per listed class scored anywhere, a column per condition, then the mean.
std::string perClassMarkdown(const EvaluationSummary& s, const MetricLayout& m, const ReportTable& t) {
  const auto cols = columns(s);
  std::vector<std::string> header = {"class"};
  for (const ConditionSummary* c : cols) header.push_back(c->condition);
  std::string out = markdownHeader(header, 1);
  for (size_t k = 0; k < s.class_names.size(); ++k) {
    if (!listed(m, k)) continue;
    bool any = false;
    std::vector<std::string> row = {s.class_names[k]};
    for (const ConditionSummary* c : cols) {
      const double v = classValue(*c, m, t.columns[0].key, k);
      any = any || std::isfinite(v);
      row.push_back(fixed(v, t.columns[0].decimals));
    }
    if (any) out += markdownRow(row);
  }
  std::vector<std::string> row = {"**mean**"};
  for (const ConditionSummary* c : cols)
    row.push_back("**" + fixed(c->scoresOf(m.key).value(t.mean[0].key), t.mean[0].decimals) + "**");
  return out + markdownRow(row);
}

std::string perClassCsv(const EvaluationSummary& s, const MetricLayout& m, const ReportTable& t) {
  std::string out = "condition,class_id,class_name";
  for (const ReportColumn& col : t.columns) out += "," + col.key;
  out += "\n";
  for (const ConditionSummary* c : columns(s)) {
    const MetricScores& scores = c->scoresOf(m.key);
    if (scores.frames == 0) continue;
    for (size_t k = 0; k < s.class_names.size(); ++k) {
      if (!listed(m, k)) continue;
      bool any = false;
      std::string values;
      for (const ReportColumn& col : t.columns) {
        const double v = classValue(*c, m, col.key, k);
        any = any || std::isfinite(v);
        values += "," + csvNumber(v);
      }
      if (any) out += csvField(c->condition) + "," + std::to_string(k) + "," + csvField(s.class_names[k]) + values + "\n";
    }
    out += csvField(c->condition) + ",-1,mean";
    for (const ReportColumn& col : t.mean) out += "," + csvNumber(scores.value(col.key));
    out += "\n";
  }
  return out;
}

// A row table: per condition, the rows of every metric of the group that scored there.
std::string rowTable(const EvaluationSummary& s, const MetricLayout& m, const ReportTable& t, bool markdown) {
  std::string out;
  if (markdown) {
    std::vector<std::string> header = {"condition"};
    for (const ReportColumn& col : t.columns) header.push_back(col.label);
    out = markdownHeader(header, t.left_aligned);
  } else {
    out = "condition";
    for (const ReportColumn& col : t.columns) out += "," + col.key;
    out += "\n";
  }
  for (const ConditionSummary* c : columns(s))
    for (const MetricLayout* g : groupOf(s, m)) {
      const ReportTable* gt = tableNamed(*g, t.name);
      const MetricScores& scores = c->scoresOf(g->key);
      if (gt == nullptr || scores.frames == 0) continue;
      for (const std::string& set : gt->rows) {
        const auto rows = scores.rows.find(set);
        if (rows == scores.rows.end()) continue;
        for (const ReportRow& row : rows->second) {
          if (markdown && !gt->skip_zero.empty() && rowValue(row, gt->skip_zero) == 0.0) continue;
          std::vector<std::string> cells = {markdown ? (c == &s.all ? "**all**" : c->condition)
                                                     : csvField(c->condition)};
          for (const ReportColumn& col : gt->columns) cells.push_back(cell(row, col, markdown));
          if (markdown) {
            out += markdownRow(cells);
          } else {
            for (size_t i = 0; i < cells.size(); ++i) out += (i ? "," : "") + cells[i];
            out += "\n";
          }
        }
      }
    }
  return out;
}

std::string tableMarkdown(const EvaluationSummary& s, const MetricLayout& m, const ReportTable& t) {
  return t.kind == ReportTable::kPerClass ? perClassMarkdown(s, m, t) : rowTable(s, m, t, true);
}

std::string tableCsvOf(const EvaluationSummary& s, const MetricLayout& m, const ReportTable& t) {
  return t.kind == ReportTable::kPerClass ? perClassCsv(s, m, t) : rowTable(s, m, t, false);
}

// Curves: x, then a column per condition, metric of the group that scored there, and curve.
std::string curveCsv(const EvaluationSummary& s, const MetricLayout& m, const CurveFile& f) {
  std::vector<const std::vector<double>*> series;
  std::string out = f.x_label;
  for (const ConditionSummary* c : columns(s))
    for (const MetricLayout* g : groupOf(s, m)) {
      const MetricScores& scores = c->scoresOf(g->key);
      if (scores.frames == 0) continue;
      for (const CurveFile& gf : g->curve_files) {
        if (gf.file != f.file) continue;
        for (const ReportColumn& curve : gf.curves) {
          static const std::vector<double> kNone;
          const auto it = scores.curves.find(curve.key);
          series.push_back(it == scores.curves.end() ? &kNone : &it->second);
          out += "," + csvField(c->condition + "/" + curve.label);
        }
      }
    }
  out += "\n";
  for (size_t i = 0; i < f.x.size(); ++i) {
    out += csvNumber(f.x[i]);
    for (const std::vector<double>* y : series) out += "," + csvNumber(i < y->size() ? (*y)[i] : NAN);
    out += "\n";
  }
  return out;
}

std::string section(const EvaluationSummary& s, const MetricLayout& m) {
  std::string out;
  for (const MarkdownPart& part : m.markdown) {
    if (part.kind == MarkdownPart::kText) out += part.text;
    else if (part.kind == MarkdownPart::kNote) out += s.all.scoresOf(m.key).note;
    else if (const ReportTable* t = tableNamed(m, part.text)) out += tableMarkdown(s, m, *t);
  }
  return out;
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

std::string reportMarkdown(const EvaluationSummary& s) {
  std::ostringstream md;
  md << "# Evaluation report\n\n";
  md << "Frames scored: ";
  bool first = true, any = false;
  for (const MetricLayout& m : s.layouts) {
    any = any || scored(s, m);
    if (m.frames_label.empty()) continue;
    md << (first ? "" : ", ") << m.frames_label << " " << s.all.scoresOf(m.key).frames;
    first = false;
  }
  md << ".\n\n";
  if (!any) {
    md << "Nothing was scored: no prediction topic delivered a frame that met its ground truth.\n";
    return md.str();
  }

  md << "## Summary\n\n";
  std::vector<std::string> header = {"condition"};
  for (const MetricLayout& m : s.layouts)
    if (scored(s, m))
      for (const ReportColumn& col : m.summary) header.push_back(col.label);
  md << markdownHeader(header, 1);
  for (const ConditionSummary* c : columns(s)) {
    std::vector<std::string> row = {c == &s.all ? "**all**" : c->condition};
    for (const MetricLayout& m : s.layouts)
      if (scored(s, m))
        for (const ReportColumn& col : m.summary) row.push_back(number(c->scoresOf(m.key).value(col.key), col, true));
    md << markdownRow(row);
  }
  md << "\n";
  for (const MetricLayout& m : s.layouts)
    if (leadsGroup(s, m) && groupScored(s, m)) md << section(s, m);
  return md.str();
}

std::string summaryCsv(const EvaluationSummary& s) {
  std::string out = "condition";
  for (const MetricLayout& m : s.layouts)
    for (const ReportColumn& col : m.summary_csv) out += "," + col.label;
  out += "\n";
  for (const ConditionSummary* c : columns(s)) {
    out += csvField(c->condition);
    for (const MetricLayout& m : s.layouts)
      for (const ReportColumn& col : m.summary_csv) out += "," + number(c->scoresOf(m.key).value(col.key), col, false);
    out += "\n";
  }
  return out;
}

std::string tableCsv(const EvaluationSummary& s, const std::string& file) {
  for (const MetricLayout& m : s.layouts) {
    if (!leadsGroup(s, m)) continue;
    for (const ReportTable& t : m.tables)
      if (t.file == file) return tableCsvOf(s, m, t);
    for (const CurveFile& f : m.curve_files)
      if (f.file == file) return curveCsv(s, m, f);
  }
  throw std::invalid_argument("tableCsv: no metric writes " + file);
}

std::string scoresYaml(const EvaluationSummary& s) {
  std::ostringstream y;
  auto block = [&](const ConditionSummary& c, const std::string& indent) {
    for (const MetricLayout& m : s.layouts) {
      const MetricScores& scores = c.scoresOf(m.key);
      if (scores.frames == 0) continue;
      y << indent << m.key << ": {";
      for (size_t i = 0; i < m.yaml.size(); ++i) {
        const ReportColumn& col = m.yaml[i];
        const double v = scores.value(col.key);
        y << (i ? ", " : "") << col.label << ": "
          << (col.decimals == ReportColumn::kCount ? number(v, col, false) : yamlNumber(v));
      }
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
  // A metric's file is written when it says so or when it scored something; otherwise one of an
  // earlier report is removed.
  for (const MetricLayout& m : s.layouts) {
    if (!leadsGroup(s, m)) continue;
    for (const ReportTable& t : m.tables) {
      if (t.file.empty()) continue;
      std::error_code ec;
      if (t.always || groupScored(s, m)) writeFile(d / t.file, tableCsvOf(s, m, t), written);
      else std::filesystem::remove(d / t.file, ec);
    }
    for (const CurveFile& f : m.curve_files) writeFile(d / f.file, curveCsv(s, m, f), written);
  }
  return written;
}

}  // namespace viper
