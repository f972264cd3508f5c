#include "core/eval/temporal_eval.h"

#include <glog/logging.h>

#include <cmath>

#include "core/eval/approximate_time.h"
#include "core/features/kdtree.h"
#include "core/features/lidar_frame.h"
#include "core/motion/drive_motion.h"

namespace stcalib {

const std::array<const char*, 3> kTemporalMethodNames = {"filter_cloud", "infer_cloud",
                                                         "infer_cloud_interpolation"};

Status TemporalEvalOptions::Validate() const {
  if (lidar_decimation < 1) return Status::Error("--lidar_decimation must be >= 1");
  if (!(lidar_delay_s >= 0 && lidar_delay_s <= 1.0)) {
    return Status::Error("--lidar_delay_s must be within [0, 1] s");
  }
  if (!(max_range_m > 0) || nn_stride < 1) return Status::Error("eval: bad range or stride");
  return Status::Ok();
}

Status MeasureCloud(const std::vector<Eigen::Vector3d>& predicted,
                    const std::vector<Eigen::Vector3d>& reference,
                    const TemporalEvalOptions& options, CloudMetrics* metrics) {
  if (predicted.size() < 100 || reference.size() < 100) {
    return Status::Error("eval: too few points to compare (" + std::to_string(predicted.size()) +
                         " predicted, " + std::to_string(reference.size()) + " reference)");
  }
  const PointKdTree tree(reference);
  double sum = 0;
  int n = 0;
  for (size_t i = 0; i < predicted.size(); i += options.nn_stride) {
    int index;
    double d;
    tree.Nearest(predicted[i], &index, &d);
    sum += d;
    ++n;
  }
  metrics->nn_dist_m = sum / n;
  for (double step : {0.01, 0.05}) {
    NdtOptions ndt = options.ndt;
    ndt.step_size_m = step;
    RegistrationResult r;
    STCALIB_RETURN_IF_ERROR(RegisterNdt(predicted, reference, Rigid3d::Identity(), ndt, &r));
    (step < 0.03 ? metrics->ndt_iters_001 : metrics->ndt_iters_005) = r.iterations;
  }
  for (int iterations : {1, 5}) {
    IcpOptions icp = options.icp;
    icp.max_iterations = iterations;
    RegistrationResult r;
    STCALIB_RETURN_IF_ERROR(RegisterIcp(predicted, reference, Rigid3d::Identity(), icp, &r));
    (iterations == 1 ? metrics->icp_fitness_1 : metrics->icp_fitness_5) = r.fitness;
  }
  return Status::Ok();
}

namespace {

// Points of a sweep (de-skewed to its stamp) within range, dynamic ones dropped if asked.
std::vector<Eigen::Vector3d> Cloud(const LidarFrameFeatures& f,
                                   const TemporalEvalOptions& options) {
  std::vector<Eigen::Vector3d> cloud;
  cloud.reserve(f.deskewed.size());
  const double r2 = options.max_range_m * options.max_range_m;
  for (size_t i = 0; i < f.deskewed.size(); ++i) {
    if (options.remove_dynamic && !f.dynamic.dynamic.empty() && f.dynamic.dynamic[i]) continue;
    if (f.deskewed[i].squaredNorm() > r2) continue;
    cloud.push_back(f.deskewed[i]);
  }
  return cloud;
}

std::vector<Eigen::Vector3d> Transformed(const Rigid3d& T,
                                         const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> out(points.size());
  for (size_t i = 0; i < points.size(); ++i) out[i] = T * points[i];
  return out;
}

}  // namespace

Status EvaluateTemporal(const Drive& drive, const TemporalEvalOptions& options,
                        TemporalEvalResult* result) {
  STCALIB_RETURN_IF_ERROR(options.Validate());
  *result = TemporalEvalResult();
  const size_t n = drive.NumFrames();
  if (n < static_cast<size_t>(2 * options.lidar_decimation + 1)) {
    return Status::Error(drive.drive_dir + ": " + std::to_string(n) + " frames are too few for a " +
                         "decimation of " + std::to_string(options.lidar_decimation) + " (need " +
                         std::to_string(2 * options.lidar_decimation + 1) + ")");
  }
  DriveMotion motion;
  STCALIB_RETURN_IF_ERROR(DriveMotion::Create(drive, &motion));
  // A gap in the oxts stream longer than three frame periods makes the motion model guess.
  for (size_t i = 1; i < drive.oxts_stamps_ns.size(); ++i) {
    const double gap = NsToSeconds(drive.oxts_stamps_ns[i] - drive.oxts_stamps_ns[i - 1]);
    const double period =
        NsToSeconds(drive.camera_stamps_ns.back() - drive.camera_stamps_ns.front()) / (n - 1);
    if (gap > 3 * period) {
      return Status::Error(drive.drive_dir + "/oxts/timestamps.txt:" + std::to_string(i + 1) +
                           ": gap of " + std::to_string(gap) + " s in the oxts stream");
    }
  }
  LidarFeatureOptions lidar_options;
  lidar_options.remove_dynamic = options.remove_dynamic;
  SweepCache cache(drive, motion, lidar_options, /*capacity=*/2 * options.lidar_decimation + 6);

  // The decimated, delayed LiDAR stream and the image stream, paired by ApproximateTime.
  std::vector<int> kept;
  std::vector<StampNs> delayed;
  for (size_t k = 0; k < n; k += options.lidar_decimation) {
    kept.push_back(static_cast<int>(k));
    delayed.push_back(drive.lidar_stamps_ns[k] + SecondsToNs(options.lidar_delay_s));
  }
  const auto pairs = PairApproximateTime(drive.camera_stamps_ns, delayed);
  std::vector<int> paired_sweep(n, -1);
  for (const auto& [image, k] : pairs) {
    paired_sweep[image] = kept[k];
    result->pairs.emplace_back(image, kept[k]);
  }
  // δ seen by the motion model: a sweep stamped s was captured at s + δ; the delay adds to the
  // stamps, so δ = δ_drive − delay for the delayed stream.
  result->time_offset_s = options.drive_time_offset_s - options.lidar_delay_s;

  auto sweep = [&](size_t frame, const LidarFrameFeatures** f) {
    return options.remove_dynamic ? cache.Finished(frame, f) : cache.Base(frame, f);
  };
  for (size_t i = 0; i < n; ++i) {
    const double t_image = motion.Seconds(drive.camera_stamps_ns[i]);
    // Held-out reference: the real sweep of this frame, carried the few ms to the image time.
    const LidarFrameFeatures* ref;
    STCALIB_RETURN_IF_ERROR(sweep(i, &ref));
    const double ref_capture = ref->stamp_s + options.drive_time_offset_s;
    const std::vector<Eigen::Vector3d> reference = Transformed(
        RelativeLidarPose(motion.PoseFunction(), t_image, ref_capture), Cloud(*ref, options));
    auto evaluate = [&](int method, int k) -> Status {
      const LidarFrameFeatures* f;
      STCALIB_RETURN_IF_ERROR(sweep(k, &f));
      // The sweep was stamped late by the delay; with δ its capture time is the true one.
      const double stamp = motion.Seconds(delayed[k / options.lidar_decimation]);
      const double capture = stamp + result->time_offset_s;
      std::vector<Eigen::Vector3d> cloud = Cloud(*f, options);
      if (method != kFilterCloud) {
        cloud = Transformed(RelativeLidarPose(motion.PoseFunction(), t_image, capture), cloud);
      }
      TemporalFrame frame;
      frame.image = static_cast<int>(i);
      frame.method = method;
      frame.sweep = k;
      frame.gap_s = capture - t_image;
      STCALIB_RETURN_IF_ERROR(MeasureCloud(cloud, reference, options, &frame.metrics)
                                  .WithContext("frame " + std::to_string(i) + ": "));
      result->frames.push_back(frame);
      return Status::Ok();
    };
    if (paired_sweep[i] >= 0) {
      STCALIB_RETURN_IF_ERROR(evaluate(kFilterCloud, paired_sweep[i]));
      STCALIB_RETURN_IF_ERROR(evaluate(kInferCloud, paired_sweep[i]));
    } else {
      // Unpaired image: predict from the latest sweep that had arrived by the image time.
      int latest = -1;
      for (size_t k = 0; k < kept.size(); ++k) {
        if (delayed[k] <= drive.camera_stamps_ns[i]) latest = kept[k];
      }
      if (latest >= 0) STCALIB_RETURN_IF_ERROR(evaluate(kInferCloudInterpolation, latest));
    }
  }
  for (const TemporalFrame& f : result->frames) {
    CloudMetrics& m = result->mean[f.method];
    const int c = ++result->count[f.method];
    auto add = [c](double* mean, double v) { *mean += (v - *mean) / c; };
    add(&m.nn_dist_m, f.metrics.nn_dist_m);
    add(&m.ndt_iters_001, f.metrics.ndt_iters_001);
    add(&m.ndt_iters_005, f.metrics.ndt_iters_005);
    add(&m.icp_fitness_1, f.metrics.icp_fitness_1);
    add(&m.icp_fitness_5, f.metrics.icp_fitness_5);
  }
  if (result->count[kFilterCloud] == 0) {
    return Status::Error(drive.drive_dir + ": ApproximateTime paired no image with a sweep");
  }
  return Status::Ok();
}

}  // namespace stcalib
