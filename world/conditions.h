// The five weather / time-of-day conditions and the shading parameters each one sets.
#pragma once

#include "math3d.h"

#include <string>

namespace viper {
namespace world {

/// Condition of a sequence.
enum class Condition { kDay, kSunset, kRain, kSnow, kNight };

/// Particles drawn last with alpha blending.
enum class Particles { kNone, kRain, kSnow };

/// Shading parameters of a condition (colours linear 0..1, directions unit vectors, world frame).
struct ConditionParams {
  Vec3 sky_zenith, sky_horizon;
  Vec3 sun_dir;          ///< towards the sun (or moon)
  Vec3 sun_color;
  Vec3 ambient;          ///< hemisphere ambient from above
  Vec3 fog_color;
  float fog_density = 0; ///< per metre (exponential fog)
  Vec3 grade{1, 1, 1};   ///< final colour multiplier
  float wet = 0;         ///< 0..1 road wetness (darker, reflective)
  float snow = 0;        ///< 0..1 snow cover on upward faces
  float night = 0;       ///< 0..1: street lights, lit windows, headlights
  float glare = 0;       ///< 0..1 strength of the sun glare sprite
  float sun_disc = 0;    ///< 0..1 visible sun disc in the sky
  float stars = 0;
  Particles particles = Particles::kNone;
};

/// Parses "day", "sunset", "rain", "snow", "night"; false for anything else.
bool parseCondition(const std::string& text, Condition& out);
const char* conditionName(Condition c);

/// Parameters of a condition. `heading_yaw` is the ego's initial heading: the low sun of the
/// sunset is placed a little to the side of it so that its glare is in view.
ConditionParams conditionParams(Condition c, float heading_yaw);

}  // namespace world
}  // namespace viper
