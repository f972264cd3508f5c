#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/io/drive.h"
#include "core/pcl/registration.h"
#include "core/types/status.h"

namespace stcalib {

// The paper's Table I (docs/method.md §8): LiDAR decimated to a lower rate and delayed; images
// paired by ApproximateTime (`filter_cloud`); the paired sweep carried to the image time by the
// motion model with the calibrated δ (`infer_cloud`); sweeps predicted for the images
// ApproximateTime left unpaired (`infer_cloud_interpolation`). Each is compared with the real sweep
// at the image time, held out.
struct TemporalEvalOptions {
  int lidar_decimation = 2;        ///< keep every n-th sweep
  double lidar_delay_s = 0.1;      ///< the kept sweeps' stamps are this late [s]
  double drive_time_offset_s = 0;  ///< the drive's own δ (simulated truth or a calibration) [s]
  bool remove_dynamic = false;     ///< drop dynamic points (docs/method.md §5) from every cloud
  double max_range_m = 120.0;      ///< points beyond are left out of every metric [m]
  int nn_stride = 2;               ///< every n-th predicted point is queried for the NN metric
  NdtOptions ndt;
  IcpOptions icp;

  TemporalEvalOptions() { ndt.max_iterations = 150; }
  Status Validate() const;
};

enum TemporalMethod { kFilterCloud = 0, kInferCloud = 1, kInferCloudInterpolation = 2 };
extern const std::array<const char*, 3> kTemporalMethodNames;

struct CloudMetrics {
  double nn_dist_m = 0;      ///< mean nearest-neighbour distance to the held-out sweep [m]
  double ndt_iters_001 = 0;  ///< PCL NDT iterations to converge, step 0.01 m
  double ndt_iters_005 = 0;  ///< ... step 0.05 m
  double icp_fitness_1 = 0;  ///< PCL ICP fitness after 1 iteration [m²]
  double icp_fitness_5 = 0;  ///< ... after 5 iterations
};

struct TemporalFrame {
  int image = 0;
  int method = 0;
  int sweep = 0;     ///< the sweep used
  double gap_s = 0;  ///< capture time of that sweep − image time [s]
  CloudMetrics metrics;
};

struct TemporalEvalResult {
  std::vector<std::pair<int, int>> pairs;  ///< (image, sweep) from ApproximateTime
  std::vector<TemporalFrame> frames;
  std::array<CloudMetrics, 3> mean;
  std::array<int, 3> count{};
  double time_offset_s = 0;  ///< δ used by the motion model (drive δ − delay) [s]
};

Status EvaluateTemporal(const Drive& drive, const TemporalEvalOptions& options,
                        TemporalEvalResult* result);

// The metrics of one predicted cloud against the reference (both in the same frame).
Status MeasureCloud(const std::vector<Eigen::Vector3d>& predicted,
                    const std::vector<Eigen::Vector3d>& reference,
                    const TemporalEvalOptions& options, CloudMetrics* metrics);

}  // namespace stcalib
