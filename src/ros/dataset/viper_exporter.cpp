#include "viper/ros/dataset/viper_exporter.h"

#include "viper/ground_truth/camera_model.h"
#include "viper/ground_truth/instance_pipeline.h"
#include "viper/dataset/viper_flow.h"
#include "viper/dataset/viper_layout.h"
#include "viper/ros/conversions/frame_conversions.h"
#include "viper/ros/conversions/object_conversions.h"
#include "viper/ros/conversions/pose_conversions.h"
#include "viper/ros/dataset/viper_layout_conversions.h"

#include <sensor_msgs/image_encodings.h>

#include <filesystem>
#include <stdexcept>

namespace viper {
namespace {

std::string sizeText(uint32_t w, uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

const std::array<double, 4> kNoBox2d{{-1, -1, -1, -1}};

}  // namespace

ViperExporter::ViperExporter(const ViperExportOptions& options) : options_(options) {
  dataset::viperFramePath(options_.root, options_.split, "img", options_.seq, 0, "png");  // checks the names
  if (options_.image_extension != "png" && options_.image_extension != "jpg")
    throw std::invalid_argument("image extension must be png or jpg, got '" + options_.image_extension + "'");
  if (options_.camera == CameraSource::kOdometry && !(options_.near_m > 0 && options_.far_m > options_.near_m))
    throw std::invalid_argument("depth range must satisfy 0 < near < far");
  options_.images.digests = options_.digests;
  options_.zip.digests = options_.digests;
  // A few frames' files in flight at most: each waiting job holds a decoded image.
  if (options_.writer_threads > 0)
    writes_ = std::make_unique<dataset::WriteQueue>(options_.writer_threads, 4 * options_.writer_threads, "viper-layout");
}

ViperExportStats ViperExporter::stats() const {
  ViperExportStats s = stats_;
  s.flow_overflowed = flow_overflowed_;
  return s;
}

std::string ViperExporter::write(uint64_t frame, dataset::WriteQueue::Job job) {
  if (!writes_) return job();
  writes_->submit([frame, job = std::move(job)] {
    const std::string note = job();
    return note.empty() ? note : "frame " + std::to_string(frame) + ": " + note;
  });
  return "";
}

std::string ViperExporter::path(const char* modality, uint64_t frame, const char* extension) {
  ensureFolder(modality);
  return dataset::viperFramePath(options_.root, options_.split, modality, options_.seq, frame, extension);
}

void ViperExporter::ensureFolder(const char* modality) {
  if (folders_[modality]) return;
  const std::filesystem::path dir =
      std::filesystem::path(dataset::viperFramePath(options_.root, options_.split, modality, options_.seq, 0, "x"))
          .parent_path();
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir.string() + ": cannot create folder: " + ec.message());
  folders_[modality] = true;
}

std::string ViperExporter::skip(const std::string& problem) {
  if (!problem.empty()) ++stats_.skipped;
  return problem;
}

std::string ViperExporter::addColor(uint64_t frame, const sensor_msgs::Image& msg) {
  dataset::Image8 rgb;
  const std::string problem = imageFromMsg(msg, "rgb8", rgb);
  if (!problem.empty()) return skip(problem);
  ++stats_.img;
  return write(frame, [file = path("img", frame, options_.image_extension.c_str()), rgb = std::move(rgb),
                       o = options_.images] {
    dataset::writeViperColorImage(file, rgb, o);
    return std::string();
  });
}

std::string ViperExporter::addSemantic(uint64_t frame, const sensor_msgs::ImageConstPtr& msg) {
  dataset::Image8 ids;
  const std::string problem = imageFromMsg(*msg, "mono8", ids);
  if (!problem.empty()) return skip(problem);
  write(frame, [file = path("cls", frame, "png"), ids = std::move(ids), this] {
    dataset::writeViperClassImage(file, ids, options_.palette, options_.images);
    return std::string();
  });
  ++stats_.cls;
  Pending& p = pending_[frame];
  if (!p.inst_written) p.semantic = msg;
  return complete(frame, p);
}

std::string ViperExporter::addInstanceIds(uint64_t frame, const sensor_msgs::ImageConstPtr& msg) {
  std::vector<int32_t> ids;
  const std::string problem = int32FromMsg(*msg, ids);
  if (!problem.empty()) return skip(problem);
  Pending& p = pending_[frame];
  if (!p.inst_written) p.instance_ids = msg;
  if (!p.boxes_written) p.id_boxes = instanceBoxes(ids.data(), msg->width, msg->height);
  return complete(frame, p);
}

std::string ViperExporter::complete(uint64_t frame, Pending& p) {
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

std::string ViperExporter::writeInstFromParts(uint64_t frame, Pending& p) {
  const sensor_msgs::Image& s = *p.semantic;
  const sensor_msgs::Image& i = *p.instance_ids;
  if (s.width != i.width || s.height != i.height)
    return skip("semantic is " + sizeText(s.width, s.height) + " but instance ids are " + sizeText(i.width, i.height) +
                "; no inst file");
  dataset::Image8 classes;
  std::vector<int32_t> ids;
  imageFromMsg(s, "mono8", classes);
  int32FromMsg(i, ids);
  dataset::Image8 inst;
  inst.width = s.width, inst.height = s.height, inst.channels = 3;
  inst.data.resize(3 * inst.pixels());
  encodeViperInstances(classes.data.data(), ids.data(), inst.pixels(), inst.data.data());
  write(frame, [file = path("inst", frame, "png"), inst = std::move(inst), o = options_.images] {
    dataset::writeViperInstanceImage(file, inst, o);
    return std::string();
  });
  ++stats_.inst;
  p.inst_written = true;
  p.semantic.reset();  // a frame's images are not kept once written
  p.instance_ids.reset();
  size_t wrapped = 0;
  for (int32_t id : ids) wrapped += id > 0xffff || id < 0;
  return wrapped == 0 ? "" : std::to_string(wrapped) + " pixels have instance ids outside 0..65535, which VIPER's "
                                                       "256 * G + B cannot hold (written modulo 65536)";
}

std::string ViperExporter::addInstancesViper(uint64_t frame, const sensor_msgs::Image& msg) {
  dataset::Image8 inst;
  const std::string problem = imageFromMsg(msg, "rgb8", inst);
  if (!problem.empty()) return skip(problem);
  write(frame, [file = path("inst", frame, "png"), inst = std::move(inst), o = options_.images] {
    dataset::writeViperInstanceImage(file, inst, o);
    return std::string();
  });
  Pending& p = pending_[frame];
  if (!p.inst_written) ++stats_.inst;
  p.inst_written = true;
  return complete(frame, p);
}

std::string ViperExporter::addFlow(uint64_t frame, const sensor_msgs::ImageConstPtr& msg, bool backward) {
  // Rows without padding are written from the message itself (it is shared and never changes): at
  // 1080p that saves copying 16.6 MB a flow image.
  std::shared_ptr<const dataset::FlowImage> copy;
  if (msg->step != static_cast<size_t>(msg->width) * 8 || msg->encoding != sensor_msgs::image_encodings::TYPE_32FC2 ||
      msg->data.size() != static_cast<size_t>(msg->step) * msg->height) {
    auto flow = std::make_shared<dataset::FlowImage>();
    const std::string problem = flowFromMsg(*msg, *flow);
    if (!problem.empty()) return skip(problem);
    copy = flow;
  }
  const float* uv = copy ? copy->uv.data() : reinterpret_cast<const float*>(msg->data.data());
  ++(backward ? stats_.flowbw : stats_.flow);
  return write(frame, [file = path(backward ? "flowbw" : "flow", frame, "npz"), msg, copy, uv, w = msg->width,
                       h = msg->height, o = options_.zip, this] {
    const auto result = dataset::writeViperFlow(file, uv, w, h, o);
    flow_overflowed_ += result.overflowed;
    return result.overflowed == 0 ? std::string()
                                  : std::to_string(result.overflowed) +
                                        " flow values of 65520 px or more became inf (invalid) in float16";
  });
}

std::string ViperExporter::addBoxesOptical(uint64_t frame, const Box3DArray::ConstPtr& msg) {
  Pending& p = pending_[frame];
  p.boxes = msg;
  p.boxes_written = false;
  return complete(frame, p);
}

std::string ViperExporter::addObjects(uint64_t frame, const ObjectArray::ConstPtr& msg) {
  Pending& p = pending_[frame];
  p.objects = msg;
  return complete(frame, p);
}

std::string ViperExporter::writeBoxes(uint64_t frame, Pending& p) {
  // 2D boxes: the objects' (the tight box of their visible pixels), else the instance image's.
  std::map<int32_t, std::array<double, 4>> boxes_2d;
  if (p.objects) {
    for (const Object& o : p.objects->objects)
      if (o.track_id > 0 && o.box_2d.width > 0 && o.box_2d.height > 0)
        boxes_2d[o.track_id] = {{double(o.box_2d.x_offset), double(o.box_2d.y_offset),
                                 double(o.box_2d.x_offset + o.box_2d.width - 1),
                                 double(o.box_2d.y_offset + o.box_2d.height - 1)}};
  } else if (p.id_boxes) {
    boxes_2d = *p.id_boxes;
  }
  std::vector<dataset::ViperBoxRow> rows;
  for (const Box3D& b : p.boxes->boxes) {
    const auto box_2d = boxes_2d.find(b.id);
    rows.push_back(viperBoxRow(fromBox3DMsg(b), b.class_id, b.id, box_2d == boxes_2d.end() ? kNoBox2d : box_2d->second));
  }
  dataset::writeViperBoxesCsv(path("bb", frame, "csv"), rows, options_.digests);
  ++stats_.bb;
  p.boxes.reset();
  p.boxes_written = true;
  p.id_boxes.reset();
  p.objects.reset();
  return "";
}

std::string ViperExporter::writeCameraRow(uint64_t frame, const dataset::RowMajor4& view,
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

std::string ViperExporter::addDraws(uint64_t frame, const DrawList& msg) {
  if (options_.camera != CameraSource::kDraws) return "";
  CaptureFrame capture;
  fromDrawListMsg(msg, capture);
  const std::optional<FrameCamera> camera = chooseFrameCamera(capture);
  if (!camera) return skip("no draw carries both a view and a projection matrix; no camera row");
  Pending& p = pending_[frame];
  if (p.camera_written) return "";
  p.camera_written = true;
  return writeCameraRow(frame, toRowMajor(camera->view), toRowMajor(camera->projection));
}

std::string ViperExporter::addOdometry(uint64_t frame, const nav_msgs::Odometry& msg) {
  if (options_.camera != CameraSource::kOdometry) return "";
  Pending& p = pending_[frame];
  p.map_from_body = fromPoseMsg(msg.pose.pose);
  if (p.camera_info && !p.camera_written) {
    p.camera_written = true;
    return writeCameraRow(frame, viewFromBodyPose(*p.map_from_body),
                          glProjectionFromK(p.camera_info->K, p.camera_info->width, p.camera_info->height,
                                            options_.near_m, options_.far_m));
  }
  return "";
}

std::string ViperExporter::addCameraInfo(uint64_t frame, const sensor_msgs::CameraInfo& msg) {
  if (options_.camera != CameraSource::kOdometry) return "";
  try {
    glProjectionFromK(msg.K, msg.width, msg.height, options_.near_m, options_.far_m);
  } catch (const std::invalid_argument& e) {
    return skip(e.what());
  }
  Pending& p = pending_[frame];
  p.camera_info = msg;
  if (p.map_from_body && !p.camera_written) {
    p.camera_written = true;
    return writeCameraRow(frame, viewFromBodyPose(*p.map_from_body),
                          glProjectionFromK(msg.K, msg.width, msg.height, options_.near_m, options_.far_m));
  }
  return "";
}

std::vector<std::string> ViperExporter::flushUpTo(uint64_t frame) {
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

std::vector<std::string> ViperExporter::finish() {
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
