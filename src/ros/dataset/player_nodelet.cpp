// The player as a nodelet: the same Player, sharing images zero-copy inside a manager.
#include "viper/ros/dataset/player.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace viper {

/// Nodelet shell around Player.
class PlayerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    player_ = std::make_unique<Player>(getNodeHandle(), getPrivateNodeHandle());
    // An impossible configuration leaves this nodelet idle instead of ending the whole manager.
    if (!player_->start(/*is_node=*/false))
      NODELET_FATAL("player nodelet '%s' not started (see the message above)", getName().c_str());
  }

  std::unique_ptr<Player> player_;
};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::PlayerNodelet, nodelet::Nodelet)
