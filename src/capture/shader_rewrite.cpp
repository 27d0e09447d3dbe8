#include "viper/capture/shader_rewrite.h"

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

namespace {

const std::regex& mainRegex() {
  static const std::regex kMain(R"(\bvoid\s+main\s*\(\s*(?:void\s*)?\))");
  return kMain;
}

// What the new main writes to the id output: (draw id, primitive id, 0, 1); with `alpha` (the
// color's alpha, when it has one), id 0 instead where a blended fragment is mostly transparent but
// writes depth (alpha < 0.5), so that an id never names a surface other than the one the depth
// image holds.
std::string idValue(const std::string& alpha, bool primitive_ids) {
  const std::string id = "vec4(" + std::string(kDrawIdUniform) + (primitive_ids ? ", float(gl_PrimitiveID)" : ", 0.0") +
                         ", 0.0, 1.0)";
  if (alpha.empty()) return id;
  return "(" + std::string(kAlphaTestUniform) + " > 0.5 && " + alpha + " < 0.5) ? vec4(0.0, 0.0, 0.0, 1.0) : " + id;
}

// GLSL before 1.50: gl_FragColor / gl_FragData[i] become gl_FragData[0] / [i]; the ids go to
// gl_FragData[kIdOutputLocation]; gl_PrimitiveID comes from GL_EXT_gpu_shader4.
FragmentRewrite rewriteLegacy(std::string code, const std::smatch* version, bool primitive_ids) {
  FragmentRewrite result;
  static const std::regex kFragColor(R"(\bgl_FragColor\b)"), kFragData(R"(\bgl_FragData\b)");
  static const std::regex kOutDecl(R"(\bout\s+(?:(?:highp|mediump|lowp)\s+)?(?:vec[234]|float)\s+\w+\s*;)");
  const bool color = std::regex_search(code, kFragColor), data = std::regex_search(code, kFragData);
  if (!color && !data) {
    result.reason = "GLSL before 1.50 writing neither gl_FragColor nor gl_FragData";
    return result;
  }
  if (std::regex_search(code, kOutDecl)) {
    result.reason = "GLSL before 1.50 with user-declared outputs";
    return result;
  }
  if (!std::regex_search(code, mainRegex())) {
    result.reason = "no `void main()` found";
    return result;
  }
  static const std::regex kFragData7(R"(\bgl_FragData\s*\[\s*7\s*\])");
  if (std::regex_search(code, kFragData7)) {
    result.reason = "GLSL before 1.50 writing gl_FragData[7], where the ids go";
    return result;
  }
  // gl_FragColor goes to every draw buffer (ARB_draw_buffers), gl_FragData[i] to draw buffer i
  // only: the colour is kept in a variable of ours and written to each, the last one too while
  // no ids are wanted (viper_draw_id 0: a draw not recorded, or into the program's own draw buffer 7).
  if (color) code = std::regex_replace(code, kFragColor, "viper_frag_color");
  code = std::regex_replace(code, mainRegex(), "void viper_original_main()");
  // The extension directive goes right after #version (or first, without one), before any code.
  const std::string extension = primitive_ids ? "#extension GL_EXT_gpu_shader4 : require\n" : "";
  if (version) {
    // version[1] is the number: the directive's line ends after it (the match may begin with blank lines).
    const size_t end = code.find('\n', static_cast<size_t>(version->position(1)));
    code.insert(end == std::string::npos ? code.size() : end + 1, extension);
  } else {
    code.insert(0, extension);
  }
  if (!code.empty() && code.back() != '\n') code += '\n';
  code += "uniform float " + std::string(kDrawIdUniform) + ";\n";
  code += "uniform float " + std::string(kAlphaTestUniform) + ";\n";
  const std::string last = "gl_FragData[" + std::to_string(kIdOutputLocation) + "]";
  if (color) {
    // Declared before the original code, which writes it: after the last #extension directive
    // (they must come before any declaration), else after #version and ours.
    static const std::regex kExtensionLine(R"([ \t]*#[ \t]*extension\b.*)");
    size_t insert = 0;
    for (size_t line = 0; line < code.size();) {
      size_t end = code.find('\n', line);
      end = end == std::string::npos ? code.size() : end + 1;
      if (std::regex_match(code.begin() + static_cast<std::ptrdiff_t>(line),
                           code.begin() + static_cast<std::ptrdiff_t>(end - (code[end - 1] == '\n' ? 1 : 0)),
                           kExtensionLine))
        insert = end;
      line = end;
    }
    if (insert == 0 && version) {
      const size_t end = code.find('\n', static_cast<size_t>(version->position(1)));
      insert = end == std::string::npos ? code.size() : end + 1;
    }
    code.insert(insert, "vec4 viper_frag_color;\n");
    code += "void main() {\n  viper_original_main();\n";
    for (int i = 0; i < kIdOutputLocation; ++i) code += "  gl_FragData[" + std::to_string(i) + "] = viper_frag_color;\n";
    code += "  " + last + " = " + kDrawIdUniform + " < 0.5 ? viper_frag_color : (" +
            idValue("viper_frag_color.a", primitive_ids) + ");\n}\n";
  } else {
    // (Written only while ids are wanted: the program's own gl_FragData[7], where its
    // framebuffer has that draw buffer, stays as it wrote it.)
    code += "void main() {\n  viper_original_main();\n  if (" + std::string(kDrawIdUniform) + " >= 0.5) " + last +
            " = " + idValue("gl_FragData[0].a", primitive_ids) + ";\n}\n";
  }
  result.ok = true;
  result.legacy = true;
  result.source = code;
  result.color_output = "gl_FragData[0]";
  result.explicit_location = true;  // nothing to bind
  return result;
}

}  // namespace

FragmentRewrite rewriteFragmentShader(const std::string& source, bool primitive_ids) {
  FragmentRewrite result;
  std::string code = stripGlslComments(source);

  static const std::regex kVersion(R"(^\s*#\s*version\s+(\d+)\s*(es)?)", std::regex::multiline);
  std::smatch version;
  const bool has_version = std::regex_search(code, version, kVersion);
  if (has_version && version[2].matched) {
    result.reason = "GLSL ES (no gl_PrimitiveID)";
    return result;
  }
  if (!has_version || std::stoi(version[1].str()) < 150) return rewriteLegacy(code, has_version ? &version : nullptr, primitive_ids);

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

  if (!std::regex_search(code, mainRegex())) {
    result.reason = "no `void main()` found";
    return result;
  }
  code = std::regex_replace(code, mainRegex(), "void viper_original_main()");

  if (!code.empty() && code.back() != '\n') code += '\n';
  code += "uniform float " + std::string(kDrawIdUniform) + ";\n";
  code += "uniform float " + std::string(kAlphaTestUniform) + ";\n";
  code += "out vec4 " + std::string(kIdOutputName) + ";\n";
  code += "void main() {\n  viper_original_main();\n  " + std::string(kIdOutputName) + " = " +
          idValue(color->components == 4 ? color->name + ".a" : "", primitive_ids) + ";\n}\n";

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
