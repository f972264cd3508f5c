#include "core/io/text.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace stcalib {

Status ReadLines(const std::string& path, std::vector<std::string>* lines) {
  lines->clear();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return Status::Error(path + ": file not found");
  if (std::filesystem::is_directory(path, ec)) {
    return Status::Error(path + ": is a directory, expected a file");
  }
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open: " + std::strerror(errno));
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines->push_back(line);
  }
  if (in.bad()) return Status::Error(path + ": read error");
  return Status::Ok();
}

bool ParseNumbers(const std::string& text, std::vector<double>* values, std::string* bad_token) {
  values->clear();
  std::istringstream stream(text);
  std::string token;
  while (stream >> token) {
    const char* begin = token.c_str();
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(begin, &end);
    if (end == begin || *end != '\0' || !std::isfinite(value)) {
      if (bad_token != nullptr) *bad_token = token;
      return false;
    }
    values->push_back(value);
  }
  return true;
}

Status WriteTextFile(const std::string& path, const std::string& contents) {
  return WriteFileAtomically(path, contents.data(), contents.size());
}

Status WriteFileAtomically(const std::string& path, const char* data, size_t size) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return Status::Error(path + ": cannot write: " + std::strerror(errno));
    out.write(data, static_cast<std::streamsize>(size));
    out.flush();
    if (!out) return Status::Error(path + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return Status::Error(path + ": cannot rename from " + tmp + ": " + ec.message());
  return Status::Ok();
}

bool IsBlank(const std::string& line) {
  for (char c : line) {
    if (!std::isspace(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

}  // namespace stcalib
