// libFuzzer target: arbitrary bytes as a capture stream and as a bare frame payload.
// Nothing may crash, leak or read out of bounds; malformed input must end in an exception. Half the
// streams are read with an image sink, which must be given storage for exactly the bytes written.
// Seeds: a valid two-frame stream of each codec (zstd, LZ4) and a bare payload, all from the
// package's writer.
#include "fuzz_support.h"
#include "seed_frame.h"
#include "viper/capture/capture_stream.h"

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

void viper::fuzz::writeSeeds(const std::string& dir) {
  viper::CaptureHeader header;
  header.program = "seed";
  for (viper::CaptureCodec codec : {viper::CaptureCodec::kZstd, viper::CaptureCodec::kLz4}) {
    header.codec = codec;
    viper::CaptureWriter writer(dir + "/stream_" + viper::captureCodecName(codec) + ".vcap", header, 1);
    writer.write(viper::fuzz::seedFrame(0));
    writer.write(viper::fuzz::seedFrame(1));
  }
  writeBytes(dir + "/payload.bin", viper::encodeFramePayload(viper::fuzz::seedFrame(2)));
}

namespace {

// Gives each image storage of exactly the size asked (AddressSanitizer reports a byte past it),
// and declines the primitive ids (left in the frame).
class FuzzSink : public viper::CaptureImageSink {
 public:
  void* imageStorage(viper::CaptureImage image, const viper::CaptureFrame&, size_t bytes) override {
    if (image == viper::CaptureImage::kPrimitiveIds) return nullptr;
    std::vector<char>& v = stored_[static_cast<int>(image)];
    v.assign(bytes, 0);
    v.shrink_to_fit();
    return v.data();
  }

 private:
  std::vector<char> stored_[4];
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Checksums guard the stream's payloads, so the decoder is also fed the bytes directly.
  viper::CaptureFrame frame;
  try {
    viper::decodeFramePayload(reinterpret_cast<const char*>(data), size, frame);
    viper::validateFrame(frame);
  } catch (const std::runtime_error&) {
  }

  if (size == 0) return 0;
  std::string bytes(reinterpret_cast<const char*>(data), size);
  std::FILE* file = fmemopen(&bytes[0], bytes.size(), "rb");
  if (!file) return 0;
  try {
    viper::CaptureReader reader(file, "fuzz-input");
    FuzzSink sink;
    if (size % 2 == 1) reader.setImageSink(&sink);
    for (int i = 0; i < 64; ++i) {
      // Whole frames and frames without images (which skips the images' zstd frame or LZ4 part) in turn.
      const bool follow = i % 2 == 1;
      const viper::CaptureReader::Status status =
          i % 4 < 2 ? reader.next(frame, follow) : reader.nextWithoutImages(frame, follow);
      if (status == viper::CaptureReader::Status::kEnd) break;
      if (status == viper::CaptureReader::Status::kFrame) viper::validateFrame(frame);
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
