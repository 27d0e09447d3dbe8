// numpy's .npy array format (https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html):
// "\x93NUMPY", major and minor version bytes, a little-endian header length (uint16 in 1.0,
// uint32 in 2.0 and 3.0), then a Python dict literal {'descr': ..., 'fortran_order': ...,
// 'shape': (...)} padded with spaces and ending in '\n', then the raw element bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace viper::dataset {

/// One numpy array with its raw bytes, element type not interpreted.
struct NpyArray {
  /// numpy's type string: byte order ('<' little, '>' big, '|' not applicable, '=' native),
  /// kind letter, item size in bytes; e.g. "<f2" (float16), "<f4" (float32).
  std::string descr;
  /// true: elements are stored column-major (first index fastest), false: row-major.
  bool fortran_order = false;
  std::vector<uint64_t> shape;
  /// Elements, product(shape) * itemSize(descr) bytes.
  std::vector<uint8_t> data;
};

/// Item size in bytes of a simple type string such as "<f2" (the digits after the kind letter).
/// Throws std::invalid_argument for anything else (structured or object types).
size_t npyItemSize(const std::string& descr);

/// Number of elements: the product of `shape` (1 for a 0-d array). Throws std::invalid_argument
/// on overflow.
uint64_t npyElementCount(const std::vector<uint64_t>& shape);

/// What an .npy header says, and where the element bytes start.
struct NpyHeader {
  std::string descr;
  bool fortran_order = false;
  std::vector<uint64_t> shape;
  size_t data_offset = 0;  ///< the element bytes are bytes[data_offset, size)
};

/// The bytes numpy.save writes before the elements of such an array: version 1.0, header padded
/// with spaces so that the data starts at a multiple of 64 bytes. Throws std::invalid_argument
/// for an unsupported descr or a header over 65535 bytes.
std::vector<uint8_t> encodeNpyHeader(const std::string& descr, bool fortran_order,
                                     const std::vector<uint64_t>& shape);

/// Parses the header of .npy bytes and checks that exactly the elements it announces follow
/// (errors as decodeNpy), without copying them.
NpyHeader decodeNpyHeader(const uint8_t* bytes, size_t size, const std::string& name);

/// Encodes an array as version 1.0 .npy bytes, exactly as numpy.save writes them (header padded
/// so that the data starts at a multiple of 64 bytes). Throws std::invalid_argument if the data
/// size does not match shape and descr.
std::vector<uint8_t> encodeNpy(const NpyArray& array);

/// Decodes .npy bytes of version 1.0, 2.0 or 3.0. `name` names the bytes in error messages (e.g.
/// "flow.npz:u.npy"). Throws std::runtime_error naming `name` and the byte offset for a bad magic,
/// unknown version, malformed or truncated header, header keys other than numpy's three, a
/// structured descr, or a data size that does not match the shape.
NpyArray decodeNpy(const uint8_t* bytes, size_t size, const std::string& name);

}  // namespace viper::dataset
