#include "viper/ground_truth/triangle_raster.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace viper {
namespace {

// Window coordinates carry 8 fractional bits, as in llvmpipe (FIXED_ORDER).
constexpr int kSubpixelBits = 8;
constexpr int64_t kSubpixel = int64_t{1} << kSubpixelBits;
// The side planes: x and y clipped at |x| <= w, the image's edges, as llvmpipe's clipper does
// (a triangle that crosses them gets vertices on them, its inner edges re-snapped from there).
constexpr float kSide = 1.0f;
// A triangle clipped by up to 6 planes has at most 9 vertices.
constexpr int kMaxPolygon = 12;

using Vec4 = Eigen::Vector4f;

// llvmpipe's snapping (SSE cvtps2dq): v * 256 rounded to nearest, ties to even.
int64_t snap(float v) {
  const float s = v * static_cast<float>(kSubpixel);
  return std::lrintf(s);
}

// Distance of `v` to plane `p` (>= 0 inside): near, far, then the four side planes.
float planeDistance(const Vec4& v, int p) {
  switch (p) {
    case 0: return v.z() + v.w();
    case 1: return v.w() - v.z();
    case 2: return kSide * v.w() + v.x();
    case 3: return kSide * v.w() - v.x();
    case 4: return kSide * v.w() + v.y();
    default: return kSide * v.w() - v.y();
  }
}

// Sutherland-Hodgman against one plane; new vertices interpolated from the inside vertex, as
// Mesa's clipper does, in float.
int clipPolygon(const Vec4* in, int n, int plane, Vec4* out) {
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const Vec4& a = in[i];
    const Vec4& b = in[(i + 1) % n];
    const float da = planeDistance(a, plane), db = planeDistance(b, plane);
    if (da >= 0.0f) out[m++] = a;
    if ((da >= 0.0f) != (db >= 0.0f) && m < kMaxPolygon) {
      if (da >= 0.0f) {
        const float t = da / (da - db);
        out[m++] = a + t * (b - a);
      } else {
        const float t = db / (db - da);
        out[m++] = b + t * (a - b);
      }
    }
  }
  return m;
}

}  // namespace

void PixelBox::add(int x, int y) {
  if (empty()) {
    x_min = x_max = x, y_min = y_max = y;
    return;
  }
  x_min = std::min(x_min, x), x_max = std::max(x_max, x);
  y_min = std::min(y_min, y), y_max = std::max(y_max, y);
}

void WindowExtent::add(double x, double y) {
  if (empty) {
    x_min = x_max = x, y_min = y_max = y, empty = false;
    return;
  }
  x_min = std::min(x_min, x), x_max = std::max(x_max, x);
  y_min = std::min(y_min, y), y_max = std::max(y_max, y);
}

TriangleRasterizer::TriangleRasterizer(uint32_t width, uint32_t height) { resize(width, height); }

void TriangleRasterizer::resize(uint32_t width, uint32_t height) {
  width_ = width, height_ = height;
  mask_.assign(static_cast<size_t>(width) * height, 0);
  box_ = PixelBox();
  extent_ = WindowExtent();
  covered_ = 0;
}

void TriangleRasterizer::clear() {
  if (!box_.empty())
    for (int y = box_.y_min; y <= box_.y_max; ++y)
      std::fill_n(mask_.begin() + static_cast<size_t>(y) * width_ + box_.x_min, box_.width(), uint8_t{0});
  box_ = PixelBox();
  extent_ = WindowExtent();
  covered_ = 0;
}

void TriangleRasterizer::drawClip(const Vec4& a, const Vec4& b, const Vec4& c) {
  if (width_ == 0 || height_ == 0 || !a.allFinite() || !b.allFinite() || !c.allFinite()) return;
  std::array<Vec4, kMaxPolygon> p0, p1;
  p0[0] = a, p0[1] = b, p0[2] = c;
  int n = 3;
  Vec4* in = p0.data();
  Vec4* out = p1.data();
  for (int plane = 0; plane < 6 && n >= 3; ++plane) {
    if (plane == 2) {
      // The extent of the near- and far-clipped polygon, before the image's sides cut it.
      for (int i = 0; i < n; ++i)
        if (in[i].w() > 0.0f)
          extent_.add((in[i].x() / in[i].w() + 1.0) * 0.5 * width_, (1.0 - in[i].y() / in[i].w()) * 0.5 * height_);
    }
    bool all_inside = true;
    for (int i = 0; i < n; ++i) all_inside = all_inside && planeDistance(in[i], plane) >= 0.0f;
    if (all_inside) continue;
    n = clipPolygon(in, n, plane, out);
    std::swap(in, out);
  }
  if (n < 3) return;

  // Perspective divide and viewport transform as Mesa's draw module writes them, into the rows of
  // the picture (y down, as llvmpipe's window-system framebuffer: scale -h/2, translate h/2).
  const float scale_x = 0.5f * static_cast<float>(width_), scale_y = 0.5f * static_cast<float>(height_);
  std::array<int64_t, kMaxPolygon> x, y;
  for (int i = 0; i < n; ++i) {
    if (!(in[i].w() > 0.0f)) return;
    const float oow = 1.0f / in[i].w();
    const float wx = in[i].x() * oow * scale_x + scale_x;
    const float wy = in[i].y() * oow * -scale_y + scale_y;  // image rows: y down
    x[i] = snap(wx - 0.5f);
    y[i] = snap(wy - 0.5f);
  }
  // A fan from the first vertex, as the clipper emits it.
  for (int i = 1; i + 1 < n; ++i) {
    const int64_t tx[3] = {x[0], x[i], x[i + 1]}, ty[3] = {y[0], y[i], y[i + 1]};
    fillSnapped(tx, ty);
  }
}

void TriangleRasterizer::fillSnapped(const int64_t* x_in, const int64_t* y_in) {
  int64_t x[3] = {x_in[0], x_in[1], x_in[2]}, y[3] = {y_in[0], y_in[1], y_in[2]};
  const int64_t area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
  if (area == 0) return;
  if (area < 0) std::swap(x[1], x[2]), std::swap(y[1], y[2]);

  // Pixel centres (i, j) sit at (i * 256, j * 256) in the snapped coordinates (image rows, j down).
  auto ceilDiv = [](int64_t v) { return v >= 0 ? (v + kSubpixel - 1) / kSubpixel : -((-v) / kSubpixel); };
  auto floorDiv = [](int64_t v) { return v >= 0 ? v / kSubpixel : -((-v + kSubpixel - 1) / kSubpixel); };
  const int64_t i0 = std::max<int64_t>(0, ceilDiv(std::min({x[0], x[1], x[2]})));
  const int64_t i1 = std::min<int64_t>(width_ - 1, floorDiv(std::max({x[0], x[1], x[2]})));
  const int64_t j0 = std::max<int64_t>(0, ceilDiv(std::min({y[0], y[1], y[2]})));
  const int64_t j1 = std::min<int64_t>(height_ - 1, floorDiv(std::max({y[0], y[1], y[2]})));
  if (i0 > i1 || j0 > j1) return;

  // Edge k from vertex k to k+1: E(P) = dx (Py - Yk) - dy (Px - Xk) > 0 inside; a centre on the
  // edge (E = 0) is the triangle's where the edge is a left edge (dy < 0) or a bottom edge of the
  // picture (dy = 0, dx < 0: the triangle above it): a bias of 1 turns E >= 0 into E + 1 > 0 there.
  int64_t e_row[3], step_x[3], step_y[3];
  for (int k = 0; k < 3; ++k) {
    const int l = (k + 1) % 3;
    const int64_t dx = x[l] - x[k], dy = y[l] - y[k];
    const int64_t bias = (dy < 0 || (dy == 0 && dx < 0)) ? 1 : 0;
    e_row[k] = dx * (j0 * kSubpixel - y[k]) - dy * (i0 * kSubpixel - x[k]) + bias;
    step_x[k] = -dy * kSubpixel;
    step_y[k] = dx * kSubpixel;
  }
  // Each row's span solved from the three edges (exact integers): E + k step_x > 0 gives a first k
  // for edges that rise along the row and a last k for those that fall.
  const int64_t span = i1 - i0;
  for (int64_t j = j0; j <= j1; ++j) {
    int64_t k_first = 0, k_last = span;
    for (int k = 0; k < 3; ++k) {
      const int64_t e = e_row[k], step = step_x[k];
      if (step > 0) {
        if (e <= 0) k_first = std::max(k_first, -e / step + 1);
      } else if (step < 0) {
        k_last = e > 0 ? std::min(k_last, (e - 1) / -step) : -1;
      } else if (e <= 0) {
        k_last = -1;
      }
    }
    if (k_first <= k_last) {
      const int row = static_cast<int>(j);
      uint8_t* line = mask_.data() + static_cast<size_t>(row) * width_;
      const int first = static_cast<int>(i0 + k_first), last = static_cast<int>(i0 + k_last);
      for (int i = first; i <= last; ++i) covered_ += line[i] == 0, line[i] = 1;
      box_.add(first, row), box_.add(last, row);
    }
    for (int k = 0; k < 3; ++k) e_row[k] += step_y[k];
  }
}

}  // namespace viper
