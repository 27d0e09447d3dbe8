// Amodal masks and visibility: core FrameAmodal -> viper/AmodalInstanceArray, and the overlay image
// rviz shows (docs/amodal.md). Part of the converter between messages and core types
// (include/viper/ros/conversions/; docs/design.md).
#pragma once

#include "viper/ground_truth/amodal.h"
#include "viper/ground_truth/amodal_overlay.h"

#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <viper/AmodalInstanceArray.h>

#include <cstdint>

namespace viper {

/// The frame's amodal objects with `header` (the frame's stamp and optical frame id); each mask a
/// mono8 image of its box (255 covered, 0 not) with the same header.
AmodalInstanceArray toAmodalInstanceArrayMsg(const FrameAmodal& amodal, const std_msgs::Header& header);

/// rgb8 picture of the frame's objects, amodal.width x amodal.height, for rviz: black where no
/// object is; paintAmodalOverlay's picture on it (amodal_overlay.h: each object's visible pixels
/// filled in its colour amodalColor, its occluded part hatched in it over what hides it).
/// `instance_ids`: the frame's width * height track ids.
void renderAmodalOverlay(const FrameAmodal& amodal, const int32_t* instance_ids, const std_msgs::Header& header,
                         sensor_msgs::Image& out);

}  // namespace viper
