// What the Vulkan capture layer reads from and writes into a program's SPIR-V: where its matrices
// and position attribute are (by the names a capture profile uses, read from the module's debug
// names), and the id output added to a fragment shader. Pure word manipulation, no Vulkan calls:
// tested on modules glslang compiles (test/capture/test_spirv_module.cpp).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace viper {
namespace capture {
namespace vulkan {

/// Where a block member lives: push constants (`push_constant`), or a uniform or storage buffer
/// bound at (set, binding). `offset` is the member's byte offset in the block.
struct BlockMember {
  bool push_constant = false;
  uint32_t set = 0;
  uint32_t binding = 0;
  uint32_t offset = 0;
  /// mat4 members: bytes between columns (rows when row_major); 0 when the member is not a matrix.
  uint32_t matrix_stride = 0;
  bool row_major = false;
  /// Columns and rows of a float matrix member (4 x 4 for mat4); 0 for other members.
  uint32_t columns = 0;
  uint32_t rows = 0;
  /// Components of a float vector member (3 for vec3); 0 for other members.
  uint32_t components = 0;
  /// Members of the structs of an array member (`ObjectData m_objects[]`, each named by its own
  /// name): bytes between elements; element i's member is at offset + i * array_stride. 0: no array.
  uint32_t array_stride = 0;
};

/// What the layer needs to know of one shader module (one entry point's view of it).
struct ModuleReflection {
  bool valid = false;
  std::string problem;  ///< why not valid
  uint32_t version = 0;  ///< SPIR-V version word (0x00010000 = 1.0)
  /// Execution model of each entry point by name (spv::ExecutionModel values: 0 vertex, 4 fragment).
  std::map<std::string, uint32_t> entry_points;
  /// Block members by name (the member's OpMemberName), in push constants and in uniform and
  /// storage blocks; the first found wins when two blocks have a member of one name.
  std::map<std::string, BlockMember> members;
  /// Input variables by name (OpName) with their Location.
  std::map<std::string, uint32_t> input_locations;
  /// Every debug name of the module (OpName, OpMemberName), one per line: what a profile's
  /// `vertex_contains` is matched against for Vulkan programs (SPIR-V carries no source text).
  std::string names_text;
  /// Highest byte offset past the end of the push-constant block the module declares (0 if none).
  uint32_t push_constant_end = 0;
  /// The module declares the BaseInstance built-in (gl_BaseInstance).
  bool reads_base_instance = false;
  /// (set, binding) of its images and combined image samplers, in set and binding order: the order
  /// of a draw's texture keys.
  std::vector<std::pair<uint32_t, uint32_t>> images;
};

/// Reads `words` (a whole SPIR-V module). Never throws; `valid` false with `problem` on bad input.
ModuleReflection reflectModule(const std::vector<uint32_t>& words);

/// Where the id output goes and what it writes: (a, b, primitive id, 1) as an unsigned 4-vector at
/// fragment output `location`, with a and b the two words at `push_offset` of the push constants,
/// or, when `descriptor_set` >= 0, at offsets 0 and 4 of a uniform buffer bound at
/// (descriptor_set, binding 0) (for programs whose push constants leave no room).
struct IdOutput {
  uint32_t location = 0;
  uint32_t push_offset = 0;
  int32_t descriptor_set = -1;
};

/// Adds the id output to the fragment entry point `entry` of `words`. Returns the new module,
/// or an empty vector with `why` set when the module cannot take it (not a fragment shader, the
/// location taken, dual-source blending, a push-constant block that overlaps the layer's bytes,
/// unparsable input). The program's own code, outputs and interface are kept as they are.
std::vector<uint32_t> addIdOutput(const std::vector<uint32_t>& words, const std::string& entry, const IdOutput& id,
                                  std::string& why);

}  // namespace vulkan
}  // namespace capture
}  // namespace viper
