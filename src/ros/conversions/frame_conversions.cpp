#include "viper/ros/conversions/frame_conversions.h"

#include <boost/make_shared.hpp>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace viper {

namespace {

// A matrix between a GlMatrix and a message's float32[16], either way (column-major both).
template <typename Array>
void copyMatrix(const GlMatrix& m, Array& out) {
  std::copy(m.data(), m.data() + 16, out.begin());
}
template <typename Array>
void copyMatrix(const Array& a, GlMatrix& m) {
  std::copy(a.begin(), a.end(), m.data());
}

// The fields a DrawRecord and a Draw message share, from one to the other (either way): one list
// for both conversions, so that a field cannot be added to one and not the other.
template <typename From, typename To>
void copyDrawFields(const From& from, To& to) {
  to.index = from.index;
  to.mesh_key = from.mesh_key;
  to.vertex_buffer_key = from.vertex_buffer_key;
  to.index_buffer_key = from.index_buffer_key;
  to.program_key = from.program_key;
  to.texture_keys = from.texture_keys;
  to.matrix_flags = from.matrix_flags;
  copyMatrix(from.world, to.world);
  copyMatrix(from.view, to.view);
  copyMatrix(from.projection, to.projection);
  to.primitive_mode = from.primitive_mode;
  to.primitive_count = from.primitive_count;
  to.visible_pixels = from.visible_pixels;
  to.deformed_clip_xyzw = from.deformed_clip_xyzw;
}

// The same for a MeshRecord and a Mesh message.
template <typename From, typename To>
void copyMeshFields(const From& from, To& to) {
  to.key = from.key;
  to.positions_xyz = from.positions_xyz;
  to.indices = from.indices;
}

void checkSize(const CaptureFrame& frame, size_t have, size_t per_pixel, const char* what) {
  if (have != frame.pixelCount() * per_pixel) {
    std::ostringstream msg;
    msg << "frame " << frame.number << ": " << what << " holds " << have << " values, expected "
        << frame.pixelCount() * per_pixel << " for " << frame.width << "x" << frame.height;
    throw std::invalid_argument(msg.str());
  }
}

}  // namespace

Draw toDrawMsg(const DrawRecord& draw) {
  Draw msg;
  copyDrawFields(draw, msg);
  return msg;
}

DrawRecord fromDrawMsg(const Draw& msg) {
  DrawRecord draw;
  fromDrawMsg(msg, draw);
  return draw;
}

void fromDrawMsg(const Draw& msg, DrawRecord& draw) {
  copyDrawFields(msg, draw);
  draw.gaps = 0;  // not in the message
}

DrawList toDrawListMsg(const CaptureFrame& frame, const std_msgs::Header& header) {
  DrawList msg;
  msg.header = header;
  msg.frame_number = frame.number;
  msg.condition = frame.condition;
  msg.draws.reserve(frame.draws.size());
  for (const DrawRecord& d : frame.draws) msg.draws.push_back(toDrawMsg(d));
  return msg;
}

void fromDrawListMsg(const DrawList& msg, CaptureFrame& frame) {
  frame.number = msg.frame_number;
  frame.condition = msg.condition;
  // Into the draws already there: their vectors keep their storage (no allocation a draw where a
  // node converts into the same frame message after message).
  frame.draws.resize(msg.draws.size());
  for (size_t i = 0; i < msg.draws.size(); ++i) fromDrawMsg(msg.draws[i], frame.draws[i]);
}

Mesh toMeshMsg(const MeshRecord& mesh) {
  Mesh msg;
  copyMeshFields(mesh, msg);
  return msg;
}

MeshRecord fromMeshMsg(const Mesh& msg) {
  MeshRecord mesh;
  copyMeshFields(msg, mesh);
  return mesh;
}

std::vector<MeshRecord> fromMeshStoreMsg(const MeshStore& msg, std::vector<std::string>& problems,
                                         const MeshRegistry* known) {
  std::vector<MeshRecord> meshes;
  for (const Mesh& m : msg.meshes) {
    if (known && known->holds(m.key, m.positions_xyz, m.indices)) continue;
    if (m.positions_xyz.size() % 3 != 0 || m.indices.size() % 3 != 0) {
      std::ostringstream what;
      what << "mesh " << std::hex << m.key << std::dec << " has " << m.positions_xyz.size() << " position floats and "
           << m.indices.size() << " indices (multiples of 3 expected); skipped";
      problems.push_back(what.str());
      continue;
    }
    meshes.push_back(fromMeshMsg(m));
  }
  return meshes;
}

std::string frameFromDrawMsgs(const DrawList& draws, const sensor_msgs::Image& ids, CaptureFrame& frame,
                              const uint32_t*& id_words) {
  const std::string problem = checkImage(ids, sensor_msgs::image_encodings::TYPE_32SC1);
  if (!problem.empty()) return "draw_ids: " + problem;
  if (ids.header.stamp != draws.header.stamp) return "draw_ids and draws have different stamps";
  frame.width = ids.width;
  frame.height = ids.height;
  frame.time_s = draws.header.stamp.toSec();
  fromDrawListMsg(draws, frame);
  // Message buffers come from new[], aligned for any scalar type.
  id_words = reinterpret_cast<const uint32_t*>(ids.data.data());
  return {};
}

std::string frameFromDrawMsgs(const DrawList& draws, const sensor_msgs::Image& ids, CaptureFrame& frame) {
  const uint32_t* id_words = nullptr;
  const std::string problem = frameFromDrawMsgs(draws, ids, frame, id_words);
  // assign, not resize + memcpy: written once, not zeroed first.
  if (problem.empty()) frame.draw_ids.assign(id_words, id_words + frame.pixelCount());
  return problem;
}

namespace {

// The raw images of a frame, each written once into a message of `pool` (frameMessages); the
// converters of one image below take theirs from a pool of their own.
sensor_msgs::ImagePtr colorMsg(const CaptureFrame& frame, const std_msgs::Header& header, ImageMsgPool& pool) {
  checkSize(frame, frame.color_rgb.size(), 3, "color");
  sensor_msgs::ImagePtr m = pool.take(header, frame.width, frame.height, sensor_msgs::image_encodings::RGB8, 3);
  std::copy(frame.color_rgb.begin(), frame.color_rgb.end(), m->data.begin());
  return m;
}

sensor_msgs::ImagePtr drawIdMsg(const CaptureFrame& frame, const std_msgs::Header& header, ImageMsgPool& pool) {
  checkSize(frame, frame.draw_ids.size(), 1, "draw ids");
  // Draw ids are index + 1 of at most a few million draws: they fit a signed int unchanged.
  sensor_msgs::ImagePtr m = pool.take(header, frame.width, frame.height, sensor_msgs::image_encodings::TYPE_32SC1, 4);
  std::memcpy(m->data.data(), frame.draw_ids.data(), m->data.size());
  return m;
}

// -1 where no draw is; `ids` holds the frame's draw ids, checked for size.
sensor_msgs::ImagePtr primitiveIdMsg(const CaptureFrame& frame, const uint32_t* ids, const std_msgs::Header& header,
                                     ImageMsgPool& pool) {
  checkSize(frame, frame.primitive_ids.size(), 1, "primitive ids");
  sensor_msgs::ImagePtr m = pool.take(header, frame.width, frame.height, sensor_msgs::image_encodings::TYPE_32SC1, 4);
  maskPrimitiveIds(ids, frame.primitive_ids.data(), frame.pixelCount(), reinterpret_cast<int32_t*>(m->data.data()));
  return m;
}

}  // namespace

sensor_msgs::Image colorImage(const CaptureFrame& frame, const std_msgs::Header& header) {
  ImageMsgPool own(1);
  return *colorMsg(frame, header, own);
}

sensor_msgs::Image depthImage(const CaptureFrame& frame, const std::vector<float>& depth_m,
                              const std_msgs::Header& header) {
  checkSize(frame, depth_m.size(), 1, "depth");
  return imageMsg(header, frame.width, frame.height, sensor_msgs::image_encodings::TYPE_32FC1, 4, depth_m.data());
}

sensor_msgs::Image drawIdImage(const CaptureFrame& frame, const std_msgs::Header& header) {
  ImageMsgPool own(1);
  return *drawIdMsg(frame, header, own);
}

sensor_msgs::Image primitiveIdImage(const CaptureFrame& frame, const std_msgs::Header& header) {
  checkSize(frame, frame.draw_ids.size(), 1, "draw ids");
  ImageMsgPool own(1);
  return *primitiveIdMsg(frame, frame.draw_ids.data(), header, own);
}

std::string colorFromImage(const sensor_msgs::Image& color, CaptureFrame& frame) {
  const std::string problem = checkImage(color, sensor_msgs::image_encodings::RGB8, frame.width, frame.height);
  if (!problem.empty()) return problem;
  frame.color_rgb.assign(color.data.begin(), color.data.end());
  return {};
}

std::string depthFromImage(const sensor_msgs::Image& depth, const CaptureFrame& frame, std::vector<float>& depth_m) {
  const std::string problem = checkImage(depth, sensor_msgs::image_encodings::TYPE_32FC1, frame.width, frame.height);
  if (!problem.empty()) return problem;
  const auto* metres = reinterpret_cast<const float*>(depth.data.data());
  depth_m.assign(metres, metres + frame.pixelCount());
  return {};
}

std::string primitiveIdsFromImage(const sensor_msgs::Image& primitive_ids, CaptureFrame& frame) {
  const std::string problem =
      checkImage(primitive_ids, sensor_msgs::image_encodings::TYPE_32SC1, frame.width, frame.height);
  if (!problem.empty()) return problem;
  const auto* words = reinterpret_cast<const uint32_t*>(primitive_ids.data.data());
  frame.primitive_ids.assign(words, words + frame.pixelCount());
  return {};
}

sensor_msgs::CameraInfo cameraInfo(const PinholeIntrinsics* intrinsics, uint32_t width, uint32_t height,
                                   const std_msgs::Header& header) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = width;
  info.height = height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (intrinsics) {
    const Eigen::Matrix3d k = intrinsics->K();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        info.K[r * 3 + c] = k(r, c);
        info.P[r * 4 + c] = k(r, c);
      }
    }
  }
  return info;
}

bool MeshStoreAccumulator::add(const std::vector<MeshRecord>& meshes) {
  bool grew = false;
  for (const MeshRecord& mesh : meshes) {
    if (keys_.insert(mesh.key).second) {
      store_.meshes.push_back(toMeshMsg(mesh));
      grew = true;
    }
  }
  return grew;
}

FrameMessages frameMessages(const CaptureFrame& frame, const std_msgs::Header& header, MeshStoreAccumulator& meshes) {
  FrameImagePools once;
  return frameMessages(frame, header, meshes, once);
}

namespace {

struct SunkImage {
  const std::string* encoding;
  uint32_t bytes_per_pixel;
};
// How FrameImageMessages holds each image (CaptureImage order).
const SunkImage kSunk[4] = {{&sensor_msgs::image_encodings::RGB8, 3},
                            {&sensor_msgs::image_encodings::TYPE_32FC1, 4},
                            {&sensor_msgs::image_encodings::TYPE_32SC1, 4},
                            {&sensor_msgs::image_encodings::TYPE_32SC1, 4}};

const uint32_t* words(const sensor_msgs::ImagePtr& m) {
  return m ? reinterpret_cast<const uint32_t*>(m->data.data()) : nullptr;
}

}  // namespace

void* FrameImageMessages::imageStorage(CaptureImage image, const CaptureFrame& frame, size_t bytes) {
  const int k = static_cast<int>(image);
  if (k < 0 || k > 3 || bytes != frame.pixelCount() * kSunk[k].bytes_per_pixel) return nullptr;
  ImageMsgPool* pool[4] = {&pools_.color, &pools_.depth, &pools_.draw_ids, &pools_.primitive_ids};
  held_[k] = pool[k]->take(std_msgs::Header(), frame.width, frame.height, *kSunk[k].encoding, kSunk[k].bytes_per_pixel);
  return held_[k]->data.data();
}

void FrameImageMessages::clear() {
  for (sensor_msgs::ImagePtr& m : held_) m.reset();
}

FrameImagesElsewhere FrameImageMessages::elsewhere() const {
  FrameImagesElsewhere at;
  if (held_[0]) at.color_rgb = held_[0]->data.data();
  if (held_[1]) at.depth_window = reinterpret_cast<const float*>(held_[1]->data.data());
  at.draw_ids = words(held_[2]);
  at.primitive_ids = words(held_[3]);
  at.draw_id_range_later = holdsIdsAndDepth();  // frameMessages checks them
  return at;
}

FrameMessages frameMessages(const CaptureFrame& frame, const std_msgs::Header& header, MeshStoreAccumulator& meshes,
                            FrameImagePools& pools) {
  const FrameImageMessages none(pools);
  return frameMessages(frame, header, meshes, pools, none);
}

FrameMessages frameMessages(const CaptureFrame& frame, const std_msgs::Header& header, MeshStoreAccumulator& meshes,
                            FrameImagePools& pools, const FrameImageMessages& sunk) {
  FrameMessages out;
  const std::optional<FrameCamera> camera = chooseFrameCamera(frame);
  std::optional<PinholeIntrinsics> intrinsics;
  if (camera) {
    try {
      intrinsics = intrinsicsFromGlProjection(camera->projection, frame.width, frame.height);
    } catch (const std::invalid_argument& e) {
      out.camera_problem = std::string(e.what()) + "; camera_info left uncalibrated";
    }
  } else {
    out.camera_problem =
        "no draw with view and projection matrices: depth is NaN where no draw projection applies, camera_info "
        "uncalibrated (check the capture profile)";
  }

  // Each image written once, into its message: the sink's messages hold theirs already; depth in
  // metres straight from the window depth, in place in the sink's message.
  const sensor_msgs::ImagePtr& sunk_color = sunk.message(CaptureImage::kColor);
  const sensor_msgs::ImagePtr& sunk_depth = sunk.message(CaptureImage::kDepth);
  const sensor_msgs::ImagePtr& sunk_ids = sunk.message(CaptureImage::kDrawIds);
  const sensor_msgs::ImagePtr& sunk_primitives = sunk.message(CaptureImage::kPrimitiveIds);
  out.color = sunk_color ? sunk_color : colorMsg(frame, header, pools.color);
  out.draw_ids = sunk_ids ? sunk_ids : drawIdMsg(frame, header, pools.draw_ids);
  const uint32_t* ids = words(out.draw_ids);  // the frame's draw ids, checked for size
  const FrameCamera* cam = camera ? &*camera : nullptr;
  if (sunk.holdsIdsAndDepth()) {
    // All three in their messages (the bridge): depth in metres, the primitive ids masked and the
    // draw ids' range checked (validateFrame left it, FrameImageMessages::elsewhere) in one pass.
    out.primitive_ids = sunk_primitives;
    out.depth = sunk_depth;
    auto* metres = reinterpret_cast<float*>(out.depth->data.data());
    const uint32_t largest = depthMetresMaskingPrimitives(
        frame, ids, metres, cam, metres, reinterpret_cast<int32_t*>(out.primitive_ids->data.data()));
    const std::string problem = drawIdsProblem(frame, ids, largest);
    if (!problem.empty()) throw std::invalid_argument(problem);
  } else {
    if (sunk_primitives) {
      out.primitive_ids = sunk_primitives;
      auto* primitives = reinterpret_cast<int32_t*>(out.primitive_ids->data.data());
      maskPrimitiveIds(ids, reinterpret_cast<const uint32_t*>(primitives), frame.pixelCount(), primitives);
    } else {
      out.primitive_ids = primitiveIdMsg(frame, ids, header, pools.primitive_ids);
    }
    if (sunk_depth) {
      out.depth = sunk_depth;
      auto* metres = reinterpret_cast<float*>(out.depth->data.data());
      depthMetres(frame, ids, metres, cam, metres);
    } else {
      out.depth = pools.depth.take(header, frame.width, frame.height, sensor_msgs::image_encodings::TYPE_32FC1, 4);
      depthMetres(frame, cam, reinterpret_cast<float*>(out.depth->data.data()));
    }
  }
  for (const sensor_msgs::ImagePtr* m : {&out.color, &out.draw_ids, &out.primitive_ids, &out.depth}) (*m)->header = header;
  out.camera_info = boost::make_shared<sensor_msgs::CameraInfo>(
      cameraInfo(intrinsics ? &*intrinsics : nullptr, frame.width, frame.height, header));
  out.draws = boost::make_shared<DrawList>(toDrawListMsg(frame, header));
  // Only once every message is built, so a frame that throws leaves the store as it was.
  if (meshes.add(frame.new_meshes)) {
    out.mesh_store = boost::make_shared<MeshStore>(meshes.store());
    out.mesh_store->header = header;
  }
  return out;
}

std::string frameFromMessages(const FrameMessages& m, CaptureFrame& frame, std::vector<float>* depth_m) {
  if (!m.draws || !m.draw_ids || !m.color || !m.depth || !m.primitive_ids)
    return "a frame needs its draws, draw_ids, color, depth and primitive_ids messages";
  std::string problem = frameFromDrawMsgs(*m.draws, *m.draw_ids, frame);
  if (problem.empty()) {
    problem = colorFromImage(*m.color, frame);
    if (!problem.empty()) problem = "color: " + problem;
  }
  if (problem.empty()) {
    problem = primitiveIdsFromImage(*m.primitive_ids, frame);
    if (!problem.empty()) problem = "primitive_ids: " + problem;
  }
  std::vector<float> metres;
  if (problem.empty()) {
    problem = depthFromImage(*m.depth, frame, metres);
    if (!problem.empty()) problem = "depth: " + problem;
  }
  if (!problem.empty()) return problem;
  const std::optional<FrameCamera> camera = chooseFrameCamera(frame);
  frame.depth_window = windowDepthFromMetres(frame, metres, camera ? &camera->projection : nullptr);
  frame.new_meshes.clear();
  if (m.mesh_store)
    for (const Mesh& mesh : m.mesh_store->meshes) frame.new_meshes.push_back(fromMeshMsg(mesh));
  if (depth_m) *depth_m = std::move(metres);
  return {};
}

}  // namespace viper
