// Amodal masks and visibility: core FrameAmodal -> viper/AmodalInstanceArray, and the overlay image
// rviz shows (docs/amodal.md). Part of the converter between messages and core types
// (include/viper/ros/conversions/; docs/design.md).
#pragma once

#include "viper/ground_truth/amodal.h"

#include <sensor_msgs/Image.h>
#include <std_msgs/Header.h>
#include <viper/AmodalInstanceArray.h>

#include <cstdint>

namespace viper {

/// The frame's amodal objects with `header` (the frame's stamp and optical frame id); each mask a
/// mono8 image of its box (255 covered, 0 not) with the same header.
AmodalInstanceArray toAmodalInstanceArrayMsg(const FrameAmodal& amodal, const std_msgs::Header& header);

/// rgb8 picture of the frame's objects, amodal.width x amodal.height, for rviz: black where no
/// object is; each object's visible pixels (instance_ids shows its track id) filled in its colour
/// (amodalColor), the rest of its mask (its occluded part) hatched in that colour over what hides
/// it: diagonal stripes on the pixels where (x + y) % 6 < 2, so that an occluding object's fill
/// shows between them. `instance_ids`: the frame's width * height track ids. Where occluded parts
/// overlap, the later object's stripes win.
void renderAmodalOverlay(const FrameAmodal& amodal, const int32_t* instance_ids, const std_msgs::Header& header,
                         sensor_msgs::Image& out);

/// The overlay's colour of a track id (r, g, b): hues spread by the golden ratio, full saturation.
void amodalColor(int32_t track_id, uint8_t rgb[3]);

}  // namespace viper
