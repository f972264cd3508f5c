#include <iostream>

#include "apps/commands.h"
#include "apps/flags.h"

namespace stcalib::cli {

int ReportError(const std::string& command, const Status& status) {
  std::cerr << "stcalib " << command << ": error: " << status.message() << "\n";
  return kExitFailure;
}

int UsageError(const std::string& command, const std::string& message) {
  std::cerr << "stcalib " << command << ": usage error: " << message << "\n(run `stcalib "
            << command << " --help`)\n";
  return kExitUsage;
}

Status OpenDriveFromFlags(Drive* drive) { return OpenDrive(FLAGS_drive, FLAGS_calib_dir, drive); }

}  // namespace stcalib::cli
