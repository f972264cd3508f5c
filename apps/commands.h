#pragma once

#include <string>

#include "core/io/drive.h"
#include "core/types/calibration.h"
#include "core/types/status.h"

namespace stcalib::cli {

// Exit codes shared by every subcommand.
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;  ///< bad input, unreadable data, or a negative result
constexpr int kExitUsage = 2;    ///< unknown subcommand, missing or invalid flag

int RunInfo();
int RunProject();
int RunSimulate();
int RunFeatures();
int RunCalibrate();
int RunDemo();
int RunEvalTemporal();

// Prints "stcalib <command>: error: <message>" to stderr and returns kExitFailure.
int ReportError(const std::string& command, const Status& status);
// Prints a usage error and returns kExitUsage.
int UsageError(const std::string& command, const std::string& message);
// Reads ground_truth.json beside a simulated drive's calibration; *found is false (and the
// status ok) when the drive has none.
Status ReadGroundTruth(const Drive& drive, bool* found, CalibrationState* truth);
// Opens --drive with --calib_dir.
Status OpenDriveFromFlags(Drive* drive);

}  // namespace stcalib::cli
