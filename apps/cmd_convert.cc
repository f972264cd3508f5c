// stcalib convert: a drive written as a ROS 2 bag (docs/method.md §9).
#include <cstdio>
#include <string>

#include "apps/commands.h"
#include "apps/flags.h"
#include "core/convert/drive_to_bag.h"

namespace stcalib::cli {

int RunConvert() {
  const char* kCommand = "convert";
  if (FLAGS_bag.empty()) return UsageError(kCommand, "--bag=OUT_DIR is required");
  Drive drive;
  Status status = OpenDriveFromFlags(&drive);
  if (!status.ok()) return ReportError(kCommand, status);
  // A simulated drive's clouds go out as its LiDAR's driver writes them.
  std::string lidar;
  status = ReadSimulatedLidarName(drive, &lidar);
  if (!status.ok()) return ReportError(kCommand, status);
  DriveToBagSummary summary;
  status = WriteDriveAsBag(drive, FLAGS_bag, CloudLayoutForLidar(lidar), &summary);
  if (!status.ok()) return ReportError(kCommand, status);
  std::string topics =
      std::string(kBagImageTopic) + ", " + kBagCameraInfoTopic + ", " + kBagCloudTopic +
      (summary.odometry ? std::string(", ") + kBagOdometryTopic + ", " + kBagImuTopic
                        : std::string()) +
      ", /tf_static";
  std::printf(
      "wrote %s: %zu frames, %llu messages (%s)\n"
      "calibrate it with: stcalib calibrate --bag=%s --image_topic=%s --cloud_topic=%s%s\n",
      summary.mcap_path.c_str(), summary.frames, static_cast<unsigned long long>(summary.messages),
      topics.c_str(), FLAGS_bag.c_str(), kBagImageTopic, kBagCloudTopic,
      summary.odometry ? (std::string(" --odom_topic=") + kBagOdometryTopic).c_str() : "");
  return kExitOk;
}

}  // namespace stcalib::cli
