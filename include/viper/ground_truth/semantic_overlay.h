// Pictures of class id images for people: class colors, and class colors over the camera image.
#pragma once

#include "viper/ground_truth/class_table.h"
#include "viper/ground_truth/instructions.h"

#include <cstddef>
#include <cstdint>

namespace viper {

/// rgb8 image of the classes' colors; ids outside the table are black. Every path of
/// `instructions` gives the same bytes.
void colorizeClasses(const uint8_t* class_ids, size_t n, const ClassTable& classes, uint8_t* rgb,
                     Instructions instructions = Instructions::kWidest);

/// The camera image with class colors blended over it: out = (1 - alpha) * color + alpha * class
/// color, alpha in [0, 1]; pixels of class 0 (unlabeled) keep the camera color. Every path of
/// `instructions` gives the same bytes: each channel is (color (256 - a) + class color a + 128) >> 8
/// with a = alpha * 256 rounded.
void overlayClasses(const uint8_t* color_rgb, const uint8_t* class_ids, size_t n, const ClassTable& classes,
                    float alpha, uint8_t* rgb, Instructions instructions = Instructions::kWidest);

}  // namespace viper
