#include "core/io/image.h"

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

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

Status MakeRectifyMaps(const CameraCalibration& camera, RectifyMaps* maps) {
  *maps = RectifyMaps();
  if (camera.distortion_model.empty()) return Status::Ok();
  cv::Mat K, R, P, D(1, static_cast<int>(camera.distortion.size()), CV_64F);
  cv::eigen2cv(camera.K, K);
  cv::eigen2cv(camera.R_rect_00, R);
  const Eigen::Matrix3d P3 = camera.P_rect.leftCols<3>();
  cv::eigen2cv(P3, P);
  for (size_t k = 0; k < camera.distortion.size(); ++k)
    D.at<double>(static_cast<int>(k)) = camera.distortion[k];
  const cv::Size size(camera.image_width, camera.image_height);
  const size_t n = camera.distortion.size();
  if (camera.distortion_model == "equidistant") {
    if (n != 4) {
      return Status::Error("camera model equidistant needs 4 coefficients, got " +
                           std::to_string(n));
    }
    cv::fisheye::initUndistortRectifyMap(K, D, R, P, size, CV_32FC1, maps->map_x, maps->map_y);
  } else if (camera.distortion_model == "plumb_bob" ||
             camera.distortion_model == "rational_polynomial") {
    if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
      return Status::Error("camera model " + camera.distortion_model +
                           " needs 4, 5, 8, 12 or 14 coefficients, got " + std::to_string(n));
    }
    cv::initUndistortRectifyMap(K, D, R, P, size, CV_32FC1, maps->map_x, maps->map_y);
  } else {
    return Status::Error("camera model \"" + camera.distortion_model +
                         "\" is not supported (plumb_bob, rational_polynomial, equidistant)");
  }
  return Status::Ok();
}

void RectifyImage(const RectifyMaps& maps, cv::Mat* image) {
  if (maps.empty()) return;
  cv::Mat rectified;
  cv::remap(*image, rectified, maps.map_x, maps.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  *image = rectified;
}

}  // namespace stcalib
