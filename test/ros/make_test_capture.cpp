// Writes a small, self-consistent capture for the capture_bridge tests: a camera driving along a
// street over a ground plane with instanced boxes, ray-cast on the CPU so that color, depth, draw ids,
// primitive ids and visible pixel counts agree with the draws' matrices.
//
// Usage: make_test_capture --output FILE [--frames N] [--width W] [--height H] [--damage flip|truncate]
//                          [--upscale K] [--frame-delay-ms MS]
//   --upscale K:        ray-cast at W/K x H/K and replicate pixels (big frames for throughput tests)
//   --frame-delay-ms:   pause between frames, to exercise readers that follow a file being written
//   --damage flip:     flips one byte inside the chunk of frame N/2 (frames before it stay intact)
//   --damage truncate: cuts the file in the middle of the last frame's chunk
#include "viper/capture/capture_stream.h"
#include "viper/capture/content_key.h"

#include "../common/gl_matrices.h"

#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

namespace {

using viper::CaptureFrame;
using viper::DrawRecord;
using viper::GlMatrix;
using viper::MeshRecord;

struct Options {
  std::string output;
  int frames = 8;
  uint32_t width = 96;
  uint32_t height = 64;
  std::string damage;
  uint32_t upscale = 1;
  int frame_delay_ms = 0;
};

MeshRecord makeMesh(std::vector<float> positions, std::vector<uint32_t> indices) {
  MeshRecord m;
  m.positions_xyz = std::move(positions);
  m.indices = std::move(indices);
  std::string bytes(reinterpret_cast<const char*>(m.positions_xyz.data()), m.positions_xyz.size() * sizeof(float));
  bytes.append(reinterpret_cast<const char*>(m.indices.data()), m.indices.size() * sizeof(uint32_t));
  m.key = viper::contentKey(bytes);
  return m;
}

MeshRecord unitCube() {
  std::vector<float> p;
  for (int i = 0; i < 8; ++i) {
    p.push_back(i & 1 ? 0.5f : -0.5f);
    p.push_back(i & 2 ? 0.5f : -0.5f);
    p.push_back(i & 4 ? 1.0f : 0.0f);  // standing on z = 0
  }
  return makeMesh(p, {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                      2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5});
}

MeshRecord ground() {
  return makeMesh({-50, -50, 0, 50, -50, 0, 50, 50, 0, -50, 50, 0}, {0, 1, 2, 0, 2, 3});
}

using viper::test::glLookAt;
using viper::test::glPerspective;

GlMatrix placed(double x, double y, double yaw, double scale) {
  Eigen::Affine3d a = Eigen::Translation3d(x, y, 0) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                      Eigen::Scaling(scale);
  return a.matrix().cast<float>();
}

// Ray/triangle intersection (Moller-Trumbore); returns the ray parameter or +inf.
double intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-12) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d s = o - a;
  const double u = s.dot(p) / det;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) / det;
  const double t = e2.dot(q) / det;
  if (u < 0 || v < 0 || u + v > 1 || t <= 0) return std::numeric_limits<double>::infinity();
  return t;
}

CaptureFrame renderFrame(int k, const Options& opt, const MeshRecord& cube, const MeshRecord& plane) {
  CaptureFrame f;
  f.number = static_cast<uint64_t>(k);
  f.time_s = 2.0 + k / 15.0;  // a 15 fps sequence, like VIPER's
  f.condition = "day";
  f.width = opt.width;
  f.height = opt.height;
  const GlMatrix proj = glPerspective(1.0, double(opt.width) / opt.height, 0.1, 200.0);
  const Eigen::Vector3d eye(0.0, -10.0 + 0.5 * k, 1.5);
  const GlMatrix view = glLookAt(eye, eye + Eigen::Vector3d(0.1, 1.0, -0.05));

  auto draw = [&](const MeshRecord& mesh, const GlMatrix& world, const char* program) {
    DrawRecord d;
    d.index = static_cast<uint32_t>(f.draws.size());
    d.mesh_key = mesh.key;
    d.vertex_buffer_key = viper::combineKeys(mesh.key, 1);
    d.index_buffer_key = viper::combineKeys(mesh.key, 2);
    d.program_key = viper::contentKey(std::string(program));
    d.texture_keys = {viper::contentKey(std::string(program) + ".albedo")};
    d.matrix_flags = viper::kHasWorld | viper::kHasView | viper::kHasProjection;
    d.world = world;
    d.view = view;
    d.projection = proj;
    d.primitive_count = static_cast<uint32_t>(mesh.indices.size() / 3);
    f.draws.push_back(d);
  };
  draw(plane, GlMatrix::Identity(), "ground");
  draw(cube, placed(2.0, 0.0, 0.3, 1.5), "building");
  draw(cube, placed(-2.5, 4.0, 0.0, 2.0), "building");
  draw(cube, placed(0.8 - 0.2 * k, 8.0, 1.0, 1.0), "car");  // moves between frames
  draw(cube, placed(0.0, -30.0, 0.0, 1.0), "car");          // behind the camera: never visible
  const std::vector<const MeshRecord*> meshes = {&plane, &cube, &cube, &cube, &cube};

  const size_t n = f.pixelCount();
  f.color_rgb.assign(n * 3, 0);
  f.depth_window.assign(n, 1.0f);
  f.draw_ids.assign(n, 0);
  f.primitive_ids.assign(n, 0);
  const Eigen::Matrix4d world_from_eye = view.cast<double>().inverse();
  const Eigen::Matrix4d p = proj.cast<double>();
  const double fy = opt.height * p(1, 1) / 2, fx = opt.width * p(0, 0) / 2;
  for (uint32_t v = 0; v < opt.height; ++v) {
    for (uint32_t u = 0; u < opt.width; ++u) {
      // Sky above the horizon on purpose: pixels without any surface.
      const Eigen::Vector3d dir_eye((u - (opt.width - 1) / 2.0) / fx, -(v - (opt.height - 1) / 2.0) / fy, -1.0);
      const Eigen::Vector3d o = world_from_eye.topRightCorner<3, 1>();
      const Eigen::Vector3d d = world_from_eye.topLeftCorner<3, 3>() * dir_eye;
      double best = std::numeric_limits<double>::infinity();
      uint32_t best_draw = 0, best_prim = 0;
      for (size_t di = 0; di < f.draws.size(); ++di) {
        const Eigen::Matrix4d w = f.draws[di].world.cast<double>();
        const MeshRecord& m = *meshes[di];
        for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
          Eigen::Vector3d c[3];
          for (int j = 0; j < 3; ++j) {
            const float* q = &m.positions_xyz[3 * m.indices[t + j]];
            c[j] = (w * Eigen::Vector4d(q[0], q[1], q[2], 1)).head<3>();
          }
          const double hit = intersect(o, d, c[0], c[1], c[2]);
          if (hit < best) {
            best = hit;
            best_draw = static_cast<uint32_t>(di + 1);
            best_prim = static_cast<uint32_t>(t / 3);
          }
        }
      }
      const size_t i = size_t(v) * opt.width + u;
      if (best_draw == 0) {
        f.color_rgb[3 * i + 2] = 200;  // sky
        continue;
      }
      // Eye-space z of the hit is -best (the direction has z = -1), then GL's depth mapping.
      const double z_eye = -best;
      const double z_ndc = (p(2, 2) * z_eye + p(2, 3)) / (-z_eye);
      if (z_ndc > 1.0) continue;  // beyond the far plane: clipped
      f.depth_window[i] = static_cast<float>((z_ndc + 1) / 2);
      f.draw_ids[i] = best_draw;
      f.primitive_ids[i] = best_prim;
      f.draws[best_draw - 1].visible_pixels++;
      f.color_rgb[3 * i + 0] = static_cast<uint8_t>(40 * best_draw);
      f.color_rgb[3 * i + 1] = static_cast<uint8_t>(10 * best_prim);
      f.color_rgb[3 * i + 2] = static_cast<uint8_t>(std::min(255.0, 10 * best));
    }
  }
  if (k == 0) f.new_meshes = {plane, cube};
  return f;
}

// Replicates every pixel into a k x k block; visible pixel counts grow by k*k.
CaptureFrame upscaled(const CaptureFrame& small, uint32_t k) {
  if (k == 1) return small;
  CaptureFrame f = small;
  f.width = small.width * k;
  f.height = small.height * k;
  const size_t n = f.pixelCount();
  f.color_rgb.resize(n * 3);
  f.depth_window.resize(n);
  f.draw_ids.resize(n);
  f.primitive_ids.resize(n);
  for (uint32_t v = 0; v < f.height; ++v) {
    for (uint32_t u = 0; u < f.width; ++u) {
      const size_t i = size_t(v) * f.width + u, j = size_t(v / k) * small.width + u / k;
      for (int c = 0; c < 3; ++c) f.color_rgb[3 * i + c] = small.color_rgb[3 * j + c];
      f.depth_window[i] = small.depth_window[j];
      f.draw_ids[i] = small.draw_ids[j];
      f.primitive_ids[i] = small.primitive_ids[j];
    }
  }
  for (DrawRecord& d : f.draws) d.visible_pixels *= k * k;
  return f;
}

bool parse(int argc, char** argv, Options& opt) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("__", 0) == 0) continue;  // roslaunch's __name:= and __log:= when started as a node
    if (i + 1 >= argc) return false;
    const char* v = argv[++i];
    if (a == "--output") opt.output = v;
    else if (a == "--frames") opt.frames = std::atoi(v);
    else if (a == "--width") opt.width = static_cast<uint32_t>(std::atoi(v));
    else if (a == "--height") opt.height = static_cast<uint32_t>(std::atoi(v));
    else if (a == "--damage") opt.damage = v;
    else if (a == "--upscale") opt.upscale = static_cast<uint32_t>(std::atoi(v));
    else if (a == "--frame-delay-ms") opt.frame_delay_ms = std::atoi(v);
    else return false;
  }
  return !opt.output.empty() && opt.frames > 1 && opt.upscale > 0 && opt.width % opt.upscale == 0 &&
         opt.height % opt.upscale == 0 && opt.width > 0 && opt.height > 0 && opt.frame_delay_ms >= 0 &&
         (opt.damage.empty() || opt.damage == "flip" || opt.damage == "truncate");
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (!parse(argc, argv, opt)) {
    std::cerr << "usage: make_test_capture --output FILE [--frames N>1] [--width W] [--height H] "
                 "[--damage flip|truncate] [--upscale K dividing W and H] [--frame-delay-ms MS]\n";
    return 2;
  }
  try {
    const MeshRecord cube = unitCube(), plane = ground();
    std::vector<uint64_t> chunk_start;
    uint64_t end_of_frames = 0;
    {
      viper::CaptureHeader header;
      header.program = "make_test_capture";
      header.profile = "none";
      viper::CaptureWriter writer(opt.output, header);
      for (int k = 0; k < opt.frames; ++k) {
        chunk_start.push_back(writer.bytesWritten());
        Options small = opt;
        small.width /= opt.upscale;
        small.height /= opt.upscale;
        const CaptureFrame frame = upscaled(renderFrame(k, small, cube, plane), opt.upscale);
        const std::string problem = viper::validateFrame(frame);
        if (!problem.empty()) throw std::runtime_error("generated frame is inconsistent: " + problem);
        writer.write(frame);
        if (opt.frame_delay_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(opt.frame_delay_ms));
      }
      end_of_frames = writer.bytesWritten();
      writer.close();
    }
    if (opt.damage == "flip") {
      const int bad = opt.frames / 2;
      const uint64_t next = bad + 1 < opt.frames ? chunk_start[bad + 1] : end_of_frames;
      const uint64_t at = (chunk_start[bad] + next) / 2;
      std::fstream file(opt.output, std::ios::in | std::ios::out | std::ios::binary);
      file.seekg(static_cast<std::streamoff>(at));
      char byte = 0;
      file.get(byte);
      file.seekp(static_cast<std::streamoff>(at));
      file.put(static_cast<char>(byte ^ 0x5a));
      std::cout << "flipped the byte at offset " << at << " (frame " << bad << ")\n";
    } else if (opt.damage == "truncate") {
      const uint64_t cut = (chunk_start.back() + end_of_frames) / 2;
      if (::truncate(opt.output.c_str(), static_cast<off_t>(cut)) != 0) throw std::runtime_error("truncate failed");
      std::cout << "truncated to " << cut << " bytes (inside frame " << opt.frames - 1 << ")\n";
    }
    std::cout << "wrote " << opt.frames << " frames of " << opt.width << "x" << opt.height << " to " << opt.output
              << "\n";
  } catch (const std::exception& e) {
    std::cerr << "make_test_capture: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
