// libFuzzer entry point for one reader; the reader's name is compiled in (STCALIB_FUZZ_READER).
// The input bytes are written to a file, because the readers take paths as users give them.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "test/fuzz/readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path =
      "/tmp/stcalib_fuzz_" STCALIB_FUZZ_READER "_" + std::to_string(getpid()) + ".in";
  FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return 0;
  if (size > 0) std::fwrite(data, 1, size, file);
  std::fclose(file);
  stcalib::fuzz::CheckReader(STCALIB_FUZZ_READER, path);
  return 0;
}
