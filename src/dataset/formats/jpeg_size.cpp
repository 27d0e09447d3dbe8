#include "jpeg_size.h"

#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE
#include <jpeglib.h>
#include <stdexcept>

namespace viper::dataset {
namespace {

// libjpeg's error handler must not return: it long-jumps back to the setjmp in readJpegSize.
struct JpegErrors {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {0};
};

[[noreturn]] void jpegError(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  cinfo->err->format_message(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}

void jpegMessage(j_common_ptr) {}  // warnings: the decoder that follows reports what matters

}  // namespace

JpegSize readJpegSize(const uint8_t* bytes, size_t size) {
  jpeg_decompress_struct cinfo;
  JpegErrors errors;
  cinfo.err = jpeg_std_error(&errors.mgr);
  errors.mgr.error_exit = jpegError;
  errors.mgr.output_message = jpegMessage;
  if (setjmp(errors.jump)) {
    jpeg_destroy_decompress(&cinfo);
    throw std::runtime_error(errors.message);
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, bytes, static_cast<unsigned long>(size));
  jpeg_read_header(&cinfo, TRUE);
  const JpegSize out{cinfo.image_width, cinfo.image_height};
  jpeg_destroy_decompress(&cinfo);
  return out;
}

}  // namespace viper::dataset
