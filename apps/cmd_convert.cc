// stcalib convert: a drive written as a ROS 2 bag (docs/method.md §9).
#include <cstdio>

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
  std::printf(
      "wrote %s: %zu frames, %llu messages (%s, %s, %s%s%s, /tf_static)\n"
      "calibrate it with: stcalib calibrate --bag=%s --image_topic=%s --cloud_topic=%s%s%s\n",
      summary.mcap_path.c_str(), summary.frames, static_cast<unsigned long long>(summary.messages),
      kBagImageTopic, kBagCameraInfoTopic, kBagCloudTopic, summary.odometry ? ", " : "",
      summary.odometry ? kBagOdometryTopic : "", FLAGS_bag.c_str(), kBagImageTopic, kBagCloudTopic,
      summary.odometry ? " --odom_topic=" : "", summary.odometry ? kBagOdometryTopic : "");
  return kExitOk;
}

}  // namespace stcalib::cli
