// The live exporters on a full disk (a file-size limit, SIGXFSZ ignored: a write fails as with
// ENOSPC): the viper_exporter node and export_viper --live each get four color frames, the third of
// which does not fit. Each must name the file in a FATAL message, end its process with exit code 2
// (not wait for Ctrl-C), keep the two frames before it whole and leave no half-written file.
#include "tester_main.h"
#include "viper/dataset/viper_images.h"

#include "../common/process_util.h"

#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <random>
#include <thread>

namespace {

namespace fs = std::filesystem;
using viper::test::readFile;

sensor_msgs::Image colorFrame(int f) {
  sensor_msgs::Image m;
  m.header.stamp = ros::Time(100 + f / 15.0);
  m.header.frame_id = "camera_optical";
  m.width = 320, m.height = 240, m.encoding = "rgb8", m.step = 320 * 3;
  m.data.assign(320 * 240 * 3, 90);  // flat: a few hundred bytes of PNG
  if (f == 2) {  // noise: 230 KB of PNG, over the 100 KiB limit
    std::mt19937 rng(7);
    for (uint8_t& v : m.data) v = static_cast<uint8_t>(rng());
  }
  return m;
}

struct Exported {
  int code = -1;
  std::string output;
};

// Runs `command` under the limit in the background, publishes the frames once it subscribes, and
// waits (at most a minute) for it to end by itself.
Exported exportUnderLimit(const std::string& command, const std::string& topic, const fs::path& dir) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::Image>(topic, 10);
  const std::string log = (dir / "run.log").string(), rc = (dir / "run.rc").string();
  std::thread process([&] {
    viper::test::run("sh -c \"trap '' XFSZ; ulimit -f 100; exec " + command + "\" > " + log + " 2>&1; echo $? > " + rc);
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (pub.getNumSubscribers() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_GT(pub.getNumSubscribers(), 0u) << "the exporter never subscribed: " << readFile(log);
  for (int f = 0; f < 4 && !fs::exists(rc); ++f) {
    pub.publish(colorFrame(f));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  while (!fs::exists(rc) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  if (!fs::exists(rc)) viper::test::run("pkill -INT -f '" + (dir / "out").string() + "'");  // ends the test, fails below
  process.join();
  Exported r;
  r.code = std::stoi(readFile(rc).empty() ? "-1" : readFile(rc));
  r.output = readFile(log);
  return r;
}

void expectFullDiskHandled(const Exported& r, const fs::path& out) {
  EXPECT_EQ(r.code, 2) << r.output;
  const std::string failed = (out / "train/img/001/001_00002.png").string();
  EXPECT_NE(r.output.find(failed + ": cannot write PNG: File too large"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the process ends (exit code 2)"), std::string::npos) << r.output;
  for (int f = 0; f < 2; ++f) {
    const viper::dataset::Image8 img =
        viper::dataset::readViperColorImage((out / ("train/img/001/001_0000" + std::to_string(f) + ".png")).string());
    EXPECT_EQ(img.width, 320u);
    EXPECT_EQ(img.data[0], 90) << "frame " << f << " whole";
  }
  EXPECT_FALSE(fs::exists(failed)) << "no half-written file under its name";
  for (const auto& e : fs::recursive_directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

fs::path freshDir(const char* name) {
  const fs::path dir = fs::temp_directory_path() / ("viper_exporter_full_disk_" + std::to_string(getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The exporter that `command(~bin, its output folder)` starts, fed on `topic` in a fresh folder
// `name` under the file size limit: full disk handled (expectFullDiskHandled).
void expectFullDiskHandledBy(const char* name, const std::function<std::string(const std::string&, const std::string&)>& command,
                             const std::string& topic) {
  const fs::path dir = freshDir(name);
  std::string bin;
  ASSERT_TRUE(ros::param::get("~bin", bin));
  const Exported r = exportUnderLimit(command(bin, (dir / "out").string()), topic, dir);
  expectFullDiskHandled(r, dir / "out");
}

TEST(ViperExporterFullDisk, NodeEndsWithExitCode2) {
  expectFullDiskHandledBy(
      "node",
      [](const std::string& bin, const std::string& out) {
        return bin + "/viper_exporter __name:=full_disk_exporter _root:=" + out + " _camera:=none";
      },
      "/capture/color/image_raw");
}

TEST(ViperExporterFullDisk, ExportViperLiveEndsWithExitCode2) {
  expectFullDiskHandledBy(
      "live",
      [](const std::string& bin, const std::string& out) {
        return bin + "/export_viper --live --out " + out +
               " --camera none --topic color=/full_disk/live/image __name:=full_disk_live";
      },
      "/full_disk/live/image");
}

}  // namespace

int main(int argc, char** argv) {
  return viper::test::runTester(argc, argv, "viper_exporter_full_disk_tester", 1);
}
