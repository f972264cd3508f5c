// The benchmarks' main: the process keeps freed heap memory as the `stcalib` CLI does
// (core/types/heap.h), so per-frame figures are those of a calibration run.
#include <benchmark/benchmark.h>
#include <glog/logging.h>

#include "core/types/heap.h"

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  if (!stcalib::RetainFreedHeapMemory()) LOG(WARNING) << "freed heap memory is not retained";
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
