#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/types/status.h"

namespace stcalib {

// Image line features (docs/method.md §4): grayscale → (blur) → edges → distance transform D →
// inverse distance transform IDT = 255·max(0, 1 − D/basin), smoothed. Projected LiDAR edge
// points read the IDT (higher = nearer an edge); the refinement samples the smoothed, capped
// distance map with a bicubic interpolator.
struct ImageFeatureOptions {
  enum class Detector {
    kCanny,     ///< Canny edges (the fast per-frame path; docs/tuning.md#canny-timing)
    kLsd,       ///< OpenCV LSD segments drawn into the mask
    kFastLine,  ///< cv::ximgproc FastLineDetector segments drawn into the mask
  };
  Detector detector = Detector::kCanny;
  double pre_blur_sigma_px = 1.0;  ///< Gaussian σ before edge detection [px], 0 = none
  double canny_low = 40;           ///< Canny hysteresis thresholds [grey levels]
  double canny_high = 120;
  double line_scale = 0.5;            ///< image scale LSD / FastLineDetector run at (0, 1]
  double min_segment_length_px = 15;  ///< shorter segments are texture, not drawn [px, full size]
  double basin_px = 20;               ///< D_max of the IDT [px]
  double smoothing_sigma_px = 1.5;    ///< Gaussian σ applied to the IDT and distance maps [px]
  double suppression_sigma_px = 12;   ///< wide blur subtracted for the texture-suppressed map [px]
  // Texture suppression on the edge mask: edge pixels whose (2·density_window_px+1)² window is
  // denser than this share of edge pixels are dropped (foliage, gravel); 0 = keep all.
  double max_edge_density = 0.0;
  int density_window_px = 7;
  // Also split the edges by orientation (Sobel gradient) into near-vertical and near-horizontal
  // lines with one distance map each, so that vertical LiDAR edges are compared with vertical
  // image edges only (dense texture has every orientation; structure has one).
  bool split_orientation = false;
  // With split_orientation: also the unsplit maps (distance_raw_px, idt, idt_suppressed,
  // idt_bandpass, distance_px). Whoever reads only the oriented maps saves a distance transform,
  // a blur, a band-pass and a min.
  bool unsplit_maps = true;
  bool precise_distance = false;  ///< exact Euclidean DT instead of the 3×3 mask, slower
                                  ///< (docs/tuning.md#precise-distance)
  // Rectangle of interest (x, y, w, h) [px]; empty = whole image. Outside it the maps are flat.
  cv::Rect region_of_interest;

  Status Validate() const;
};

// ImageFeatureOptions::Detector by name: canny | lsd | fld. ParseDetector: false, `detector`
// untouched, when `name` is none of them. DetectorChoices: the names, for a message.
std::string DetectorName(ImageFeatureOptions::Detector detector);
bool ParseDetector(const std::string& name, ImageFeatureOptions::Detector* detector);
std::string DetectorChoices();

// The maps of one edge orientation (near-vertical or near-horizontal image edges).
struct OrientedMaps {
  cv::Mat idt;             ///< CV_32F, smoothed IDT in [0, 255]
  cv::Mat idt_suppressed;  ///< texture-suppressed IDT
  cv::Mat idt_bandpass;    ///< IDT − wide blur, not clipped (see BandPass)
  cv::Mat distance_px;     ///< smoothed min(D, basin) [px]
};

struct ImageFeatures {
  cv::Mat edge_mask;        ///< CV_8U, 255 on edge pixels
  cv::Mat distance_raw_px;  ///< CV_32F, distance to the nearest edge pixel [px], unsmoothed
                            ///< (empty with split_orientation and not unsplit_maps)
  cv::Mat distance_px;      ///< CV_32F, smoothed min(D, basin) [px]; 0 on edges
  cv::Mat distance_vertical_raw_px;    ///< to near-vertical edge pixels [px] (split_orientation)
  cv::Mat distance_horizontal_raw_px;  ///< to near-horizontal edge pixels [px] (split_orientation)
  // The unsplit maps (empty with split_orientation and not unsplit_maps):
  cv::Mat idt;             ///< CV_32F, smoothed IDT in [0, 255]
  cv::Mat idt_suppressed;  ///< CV_32F, max(0, IDT − wide blur of IDT): dense texture fades
  cv::Mat idt_bandpass;    ///< CV_32F, IDT − wide blur of IDT, not clipped (see BandPass)
  std::vector<cv::Vec4f> segments;  ///< line segments at full-size coordinates (LSD/FLD)
  // With split_orientation: the maps of near-vertical [0] and near-horizontal [1] edges.
  std::array<OrientedMaps, 2> oriented;
  int edge_pixels = 0;  ///< after texture suppression
  int dense_pixels_removed = 0;

  bool empty() const { return edge_pixels == 0; }
};

// Never fails on image content: an empty or edge-less image gives empty features (flat maps,
// edge_pixels = 0) and a warning. `options` must be valid.
ImageFeatures ExtractImageFeatures(const cv::Mat& image, const ImageFeatureOptions& options);

// Distance [px] from every pixel to the nearest non-zero pixel of `edges` (CV_8U) under the 3×3
// chamfer metric that cv::distanceTransform uses for DIST_L2 with DIST_MASK_3 (steps of 0.955
// along an axis and 1.3693 along a diagonal, in 16-bit fixed point); the output (CV_32F) equals
// cv::distanceTransform(edges == 0, DIST_L2, DIST_MASK_3) bit for bit. Paths stay inside the
// image. Without any edge pixel every distance is the metric's "unreachable" value, as OpenCV's.
// Two raster passes whose row-to-row part vectorises, faster than OpenCV's (measured:
// docs/tuning.md#chamfer-distance).
void ChamferDistance(const cv::Mat& edges, cv::Mat* distance_px);

// IDT from a distance map: 255·max(0, 1 − D/basin), Gaussian-smoothed.
cv::Mat InverseDistanceTransform(const cv::Mat& distance_px, double basin_px, double sigma_px);

// IDT minus its wide blur (computed at reduced resolution): a band-pass map with zero mean over
// any patch much wider than sigma_px. Dense texture (foliage) averages to zero, an isolated edge
// is a peak in a negative moat. As a score it does not reward moving points into edge-dense
// regions; the clipped form (SuppressTexture) keeps the positive half of the texture and does.
// Measured: docs/tuning.md#band-pass
cv::Mat BandPass(const cv::Mat& idt, double sigma_px);
// max(0, BandPass(idt, sigma_px)).
cv::Mat SuppressTexture(const cv::Mat& idt, double sigma_px);

// The acquisition's coarse score map (docs/method.md §7): the raw distance map averaged over
// `scale`×`scale` cells, its IDT (basin `basin_px`, full-size pixels) minus its blur at
// σ = `basin_px` (a band-pass: dense texture averages to zero, an isolated edge is a wide peak),
// padded by one zero cell on each side. CV_32F, (cols/scale + 2)×(rows/scale + 2).
cv::Mat CoarseScoreMap(const cv::Mat& distance_raw_px, double basin_px, int scale);

}  // namespace stcalib
