// A captured frame: core types (CaptureFrame, draws, meshes) <-> the capture bridge's raw messages
// (draw list, mesh store, color, depth, draw id and primitive id images, camera info), both ways.
// Part of the converter between messages and core types (include/viper/ros/conversions/;
// docs/design.md).
#pragma once

#include "viper/capture/capture_frame.h"
#include "viper/capture/capture_stream.h"
#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/camera_model.h"
#include "viper/ros/conversions/image_conversions.h"
#include "viper/ros/conversions/image_msg_pool.h"

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <viper/Draw.h>
#include <viper/DrawList.h>
#include <viper/Mesh.h>
#include <viper/MeshStore.h>

#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

namespace viper {

/// DrawRecord -> viper/Draw (matrices copied as stored: column-major, OpenGL axes).
Draw toDrawMsg(const DrawRecord& draw);
/// viper/Draw -> DrawRecord.
DrawRecord fromDrawMsg(const Draw& msg);
/// The same into `draw`, every field (its vectors keep their storage).
void fromDrawMsg(const Draw& msg, DrawRecord& draw);

/// The draw list of `frame` (frame number, condition, draws) with `header`.
DrawList toDrawListMsg(const CaptureFrame& frame, const std_msgs::Header& header);
/// Fills `frame`'s number, condition and draws from `msg`; leaves images and meshes untouched. The
/// draws are converted into those `frame` already holds, reusing their storage.
void fromDrawListMsg(const DrawList& msg, CaptureFrame& frame);

/// MeshRecord <-> viper/Mesh.
Mesh toMeshMsg(const MeshRecord& mesh);
MeshRecord fromMeshMsg(const Mesh& msg);
/// The well-formed meshes of a mesh store message. A mesh whose position or index count is not a
/// multiple of 3 is left out, with a sentence naming it appended to `problems`. With `known`, so
/// are the meshes it already holds unchanged (the store is sent again whole with every new mesh).
std::vector<MeshRecord> fromMeshStoreMsg(const MeshStore& msg, std::vector<std::string>& problems,
                                         const MeshRegistry* known = nullptr);

/// Fills `frame`'s size, number, time, condition, draws and draw ids from a draw list and a draw id
/// image (32SC1, packed). Returns an empty string, or what is wrong (encoding, size, stamps that
/// differ).
std::string frameFromDrawMsgs(const DrawList& draws, const sensor_msgs::Image& draw_ids, CaptureFrame& frame);
/// The same without copying the ids: `frame.draw_ids` is left as it was, and on success `ids` points
/// at the image's width*height ids (for a caller that holds the message).
std::string frameFromDrawMsgs(const DrawList& draws, const sensor_msgs::Image& draw_ids, CaptureFrame& frame,
                              const uint32_t*& ids);

/// Color image of `frame`, encoding rgb8, top row first.
/// Throws std::invalid_argument if the frame's color buffer does not hold width*height*3 bytes.
sensor_msgs::Image colorImage(const CaptureFrame& frame, const std_msgs::Header& header);
/// Depth image, encoding 32FC1, metres along the optical axis, NaN where there is no surface
/// (REP 118). `depth_m` holds width*height values (see depthMetres()); throws std::invalid_argument
/// otherwise.
sensor_msgs::Image depthImage(const CaptureFrame& frame, const std::vector<float>& depth_m,
                              const std_msgs::Header& header);
/// Draw id image, encoding 32SC1: draw index + 1 of the pixel's visible surface, 0 = none.
/// Throws std::invalid_argument on a size mismatch.
sensor_msgs::Image drawIdImage(const CaptureFrame& frame, const std_msgs::Header& header);
/// Primitive id image, encoding 32SC1: index of the triangle within its draw, -1 where the draw id
/// is 0. Throws std::invalid_argument on a size mismatch.
sensor_msgs::Image primitiveIdImage(const CaptureFrame& frame, const std_msgs::Header& header);

/// The inverses of the images above, for a frame whose size is already set (frameFromDrawMsgs):
/// each checks its image (checkImage: encoding, the frame's size, packed rows) and returns "" or
/// what is wrong, leaving the frame as it was.
std::string colorFromImage(const sensor_msgs::Image& color, CaptureFrame& frame);
/// Depth in metres (NaN = no surface), frame.pixelCount() values.
std::string depthFromImage(const sensor_msgs::Image& depth, const CaptureFrame& frame, std::vector<float>& depth_m);
/// Primitive ids (-1 where there is no draw reads back as 0xffffffff, meaningless there).
std::string primitiveIdsFromImage(const sensor_msgs::Image& primitive_ids, CaptureFrame& frame);

/// Camera info of a pinhole camera without distortion (plumb_bob, D = 0, R = I, P = [K | 0]).
/// With no intrinsics (frame without a camera) K, P are all zero: "uncalibrated" in ROS terms.
sensor_msgs::CameraInfo cameraInfo(const PinholeIntrinsics* intrinsics, uint32_t width, uint32_t height,
                                   const std_msgs::Header& header);

/// The mesh store as the capture bridge publishes it: every mesh seen so far, each key once, in the
/// order the capture first brought them.
class MeshStoreAccumulator {
 public:
  /// Appends the meshes whose keys are new; returns whether the store grew.
  bool add(const std::vector<MeshRecord>& meshes);
  /// The store so far (header left empty).
  const MeshStore& store() const { return store_; }

 private:
  MeshStore store_;
  std::unordered_set<uint64_t> keys_;
};

/// Every message the capture bridge publishes for one frame (the raw topics of docs/capture_bridge.md),
/// all with the same header. Shared pointers, so that publishing them in a nodelet manager copies nothing.
struct FrameMessages {
  sensor_msgs::ImagePtr color;          ///< color/image_raw, rgb8
  sensor_msgs::ImagePtr depth;          ///< depth/image_raw, 32FC1 metres, NaN = no surface
  sensor_msgs::ImagePtr draw_ids;       ///< draw_ids, 32SC1
  sensor_msgs::ImagePtr primitive_ids;  ///< primitive_ids, 32SC1
  sensor_msgs::CameraInfoPtr camera_info;  ///< color/camera_info and depth/camera_info (one camera)
  DrawListPtr draws;                    ///< draws
  MeshStorePtr mesh_store;              ///< mesh_store (latched) when this frame grew the store, else null
  /// Empty, or why camera_info is uncalibrated (no draw with view and projection, or a projection
  /// without intrinsics): a warning for whoever publishes, the messages are complete either way.
  std::string camera_problem;
};

/// Builds the messages of `frame` with `header` (the bridge's per-frame conversion, shared with the
/// capture_to_bag command), and adds the frame's new meshes to `meshes`. The frame should have passed
/// validateFrame(). Throws std::invalid_argument if an image buffer does not match the frame's size;
/// `meshes` is then left unchanged.
FrameMessages frameMessages(const CaptureFrame& frame, const std_msgs::Header& header, MeshStoreAccumulator& meshes);

/// Where a publisher of frame after frame keeps its image messages, recycled (ImageMsgPool): each
/// image is then written once into a message whose pages are in use already.
struct FrameImagePools {
  ImageMsgPool color, depth, draw_ids, primitive_ids;
};
/// The same with the images in messages of `pools`.
FrameMessages frameMessages(const CaptureFrame& frame, const std_msgs::Header& header, MeshStoreAccumulator& meshes,
                            FrameImagePools& pools);

/// A CaptureReader's image sink (CaptureImageSink) that takes each image of a frame of the right size
/// straight into a message of `pools`, so that the capture's pixels are decompressed once, into the
/// messages that are published. Draw ids and primitive ids go in as 32SC1, colour as rgb8, window
/// depth as 32FC1, which frameMessages() then turns into metres in place.
class FrameImageMessages : public CaptureImageSink {
 public:
  explicit FrameImageMessages(FrameImagePools& pools) : pools_(pools) {}
  /// A message's pixels when `bytes` is what the frame's width and height need, else nullptr (the
  /// reader then keeps the image in the frame, and validateFrame reports its size).
  void* imageStorage(CaptureImage image, const CaptureFrame& frame, size_t bytes) override;
  /// Forgets the images of the frame before: call before each read.
  void clear();
  /// The images this sink holds, for validateFrame(frame, elsewhere).
  FrameImagesElsewhere elsewhere() const;
  /// The message holding `image`, or null when the frame keeps it.
  const sensor_msgs::ImagePtr& message(CaptureImage image) const { return held_[static_cast<int>(image)]; }
  /// Whether it holds depth, draw ids and primitive ids: frameMessages() then converts, masks and
  /// checks the draw ids' range in one pass, and elsewhere() leaves that check to it.
  bool holdsIdsAndDepth() const {
    return message(CaptureImage::kDepth) && message(CaptureImage::kDrawIds) && message(CaptureImage::kPrimitiveIds);
  }

 private:
  FrameImagePools& pools_;
  sensor_msgs::ImagePtr held_[4];
};
/// The same, the images that `sunk` holds (of this frame, read with it as the reader's sink) taken
/// from there: primitive ids masked and depth turned into metres in place, nothing else written.
FrameMessages frameMessages(const CaptureFrame& frame, const std_msgs::Header& header, MeshStoreAccumulator& meshes,
                            FrameImagePools& pools, const FrameImageMessages& sunk);

/// The inverse of frameMessages: the frame of one frame's raw messages. Draws, draw ids,
/// primitive ids and color come back exactly; window depth comes back from the metres through
/// windowDepthFromMetres (to float precision; 1 where there is no surface); `new_meshes` holds the
/// mesh store's meshes when the messages carry one. `depth_m` (may be null) receives the metres.
/// Returns "" or what is wrong (a missing message or one that does not fit the draw id image);
/// `frame` is then incomplete.
std::string frameFromMessages(const FrameMessages& messages, CaptureFrame& frame,
                              std::vector<float>* depth_m = nullptr);

}  // namespace viper
