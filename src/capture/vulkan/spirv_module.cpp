#include "spirv_module.h"

#include <spirv-tools/libspirv.hpp>
#include <spirv/unified1/spirv.hpp>

#include <algorithm>
#include <set>

namespace viper {
namespace capture {
namespace vulkan {
namespace {

constexpr uint32_t kHeaderWords = 5;

/// One instruction: its opcode and operand words (the word count and opcode word left out).
struct Instruction {
  uint32_t opcode = 0;
  std::vector<uint32_t> operands;
};

// The operands the layer reads of the instructions it looks at (a valid module has at least these).
size_t minimumOperands(uint32_t opcode) {
  switch (opcode) {
    case spv::OpCapability:
    case spv::OpTypeStruct:
    case spv::OpLabel:
      return 1;
    case spv::OpName:
    case spv::OpDecorate:
    case spv::OpTypeRuntimeArray:
    case spv::OpTypeFloat:
      return 2;
    case spv::OpMemberName:
    case spv::OpMemberDecorate:
    case spv::OpEntryPoint:
    case spv::OpTypeInt:
    case spv::OpTypeVector:
    case spv::OpTypeMatrix:
    case spv::OpTypeArray:
    case spv::OpTypePointer:
    case spv::OpVariable:
      return 3;
    case spv::OpFunction:
      return 4;
    default:
      return 0;
  }
}

bool parse(const std::vector<uint32_t>& words, std::vector<Instruction>& out, std::string& why) {
  if (words.size() < kHeaderWords || words[0] != spv::MagicNumber) {
    why = "not a SPIR-V module (no magic number)";
    return false;
  }
  for (size_t at = kHeaderWords; at < words.size();) {
    const uint32_t count = words[at] >> 16;
    if (count == 0 || at + count > words.size()) {
      why = "instruction at word " + std::to_string(at) + " runs past the module's end";
      return false;
    }
    Instruction i;
    i.opcode = words[at] & 0xffffu;
    i.operands.assign(words.begin() + static_cast<long>(at) + 1, words.begin() + static_cast<long>(at + count));
    if (i.operands.size() < minimumOperands(i.opcode)) {
      why = "instruction at word " + std::to_string(at) + " (opcode " + std::to_string(i.opcode) + ") has too few operands";
      return false;
    }
    out.push_back(std::move(i));
    at += count;
  }
  return true;
}

/// A literal string starting at operand `first`; `next` is set to the operand after it.
std::string literalString(const std::vector<uint32_t>& ops, size_t first, size_t* next = nullptr) {
  std::string s;
  size_t i = first;
  for (; i < ops.size(); ++i) {
    bool ended = false;
    for (int b = 0; b < 4; ++b) {
      const char c = static_cast<char>((ops[i] >> (8 * b)) & 0xffu);
      if (c == '\0') {
        ended = true;
        break;
      }
      s.push_back(c);
    }
    if (ended) {
      ++i;
      break;
    }
  }
  if (next) *next = i;
  return s;
}

/// The types, names and decorations of a module, indexed by id.
struct Index {
  std::map<uint32_t, std::string> names;
  std::map<std::pair<uint32_t, uint32_t>, std::string> member_names;
  std::map<uint32_t, std::map<uint32_t, uint32_t>> decorations;  // id -> decoration -> first literal
  std::map<std::pair<uint32_t, uint32_t>, std::map<uint32_t, uint32_t>> member_decorations;
  std::map<uint32_t, Instruction> types;  // result id -> type instruction
  struct Variable {
    uint32_t pointer_type = 0;
    uint32_t storage = 0;
  };
  std::map<uint32_t, Variable> variables;  // global variables

  uint32_t decoration(uint32_t id, spv::Decoration d, uint32_t fallback) const {
    auto i = decorations.find(id);
    if (i == decorations.end()) return fallback;
    auto j = i->second.find(d);
    return j == i->second.end() ? fallback : j->second;
  }
  bool decorated(uint32_t id, spv::Decoration d) const {
    auto i = decorations.find(id);
    return i != decorations.end() && i->second.count(d);
  }
  /// The type a pointer type points at (0 if `pointer` is not a pointer type).
  uint32_t pointee(uint32_t pointer) const {
    auto i = types.find(pointer);
    return i != types.end() && i->second.opcode == spv::OpTypePointer ? i->second.operands[2] : 0;
  }
};

bool isTypeOrGlobal(uint32_t op) {
  return (op >= spv::OpTypeVoid && op <= spv::OpTypeForwardPointer) || op == spv::OpVariable ||
         (op >= spv::OpConstantTrue && op <= spv::OpSpecConstantOp) || op == spv::OpUndef ||
         op == spv::OpTypeAccelerationStructureKHR || op == spv::OpTypeRayQueryKHR;
}

Index buildIndex(const std::vector<Instruction>& module) {
  Index x;
  for (const Instruction& i : module) {
    const auto& o = i.operands;
    switch (i.opcode) {
      case spv::OpName:
        if (o.size() >= 2) x.names[o[0]] = literalString(o, 1);
        break;
      case spv::OpMemberName:
        if (o.size() >= 3) x.member_names[{o[0], o[1]}] = literalString(o, 2);
        break;
      case spv::OpDecorate:
        if (o.size() >= 2) x.decorations[o[0]][o[1]] = o.size() >= 3 ? o[2] : 0;
        break;
      case spv::OpMemberDecorate:
        if (o.size() >= 3) x.member_decorations[{o[0], o[1]}][o[2]] = o.size() >= 4 ? o[3] : 0;
        break;
      case spv::OpVariable:
        if (o.size() >= 3) x.variables[o[1]] = {o[0], o[2]};
        break;
      default:
        if (i.opcode >= spv::OpTypeVoid && i.opcode <= spv::OpTypeForwardPointer && !o.empty()) {
          if (i.opcode == spv::OpTypePointer && o.size() < 3) break;
          x.types[o[0]] = i;
        }
    }
  }
  return x;
}

void addBlockMembers(const Index& x, uint32_t struct_id, BlockMember where, std::map<std::string, BlockMember>& out,
                     uint32_t* end) {
  auto s = x.types.find(struct_id);
  if (s == x.types.end() || s->second.opcode != spv::OpTypeStruct) return;
  const auto& members = s->second.operands;  // [result, member types...]
  for (uint32_t m = 0; m + 1 < members.size(); ++m) {
    auto md = x.member_decorations.find({struct_id, m});
    if (md == x.member_decorations.end()) continue;
    auto offset = md->second.find(spv::DecorationOffset);
    if (offset == md->second.end()) continue;
    BlockMember b = where;
    b.offset = offset->second;
    auto stride = md->second.find(spv::DecorationMatrixStride);
    b.row_major = md->second.count(spv::DecorationRowMajor) != 0;
    uint32_t size = 4;
    auto type = x.types.find(members[m + 1]);
    if (type != x.types.end() && type->second.opcode == spv::OpTypeMatrix && stride != md->second.end()) {
      auto column = x.types.find(type->second.operands[1]);
      b.columns = type->second.operands[2];
      b.rows = column != x.types.end() && column->second.opcode == spv::OpTypeVector ? column->second.operands[2] : 0;
      b.matrix_stride = stride->second;
      size = b.matrix_stride * (b.row_major ? b.rows : b.columns);
    } else if (type != x.types.end() && type->second.opcode == spv::OpTypeVector) {
      size = 4 * type->second.operands[2];
      b.components = type->second.operands[2];
    } else if (type != x.types.end() &&
               (type->second.opcode == spv::OpTypeArray || type->second.opcode == spv::OpTypeRuntimeArray) &&
               b.array_stride == 0) {
      // An array of structs (per-object data indexed by instance): its elements' members by name.
      const uint32_t stride = x.decoration(type->first, spv::DecorationArrayStride, 0);
      BlockMember element = b;
      element.array_stride = stride;
      std::map<std::string, BlockMember> inner;
      if (stride) addBlockMembers(x, type->second.operands[1], element, inner, nullptr);
      for (auto& [name, member] : inner) {
        member.offset += b.offset;
        out.emplace(name, member);
      }
    }
    if (end) *end = std::max(*end, b.offset + size);
    auto name = x.member_names.find({struct_id, m});
    if (name != x.member_names.end() && !name->second.empty()) out.emplace(name->second, b);
  }
}

std::vector<uint32_t> assemble(const std::vector<uint32_t>& header, const std::vector<Instruction>& module) {
  std::vector<uint32_t> words(header.begin(), header.end());
  for (const Instruction& i : module) {
    words.push_back(static_cast<uint32_t>(i.operands.size() + 1) << 16 | i.opcode);
    words.insert(words.end(), i.operands.begin(), i.operands.end());
  }
  return words;
}

Instruction make(spv::Op op, std::vector<uint32_t> operands) { return Instruction{static_cast<uint32_t>(op), std::move(operands)}; }

}  // namespace

ModuleReflection reflectModule(const std::vector<uint32_t>& words) {
  ModuleReflection r;
  std::vector<Instruction> module;
  if (!parse(words, module, r.problem)) return r;
  r.version = words[1];
  const Index x = buildIndex(module);
  for (const Instruction& i : module) {
    if (i.opcode == spv::OpEntryPoint && i.operands.size() >= 3) r.entry_points[literalString(i.operands, 2)] = i.operands[0];
  }
  for (const auto& [id, v] : x.variables) {
    const uint32_t type = x.pointee(v.pointer_type);
    BlockMember where;
    if (v.storage == spv::StorageClassPushConstant) {
      where.push_constant = true;
      addBlockMembers(x, type, where, r.members, &r.push_constant_end);
    } else if (v.storage == spv::StorageClassUniform || v.storage == spv::StorageClassStorageBuffer) {
      where.set = x.decoration(id, spv::DecorationDescriptorSet, 0);
      where.binding = x.decoration(id, spv::DecorationBinding, 0);
      addBlockMembers(x, type, where, r.members, nullptr);
    } else if (v.storage == spv::StorageClassUniformConstant) {
      uint32_t t = type;
      for (int depth = 0; depth < 2; ++depth) {  // an array of them: its element type
        auto a = x.types.find(t);
        if (a != x.types.end() && (a->second.opcode == spv::OpTypeArray || a->second.opcode == spv::OpTypeRuntimeArray))
          t = a->second.operands[1];
      }
      auto image = x.types.find(t);
      if (image != x.types.end() &&
          (image->second.opcode == spv::OpTypeSampledImage || image->second.opcode == spv::OpTypeImage))
        r.images.emplace_back(x.decoration(id, spv::DecorationDescriptorSet, 0), x.decoration(id, spv::DecorationBinding, 0));
    } else if (v.storage == spv::StorageClassInput && x.decoration(id, spv::DecorationBuiltIn, ~0u) == spv::BuiltInBaseInstance) {
      r.reads_base_instance = true;
    } else if (v.storage == spv::StorageClassInput && x.decorated(id, spv::DecorationLocation)) {
      auto name = x.names.find(id);
      if (name != x.names.end()) r.input_locations[name->second] = x.decoration(id, spv::DecorationLocation, 0);
    }
  }
  std::sort(r.images.begin(), r.images.end());
  for (const auto& [id, name] : x.names) r.names_text += name + "\n";
  for (const auto& [key, name] : x.member_names) r.names_text += name + "\n";
  r.valid = true;
  return r;
}

std::vector<uint32_t> addIdOutput(const std::vector<uint32_t>& words, const std::string& entry, const IdOutput& id,
                                  std::string& why) {
  std::vector<Instruction> module;
  if (!parse(words, module, why)) return {};
  std::vector<uint32_t> header(words.begin(), words.begin() + kHeaderWords);
  uint32_t& bound = header[3];
  const uint32_t version = header[1];
  const Index x = buildIndex(module);

  // The entry point, its function and where the sections are.
  size_t entry_at = module.size(), last_capability = module.size(), first_global = module.size(),
         first_function = module.size();
  bool has_geometry = false;
  for (size_t k = 0; k < module.size(); ++k) {
    const Instruction& i = module[k];
    if (i.opcode == spv::OpCapability) {
      last_capability = k;
      has_geometry |= i.operands[0] == spv::CapabilityGeometry || i.operands[0] == spv::CapabilityTessellation;
    } else if (i.opcode == spv::OpEntryPoint && i.operands.size() >= 3 && literalString(i.operands, 2) == entry) {
      entry_at = k;
    } else if (first_global == module.size() && isTypeOrGlobal(i.opcode)) {
      first_global = k;
    } else if (i.opcode == spv::OpFunction && first_function == module.size()) {
      first_function = k;
    }
  }
  if (entry_at == module.size()) return why = "no entry point \"" + entry + "\"", std::vector<uint32_t>{};
  if (module[entry_at].operands[0] != spv::ExecutionModelFragment)
    return why = "entry point \"" + entry + "\" is not a fragment shader", std::vector<uint32_t>{};
  if (first_global == module.size() || first_function == module.size() || last_capability == module.size())
    return why = "module has no types or no functions", std::vector<uint32_t>{};
  const uint32_t function_id = module[entry_at].operands[1];

  // The program's outputs: the id location must be free and no output may blend dual-source.
  uint32_t primitive_variable = 0, push_variable = 0;
  for (const auto& [var, v] : x.variables) {
    if (v.storage == spv::StorageClassOutput) {
      if (x.decorated(var, spv::DecorationIndex))
        return why = "the shader blends with two sources (dual-source blending): no location left for ids", std::vector<uint32_t>{};
      if (x.decorated(var, spv::DecorationLocation) && x.decoration(var, spv::DecorationLocation, 0) >= id.location)
        return why = "the shader writes output location " + std::to_string(x.decoration(var, spv::DecorationLocation, 0)) +
                     ", where the id attachment goes",
               std::vector<uint32_t>{};
    } else if (v.storage == spv::StorageClassInput && x.decoration(var, spv::DecorationBuiltIn, ~0u) == spv::BuiltInPrimitiveId) {
      primitive_variable = var;
    } else if (v.storage == spv::StorageClassPushConstant) {
      push_variable = var;
    }
  }

  std::vector<Instruction> scalar_types, annotations, globals, code;
  std::map<size_t, std::vector<Instruction>> after;  // new types to go right after instruction k
  std::map<size_t, size_t> move_before;  // instruction v of the module goes right before instruction k
  // Scalar and vector types are unique in a module: found, or declared before every other type.
  auto findType = [&](spv::Op op, std::vector<uint32_t> rest) -> uint32_t {
    for (const auto& [tid, t] : x.types)
      if (t.opcode == static_cast<uint32_t>(op) && std::equal(rest.begin(), rest.end(), t.operands.begin() + 1) &&
          t.operands.size() == rest.size() + 1)
        return tid;
    for (const Instruction& t : scalar_types)
      if (t.opcode == static_cast<uint32_t>(op) && std::equal(rest.begin(), rest.end(), t.operands.begin() + 1) &&
          t.operands.size() == rest.size() + 1)
        return t.operands[0];
    const uint32_t tid = bound++;
    const uint32_t component = op == spv::OpTypeVector ? rest[0] : 0;
    rest.insert(rest.begin(), tid);
    // A vector goes right after its component's declaration when the module has it; scalars and
    // vectors of new scalars go first of all types.
    for (size_t k = 0; component && k < module.size(); ++k)
      if (isTypeOrGlobal(module[k].opcode) && !module[k].operands.empty() && module[k].operands[0] == component &&
          module[k].opcode != spv::OpVariable) {
        after[k].push_back(make(op, rest));
        return tid;
      }
    scalar_types.push_back(make(op, rest));
    return tid;
  };
  const uint32_t uint_type = findType(spv::OpTypeInt, {32, 0});
  const uint32_t uvec4_type = findType(spv::OpTypeVector, {uint_type, 4});
  auto pointer = [&](spv::StorageClass storage, uint32_t type) {
    const uint32_t pid = bound++;
    globals.push_back(make(spv::OpTypePointer, {pid, static_cast<uint32_t>(storage), type}));
    return pid;
  };
  auto constant = [&](uint32_t value) {
    const uint32_t cid = bound++;
    globals.push_back(make(spv::OpConstant, {uint_type, cid, value}));
    return cid;
  };
  std::vector<uint32_t> new_interface;

  // The layer's two words: members of the shader's own push-constant block, a push-constant block
  // of ours, or a uniform block of ours at (descriptor_set, 0).
  uint32_t member_a = 0;
  spv::StorageClass id_storage = spv::StorageClassPushConstant;
  if (id.descriptor_set >= 0) {
    id_storage = spv::StorageClassUniform;
    const uint32_t block = bound++;
    globals.push_back(make(spv::OpTypeStruct, {block, uint_type, uint_type}));
    annotations.push_back(make(spv::OpDecorate, {block, spv::DecorationBlock}));
    annotations.push_back(make(spv::OpMemberDecorate, {block, 0, spv::DecorationOffset, 0}));
    annotations.push_back(make(spv::OpMemberDecorate, {block, 1, spv::DecorationOffset, 4}));
    const uint32_t block_pointer = pointer(spv::StorageClassUniform, block);
    push_variable = bound++;  // the variable the two words are read from
    globals.push_back(make(spv::OpVariable, {block_pointer, push_variable, spv::StorageClassUniform}));
    annotations.push_back(make(spv::OpDecorate, {push_variable, spv::DecorationDescriptorSet,
                                                 static_cast<uint32_t>(id.descriptor_set)}));
    annotations.push_back(make(spv::OpDecorate, {push_variable, spv::DecorationBinding, 0}));
    if (version >= 0x00010400) new_interface.push_back(push_variable);
  } else if (push_variable) {
    const uint32_t block = x.pointee(x.variables.at(push_variable).pointer_type);
    auto s = std::find_if(module.begin(), module.end(), [&](const Instruction& i) {
      return i.opcode == spv::OpTypeStruct && i.operands[0] == block;
    });
    if (s == module.end()) return why = "push-constant block is not a struct", std::vector<uint32_t>{};
    member_a = static_cast<uint32_t>(s->operands.size() - 1);
    for (uint32_t m = 0; m < member_a; ++m) {
      const uint32_t offset = x.member_decorations.count({block, m})
                                  ? x.member_decorations.at({block, m}).count(spv::DecorationOffset)
                                        ? x.member_decorations.at({block, m}).at(spv::DecorationOffset)
                                        : 0
                                  : 0;
      if (offset >= id.push_offset)
        return why = "the shader's push constants reach offset " + std::to_string(offset) + ", where the layer's id goes",
               std::vector<uint32_t>{};
    }
    s->operands.push_back(uint_type);
    s->operands.push_back(uint_type);
    // The block now names the integer type: a module that declares it only after the block (glslang
    // does, for SuperTuxKart's skybox) has the declaration moved up to just before the block.
    const size_t block_at = static_cast<size_t>(s - module.begin());
    for (size_t k = block_at + 1; k < module.size(); ++k)
      if (module[k].opcode == spv::OpTypeInt && module[k].operands[0] == uint_type) move_before[block_at] = k;
    annotations.push_back(make(spv::OpMemberDecorate, {block, member_a, spv::DecorationOffset, id.push_offset}));
    annotations.push_back(make(spv::OpMemberDecorate, {block, member_a + 1, spv::DecorationOffset, id.push_offset + 4}));
  } else {
    const uint32_t block = bound++;
    globals.push_back(make(spv::OpTypeStruct, {block, uint_type, uint_type}));
    annotations.push_back(make(spv::OpDecorate, {block, spv::DecorationBlock}));
    annotations.push_back(make(spv::OpMemberDecorate, {block, 0, spv::DecorationOffset, id.push_offset}));
    annotations.push_back(make(spv::OpMemberDecorate, {block, 1, spv::DecorationOffset, id.push_offset + 4}));
    const uint32_t block_pointer = pointer(spv::StorageClassPushConstant, block);
    push_variable = bound++;
    globals.push_back(make(spv::OpVariable, {block_pointer, push_variable, spv::StorageClassPushConstant}));
    if (version >= 0x00010400) new_interface.push_back(push_variable);
  }
  const uint32_t push_uint_pointer = pointer(id_storage, uint_type);
  const uint32_t index_a = constant(member_a), index_b = constant(member_a + 1), one = constant(1);

  // gl_PrimitiveID: the shader's own, or an input of ours.
  uint32_t primitive_type = 0;
  if (primitive_variable) {
    primitive_type = x.pointee(x.variables.at(primitive_variable).pointer_type);
    auto& ops = module[entry_at].operands;
    if (std::find(ops.begin() + 3, ops.end(), primitive_variable) == ops.end()) new_interface.push_back(primitive_variable);
  } else {
    primitive_type = findType(spv::OpTypeInt, {32, 1});
    const uint32_t input_pointer = pointer(spv::StorageClassInput, primitive_type);
    primitive_variable = bound++;
    globals.push_back(make(spv::OpVariable, {input_pointer, primitive_variable, spv::StorageClassInput}));
    annotations.push_back(make(spv::OpDecorate, {primitive_variable, spv::DecorationBuiltIn, spv::BuiltInPrimitiveId}));
    annotations.push_back(make(spv::OpDecorate, {primitive_variable, spv::DecorationFlat}));
    new_interface.push_back(primitive_variable);
  }
  auto primitive_int = x.types.find(primitive_type);
  const bool primitive_signed = primitive_int == x.types.end() || primitive_int->second.operands.size() < 3 ||
                                primitive_int->second.operands[2] == 1;

  // The id output.
  const uint32_t output_pointer = pointer(spv::StorageClassOutput, uvec4_type);
  const uint32_t output = bound++;
  globals.push_back(make(spv::OpVariable, {output_pointer, output, spv::StorageClassOutput}));
  annotations.push_back(make(spv::OpDecorate, {output, spv::DecorationLocation, id.location}));
  new_interface.push_back(output);

  // Written first thing in the entry point (a discarded fragment writes nothing).
  const uint32_t a_ptr = bound++, a = bound++, b_ptr = bound++, b = bound++, prim = bound++, value = bound++;
  code.push_back(make(spv::OpAccessChain, {push_uint_pointer, a_ptr, push_variable, index_a}));
  code.push_back(make(spv::OpLoad, {uint_type, a, a_ptr}));
  code.push_back(make(spv::OpAccessChain, {push_uint_pointer, b_ptr, push_variable, index_b}));
  code.push_back(make(spv::OpLoad, {uint_type, b, b_ptr}));
  uint32_t prim_uint = prim;
  code.push_back(make(spv::OpLoad, {primitive_type, prim, primitive_variable}));
  if (primitive_signed) {
    prim_uint = bound++;
    code.push_back(make(spv::OpBitcast, {uint_type, prim_uint, prim}));
  }
  code.push_back(make(spv::OpCompositeConstruct, {uvec4_type, value, a, b, prim_uint, one}));
  code.push_back(make(spv::OpStore, {output, value}));

  size_t body_at = module.size();
  for (size_t k = first_function; k < module.size(); ++k) {
    if (module[k].opcode != spv::OpFunction || module[k].operands[1] != function_id) continue;
    size_t j = k + 1;
    while (j < module.size() && module[j].opcode == spv::OpFunctionParameter) ++j;
    if (j >= module.size() || module[j].opcode != spv::OpLabel) break;
    ++j;
    while (j < module.size() && (module[j].opcode == spv::OpVariable || module[j].opcode == spv::OpLine ||
                                 module[j].opcode == spv::OpNoLine))
      ++j;
    body_at = j;
    break;
  }
  if (body_at == module.size()) return why = "entry point's function body not found", std::vector<uint32_t>{};

  auto& interface = module[entry_at].operands;
  interface.insert(interface.end(), new_interface.begin(), new_interface.end());

  // Reassembled in section order: capability, ..., annotations, types, globals, functions.
  std::vector<Instruction> out;
  out.reserve(module.size() + scalar_types.size() + annotations.size() + globals.size() + code.size() + 1);
  for (size_t k = 0; k < module.size(); ++k) {
    if (k == first_global) {
      out.insert(out.end(), annotations.begin(), annotations.end());
      out.insert(out.end(), scalar_types.begin(), scalar_types.end());
    }
    if (k == first_function) out.insert(out.end(), globals.begin(), globals.end());
    if (k == body_at) out.insert(out.end(), code.begin(), code.end());
    if (move_before.count(k)) out.push_back(module[move_before[k]]);
    if (std::any_of(move_before.begin(), move_before.end(), [k](const auto& m) { return m.second == k; })) {
      if (after.count(k)) out.insert(out.end(), after[k].begin(), after[k].end());
      continue;
    }
    out.push_back(module[k]);
    if (after.count(k)) out.insert(out.end(), after[k].begin(), after[k].end());
    if (k == last_capability && !has_geometry) out.push_back(make(spv::OpCapability, {spv::CapabilityGeometry}));
  }
  std::vector<uint32_t> rewritten = assemble(header, out);
  // Never hand the driver a module that is not valid: SPIRV-Tools' validator, for the Vulkan
  // version the module's SPIR-V version implies.
  const spv_target_env env = version >= 0x00010600   ? SPV_ENV_VULKAN_1_3
                             : version >= 0x00010400 ? SPV_ENV_VULKAN_1_2
                             : version >= 0x00010300 ? SPV_ENV_VULKAN_1_1
                                                     : SPV_ENV_VULKAN_1_0;
  spvtools::SpirvTools tools(env);
  std::string messages;
  tools.SetMessageConsumer([&messages](spv_message_level_t, const char*, const spv_position_t&, const char* m) {
    if (messages.empty()) messages = m;
  });
  spvtools::ValidatorOptions options;
  options.SetRelaxBlockLayout(true);
  options.SetScalarBlockLayout(true);  // the program's own layouts are the driver's to accept
  if (!tools.Validate(rewritten.data(), rewritten.size(), options)) {
    why = "the rewritten module is not valid SPIR-V (" + messages + ")";
    return {};
  }
  return rewritten;
}

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
