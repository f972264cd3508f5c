// stcalib eval-temporal: the paper's Table I against ROS ApproximateTime pairing (docs/method.md
// §8).
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "apps/commands.h"
#include "apps/flags.h"
#include "apps/plot.h"
#include "core/eval/temporal_eval.h"
#include "core/io/image.h"
#include "core/io/text.h"

namespace stcalib::cli {
namespace {

std::string TableCsv(const TemporalEvalResult& r) {
  std::string csv =
      "method,nn_dist_m,ndt_iters_step_0.01,ndt_iters_step_0.05,icp_fitness_1,icp_fitness_5\n";
  for (int m = 0; m < 3; ++m) {
    char row[256];
    const CloudMetrics& c = r.mean[m];
    std::snprintf(row, sizeof(row), "%s,%.4f,%.2f,%.2f,%.5f,%.5f\n", kTemporalMethodNames[m],
                  c.nn_dist_m, c.ndt_iters_001, c.ndt_iters_005, c.icp_fitness_1, c.icp_fitness_5);
    csv += r.count[m] > 0 ? row : std::string(kTemporalMethodNames[m]) + ",,,,,\n";
  }
  return csv;
}

std::string TableMarkdown(const std::string& title, const TemporalEvalResult& r) {
  std::string md = "### " + title +
                   "\n\n| method | frames | NN distance [m] | NDT iterations (step 0.01 m) | "
                   "NDT iterations (step 0.05 m) | ICP fitness, 1 iteration [m²] | ICP fitness, 5 "
                   "iterations [m²] |\n"
                   "|---|---|---|---|---|---|---|\n";
  for (int m = 0; m < 3; ++m) {
    char row[256];
    const CloudMetrics& c = r.mean[m];
    std::snprintf(row, sizeof(row), "| %s | %d | %.4f | %.1f | %.1f | %.5f | %.5f |\n",
                  kTemporalMethodNames[m], r.count[m], c.nn_dist_m, c.ndt_iters_001,
                  c.ndt_iters_005, c.icp_fitness_1, c.icp_fitness_5);
    md += row;
  }
  if (r.count[kFilterCloud] > 0 && r.count[kInferCloud] > 0) {
    char gain[160];
    std::snprintf(gain, sizeof(gain),
                  "\ninfer_cloud vs filter_cloud, NN distance: %.1f %% better\n",
                  100.0 * (1.0 - r.mean[kInferCloud].nn_dist_m / r.mean[kFilterCloud].nn_dist_m));
    md += gain;
  }
  return md;
}

cv::Mat Curves(const TemporalEvalResult& r) {
  const cv::Scalar colours[3] = {cv::Scalar(0, 0, 220), cv::Scalar(0, 150, 0),
                                 cv::Scalar(200, 100, 0)};
  std::vector<double> x;
  for (const TemporalFrame& f : r.frames) {
    if (x.empty() || x.back() != f.image) x.push_back(f.image);
  }
  auto series = [&](double CloudMetrics::*field) {
    std::vector<Series> s;
    for (int m = 0; m < 3; ++m) {
      Series line{kTemporalMethodNames[m], std::vector<double>(x.size(), NAN), colours[m]};
      for (const TemporalFrame& f : r.frames) {
        if (f.method != m) continue;
        const size_t k = std::lower_bound(x.begin(), x.end(), f.image) - x.begin();
        line.values[k] = f.metrics.*field;
      }
      s.push_back(line);
    }
    return s;
  };
  std::vector<cv::Mat> panels = {
      PlotPanel("mean nearest-neighbour distance to the held-out sweep [m]", x,
                series(&CloudMetrics::nn_dist_m)),
      PlotPanel("NDT iterations to converge (step 0.01 m)", x,
                series(&CloudMetrics::ndt_iters_001)),
      PlotPanel("ICP fitness after 5 iterations [m^2]", x, series(&CloudMetrics::icp_fitness_5))};
  cv::Mat out;
  cv::vconcat(panels, out);
  return out;
}

}  // namespace

int RunEvalTemporal() {
  const char* kCommand = "eval-temporal";
  // docs/method.md §9: --out is optional; without it the tables are printed and nothing is written.
  const bool write = !FLAGS_out.empty();
  Drive drive;
  Status status = OpenDriveFromFlags(&drive);
  if (!status.ok()) return ReportError(kCommand, status);
  TemporalEvalOptions options;
  options.lidar_decimation = FLAGS_lidar_decimation;
  options.lidar_delay_s = FLAGS_lidar_delay_s;
  options.drive_time_offset_s = FLAGS_time_offset_s;
  options.max_range_m = FLAGS_eval_max_range_m;
  status = options.Validate();
  if (!status.ok()) return UsageError(kCommand, status.message());
  // A simulated drive knows its own δ.
  bool simulated = false;
  CalibrationState truth;
  status = ReadGroundTruth(drive, &simulated, &truth);
  if (!status.ok()) return ReportError(kCommand, status);
  if (simulated) options.drive_time_offset_s = truth.time_offset_s;
  if (write) {
    std::error_code ec;
    std::filesystem::create_directories(FLAGS_out, ec);
    if (ec || !std::filesystem::is_directory(FLAGS_out)) {
      return ReportError(kCommand, Status::Error(FLAGS_out + ": cannot create output folder"));
    }
  }
  std::string md = "# Temporal evaluation (docs/method.md §8)\n\nDrive " + drive.drive_dir +
                   ", LiDAR decimated by " + std::to_string(options.lidar_decimation) + " and " +
                   std::to_string(options.lidar_delay_s) + " s late.\n\n";
  TemporalEvalResult all, static_only;
  for (bool remove_dynamic : {false, true}) {
    options.remove_dynamic = remove_dynamic;
    TemporalEvalResult& r = remove_dynamic ? static_only : all;
    std::fprintf(stderr, "eval-temporal: %s dynamic-point removal...\n",
                 remove_dynamic ? "with" : "without");
    status = EvaluateTemporal(drive, options, &r);
    if (!status.ok()) return ReportError(kCommand, status);
    const std::string section =
        TableMarkdown(remove_dynamic ? "With dynamic points removed" : "All points", r);
    md += section + "\n";
    std::printf("%s\n", section.c_str());
    if (!write) continue;
    const std::string name = remove_dynamic ? "table_dynamic_removed" : "table";
    status = WriteTextFile(FLAGS_out + "/" + name + ".csv", TableCsv(r));
    if (!status.ok()) return ReportError(kCommand, status);
    status =
        WriteImage(FLAGS_out + "/" + (remove_dynamic ? "curves_dynamic_removed.png" : "curves.png"),
                   Curves(r));
    if (!status.ok()) return ReportError(kCommand, status);
  }
  char line[128];
  std::snprintf(line, sizeof(line), "Motion model time offset: %.4f s (drive %.4f s − delay).\n",
                all.time_offset_s, options.drive_time_offset_s);
  md += line;
  std::printf("%s", line);
  if (!write) return kExitOk;
  status = WriteTextFile(FLAGS_out + "/table.md", md);
  if (!status.ok()) return ReportError(kCommand, status);
  std::printf(
      "wrote "
      "%s/{table.csv,table.md,table_dynamic_removed.csv,curves.png,curves_dynamic_removed.png}\n",
      FLAGS_out.c_str());
  return kExitOk;
}

}  // namespace stcalib::cli
