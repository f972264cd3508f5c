#include "core/features/image_features.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/fast_line_detector.hpp>

#include "core/types/enum_names.h"

namespace stcalib {
namespace {

void Smooth(cv::Mat* map, double sigma_px) {
  if (sigma_px > 0)
    cv::GaussianBlur(*map, *map, cv::Size(), sigma_px, sigma_px, cv::BORDER_REPLICATE);
}

// Draws segments at least min_length long (full-size coordinates) into the mask.
void DrawSegments(const std::vector<cv::Vec4f>& segments, double min_length, cv::Mat* mask) {
  for (const cv::Vec4f& s : segments) {
    if (std::hypot(s[2] - s[0], s[3] - s[1]) < min_length) continue;
    cv::line(*mask, cv::Point2f(s[0], s[1]), cv::Point2f(s[2], s[3]), cv::Scalar(255), 1,
             cv::LINE_8);
  }
}

std::vector<cv::Vec4f> DetectSegments(const cv::Mat& gray, const ImageFeatureOptions& options) {
  cv::Mat small = gray;
  if (options.line_scale < 1.0) {
    cv::resize(gray, small, cv::Size(), options.line_scale, options.line_scale, cv::INTER_AREA);
  }
  std::vector<cv::Vec4f> segments;
  if (options.detector == ImageFeatureOptions::Detector::kLsd) {
    cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector(cv::LSD_REFINE_STD);
    lsd->detect(small, segments);
  } else {
    cv::Ptr<cv::ximgproc::FastLineDetector> fld = cv::ximgproc::createFastLineDetector(
        /*length_threshold=*/10, /*distance_threshold=*/1.414f, options.canny_low,
        options.canny_high, /*canny_aperture_size=*/3, /*do_merge=*/false);
    fld->detect(small, segments);
  }
  // Pixel centres: small pixel i covers full pixels [i/scale, (i+1)/scale), so its centre is at
  // full coordinate (i + 0.5)/scale − 0.5 (scaling alone would shift every segment by
  // 0.5·(1/scale − 1) px towards the origin: half a pixel at scale 0.5).
  const float inv = static_cast<float>(1.0 / options.line_scale);
  const float shift = 0.5f * (inv - 1.0f);
  for (cv::Vec4f& s : segments) s = s * inv + cv::Vec4f(shift, shift, shift, shift);
  return segments;
}

// The smoothed capped distance min(D, basin) and the IDT. The IDT 255·max(0, 1 − D/basin) is
// 255·(1 − min(D, basin)/basin), an affine map of the capped distance, and the Gaussian blur is
// linear (unit kernel sum, the same border), so one blur serves both: the IDT equals
// InverseDistanceTransform(D, basin, σ) up to float rounding.
void CappedDistanceAndIdt(const cv::Mat& distance_raw_px, const ImageFeatureOptions& options,
                          cv::Mat* distance_px, cv::Mat* idt) {
  cv::min(distance_raw_px, options.basin_px, *distance_px);
  Smooth(distance_px, options.smoothing_sigma_px);
  distance_px->convertTo(*idt, CV_32F, -255.0 / options.basin_px, 255.0);
}

}  // namespace

namespace {
constexpr EnumNames<ImageFeatureOptions::Detector, 3> kDetectorNames = {
    {{ImageFeatureOptions::Detector::kCanny, "canny"},
     {ImageFeatureOptions::Detector::kLsd, "lsd"},
     {ImageFeatureOptions::Detector::kFastLine, "fld"}}};
}  // namespace

std::string DetectorName(ImageFeatureOptions::Detector detector) {
  return EnumName(kDetectorNames, detector);
}

bool ParseDetector(const std::string& name, ImageFeatureOptions::Detector* detector) {
  return ParseEnumName(kDetectorNames, name, detector);
}

std::string DetectorChoices() { return EnumNameChoices(kDetectorNames); }

Status ImageFeatureOptions::Validate() const {
  if (!(basin_px > 0)) return Status::Error("image features: basin_px must be > 0");
  if (!(line_scale > 0 && line_scale <= 1)) {
    return Status::Error("image features: line_scale must be in (0, 1]");
  }
  if (pre_blur_sigma_px < 0 || smoothing_sigma_px < 0 || suppression_sigma_px <= 0) {
    return Status::Error("image features: blur sigmas must be >= 0 (suppression > 0)");
  }
  if (max_edge_density < 0 || max_edge_density > 1 || density_window_px < 1) {
    return Status::Error("image features: max_edge_density in [0, 1], density_window_px >= 1");
  }
  if (canny_low < 0 || canny_high < canny_low) {
    return Status::Error("image features: need 0 <= canny_low <= canny_high");
  }
  return Status::Ok();
}

void ChamferDistance(const cv::Mat& edges, cv::Mat* distance_px) {
  CHECK(edges.type() == CV_8UC1) << "ChamferDistance needs a CV_8UC1 mask";
  CHECK(distance_px != nullptr);
  // Fixed point with 16 fractional bits, as OpenCV: an axis step of 0.955, a diagonal one of
  // 1.3693 (the 3×3 mask that best fits the Euclidean metric, Borgefors 1986).
  constexpr int kShift = 16;
  const int32_t axis = static_cast<int32_t>(std::lround(0.955 * (1 << kShift)));
  const int32_t diagonal = static_cast<int32_t>(std::lround(1.3693 * (1 << kShift)));
  constexpr int32_t kUnreachable = std::numeric_limits<int32_t>::max() >> 2;
  const int rows = edges.rows, cols = edges.cols;
  distance_px->create(rows, cols, CV_32F);
  if (rows == 0 || cols == 0) return;
  // One padded row above and below and one column each side, all unreachable: paths stay inside.
  const int stride = cols + 2;
  std::vector<int32_t> d(static_cast<size_t>(rows + 2) * stride, kUnreachable);
  auto row = [&](int y) { return d.data() + static_cast<size_t>(y + 1) * stride + 1; };
  // Forward: from the row above (three neighbours, independent per pixel, so it vectorises),
  // then from the left (serial). Values only grow by a step, so they never overflow.
  for (int y = 0; y < rows; ++y) {
    const uint8_t* e = edges.ptr<uint8_t>(y);
    const int32_t* up = row(y - 1);
    int32_t* r = row(y);
    for (int x = 0; x < cols; ++x) {
      const int32_t from_up = std::min(up[x] + axis, std::min(up[x - 1], up[x + 1]) + diagonal);
      r[x] = e[x] ? 0 : from_up;
    }
    for (int x = 0; x < cols; ++x) r[x] = std::min(r[x], r[x - 1] + axis);
  }
  // Backward: from the row below, then from the right; then to pixels.
  const float scale = 1.0f / (1 << kShift);
  for (int y = rows - 1; y >= 0; --y) {
    const int32_t* down = row(y + 1);
    int32_t* r = row(y);
    for (int x = 0; x < cols; ++x) {
      r[x] =
          std::min(r[x], std::min(down[x] + axis, std::min(down[x - 1], down[x + 1]) + diagonal));
    }
    for (int x = cols - 1; x >= 0; --x) r[x] = std::min(r[x], r[x + 1] + axis);
    float* out = distance_px->ptr<float>(y);
    for (int x = 0; x < cols; ++x)
      out[x] = static_cast<float>(std::min(r[x], kUnreachable)) * scale;
  }
}

cv::Mat InverseDistanceTransform(const cv::Mat& distance_px, double basin_px, double sigma_px) {
  cv::Mat idt;
  // 255·(1 − D/basin), clipped at 0.
  distance_px.convertTo(idt, CV_32F, -255.0 / basin_px, 255.0);
  cv::max(idt, 0.0, idt);
  Smooth(&idt, sigma_px);
  return idt;
}

cv::Mat BandPass(const cv::Mat& idt, double sigma_px) {
  // The wide blur at a quarter of the resolution costs ~1/16 of a full-size one.
  const double scale = sigma_px >= 8 ? 0.25 : 1.0;
  cv::Mat small, blurred;
  cv::resize(idt, small, cv::Size(), scale, scale, cv::INTER_AREA);
  cv::GaussianBlur(small, small, cv::Size(), sigma_px * scale, sigma_px * scale,
                   cv::BORDER_REPLICATE);
  cv::resize(small, blurred, idt.size(), 0, 0, cv::INTER_LINEAR);
  return idt - blurred;
}

cv::Mat SuppressTexture(const cv::Mat& idt, double sigma_px) {
  cv::Mat out;
  cv::max(BandPass(idt, sigma_px), 0.0, out);
  return out;
}

cv::Mat CoarseScoreMap(const cv::Mat& distance_raw_px, double basin_px, int scale) {
  CHECK_GT(scale, 0);
  CHECK(basin_px > 0);
  cv::Mat distance, idt, blurred, padded;
  // Whole cells only, so that cell j covers pixels [j·scale, (j + 1)·scale) exactly.
  const cv::Size cells(distance_raw_px.cols / scale, distance_raw_px.rows / scale);
  cv::resize(distance_raw_px(cv::Rect(0, 0, cells.width * scale, cells.height * scale)), distance,
             cells, 0, 0, cv::INTER_AREA);
  cv::min(distance, basin_px, distance);
  distance.convertTo(idt, CV_32F, -255.0 / basin_px, 255.0);
  const double sigma = basin_px / scale;
  cv::GaussianBlur(idt, blurred, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
  cv::copyMakeBorder(idt - blurred, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  return padded;
}

ImageFeatures ExtractImageFeatures(const cv::Mat& image, const ImageFeatureOptions& options) {
  CHECK(options.Validate().ok()) << options.Validate().message();
  ImageFeatures features;
  if (image.empty()) {
    LOG(WARNING) << "image features: empty image, no features";
    return features;
  }
  cv::Mat gray;
  if (image.channels() == 3) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  } else {
    gray = image;
  }
  if (gray.depth() != CV_8U) gray.convertTo(gray, CV_8U);
  const cv::Rect full(0, 0, gray.cols, gray.rows);
  const cv::Rect roi =
      options.region_of_interest.area() > 0 ? (options.region_of_interest & full) : full;
  if (roi != full) {
    // Work on the crop (everything costs in proportion to its area), then embed: outside the
    // region there are no edges.
    ImageFeatureOptions crop_options = options;
    crop_options.region_of_interest = cv::Rect();
    const ImageFeatures crop =
        roi.area() > 0 ? ExtractImageFeatures(gray(roi).clone(), crop_options) : ImageFeatures();
    auto embed = [&](const cv::Mat& part, int type, double fill) {
      if (part.empty() && roi.area() > 0) return cv::Mat();  // a map not asked for stays empty
      cv::Mat out(gray.size(), type, cv::Scalar(fill));
      if (!part.empty()) part.copyTo(out(roi));
      return out;
    };
    const double far = 1e6;
    features.edge_mask = embed(crop.edge_mask, CV_8U, 0);
    features.distance_raw_px = embed(crop.distance_raw_px, CV_32F, far);
    if (options.split_orientation) {
      features.distance_vertical_raw_px = embed(crop.distance_vertical_raw_px, CV_32F, far);
      features.distance_horizontal_raw_px = embed(crop.distance_horizontal_raw_px, CV_32F, far);
    }
    features.distance_px = embed(crop.distance_px, CV_32F, options.basin_px);
    features.idt = embed(crop.idt, CV_32F, 0);
    features.idt_suppressed = embed(crop.idt_suppressed, CV_32F, 0);
    features.idt_bandpass = embed(crop.idt_bandpass, CV_32F, 0);
    features.segments = crop.segments;
    for (cv::Vec4f& s : features.segments) s += cv::Vec4f(roi.x, roi.y, roi.x, roi.y);
    features.edge_pixels = crop.edge_pixels;
    features.dense_pixels_removed = crop.dense_pixels_removed;
    return features;
  }
  cv::Mat blurred = gray;
  if (options.pre_blur_sigma_px > 0) {
    cv::GaussianBlur(gray, blurred, cv::Size(), options.pre_blur_sigma_px);
  }
  features.edge_mask = cv::Mat::zeros(gray.size(), CV_8U);
  if (options.detector == ImageFeatureOptions::Detector::kCanny) {
    cv::Canny(blurred, features.edge_mask, options.canny_low, options.canny_high);
  } else {
    features.segments = DetectSegments(blurred, options);
    DrawSegments(features.segments, options.min_segment_length_px, &features.edge_mask);
  }
  if (options.max_edge_density > 0) {
    cv::Mat density;
    const int window = 2 * options.density_window_px + 1;
    cv::boxFilter(features.edge_mask, density, CV_32F, cv::Size(window, window), cv::Point(-1, -1),
                  /*normalize=*/true, cv::BORDER_REPLICATE);
    const cv::Mat dense = density > 255.0 * options.max_edge_density;
    const int before = cv::countNonZero(features.edge_mask);
    features.edge_mask.setTo(0, dense);
    features.dense_pixels_removed = before - cv::countNonZero(features.edge_mask);
  }
  features.edge_pixels = cv::countNonZero(features.edge_mask);

  if (features.edge_pixels == 0) {
    LOG(WARNING) << "image features: no edges found (black, flat or featureless image)";
    features.distance_px = cv::Mat(gray.size(), CV_32F, cv::Scalar(options.basin_px));
    features.distance_raw_px = cv::Mat(gray.size(), CV_32F, cv::Scalar(1e6));
    if (options.split_orientation) {
      features.distance_vertical_raw_px = features.distance_raw_px.clone();
      features.distance_horizontal_raw_px = features.distance_raw_px.clone();
    }
    features.idt = cv::Mat::zeros(gray.size(), CV_32F);
    features.idt_suppressed = features.idt.clone();
    features.idt_bandpass = features.idt.clone();
    if (options.split_orientation) {  // the same maps as with edges, all flat
      for (OrientedMaps& m : features.oriented) {
        m.idt = features.idt.clone();
        m.idt_suppressed = features.idt.clone();
        m.idt_bandpass = features.idt.clone();
        m.distance_px = features.distance_px.clone();
      }
    }
    return features;
  }

  // Distance to the nearest non-zero pixel of `edges`.
  auto distance_to = [&](const cv::Mat& edges, cv::Mat* distance) {
    if (options.precise_distance) {
      cv::distanceTransform(edges == 0, *distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    } else {
      ChamferDistance(edges, distance);
    }
  };
  const bool unsplit = !options.split_orientation || options.unsplit_maps;
  if (unsplit) distance_to(features.edge_mask, &features.distance_raw_px);
  if (options.split_orientation) {
    // Gradient mostly along x = a near-vertical line; the 30° band in between (diagonal lines)
    // goes to neither. The 3×3 Sobel of 8-bit grey levels is an integer of at most 4·255 in
    // magnitude, so 16 bits hold it exactly; one pass over the edge pixels sorts them.
    cv::Mat gx, gy;
    cv::Sobel(blurred, gx, CV_16S, 1, 0, 3);
    cv::Sobel(blurred, gy, CV_16S, 0, 1, 3);
    cv::Mat vertical = cv::Mat::zeros(gray.size(), CV_8U);
    cv::Mat horizontal = cv::Mat::zeros(gray.size(), CV_8U);
    for (int y = 0; y < gray.rows; ++y) {
      const uint8_t* edge = features.edge_mask.ptr<uint8_t>(y);
      const int16_t* dx = gx.ptr<int16_t>(y);
      const int16_t* dy = gy.ptr<int16_t>(y);
      uint8_t* v = vertical.ptr<uint8_t>(y);
      uint8_t* h = horizontal.ptr<uint8_t>(y);
      for (int x = 0; x < gray.cols; ++x) {
        if (!edge[x]) continue;
        const float ax = static_cast<float>(std::abs(dx[x]));
        const float ay = static_cast<float>(std::abs(dy[x]));
        v[x] = ax * 0.577f >= ay ? edge[x] : 0;  // within 30° of vertical
        h[x] = ay * 0.577f >= ax ? edge[x] : 0;  // within 30° of horizontal
      }
    }
    distance_to(vertical, &features.distance_vertical_raw_px);
    distance_to(horizontal, &features.distance_horizontal_raw_px);
  }
  const cv::Mat& distance = features.distance_raw_px;
  if (unsplit) {
    CappedDistanceAndIdt(distance, options, &features.distance_px, &features.idt);
    features.idt_bandpass = BandPass(features.idt, options.suppression_sigma_px);
    cv::max(features.idt_bandpass, 0.0, features.idt_suppressed);
  }
  if (options.split_orientation) {
    const cv::Mat* raw[2] = {&features.distance_vertical_raw_px,
                             &features.distance_horizontal_raw_px};
    for (int o = 0; o < 2; ++o) {
      OrientedMaps& m = features.oriented[o];
      CappedDistanceAndIdt(*raw[o], options, &m.distance_px, &m.idt);
      m.idt_bandpass = BandPass(m.idt, options.suppression_sigma_px);
      cv::max(m.idt_bandpass, 0.0, m.idt_suppressed);
    }
  }
  return features;
}

}  // namespace stcalib
