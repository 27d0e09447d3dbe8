#include "viper/ground_truth/tracking.h"

#include "viper/ground_truth/assignment.h"

#include <algorithm>
#include <iterator>

namespace viper {
namespace {

// Price of a forbidden edge: larger than any sum of real motions, so the solver first maximises
// the number of real matches and then minimises their total motion.
constexpr double kForbidden = 1e12;

std::vector<uint64_t> resourcesOf(const FrameObject& o) {
  std::vector<uint64_t> r;
  std::merge(o.mesh_keys.begin(), o.mesh_keys.end(), o.texture_keys.begin(), o.texture_keys.end(),
             std::back_inserter(r));
  r.erase(std::unique(r.begin(), r.end()), r.end());
  return r;
}

bool intersects(const std::vector<uint64_t>& a, const std::vector<uint64_t>& b) {
  auto i = a.begin();
  auto j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (*i == *j) return true;
    if (*i < *j) ++i; else ++j;
  }
  return false;
}

}  // namespace

std::vector<double> TrackerOptions::defaultMaxSpeeds() {
  std::vector<double> v(256, 0.5);
  v[20] = 10.0;                                 // person
  v[21] = v[22] = 20.0;                         // animal, bicycle
  for (int c = 23; c <= 28; ++c) v[c] = 60.0;   // motorcycle .. trailer
  v[29] = 100.0;                                // train
  v[30] = 300.0;                                // plane
  v[31] = 30.0;                                 // boat
  return v;
}

std::vector<bool> TrackerOptions::defaultDynamicClasses() {
  std::vector<bool> v(256, false);
  for (int c = 20; c <= 31; ++c) v[c] = true;
  return v;
}

Tracker::Tracker(TrackerOptions options) : options_(std::move(options)) {}

void Tracker::reset() {
  tracks_.clear();
  dormant_.clear();
  have_time_ = false;
}

bool Tracker::edgeAllowed(const Track& t, const FrameObject& o, const Eigen::Vector3d& predicted,
                          const Eigen::Vector3d& position, double dt) const {
  if (t.class_id != o.class_id) return false;
  const double speed = o.class_id < options_.max_speed_mps.size() ? options_.max_speed_mps[o.class_id] : 0.5;
  const double miss = (position - predicted).norm();
  if ((position - t.position).norm() > speed * dt + options_.slack_m && miss > options_.slack_m) return false;
  const bool dynamic = o.class_id < options_.dynamic_classes.size() && options_.dynamic_classes[o.class_id];
  if (dynamic && !intersects(t.resources, resourcesOf(o)) && miss > options_.lod_tolerance_m) return false;
  return true;
}

int Tracker::resumable(const FrameObject& o, const std::vector<uint64_t>& res) const {
  const bool dynamic = o.class_id < options_.dynamic_classes.size() && options_.dynamic_classes[o.class_id];
  if (!options_.resume_by_resources || !dynamic || res.empty()) return -1;
  auto holds = [&](const Track& t) {
    return t.class_id == o.class_id && std::includes(t.resources.begin(), t.resources.end(), res.begin(), res.end());
  };
  int found = -1;
  for (size_t d = 0; d < dormant_.size(); ++d) {
    if (!holds(dormant_[d])) continue;
    if (found >= 0) return -1;  // two candidates: the resources do not tell them apart
    found = static_cast<int>(d);
  }
  for (const Track& t : tracks_)
    if (holds(t)) return -1;
  return found;
}

std::vector<int32_t> Tracker::update(double time_s, const std::vector<FrameObject>& objects,
                                     const std::vector<Eigen::Vector3d>& positions) {
  was_reset_ = false;
  if (have_time_ && time_s <= last_time_s_) {
    reset();
    was_reset_ = true;
  }
  std::vector<int32_t> ids(objects.size(), 0);
  std::vector<size_t> things;
  for (size_t k = 0; k < objects.size() && k < positions.size(); ++k)
    if (objects[k].is_thing) things.push_back(k);

  // Allowed edges, then one assignment per connected component of the edge graph: gating by
  // class, speed and resources keeps components small, so this stays far below a dense n^2 m solve.
  const size_t n = things.size(), m = tracks_.size();
  std::vector<int> match(n, -1);
  std::vector<std::vector<std::pair<size_t, double>>> edges(n);  // per thing: (track, cost)
  for (size_t r = 0; r < n; ++r) {
    const FrameObject& o = objects[things[r]];
    const Eigen::Vector3d& p = positions[things[r]];
    for (size_t c = 0; c < m; ++c) {
      const Track& t = tracks_[c];
      if (t.class_id != o.class_id) continue;
      const double dt = time_s - t.time_s;
      const Eigen::Vector3d predicted = t.position + t.velocity * dt;
      if (edgeAllowed(t, o, predicted, p, dt)) edges[r].emplace_back(c, (p - predicted).norm());
    }
  }
  // Union-find over things (0..n-1) and tracks (n..n+m-1).
  std::vector<size_t> parent(n + m);
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (size_t r = 0; r < n; ++r)
    for (const auto& e : edges[r]) parent[find(r)] = find(n + e.first);
  std::vector<std::vector<size_t>> comp_rows(n + m), comp_cols(n + m);
  for (size_t r = 0; r < n; ++r)
    if (!edges[r].empty()) comp_rows[find(r)].push_back(r);
  for (size_t c = 0; c < m; ++c) comp_cols[find(n + c)].push_back(c);
  for (size_t root = 0; root < n + m; ++root) {
    const auto& rows = comp_rows[root];
    if (rows.empty()) continue;
    const auto& cols = comp_cols[root];
    // Columns: the component's tracks, then one "new track" column per row.
    Eigen::MatrixXd cost = Eigen::MatrixXd::Constant(rows.size(), cols.size() + rows.size(), kForbidden);
    for (size_t i = 0; i < rows.size(); ++i) {
      for (const auto& e : edges[rows[i]])
        cost(i, std::lower_bound(cols.begin(), cols.end(), e.first) - cols.begin()) = e.second;
      cost(i, cols.size() + i) = kForbidden / 2;  // starting a new track beats a forbidden edge
    }
    const std::vector<int> assigned = solveAssignment(cost);
    for (size_t i = 0; i < rows.size(); ++i)
      if (assigned[i] >= 0 && static_cast<size_t>(assigned[i]) < cols.size() && cost(i, assigned[i]) < kForbidden / 2)
        match[rows[i]] = static_cast<int>(cols[assigned[i]]);
  }

  std::vector<char> track_used(m, false);
  std::vector<Track> born;
  for (size_t r = 0; r < n; ++r) {
    const FrameObject& o = objects[things[r]];
    const Eigen::Vector3d& p = positions[things[r]];
    std::vector<uint64_t> res = resourcesOf(o);
    if (match[r] >= 0) {
      Track& t = tracks_[match[r]];
      const double dt = time_s - t.time_s;
      if (dt > 0) t.velocity = (p - t.position) / dt;
      t.position = p;
      t.time_s = time_s;
      t.missed = 0;
      std::vector<uint64_t> merged;
      std::set_union(t.resources.begin(), t.resources.end(), res.begin(), res.end(), std::back_inserter(merged));
      t.resources.swap(merged);
      track_used[match[r]] = true;
      ids[things[r]] = t.id;
    } else if (const int d = resumable(o, res); d >= 0) {
      Track t = std::move(dormant_[d]);  // back after a long absence: its old id
      dormant_.erase(dormant_.begin() + d);
      t.position = p, t.velocity = Eigen::Vector3d::Zero(), t.time_s = time_s, t.missed = 0;
      ids[things[r]] = t.id;
      born.push_back(std::move(t));
    } else {
      Track t{next_id_++, o.class_id, p, Eigen::Vector3d::Zero(), time_s, 0, std::move(res)};
      ids[things[r]] = t.id;
      born.push_back(std::move(t));
    }
  }
  std::vector<Track> kept;
  for (size_t c = 0; c < m; ++c) {
    if (!track_used[c] && ++tracks_[c].missed > options_.extrapolate_frames) {
      if (options_.resume_by_resources) dormant_.push_back(std::move(tracks_[c]));
      continue;
    }
    kept.push_back(std::move(tracks_[c]));
  }
  constexpr size_t kMaxDormant = 4096;
  if (dormant_.size() > kMaxDormant) dormant_.erase(dormant_.begin(), dormant_.end() - kMaxDormant);
  kept.insert(kept.end(), std::make_move_iterator(born.begin()), std::make_move_iterator(born.end()));
  tracks_.swap(kept);
  last_time_s_ = time_s;
  have_time_ = true;
  return ids;
}

}  // namespace viper
