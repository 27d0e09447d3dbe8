// A CPU rasteriser of clip-space triangles into a coverage mask, following the rules OpenGL
// rasterisation follows on llvmpipe (Mesa's software driver, which renders the captures here), so
// that it covers the pixels GL covers for the same triangles: triangles clipped in clip space
// against the near and far planes and the image's sides (new vertices interpolated in float),
// perspective divide and viewport transform in float into the picture's rows (y down), window
// coordinates snapped to 1/256 px (8 bits of sub-pixel precision, (v - 0.5) * 256 rounded to
// nearest, ties to even, as SSE rounds: pixel centres at half-integers), a pixel covered when its centre is inside the
// triangle, and a centre exactly on an edge owned by one triangle only: the bottom-left rule of the
// picture, what llvmpipe gives for OpenGL. No culling: every triangle of either winding is drawn;
// zero-area triangles (after snapping) are not. docs/amodal.md.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace viper {

/// A pixel box, inclusive, in image pixels (top row 0); empty when x_max < x_min.
struct PixelBox {
  int x_min = 0, y_min = 0, x_max = -1, y_max = -1;
  bool empty() const { return x_max < x_min || y_max < y_min; }
  int width() const { return empty() ? 0 : x_max - x_min + 1; }
  int height() const { return empty() ? 0 : y_max - y_min + 1; }
  void add(int x, int y);
};

/// Window-space extent of what was drawn, before the image bounds cut it (pixels, x right, y down
/// from the image's top edge; continuous coordinates: pixel (x, y) spans [x, x+1) x [y, y+1)).
struct WindowExtent {
  double x_min = 0, y_min = 0, x_max = 0, y_max = 0;
  bool empty = true;
  void add(double x, double y);
};

/// Rasterises triangles into a width x height byte mask (1 = covered, top row 0). Draws accumulate
/// until clear(); clear() touches only the box drawn since the last clear.
class TriangleRasterizer {
 public:
  TriangleRasterizer(uint32_t width = 0, uint32_t height = 0);

  /// A new image size (clears).
  void resize(uint32_t width, uint32_t height);
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }

  /// One triangle of clip-space vertices (x, y, z, w), as a vertex shader outputs them.
  void drawClip(const Eigen::Vector4f& a, const Eigen::Vector4f& b, const Eigen::Vector4f& c);

  /// The mask (width * height bytes, 1 where covered).
  const std::vector<uint8_t>& mask() const { return mask_; }
  /// Box of the covered pixels since the last clear (empty if none).
  const PixelBox& box() const { return box_; }
  /// Window extent of the triangles since the last clear, clipped at the near and far planes but
  /// not at the image's sides: how far the drawn geometry reaches past the image.
  const WindowExtent& extent() const { return extent_; }
  /// Covered pixels since the last clear.
  uint64_t coveredPixels() const { return covered_; }
  /// Clears the mask, box, extent and count.
  void clear();

 private:
  // One triangle of a clipped polygon, window coordinates (picture rows, y down) snapped to 1/256 px.
  void fillSnapped(const int64_t* x, const int64_t* y);
  uint32_t width_ = 0, height_ = 0;
  std::vector<uint8_t> mask_;
  PixelBox box_;
  WindowExtent extent_;
  uint64_t covered_ = 0;
};

}  // namespace viper
