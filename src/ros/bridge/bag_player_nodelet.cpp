// bag_player as a nodelet: the same BagPlayer, sharing the bag's images zero-copy inside a manager.
#include "viper/ros/bridge/bag_player.h"

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

namespace viper {

/// Nodelet shell around BagPlayer.
class BagPlayerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    player_ = std::make_unique<BagPlayer>(getNodeHandle(), getPrivateNodeHandle());
    // An impossible configuration leaves this nodelet idle instead of ending the whole manager.
    if (!player_->start(/*is_node=*/false))
      NODELET_FATAL("bag_player nodelet '%s' not started (see the message above)", getName().c_str());
  }

  std::unique_ptr<BagPlayer> player_;
};

}  // namespace viper

PLUGINLIB_EXPORT_CLASS(viper::BagPlayerNodelet, nodelet::Nodelet)
