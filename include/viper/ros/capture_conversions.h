// The one converter between capture core types and ROS messages: draws, meshes, the per-pixel images
// of a frame and its camera info.
#pragma once

#include "viper/core/camera_model.h"
#include "viper/core/capture_frame.h"

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <viper/Draw.h>
#include <viper/DrawList.h>
#include <viper/Mesh.h>
#include <viper/MeshStore.h>

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

}  // namespace viper
