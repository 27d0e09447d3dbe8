#include "conditions.h"

#include <cmath>
#include <iterator>

namespace viper {
namespace world {

namespace {
// By Condition's value.
const char* const kConditionNames[] = {"day", "sunset", "rain", "snow", "night"};

Vec3 sunFrom(float azimuth, float elevation) {
  return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
          std::sin(elevation)};
}
}  // namespace

bool parseCondition(const std::string& text, Condition& out) {
  for (size_t c = 0; c < std::size(kConditionNames); ++c)
    if (text == kConditionNames[c]) {
      out = static_cast<Condition>(c);
      return true;
    }
  return false;
}

const char* conditionName(Condition c) {
  const auto index = static_cast<size_t>(c);
  return index < std::size(kConditionNames) ? kConditionNames[index] : "day";
}

ConditionParams conditionParams(Condition c, float heading_yaw) {
  ConditionParams p;
  switch (c) {
    case Condition::kDay:  // overcast: soft light from above, grey-white sky
      p.sky_zenith = {0.62f, 0.68f, 0.76f};
      p.sky_horizon = {0.82f, 0.84f, 0.86f};
      p.sun_dir = sunFrom(0.8f, 1.0f);
      p.sun_color = {0.45f, 0.45f, 0.45f};
      p.ambient = {0.62f, 0.64f, 0.68f};
      p.fog_color = {0.78f, 0.8f, 0.83f};
      p.fog_density = 0.004f;
      break;
    case Condition::kSunset:  // low warm sun towards the view, long warm light, glare
      p.sky_zenith = {0.25f, 0.3f, 0.55f};
      p.sky_horizon = {1.0f, 0.55f, 0.25f};
      p.sun_dir = sunFrom(heading_yaw + 0.3f, 0.07f);
      p.sun_color = {1.3f, 0.7f, 0.35f};
      p.ambient = {0.28f, 0.22f, 0.28f};
      p.fog_color = {0.85f, 0.5f, 0.3f};
      p.fog_density = 0.005f;
      p.grade = {1.05f, 0.92f, 0.8f};
      p.glare = 1.0f;
      p.sun_disc = 1.0f;
      break;
    case Condition::kRain:  // dark, wet and reflective, streaks
      p.sky_zenith = {0.2f, 0.22f, 0.25f};
      p.sky_horizon = {0.3f, 0.32f, 0.34f};
      p.sun_dir = sunFrom(0.8f, 1.1f);
      p.sun_color = {0.08f, 0.08f, 0.09f};
      p.ambient = {0.22f, 0.24f, 0.27f};
      p.fog_color = {0.27f, 0.29f, 0.32f};
      p.fog_density = 0.012f;
      p.grade = {0.85f, 0.9f, 1.0f};
      p.wet = 1.0f;
      p.night = 0.25f;
      p.particles = Particles::kRain;
      break;
    case Condition::kSnow:  // white cover, falling flakes, low contrast
      p.sky_zenith = {0.78f, 0.8f, 0.84f};
      p.sky_horizon = {0.88f, 0.89f, 0.9f};
      p.sun_dir = sunFrom(0.8f, 0.9f);
      p.sun_color = {0.25f, 0.25f, 0.27f};
      p.ambient = {0.7f, 0.72f, 0.76f};
      p.fog_color = {0.86f, 0.87f, 0.9f};
      p.fog_density = 0.03f;
      p.snow = 1.0f;
      p.particles = Particles::kSnow;
      break;
    case Condition::kNight:  // dark sky, street lights, headlights, lit windows
      p.sky_zenith = {0.01f, 0.012f, 0.03f};
      p.sky_horizon = {0.04f, 0.045f, 0.07f};
      p.sun_dir = sunFrom(2.0f, 0.8f);
      p.sun_color = {0.04f, 0.05f, 0.08f};
      p.ambient = {0.035f, 0.04f, 0.06f};
      p.fog_color = {0.03f, 0.035f, 0.05f};
      p.fog_density = 0.008f;
      p.night = 1.0f;
      p.stars = 1.0f;
      break;
  }
  return p;
}

}  // namespace world
}  // namespace viper
