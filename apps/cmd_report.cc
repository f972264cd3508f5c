// stcalib report RUN_DIR: report.html of a calibrate or check run folder, written again
// (docs/output.md).
#include <cstdio>

#include "apps/commands.h"
#include "apps/report.h"

namespace stcalib::cli {

int RunReport() {
  const std::string& run_dir = PositionalArgument();
  if (run_dir.empty()) return UsageError("report", "give the run folder: stcalib report RUN_DIR");
  const Status status = WriteRunReport(run_dir);
  if (!status.ok()) return ReportError("report", status);
  std::printf("wrote %s/report.html\n", run_dir.c_str());
  return kExitOk;
}

}  // namespace stcalib::cli
