#include "viper/capture/capture_profile.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace viper {

namespace {

std::runtime_error profileError(const std::string& source, const YAML::Node& node, const std::string& what) {
  std::ostringstream s;
  s << "capture profile " << source;
  if (node.Mark().line >= 0) s << ":" << node.Mark().line + 1;
  s << ": " << what;
  return std::runtime_error(s.str());
}

std::string scalar(const std::string& source, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar()) throw profileError(source, node, "'" + key + "' must be a string");
  return node.as<std::string>();
}

uint64_t parseKey(const std::string& source, const YAML::Node& node) {
  const std::string text = scalar(source, node, "program_key");
  try {
    size_t used = 0;
    const uint64_t key = std::stoull(text, &used, 0);
    if (used != text.size()) throw std::invalid_argument(text);
    return key;
  } catch (const std::exception&) {
    throw profileError(source, node, "'program_key' must be an integer (e.g. 0x1f2e...), got '" + text + "'");
  }
}

Deforming parseDeforming(const std::string& source, const YAML::Node& node) {
  const std::string text = scalar(source, node, "deforming");
  if (text == "auto") return Deforming::kAuto;
  if (text == "true" || text == "yes") return Deforming::kYes;
  if (text == "false" || text == "no") return Deforming::kNo;
  throw profileError(source, node, "'deforming' must be auto, true or false, got '" + text + "'");
}

bool parseBool(const std::string& source, const YAML::Node& node, const std::string& key) {
  const std::string text = scalar(source, node, key);
  if (text == "true" || text == "yes") return true;
  if (text == "false" || text == "no") return false;
  throw profileError(source, node, "'" + key + "' must be true or false, got '" + text + "'");
}

// A matrix name (parseMatrixName), as an error of the profile where it is not one.
std::string matrixName(const std::string& source, const YAML::Node& node, const std::string& key) {
  const std::string text = scalar(source, node, key);
  try {
    parseMatrixName(text);
  } catch (const std::invalid_argument& e) {
    throw profileError(source, node, "'" + key + "': " + e.what());
  }
  return text;
}

ProgramProfile parseEntry(const std::string& source, const YAML::Node& node) {
  if (!node.IsMap()) throw profileError(source, node, "each entry of 'programs' must be a map");
  ProgramProfile p;
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& value = kv.second;
    if (key == "vertex_contains") p.vertex_contains = scalar(source, value, key);
    else if (key == "program_key") p.program_key = parseKey(source, value);
    else if (key == "world") p.world = matrixName(source, value, key);
    else if (key == "view") p.view = matrixName(source, value, key);
    else if (key == "projection") p.projection = matrixName(source, value, key);
    else if (key == "model_view") p.model_view = matrixName(source, value, key);
    else if (key == "view_projection") p.view_projection = matrixName(source, value, key);
    else if (key == "model_view_projection") p.model_view_projection = matrixName(source, value, key);
    else if (key == "world_space") p.world_space = parseBool(source, value, key);
    else if (key == "position") p.position = scalar(source, value, key);
    else if (key == "deforming") p.deforming = parseDeforming(source, value);
    else if (key == "instance_world") p.instance_world = scalar(source, value, key);
    else if (key == "instance_translation") p.instance_translation = scalar(source, value, key);
    else if (key == "instance_rotation") p.instance_rotation = scalar(source, value, key);
    else if (key == "instance_scale") p.instance_scale = scalar(source, value, key);
    else if (key == "instance_rotation_conjugate") p.instance_rotation_conjugate = parseBool(source, value, key);
    else if (key == "overlay") p.overlay = parseBool(source, value, key);
    else if (key == "fixed_function") p.fixed_function = parseBool(source, value, key);
    else if (key == "matrix_stack") {
      p.matrix_stack = scalar(source, value, key);
      if (p.matrix_stack != "load_view_mult_world" && p.matrix_stack != "push_world")
        throw profileError(source, value,
                           "'matrix_stack' must be load_view_mult_world or push_world, got '" + p.matrix_stack + "'");
    } else
      throw profileError(source, kv.first,
                         "unknown key '" + key +
                             "' (known: vertex_contains, program_key, world, view, projection, model_view, "
                             "view_projection, model_view_projection, world_space, position, deforming, "
                             "instance_world, instance_translation, instance_rotation, instance_scale, "
                             "instance_rotation_conjugate, overlay, matrix_stack, fixed_function)");
  }
  if (!p.instance_world.empty() &&
      (!p.instance_translation.empty() || !p.instance_rotation.empty() || !p.instance_scale.empty()))
    throw profileError(source, node,
                       "'instance_world' (a mat4 attribute) and instance_translation/rotation/scale exclude each other");
  if (p.fixed_function &&
      (!p.vertex_contains.empty() || p.program_key != 0 || !p.world.empty() || !p.view.empty() ||
       !p.projection.empty() || !p.model_view.empty() || !p.view_projection.empty() ||
       !p.model_view_projection.empty() || !p.position.empty() || p.deforming != Deforming::kAuto ||
       p.hasInstanceTransform()))
    throw profileError(source, node,
                       "'fixed_function: true' is for draws without a program: only matrix_stack, world_space and "
                       "overlay go with it (no shader to match, no uniform or attribute to name)");
  if (p.world_space && (!p.world.empty() || p.hasInstanceTransform()))
    throw profileError(source, node, "'world_space: true' says the world is the identity: no world or instance_* with it");
  if (p.world_space && !p.matrix_stack.empty())
    throw profileError(source, node, "'world_space' and 'matrix_stack' exclude each other");
  if (!p.matrix_stack.empty() && (!p.world.empty() || !p.view.empty() || !p.projection.empty() ||
                                  !p.model_view.empty() || !p.view_projection.empty() ||
                                  !p.model_view_projection.empty()))
    throw profileError(source, node, "'matrix_stack' and named matrices (world, view, projection, combined) exclude each other");
  return p;
}

}  // namespace

MatrixName parseMatrixName(const std::string& text) {
  MatrixName m;
  std::istringstream words(text);
  std::string first, second, more;
  words >> first >> second >> more;
  if (second.empty()) {
    m.name = text;  // a mat4, named as the program names it
    return m;
  }
  if (!more.empty() || (second != "rows" && second != "columns"))
    throw std::invalid_argument("'" + text + "' is neither a mat4's name nor 'ARRAY[N] rows' or 'ARRAY[N] columns'");
  const size_t open = first.rfind('[');
  const std::string digits = open == std::string::npos ? "" : first.substr(open + 1, first.size() - open - 2);
  if (open == std::string::npos || open == 0 || first.back() != ']' || digits.empty() || digits.size() > 5 ||
      digits.find_first_not_of("0123456789") != std::string::npos || std::stoi(digits) > kMaxMatrixElement)
    throw std::invalid_argument("'" + first + "' must be an array element, ARRAY[N] with N from 0 to " +
                                std::to_string(kMaxMatrixElement) + " (the first of four vec4 elements)");
  m.name = first.substr(0, open);
  m.first_element = std::stoi(digits);
  m.rows = second == "rows";
  return m;
}

const ProgramProfile* CaptureProfile::match(const std::string& vertex_source, uint64_t program_key) const {
  static const ProgramProfile kFallback;
  for (const ProgramProfile& p : programs) {
    if (p.fixed_function) continue;
    if (p.program_key != 0 && p.program_key != program_key) continue;
    if (!p.vertex_contains.empty() && vertex_source.find(p.vertex_contains) == std::string::npos) continue;
    return &p;
  }
  return &kFallback;
}

bool CaptureProfile::combinesMatrices() const {
  for (const ProgramProfile& p : programs)
    if (!p.model_view.empty() || !p.view_projection.empty() || !p.model_view_projection.empty() || p.world_space ||
        (p.fixed_function && p.matrix_stack.empty()))
      return true;
  return false;
}

const ProgramProfile* CaptureProfile::matchFixedFunction() const {
  static const ProgramProfile kFallback = [] {
    ProgramProfile p;
    p.fixed_function = true;
    return p;
  }();
  for (const ProgramProfile& p : programs)
    if (p.fixed_function) return &p;
  return &kFallback;
}

CaptureProfile parseCaptureProfile(const std::string& yaml_text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("capture profile " + source_name + ":" + std::to_string(e.mark.line + 1) +
                             ": not valid YAML: " + e.msg);
  }
  CaptureProfile profile;
  profile.source = source_name;
  if (root.IsNull()) return profile;
  if (!root.IsMap()) throw profileError(source_name, root, "top level must be a map with key 'programs'");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (key == "handedness") {
      const std::string h = scalar(source_name, kv.second, key);
      if (h != "left" && h != "right")
        throw profileError(source_name, kv.second, "'handedness' must be left or right, got '" + h + "'");
      profile.left_handed = h == "left";
      continue;
    }
    if (key == "depth_clear_ends_scene") {
      profile.depth_clear_ends_scene = parseBool(source_name, kv.second, key);
      continue;
    }
    if (key == "clip_depth") {
      const std::string d = scalar(source_name, kv.second, key);
      if (d != "zero_to_one" && d != "minus_one_to_one")
        throw profileError(source_name, kv.second, "'clip_depth' must be zero_to_one or minus_one_to_one, got '" + d + "'");
      profile.clip_depth_zero_to_one = d == "zero_to_one";
      continue;
    }
    if (key != "programs")
      throw profileError(source_name, kv.first,
                         "unknown top-level key '" + key + "' (known: programs, handedness, depth_clear_ends_scene, clip_depth)");
    if (kv.second.IsNull()) continue;
    if (!kv.second.IsSequence()) throw profileError(source_name, kv.second, "'programs' must be a list");
    for (const auto& entry : kv.second) profile.programs.push_back(parseEntry(source_name, entry));
  }
  return profile;
}

CaptureProfile loadCaptureProfile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("capture profile " + path + ": cannot open file");
  std::stringstream text;
  text << in.rdbuf();
  return parseCaptureProfile(text.str(), path);
}

}  // namespace viper
