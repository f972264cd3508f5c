#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "core/types/status.h"

namespace stcalib {

// Reads a colour image (BGR, 8 bit); errors name the file when it is missing or undecodable.
Status ReadImage(const std::string& path, cv::Mat* image_bgr);
// Writes an image; the format follows the extension (PNG for .png).
Status WriteImage(const std::string& path, const cv::Mat& image);

}  // namespace stcalib
