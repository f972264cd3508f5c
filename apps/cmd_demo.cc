// stcalib demo: simulate a drive with a known extrinsic and time offset, calibrate it from a
// wrong start, and print truth, start, estimate and error side by side.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "apps/calibrate_job.h"
#include "apps/commands.h"
#include "apps/flags.h"
#include "core/sim/simulator.h"

namespace stcalib::cli {

int RunDemo() {
  namespace fs = std::filesystem;
  const std::string flags_error = CalibrateFlagsError();
  if (!flags_error.empty()) return UsageError("demo", flags_error);
  const auto start = std::chrono::steady_clock::now();
  std::error_code ec;
  const std::string root =
      FLAGS_out.empty()
          ? (fs::temp_directory_path() / ("stcalib_demo_" + std::to_string(::getpid()))).string()
          : FLAGS_out;
  fs::create_directories(root, ec);
  sim::SimulatorOptions sim_options;
  sim_options.frames = FLAGS_frames > 0 && FLAGS_frames != 40 ? FLAGS_frames : 20;
  sim_options.seed = FLAGS_seed;
  sim_options.time_offset_s = 0.03;
  sim_options.dynamic_objects = 6;
  std::printf(
      "1/2 simulating %d frames (seed %llu, true time offset +30 ms, 6 moving objects) in %s\n",
      sim_options.frames, static_cast<unsigned long long>(sim_options.seed), root.c_str());
  std::fflush(stdout);
  std::string drive_dir;
  Status status = sim::WriteSimulatedDrive(sim_options, root + "/sim", &drive_dir);
  if (!status.ok()) return ReportError("demo", status);

  CalibrateJob job = CalibrateJobFromFlags();
  job.drive_dir = drive_dir;
  job.calib_dir.clear();
  job.init_calib.clear();
  job.out_dir = root + "/calibration";
  job.perturb_rot_deg = 2.0;
  job.perturb_trans_m = 0.05;
  job.perturb_time_s = 0.0;
  job.first_frame = 0;
  job.num_frames = 0;
  std::printf("2/2 calibrating from +-2 deg on roll, pitch and yaw, +-5 cm, time offset 0\n");
  std::fflush(stdout);
  std::vector<CalibrateOutcome> outcomes;
  const int code = RunCalibrateJob(job, &outcomes);
  if (outcomes.empty() || outcomes.front().reports.empty()) return code;
  const CalibrateOutcome& outcome = outcomes.front();

  // `observable`: per axis (kAxisNames order), whether to print the value; an axis the tool
  // could not observe is shown as "held" (it rests on its start or prior, it is no estimate).
  auto row = [](const char* name, const CalibrationError& e, double delta_ms,
                const std::array<bool, kNumAxes>& observable) {
    const double values[kNumAxes] = {e.roll_deg,
                                     e.pitch_deg,
                                     e.yaw_deg,
                                     100 * e.translation_m.x(),
                                     100 * e.translation_m.y(),
                                     100 * e.translation_m.z(),
                                     delta_ms};
    char cells[kNumAxes][16];
    for (int k = 0; k < kNumAxes; ++k) {
      const int width = k < 3 ? 8 : (k < 6 ? 7 : 8);
      if (observable[k]) {
        std::snprintf(cells[k], sizeof(cells[k]), k < 3 ? "%*.3f" : (k < 6 ? "%*.1f" : "%*.2f"),
                      width, values[k]);
      } else {
        std::snprintf(cells[k], sizeof(cells[k]), "%*s", width, "held");
      }
    }
    std::printf("  %-9s %8.3f %s %s %s | %s %s %s | %s\n", name, e.rotation_deg, cells[0], cells[1],
                cells[2], cells[3], cells[4], cells[5], cells[6]);
  };
  std::array<bool, kNumAxes> all;
  all.fill(true);
  std::printf(
      "\n            rotation error [deg]                 | translation error [cm] | time offset "
      "[ms]\n");
  std::printf("            total     roll    pitch      yaw |       x       y       z |\n");
  row("truth", CalibrationError(), 1000 * outcome.reference_state.time_offset_s, all);
  row("start", outcome.initial_error, 1000 * outcome.initial.time_offset_s, all);
  row("estimate", outcome.error, 1000 * outcome.estimate.time_offset_s, outcome.observable);
  std::printf(
      "  (\"held\": not observable in this drive, the value rests on its start or prior; "
      "see result.json's std and observable)\n");
  std::printf("  (time offset column: the value itself; its error is %+.2f ms)\n",
              1000 * outcome.error.time_offset_s);
  std::printf("%s", TimeOffsetPriorNote(outcome).c_str());
  // A verdict other than success gives its reason ("not converged: ...").
  const std::string verdict =
      outcome.converged && outcome.held_axes.empty() ? "converged" : outcome.reason;
  std::printf("\n%s; %.0f ms per frame; %.1f s in all\n", verdict.c_str(), outcome.mean_frame_ms,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  std::printf("pictures:\n");
  for (const std::string& p : outcome.pictures) std::printf("  %s\n", p.c_str());
  std::printf("estimate and result.json: %s\n", job.out_dir.c_str());
  return code;
}

}  // namespace stcalib::cli
