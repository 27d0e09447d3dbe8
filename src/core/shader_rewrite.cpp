#include "viper/core/shader_rewrite.h"

#include <regex>
#include <vector>

namespace viper {

std::string stripGlslComments(const std::string& source) {
  std::string out = source;
  size_t i = 0;
  while (i < out.size()) {
    if (out[i] == '/' && i + 1 < out.size() && out[i + 1] == '/') {
      while (i < out.size() && out[i] != '\n') out[i++] = ' ';
    } else if (out[i] == '/' && i + 1 < out.size() && out[i + 1] == '*') {
      out[i++] = ' ';
      out[i++] = ' ';
      while (i < out.size() && !(out[i] == '*' && i + 1 < out.size() && out[i + 1] == '/')) {
        if (out[i] != '\n') out[i] = ' ';
        ++i;
      }
      for (int k = 0; k < 2 && i < out.size(); ++k) out[i++] = ' ';
    } else {
      ++i;
    }
  }
  return out;
}

namespace {

struct OutputDecl {
  std::string name;
  int components = 4;
  int location = -1;  // -1: no explicit location
  bool second_source = false;  // layout(index = 1): dual-source blending
};

int componentsOf(const std::string& type) {
  if (type == "float") return 1;
  return type.back() - '0';
}

std::vector<OutputDecl> findOutputs(const std::string& code) {
  static const std::regex kOut(
      R"((?:layout\s*\(([^)]*)\)\s*)?(?:(?:flat|smooth|noperspective|invariant|highp|mediump|lowp)\s+)*)"
      R"(\bout\s+(?:(?:highp|mediump|lowp)\s+)?(vec4|vec3|vec2|float)\s+(\w+)\s*;)");
  static const std::regex kLocation(R"(location\s*=\s*(\d+))");
  static const std::regex kIndex(R"(\bindex\s*=\s*1\b)");
  std::vector<OutputDecl> outputs;
  for (auto it = std::sregex_iterator(code.begin(), code.end(), kOut); it != std::sregex_iterator(); ++it) {
    OutputDecl d;
    d.components = componentsOf((*it)[2].str());
    d.name = (*it)[3].str();
    std::smatch loc;
    const std::string layout = (*it)[1].str();
    if (std::regex_search(layout, loc, kLocation)) d.location = std::stoi(loc[1].str());
    d.second_source = std::regex_search(layout, kIndex);
    outputs.push_back(d);
  }
  return outputs;
}

}  // namespace

FragmentRewrite rewriteFragmentShader(const std::string& source) {
  FragmentRewrite result;
  std::string code = stripGlslComments(source);

  static const std::regex kVersion(R"(^\s*#\s*version\s+(\d+)\s*(es)?)", std::regex::multiline);
  std::smatch version;
  if (!std::regex_search(code, version, kVersion) || std::stoi(version[1].str()) < 150 ||
      version[2].matched) {
    result.reason = "needs desktop GLSL >= 1.50 (gl_PrimitiveID)";
    return result;
  }

  const std::vector<OutputDecl> outputs = findOutputs(code);
  const OutputDecl* color = nullptr;
  if (outputs.size() == 1) {
    color = &outputs[0];
  } else if (outputs.empty()) {
    result.reason = "no fragment color output declared";
    return result;
  } else {
    // Several outputs (multiple render targets): placed only when all have explicit locations,
    // ours (kIdOutputLocation) free.
    for (const OutputDecl& d : outputs) {
      if (d.location < 0) {
        result.reason = "several outputs, '" + d.name + "' without an explicit location";
        return result;
      }
      if (d.location == kIdOutputLocation) {
        result.reason = "output '" + d.name + "' at location " + std::to_string(kIdOutputLocation) +
                        ", which the id output needs";
        return result;
      }
      if (d.location == 0 && !d.second_source) color = &d;
    }
    if (!color) {
      result.reason = "several outputs and none at location 0";
      return result;
    }
  }
  if (color->location > 0) {
    result.reason = "color output is not at location 0";
    return result;
  }
  for (const OutputDecl& d : outputs) {
    if (d.second_source) {
      result.reason = "dual-source blending (output '" + d.name + "' has index = 1)";
      return result;
    }
  }

  static const std::regex kMain(R"(\bvoid\s+main\s*\(\s*(?:void\s*)?\))");
  if (!std::regex_search(code, kMain)) {
    result.reason = "no `void main()` found";
    return result;
  }
  code = std::regex_replace(code, kMain, "void viper_original_main()");

  const std::string coverage =
      color->components == 4
          ? "(" + std::string(kAlphaTestUniform) + " > 0.5 && " + color->name + ".a < 0.5) ? 0.0 : 1.0"
          : std::string("1.0");
  if (!code.empty() && code.back() != '\n') code += '\n';
  code += "uniform float " + std::string(kDrawIdUniform) + ";\n";
  code += "uniform float " + std::string(kAlphaTestUniform) + ";\n";
  code += "out vec4 " + std::string(kIdOutputName) + ";\n";
  code += "void main() {\n  viper_original_main();\n  " + std::string(kIdOutputName) + " = vec4(" +
          kDrawIdUniform + ", float(gl_PrimitiveID), 0.0, " + coverage + ");\n}\n";

  result.ok = true;
  result.source = code;
  result.color_output = color->name;
  result.explicit_location = color->location >= 0;
  result.color_components = color->components;
  return result;
}

bool declaresMat4ArrayUniform(const std::string& source) {
  static const std::regex kArray(R"(\buniform\s+(?:(?:highp|mediump|lowp)\s+)?mat4\s+\w+\s*\[)");
  const std::string code = stripGlslComments(source);
  return std::regex_search(code, kArray);
}

}  // namespace viper
