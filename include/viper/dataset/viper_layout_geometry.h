// The geometry of VIPER's release layout: its row-major matrices, camera rows (OpenGL view and
// projection matrices) against poses and intrinsics, box rows (model box and model-to-camera
// matrix) against oriented boxes in the optical frame, and the 2D boxes of an instance id image.
// The layout's camera is OpenGL's (X right, Y up, looking down -Z); poses use REP 103/105 (camera
// body x forward / y left / z up, optical frame x right / y down / z forward). Shared by the layout
// writer (viper_layout_writer.h) and the converter between the layout and messages
// (src/ros/dataset/viper_layout_conversions.cpp). docs/viper_layout.md.
#pragma once

#include "viper/dataset/viper_boxes.h"
#include "viper/dataset/viper_camera.h"
#include "viper/ground_truth/boxes.h"
#include "viper/ground_truth/camera_model.h"

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <map>

namespace viper {

/// Row-major 4x4 (the layout's) <-> Eigen.
Eigen::Matrix4d toEigen(const dataset::RowMajor4& m);
dataset::RowMajor4 toRowMajor(const Eigen::Matrix4d& m);
dataset::RowMajor4 toRowMajor(const GlMatrix& m);
GlMatrix toGlMatrix(const dataset::RowMajor4& m);

/// Pose of the camera body (x forward, y left, z up) in the world of an OpenGL view matrix (world
/// -> OpenGL camera). Throws std::invalid_argument if the matrix is not finite or not rigid (its
/// rotation part orthonormal within 1e-4, last row 0 0 0 1 within 1e-6).
Eigen::Isometry3d worldFromBody(const dataset::RowMajor4& view);

/// `view` relative to `origin`: view * origin^-1, the view matrix in a world whose origin and axes
/// are `origin`'s camera (VIPER's "poses relative to the first frame": the origin's relative view
/// is the identity). Throws std::invalid_argument if `origin` is not rigid.
dataset::RowMajor4 relativeView(const dataset::RowMajor4& view, const dataset::RowMajor4& origin);

/// OpenGL view matrix (world -> OpenGL camera) of a camera body pose in the world; the inverse of
/// worldFromBody.
dataset::RowMajor4 viewFromBodyPose(const Eigen::Isometry3d& world_from_body);

/// An OpenGL perspective projection with the intrinsics of camera_info's K for a `width` x
/// `height` image (the inverse of intrinsicsFromGlProjection) and depth range [near_m, far_m].
/// Throws std::invalid_argument if K is not a pinhole matrix (fx, fy > 0, K(2,:) = 0 0 1) or the
/// range is not 0 < near < far.
dataset::RowMajor4 glProjectionFromCameraMatrix(const std::array<double, 9>& K, uint32_t width, uint32_t height,
                                                double near_m, double far_m);

/// The box of a layout row in OpenGL camera coordinates: the model box's centre and extent moved by
/// `model_to_camera`, whose rotation is taken from its polar decomposition and whose column norms
/// scale the extent. Throws std::invalid_argument if the matrix is singular or not affine.
OrientedBox boxInGlCamera(const dataset::ViperBoxRow& row);

/// A layout row for a box given in the camera optical frame: the model frame is the box's own
/// (centred, axes along the box), so box_3d = -size/2 .. size/2 and model_to_camera is rigid.
/// `box_2d` as in ViperBoxRow (x_min, y_min, x_max, y_max; -1s for no visible pixels).
dataset::ViperBoxRow viperBoxRow(const OrientedBox& box_in_optical, int class_id, int64_t instance_id,
                                 const std::array<double, 4>& box_2d);

/// The optical frame's axes (x right, y down, z forward) in OpenGL camera axes (x right, y up, -z
/// forward): p_gl = glCameraFromOptical() * p_optical.
Eigen::Isometry3d glCameraFromOptical();

/// Tight 2D boxes (x_min, y_min, x_max, y_max, inclusive pixels) of every instance id > 0 in a
/// 32SC1 instance id image of `width` x `height` pixels.
std::map<int32_t, std::array<double, 4>> instanceBoxes(const int32_t* ids, uint32_t width, uint32_t height);

}  // namespace viper
