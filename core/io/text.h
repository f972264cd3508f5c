#pragma once

#include <string>
#include <vector>

#include "core/types/status.h"

namespace stcalib {

// Reads a whole text file into lines (without line terminators; a trailing '\r' is dropped).
Status ReadLines(const std::string& path, std::vector<std::string>* lines);

// Parses whitespace-separated numbers; false when a token is not a number or is not finite.
// `bad_token` (optional) receives the first offending token.
bool ParseNumbers(const std::string& text, std::vector<double>* values,
                  std::string* bad_token = nullptr);

// Writes `contents` to `path` atomically enough for our needs: to `path.tmp`, then renamed.
Status WriteTextFile(const std::string& path, const std::string& contents);
// Writes bytes to `path.tmp`, then renames it onto `path`.
Status WriteFileAtomically(const std::string& path, const char* data, size_t size);

// True when the line holds only whitespace.
bool IsBlank(const std::string& line);

}  // namespace stcalib
