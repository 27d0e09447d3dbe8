// The one converter between capture core types and ROS messages: draws, meshes, the per-pixel images
// of a frame and its camera info.
#pragma once

#include "viper/ground_truth/camera_model.h"
#include "viper/capture/capture_frame.h"

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

/// The draw list of `frame` (frame number, condition, draws) with `header`.
DrawList toDrawListMsg(const CaptureFrame& frame, const std_msgs::Header& header);
/// Fills `frame`'s number, condition and draws from `msg`; leaves images and meshes untouched.
void fromDrawListMsg(const DrawList& msg, CaptureFrame& frame);

/// MeshRecord <-> viper/Mesh.
Mesh toMeshMsg(const MeshRecord& mesh);
MeshRecord fromMeshMsg(const Mesh& msg);
/// The well-formed meshes of a mesh store message. A mesh whose position or index count is not a
/// multiple of 3 is left out, with a sentence naming it appended to `problems`.
std::vector<MeshRecord> fromMeshStoreMsg(const MeshStore& msg, std::vector<std::string>& problems);

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

/// Camera info of a pinhole camera without distortion (plumb_bob, D = 0, R = I, P = [K | 0]).
/// With no intrinsics (frame without a camera) K, P are all zero: "uncalibrated" in ROS terms.
sensor_msgs::CameraInfo cameraInfo(const PinholeIntrinsics* intrinsics, uint32_t width, uint32_t height,
                                   const std_msgs::Header& header);

/// An image message of `width` x `height` pixels of `bytes_per_pixel` bytes copied from `data`.
sensor_msgs::Image imageMsg(const std_msgs::Header& header, uint32_t width, uint32_t height,
                            const std::string& encoding, uint32_t bytes_per_pixel, const void* data);

/// The same, shared: what the nodelets publish, so that subscribers in the same manager get the
/// message itself (zero-copy) instead of a serialised copy of it.
sensor_msgs::ImagePtr imageMsgPtr(const std_msgs::Header& header, uint32_t width, uint32_t height,
                                  const std::string& encoding, uint32_t bytes_per_pixel, const void* data);

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

}  // namespace viper
