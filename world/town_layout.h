// The procedural town: a grid of roads with lanes, crossings and traffic lights, blocks of
// buildings, parks and plazas, street furniture, and the ego route through it. Everything comes
// from one seeded std::mt19937, so a seed always gives the same town.
#pragma once

#include "math3d.h"
#include "mesh_library.h"
#include "town_route.h"

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace viper {
namespace world {

/// Road geometry constants (metres).
struct RoadDims {
  static constexpr float kBlock = 72.0f;        ///< distance between intersection centres
  static constexpr float kRoadHalf = 7.0f;      ///< half width of the carriageway (2 lanes each way)
  static constexpr float kLane = 3.5f;          ///< lane width
  static constexpr float kSidewalkOuter = 11.0f;  ///< sidewalk spans 7..11 m from the centre line
  static constexpr float kCurb = 0.15f;         ///< sidewalk height
  static constexpr float kStopLine = 12.0f;     ///< stop line distance from the intersection centre
  static constexpr float kWalkOffset = 9.0f;    ///< pedestrian path offset from road centre lines
};

/// A merged static scenery mesh of one class in one block (or one road cell).
struct StaticChunk {
  uint8_t class_id = 0;
  int mesh = -1;     ///< index in the MeshLibrary
  Mat4 world;        ///< its own matrix, distinct from every other chunk's
  Vec3 center;       ///< world-space bounding sphere
  float radius = 0;
};

/// A stand-alone static object (fire hydrant, chair, trash can).
struct PropInstance {
  uint8_t class_id = 0;
  int mesh = -1;
  Mat4 world;
  Vec3 position;
  float yaw = 0;
};

/// One traffic light head, controlling vehicles that travel along `heading` into intersection
/// (i, j).
struct TrafficLightSite {
  int i = 0, j = 0;
  int axis = 0;       ///< 0: controls traffic along x, 1: along y
  Mat4 world;
  Vec3 position;
};

/// Colour a traffic light shows.
enum class LightColor { kGreen, kYellow, kRed };

/// The town and the ego route through it.
class TownLayout {
 public:
  /// Builds the route (about route_length_m long) and a town around it; registers all static
  /// meshes in `meshes`. With `city`, the route stays in the city's region and the town is the
  /// part of the city around it, at the city's coordinates (throws std::runtime_error when no
  /// route fits the region).
  void generate(uint32_t seed, float route_length_m, MeshLibrary& meshes, const CityPlace* city = nullptr);

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  /// World position of intersection (i, j) (z = 0); a city's intersection (origin_i + i, origin_j + j).
  Vec3 intersection(int i, int j) const {
    return {(origin_i_ + i) * RoadDims::kBlock, (origin_j_ + j) * RoadDims::kBlock, 0.0f};
  }
  /// Global indices of intersection (0, 0): (0, 0) for a town of its own.
  std::pair<int, int> origin() const { return {origin_i_, origin_j_}; }
  /// Light shown at intersection (i, j) for traffic along `axis` at simulation time t (s).
  LightColor lightAt(int i, int j, int axis, double t) const;
  /// Seconds until the light for `axis` at (i, j) next turns from red to green (0 when green).
  double secondsOfRedLeft(int i, int j, int axis, double t) const;

  const std::vector<StaticChunk>& chunks() const { return chunks_; }
  const std::vector<PropInstance>& props() const { return props_; }
  const std::vector<TrafficLightSite>& lights() const { return lights_; }
  /// World positions of the street lamp heads (the night lights).
  const std::vector<Vec3>& lampHeads() const { return lamp_heads_; }
  /// Indices into props() of the chairs.
  const std::vector<int>& chairs() const { return chairs_; }
  /// Intersections (i, j) the ego route visits, in order.
  const std::vector<std::pair<int, int>>& route() const { return route_; }

 private:
  void placeTown(Route route, bool in_city);
  void setLightPhases(std::mt19937& rng, const CityPlace* city);
  void makeRoadCell(int i, int j, MeshLibrary& meshes);
  void makeBlock(int i, int j, std::mt19937& rng, MeshLibrary& meshes);
  void makeGround(MeshLibrary& meshes);
  void addChunk(const std::string& name, uint8_t class_id, MeshData world_mesh, Vec3 origin,
                MeshLibrary& meshes);
  void addProp(uint8_t class_id, int mesh, Vec3 position, float yaw);

  int nx_ = 0, ny_ = 0;
  int origin_i_ = 0, origin_j_ = 0;
  std::vector<float> phase_offset_s_;  ///< per intersection
  std::vector<StaticChunk> chunks_;
  std::vector<PropInstance> props_;
  std::vector<TrafficLightSite> lights_;
  std::vector<Vec3> lamp_heads_;
  std::vector<int> chairs_;
  std::vector<std::pair<int, int>> route_;
};

}  // namespace world
}  // namespace viper
