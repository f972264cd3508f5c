#pragma once

#include <string>

namespace stcalib::fuzz {

// The readers under fuzzing, by name: velodyne (velodyne .bin and labels .bin), oxts (one
// packet), timestamps, cam_to_cam, velo_to_cam, imu_to_velo, mcap (a ROS 2 bag's file, each
// message decoded as below), ros_cdr (one CDR message as each message type the bag path decodes).
extern const char* const kReaders[8];

// Runs reader `name` on the file at `path` and checks what it promises: either an error that
// names the file, or a result with only finite numbers (and proper rotations). Aborts on a broken
// promise, so that libFuzzer and the regression test both see it. Returns false for an unknown
// reader name.
bool CheckReader(const std::string& name, const std::string& path);

}  // namespace stcalib::fuzz
