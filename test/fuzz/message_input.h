// Messages from fuzz bytes: ROS-serialized messages, one after another, read with
// ros::serialization as roscpp reads them off the wire, and the seeds' way back (serialized
// messages the package's converter built).
#pragma once

#include <ros/serialization.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <vector>

namespace viper::fuzz {

/// An allocator that refuses to hold more elements than the input has bytes. roscpp resizes a
/// vector to the length the bytes announce before it reads its elements, so four bytes can ask for
/// gigabytes; every element takes at least one byte, so no valid message needs more.
template <class T>
struct CappedAllocator {
  using value_type = T;
  static inline size_t max_elements = 0;
  CappedAllocator() = default;
  template <class U>
  CappedAllocator(const CappedAllocator<U>&) {}
  template <class U>
  struct rebind {
    using other = CappedAllocator<U>;
  };
  T* allocate(size_t n) {
    if (n > max_elements + 1) throw std::bad_alloc();
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, size_t n) { std::allocator<T>().deallocate(p, n); }
  template <class U>
  bool operator==(const CappedAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const CappedAllocator<U>&) const { return false; }
};

/// Reads the messages of a fuzz input in order.
class MessageInput {
 public:
  MessageInput(const uint8_t* data, size_t size)
      : data_(const_cast<uint8_t*>(data)), size_(static_cast<uint32_t>(size)), stream_(data_, size_) {}

  /// Reads the next message into `msg` (of type M<std::allocator<void>>). False, with `msg` and
  /// the position unchanged, if the bytes left do not hold one: first read as M<CappedAllocator>,
  /// so a length no input could fill is refused before anything is allocated for it.
  template <template <class> class M>
  bool next(M<std::allocator<void>>& msg) {
    namespace ser = ros::serialization;
    CappedAllocator<void>::max_elements = size_;
    try {
      M<CappedAllocator<void>> probe;
      ser::IStream copy(stream_.getData(), stream_.getLength());
      ser::deserialize(copy, probe);
      ser::deserialize(stream_, msg);
    } catch (const ser::StreamOverrunException&) {
      return false;
    } catch (const std::bad_alloc&) {
      return false;
    }
    return true;
  }

 private:
  uint8_t* data_;
  uint32_t size_;
  ros::serialization::IStream stream_;
};

/// Appends the serialized bytes of `msg` to `out` (what MessageInput::next reads back).
template <class M>
void appendMessage(std::vector<uint8_t>& out, const M& msg) {
  const uint32_t length = ros::serialization::serializationLength(msg);
  const size_t at = out.size();
  out.resize(at + length);
  ros::serialization::OStream stream(out.data() + at, length);
  ros::serialization::serialize(stream, msg);
}

}  // namespace viper::fuzz
