#pragma once

#include <string>

#include "core/types/status.h"

namespace stcalib::cli {

// report.html of a calibrate or check run folder (docs/output.md): one self-contained page made
// from the folder's own files only (result.json and per_frame.csv, or check.json, and the
// pictures, inlined as data URIs; no network, no script fetched), so `stcalib report RUN_DIR`
// writes the same page again. A folder with neither file, or whose file lacks a key the page
// shows (a run of another version), is an error naming the file and what is missing: nothing is
// invented.
Status WriteRunReport(const std::string& run_dir);

// The version every output names: the project's version and the commit it was configured at.
const char* StcalibVersion();

}  // namespace stcalib::cli
