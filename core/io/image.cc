#include "core/io/image.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

namespace stcalib {

Status ReadImage(const std::string& path, cv::Mat* image_bgr) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status::Error(path + ": image file not found");
  }
  cv::Mat image;
  try {
    image = cv::imread(path, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": cannot decode image: " + e.what());
  }
  if (image.empty())
    return Status::Error(path + ": cannot decode image (unreadable or not an image)");
  *image_bgr = image;
  return Status::Ok();
}

Status WriteImage(const std::string& path, const cv::Mat& image) {
  if (image.empty()) return Status::Error(path + ": refusing to write an empty image");
  bool written = false;
  try {
    written = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": cannot write image: " + e.what());
  }
  if (!written) return Status::Error(path + ": cannot write image");
  return Status::Ok();
}

}  // namespace stcalib
