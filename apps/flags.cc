#include "apps/flags.h"

DEFINE_string(drive, "", "KITTI raw synced drive folder (image_02/, velodyne_points/, oxts/)");
DEFINE_string(calib_dir, "",
              "folder with calib_cam_to_cam.txt, calib_velo_to_cam.txt, calib_imu_to_velo.txt "
              "(default: the drive's parent folder)");
DEFINE_int32(frame, 0, "frame index (0-based, in file-name order)");
DEFINE_string(out, "", "output file or folder");
DEFINE_int32(frames, 40, "simulate: number of frames");
DEFINE_uint64(seed, 1, "random seed (simulate: the whole drive)");
DEFINE_double(time_offset_s, 0.0,
              "simulate: true time offset δ [s]; LiDAR stamps are the true time minus δ");
DEFINE_int32(dynamic_objects, 6, "simulate: moving vehicles and pedestrians");
DEFINE_string(scene, "urban", "simulate: urban | poles (vertical structures only) | open");
DEFINE_double(lidar_hz, 10.0, "simulate: LiDAR spin rate = frame rate of every sensor [Hz]");
DEFINE_string(detector, "canny", "image edges: canny | lsd | fld (cv::ximgproc FastLineDetector)");
DEFINE_double(min_segment_px, 15, "lsd/fld: shorter segments are dropped as texture [px]");
DEFINE_double(max_edge_density, 0.0,
              "features: drop edge pixels in windows denser than this share (texture), 0 = off");
