#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "core/io/kitti_calib.h"
#include "core/types/status.h"

namespace stcalib {

// Reads a colour image (BGR, 8 bit); errors name the file when it is missing or undecodable.
Status ReadImage(const std::string& path, cv::Mat* image_bgr);
// Writes an image; the format follows the extension (PNG for .png).
Status WriteImage(const std::string& path, const cv::Mat& image);

// The pixel maps that take a raw image of `camera` (its distortion model, K and coefficients) to
// the rectified image P_rect_02 · R_rect_00 describes, for cv::remap; empty maps when the camera
// has no distortion model. An error names an unsupported model or a wrong number of coefficients.
struct RectifyMaps {
  cv::Mat map_x, map_y;
  bool empty() const { return map_x.empty(); }
};
Status MakeRectifyMaps(const CameraCalibration& camera, RectifyMaps* maps);
// Rectifies `image` in place with `maps` (bilinear); nothing when the maps are empty.
void RectifyImage(const RectifyMaps& maps, cv::Mat* image);

}  // namespace stcalib
