// What test_scene and vk_test_scene write next to their pictures: the oracle record of a frame and
// the file name of a frame's dump. Shared so that both programs describe the same scene the same way.
#pragma once

#include "world.h"

#include "viper/ground_truth/oracle.h"

#include <cstdint>
#include <string>

namespace viper {
namespace scene {

/// Appends frame `number` (the count of presented frames before it) with `state`'s draws to
/// `oracle`, after a record for every mesh those draws use that `oracle` has not written yet.
/// Throws what OracleWriter throws.
void writeOracleFrame(OracleWriter& oracle, uint64_t number, const FrameState& state, const World& world);

/// DIR/frame_NNNNNN.ppm, the dump file of frame `number`.
std::string dumpPath(const std::string& dir, uint64_t number);

}  // namespace scene
}  // namespace viper
