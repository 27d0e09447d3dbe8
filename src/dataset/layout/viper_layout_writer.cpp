#include "viper/dataset/viper_layout_writer.h"

#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_layout.h"
#include "viper/dataset/viper_layout_geometry.h"

#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace viper {
namespace {

std::string sizeText(uint32_t w, uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

const std::array<double, 4> kNoBox2d{{-1, -1, -1, -1}};

}  // namespace

std::vector<ViperBox> viperBoxes(const FrameBoxes& boxes) {
  std::vector<ViperBox> out;
  out.reserve(boxes.boxes.size());
  for (const TrackBox& b : boxes.boxes) {
    ViperBox v;
    v.in_optical = b.in_optical;
    v.in_optical.orientation = Eigen::Quaterniond(Eigen::Matrix3d(b.in_optical.orientation.normalized().toRotationMatrix()));
    v.class_id = b.class_id;
    v.id = b.track_id;
    out.push_back(v);
  }
  return out;
}

Boxes2d objectBoxes2d(const std::vector<TrackedObject>& objects) {
  Boxes2d boxes;
  for (const TrackedObject& t : objects) {
    const FrameObject& o = t.object;
    if (t.track_id > 0 && o.pixel_count > 0)
      boxes[t.track_id] = {{double(o.x_min), double(o.y_min), double(o.x_max), double(o.y_max)}};
  }
  return boxes;
}

ViperLayoutWriter::ViperLayoutWriter(const ViperExportOptions& options) : options_(options) {
  dataset::viperFramePath(options_.root, options_.split, "img", options_.seq, 0, "png");  // checks the names
  if (options_.image_extension != "png" && options_.image_extension != "jpg")
    throw std::invalid_argument("image extension must be png or jpg, got '" + options_.image_extension + "'");
  if (options_.camera == CameraSource::kOdometry && !(options_.near_m > 0 && options_.far_m > options_.near_m))
    throw std::invalid_argument("depth range must satisfy 0 < near < far");
  options_.images.digests = options_.digests;
  options_.zip.digests = options_.digests;
  // A few frames' files in flight at most: each waiting job holds an image.
  if (options_.writer_threads > 0)
    writes_ = std::make_unique<dataset::WriteQueue>(options_.writer_threads, 4 * options_.writer_threads, "viper-layout");
}

ViperExportStats ViperLayoutWriter::stats() const {
  ViperExportStats s = stats_;
  s.flow_overflowed = flow_overflowed_;
  return s;
}

ViperLayoutWriter::Image ViperLayoutWriter::held(const dataset::ImageView8& view, PixelOwner owner) {
  if (owner) return Image{view, std::move(owner)};
  auto copy = std::make_shared<dataset::Image8>();
  copy->width = view.width, copy->height = view.height, copy->channels = view.channels;
  copy->data.assign(view.data, view.data + view.pixels() * view.channels);
  return Image{dataset::ImageView8(*copy), copy};
}

std::string ViperLayoutWriter::write(uint64_t frame, dataset::WriteQueue::Job job) {
  if (!writes_) return job();
  writes_->submit([frame, job = std::move(job)] {
    const std::string note = job();
    return note.empty() ? note : "frame " + std::to_string(frame) + ": " + note;
  });
  return "";
}

std::string ViperLayoutWriter::path(const char* modality, uint64_t frame, const char* extension) {
  ensureFolder(modality);
  return dataset::viperFramePath(options_.root, options_.split, modality, options_.seq, frame, extension);
}

void ViperLayoutWriter::ensureFolder(const char* modality) {
  if (folders_[modality]) return;
  const std::filesystem::path dir =
      std::filesystem::path(dataset::viperFramePath(options_.root, options_.split, modality, options_.seq, 0, "x"))
          .parent_path();
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir.string() + ": cannot create folder: " + ec.message());
  folders_[modality] = true;
}

std::string ViperLayoutWriter::skip(const std::string& problem) {
  if (!problem.empty()) ++stats_.skipped;
  return problem;
}

std::string ViperLayoutWriter::addColor(uint64_t frame, const dataset::ImageView8& rgb, PixelOwner owner) {
  ++stats_.img;
  return write(frame, [file = path("img", frame, options_.image_extension.c_str()), rgb = held(rgb, std::move(owner)),
                       o = options_.images] {
    dataset::writeViperColorImage(file, rgb.view, o);
    return std::string();
  });
}

std::string ViperLayoutWriter::addSemantic(uint64_t frame, const dataset::ImageView8& class_ids, PixelOwner owner) {
  const Image ids = held(class_ids, std::move(owner));
  write(frame, [file = path("cls", frame, "png"), ids, this] {
    dataset::writeViperClassImage(file, ids.view, options_.palette, options_.images);
    return std::string();
  });
  ++stats_.cls;
  Pending& p = pending_[frame];
  if (!p.inst_written) p.semantic = ids;
  return complete(frame, p);
}

std::string ViperLayoutWriter::addInstanceIds(uint64_t frame, const int32_t* ids, uint32_t width, uint32_t height,
                                              PixelOwner owner) {
  Pending& p = pending_[frame];
  if (!p.inst_written) {
    if (!owner) {
      auto copy = std::make_shared<std::vector<int32_t>>(ids, ids + static_cast<size_t>(width) * height);
      ids = copy->data();
      owner = copy;
    }
    p.instance_ids = Ids{ids, width, height, std::move(owner)};
  }
  if (!p.boxes_written) p.id_boxes = instanceBoxes(ids, width, height);
  return complete(frame, p);
}

std::string ViperLayoutWriter::complete(uint64_t frame, Pending& p) {
  const ViperExportInputs& in = options_.inputs;
  std::string note;
  if (!p.inst_written && p.semantic && p.instance_ids) note = writeInstFromParts(frame, p);
  // Nobody will pair these: let them go.
  if (p.inst_written || in.instances_viper || !in.instance_ids) p.semantic.reset();
  if (p.inst_written || in.instances_viper || !in.semantic) p.instance_ids.reset();
  if (p.boxes && !p.boxes_written && (p.objects || (!in.objects && (p.id_boxes || !in.instance_ids)))) {
    const std::string n = writeBoxes(frame, p);
    if (note.empty()) note = n;
  }
  return note;
}

std::string ViperLayoutWriter::writeInstFromParts(uint64_t frame, Pending& p) {
  const dataset::ImageView8& s = p.semantic->view;
  const Ids& i = *p.instance_ids;
  if (s.width != i.width || s.height != i.height)
    return skip("semantic is " + sizeText(s.width, s.height) + " but instance ids are " + sizeText(i.width, i.height) +
                "; no inst file");
  dataset::Image8 inst;
  inst.width = s.width, inst.height = s.height, inst.channels = 3;
  inst.data.resize(3 * inst.pixels());
  encodeViperInstances(s.data, i.ids, inst.pixels(), inst.data.data());
  size_t wrapped = 0;
  for (size_t k = 0; k < inst.pixels(); ++k) wrapped += i.ids[k] > 0xffff || i.ids[k] < 0;
  write(frame, [file = path("inst", frame, "png"), inst = std::move(inst), o = options_.images] {
    dataset::writeViperInstanceImage(file, inst, o);
    return std::string();
  });
  ++stats_.inst;
  p.inst_written = true;
  p.semantic.reset();  // a frame's images are not kept once written
  p.instance_ids.reset();
  return wrapped == 0 ? "" : std::to_string(wrapped) + " pixels have instance ids outside 0..65535, which VIPER's "
                                                       "256 * G + B cannot hold (written modulo 65536)";
}

std::string ViperLayoutWriter::addInstancesViper(uint64_t frame, const dataset::ImageView8& rgb, PixelOwner owner) {
  write(frame, [file = path("inst", frame, "png"), inst = held(rgb, std::move(owner)), o = options_.images] {
    dataset::writeViperInstanceImage(file, inst.view, o);
    return std::string();
  });
  Pending& p = pending_[frame];
  if (!p.inst_written) ++stats_.inst;
  p.inst_written = true;
  return complete(frame, p);
}

std::string ViperLayoutWriter::addFlow(uint64_t frame, const float* uv, uint32_t w, uint32_t h, PixelOwner owner,
                                       bool backward) {
  if (!owner) {
    auto copy = std::make_shared<std::vector<float>>(uv, uv + 2 * static_cast<size_t>(w) * h);
    uv = copy->data();
    owner = copy;
  }
  ++(backward ? stats_.flowbw : stats_.flow);
  return write(frame, [file = path(backward ? "flowbw" : "flow", frame, "npz"), owner, uv, w, h, o = options_.zip,
                       this] {
    const auto result = dataset::writeViperFlow(file, uv, w, h, o);
    flow_overflowed_ += result.overflowed;
    return result.overflowed == 0 ? std::string()
                                  : std::to_string(result.overflowed) +
                                        " flow values of 65520 px or more became inf (invalid) in float16";
  });
}

std::string ViperLayoutWriter::addBoxesOptical(uint64_t frame, std::vector<ViperBox> boxes) {
  Pending& p = pending_[frame];
  p.boxes = std::move(boxes);
  p.boxes_written = false;
  return complete(frame, p);
}

std::string ViperLayoutWriter::addObjects(uint64_t frame, Boxes2d boxes_2d) {
  Pending& p = pending_[frame];
  p.objects = std::move(boxes_2d);
  return complete(frame, p);
}

std::string ViperLayoutWriter::writeBoxes(uint64_t frame, Pending& p) {
  // 2D boxes: the objects' (the tight box of their visible pixels), else the instance image's.
  static const Boxes2d kNone;
  const Boxes2d& boxes_2d = p.objects ? *p.objects : p.id_boxes ? *p.id_boxes : kNone;
  std::vector<dataset::ViperBoxRow> rows;
  for (const ViperBox& b : *p.boxes) {
    const auto box_2d = boxes_2d.find(b.id);
    rows.push_back(viperBoxRow(b.in_optical, b.class_id, b.id, box_2d == boxes_2d.end() ? kNoBox2d : box_2d->second));
  }
  dataset::writeViperBoxesCsv(path("bb", frame, "csv"), rows, options_.digests);
  ++stats_.bb;
  p.boxes.reset();
  p.boxes_written = true;
  p.id_boxes.reset();
  p.objects.reset();
  return "";
}

std::string ViperLayoutWriter::writeCameraRow(uint64_t frame, const dataset::RowMajor4& view,
                                              const dataset::RowMajor4& projection) {
  dataset::ViperCameraRow row;
  row.frame = frame;
  row.projection = projection;
  row.view = view;
  if (options_.relative_poses) {
    try {
      if (!origin_view_) {
        relativeView(view, view);  // throws for a view that is not rigid
        origin_view_ = view;
      }
      row.view = relativeView(view, *origin_view_);
    } catch (const std::invalid_argument& e) {
      return skip(std::string("view matrix: ") + e.what() + "; no camera row");
    }
  }
  if (!camera_file_.is_open()) {
    camera_path_ = dataset::viperCameraPath(options_.root, options_.split, options_.seq);
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(camera_path_).parent_path(), ec);
    if (ec) throw std::runtime_error(camera_path_ + ": cannot create its folder: " + ec.message());
    camera_file_.open(camera_path_, std::ios::trunc);
    if (!camera_file_) throw std::runtime_error(camera_path_ + ": cannot write camera file");
    if (options_.digests) camera_digest_ = std::make_unique<dataset::Sha256>();
  }
  const std::string line = dataset::formatViperCameraRow(row) + '\n';
  camera_file_ << line;
  camera_file_.flush();
  if (camera_digest_) {
    camera_digest_->update(line.data(), line.size());
    camera_bytes_ += line.size();
  }
  if (!camera_file_) throw std::runtime_error(camera_path_ + ": cannot write camera file");
  ++stats_.camera_rows;
  return "";
}

std::string ViperLayoutWriter::addCamera(uint64_t frame, const std::optional<FrameCamera>& camera) {
  if (options_.camera != CameraSource::kDraws) return "";
  if (!camera) return skip("no draw carries both a view and a projection matrix; no camera row");
  Pending& p = pending_[frame];
  if (p.camera_written) return "";
  p.camera_written = true;
  return writeCameraRow(frame, toRowMajor(camera->view), toRowMajor(camera->projection));
}

std::string ViperLayoutWriter::addOdometry(uint64_t frame, const Eigen::Isometry3d& map_from_body) {
  if (options_.camera != CameraSource::kOdometry) return "";
  Pending& p = pending_[frame];
  p.map_from_body = map_from_body;
  if (p.camera_info && !p.camera_written) {
    p.camera_written = true;
    const Intrinsics& k = *p.camera_info;
    return writeCameraRow(frame, viewFromBodyPose(*p.map_from_body),
                          glProjectionFromCameraMatrix(k.K, k.width, k.height, options_.near_m, options_.far_m));
  }
  return "";
}

std::string ViperLayoutWriter::addCameraInfo(uint64_t frame, const std::array<double, 9>& K, uint32_t width,
                                             uint32_t height) {
  if (options_.camera != CameraSource::kOdometry) return "";
  try {
    glProjectionFromCameraMatrix(K, width, height, options_.near_m, options_.far_m);
  } catch (const std::invalid_argument& e) {
    return skip(e.what());
  }
  Pending& p = pending_[frame];
  p.camera_info = Intrinsics{K, width, height};
  if (p.map_from_body && !p.camera_written) {
    p.camera_written = true;
    return writeCameraRow(frame, viewFromBodyPose(*p.map_from_body),
                          glProjectionFromCameraMatrix(K, width, height, options_.near_m, options_.far_m));
  }
  return "";
}

std::vector<std::string> ViperLayoutWriter::flushUpTo(uint64_t frame) {
  std::vector<std::string> notes;
  if (writes_) notes = writes_->check();
  while (!pending_.empty() && pending_.begin()->first <= frame) {
    const uint64_t f = pending_.begin()->first;
    Pending& p = pending_.begin()->second;
    const std::string at = "frame " + std::to_string(f) + ": ";
    if (p.boxes) {
      if (!p.objects && !p.id_boxes)
        notes.push_back(at + "boxes without objects or instance ids: 2D boxes written as -1");
      const std::string note = writeBoxes(f, p);
      if (!note.empty()) notes.push_back(at + note);
    }
    if (!p.inst_written && (p.semantic || p.instance_ids))
      notes.push_back(at + (p.semantic ? "semantic without instance ids" : "instance ids without semantic") +
                      ": no inst file");
    if (options_.camera == CameraSource::kOdometry && !p.camera_written && (p.map_from_body || p.camera_info))
      notes.push_back(at + (p.map_from_body ? "odometry without camera_info" : "camera_info without odometry") +
                      ": no camera row");
    pending_.erase(pending_.begin());
  }
  return notes;
}

std::vector<std::string> ViperLayoutWriter::finish() {
  std::vector<std::string> notes = flushUpTo(UINT64_MAX);
  if (writes_)
    for (std::string& n : writes_->drain()) notes.push_back(std::move(n));
  if (camera_file_.is_open()) {
    camera_file_.close();
    if (camera_digest_ && camera_file_) options_.digests->record(camera_path_, camera_bytes_, camera_digest_->hex());
    camera_digest_.reset();
  }
  return notes;
}

}  // namespace viper
