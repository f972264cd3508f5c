#include "apps/flags.h"

DEFINE_string(drive, "", "KITTI raw synced drive folder (image_02/, velodyne_points/, oxts/)");
DEFINE_string(calib_dir, "",
              "folder with calib_cam_to_cam.txt, calib_velo_to_cam.txt, calib_imu_to_velo.txt "
              "(default: the drive's parent folder)");
DEFINE_int32(frame, 0, "frame index (0-based, in file-name order)");
DEFINE_string(out, "", "output file or folder");
