// A picture of a frame's amodal masks (docs/amodal.md): each object's visible part filled in its
// colour, its occluded part hatched in it. The amodal node's overlay topic and capture_sheet
// --modalities draw it.
#pragma once

#include "viper/ground_truth/amodal.h"

#include <cstdint>

namespace viper {

/// The colour (rgb) of a track in amodal pictures: a fully saturated hue stepped by the golden
/// ratio, so that consecutive track ids differ.
void amodalColor(int32_t track_id, uint8_t rgb[3]);

/// Paints the frame's objects into `rgb` (rgb8, amodal.width x amodal.height, 3 bytes a pixel, row
/// by row), leaving every pixel no mask covers as it was: each object's visible pixels (those where
/// `instance_ids`, the frame's width * height track ids, shows its track id) filled in its colour
/// (amodalColor), then the rest of its mask (its occluded part) hatched in that colour over what
/// hides it: diagonal stripes on the pixels where (x + y) % 6 < 2, so that an occluding object's
/// fill shows between them. Where occluded parts overlap, the later object's stripes win.
void paintAmodalOverlay(const FrameAmodal& amodal, const int32_t* instance_ids, uint8_t* rgb);

}  // namespace viper
