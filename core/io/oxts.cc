#include "core/io/oxts.h"

#include <cmath>
#include <cstdio>

#include "core/io/text.h"

namespace stcalib {
namespace {

// Field order of oxts/dataformat.txt; the last five are integers.
template <typename Packet, typename Visitor>
void VisitFields(Packet& p, Visitor&& visit) {
  double* reals[] = {&p.lat, &p.lon, &p.alt,          &p.roll,        &p.pitch, &p.yaw, &p.vn,
                     &p.ve,  &p.vf,  &p.vl,           &p.vu,          &p.ax,    &p.ay,  &p.az,
                     &p.af,  &p.al,  &p.au,           &p.wx,          &p.wy,    &p.wz,  &p.wf,
                     &p.wl,  &p.wu,  &p.pos_accuracy, &p.vel_accuracy};
  int* integers[] = {&p.navstat, &p.numsats, &p.posmode, &p.velmode, &p.orimode};
  for (double* r : reals) visit(r, nullptr);
  for (int* i : integers) visit(nullptr, i);
}

}  // namespace

Status ParseOxtsPacket(const std::string& line, const std::string& path, OxtsPacket* packet) {
  std::vector<double> values;
  std::string bad;
  if (!ParseNumbers(line, &values, &bad)) {
    return Status::Error(path + ":1: '" + bad + "' is not a finite number");
  }
  if (static_cast<int>(values.size()) != kOxtsFieldCount) {
    return Status::Error(path + ":1: oxts packet has " + std::to_string(values.size()) +
                         " fields, expected " + std::to_string(kOxtsFieldCount));
  }
  OxtsPacket parsed;
  size_t index = 0;
  bool integral = true;
  VisitFields(parsed, [&](double* real, int* integer) {
    const double v = values[index++];
    if (real != nullptr) {
      *real = v;
    } else {
      if (v != std::floor(v) || std::abs(v) > 1e9) {
        integral = false;  // and never cast: out of int range is undefined behaviour
        return;
      }
      *integer = static_cast<int>(v);
    }
  });
  if (!integral) {
    return Status::Error(path + ":1: oxts fields navstat..orimode must be integers");
  }
  if (std::abs(parsed.lat) > 90 || std::abs(parsed.lon) > 180) {
    return Status::Error(path + ":1: latitude/longitude out of range");
  }
  *packet = parsed;
  return Status::Ok();
}

Status ReadOxtsPacket(const std::string& path, OxtsPacket* packet) {
  std::vector<std::string> lines;
  STCALIB_RETURN_IF_ERROR(ReadLines(path, &lines));
  while (!lines.empty() && IsBlank(lines.back())) lines.pop_back();
  if (lines.empty()) return Status::Error(path + ": empty oxts file");
  if (lines.size() > 1) return Status::Error(path + ":2: expected one packet line");
  return ParseOxtsPacket(lines[0], path, packet);
}

std::string FormatOxtsPacket(const OxtsPacket& packet) {
  std::string line;
  OxtsPacket copy = packet;
  VisitFields(copy, [&](double* real, int* integer) {
    char buffer[40];
    if (real != nullptr) {
      std::snprintf(buffer, sizeof(buffer), "%.17g", *real);
    } else {
      std::snprintf(buffer, sizeof(buffer), "%d", *integer);
    }
    if (!line.empty()) line += ' ';
    line += buffer;
  });
  return line;
}

Status WriteOxtsPacket(const std::string& path, const OxtsPacket& packet) {
  return WriteTextFile(path, FormatOxtsPacket(packet) + "\n");
}

}  // namespace stcalib
