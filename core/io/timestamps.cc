#include "core/io/timestamps.h"

#include <cctype>
#include <cstdio>

#include "core/io/text.h"

namespace stcalib {
namespace {

constexpr int64_t kNsPerSecond = 1000000000LL;
constexpr int64_t kSecondsPerDay = 86400;

// Days since 1970-01-01 of a proleptic Gregorian date (civil calendar arithmetic on eras of
// 400 years, 146097 days each).
int64_t DaysFromCivil(int64_t year, int64_t month, int64_t day) {
  year -= month <= 2 ? 1 : 0;
  const int64_t era = (year >= 0 ? year : year - 399) / 400;
  const int64_t year_of_era = year - era * 400;
  const int64_t shifted_month = month > 2 ? month - 3 : month + 9;  // March = 0
  const int64_t day_of_year = (153 * shifted_month + 2) / 5 + day - 1;
  const int64_t day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
  return era * 146097 + day_of_era - 719468;
}

void CivilFromDays(int64_t days, int64_t* year, int64_t* month, int64_t* day) {
  days += 719468;
  const int64_t era = (days >= 0 ? days : days - 146096) / 146097;
  const int64_t day_of_era = days - era * 146097;
  const int64_t year_of_era =
      (day_of_era - day_of_era / 1460 + day_of_era / 36524 - day_of_era / 146096) / 365;
  const int64_t day_of_year =
      day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
  const int64_t shifted_month = (5 * day_of_year + 2) / 153;
  *day = day_of_year - (153 * shifted_month + 2) / 5 + 1;
  *month = shifted_month < 10 ? shifted_month + 3 : shifted_month - 9;
  *year = year_of_era + era * 400 + (*month <= 2 ? 1 : 0);
}

int DaysInMonth(int64_t year, int64_t month) {
  static const int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  return month == 2 && leap ? 29 : kDays[month - 1];
}

// Reads exactly `count` digits at text[*pos].
bool ReadDigits(const std::string& text, size_t* pos, int count, int64_t* value) {
  *value = 0;
  for (int i = 0; i < count; ++i, ++*pos) {
    if (*pos >= text.size() || !std::isdigit(static_cast<unsigned char>(text[*pos]))) {
      return false;
    }
    *value = *value * 10 + (text[*pos] - '0');
  }
  return true;
}

bool Expect(const std::string& text, size_t* pos, char c) {
  if (*pos >= text.size() || text[*pos] != c) return false;
  ++*pos;
  return true;
}

}  // namespace

bool ParseKittiTimestamp(const std::string& raw, StampNs* stamp_ns) {
  size_t begin = 0, end = raw.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(raw[begin]))) ++begin;
  while (end > begin && std::isspace(static_cast<unsigned char>(raw[end - 1]))) --end;
  const std::string text = raw.substr(begin, end - begin);
  size_t pos = 0;
  int64_t year, month, day, hour, minute, second;
  if (!ReadDigits(text, &pos, 4, &year) || !Expect(text, &pos, '-') ||
      !ReadDigits(text, &pos, 2, &month) || !Expect(text, &pos, '-') ||
      !ReadDigits(text, &pos, 2, &day) || !Expect(text, &pos, ' ') ||
      !ReadDigits(text, &pos, 2, &hour) || !Expect(text, &pos, ':') ||
      !ReadDigits(text, &pos, 2, &minute) || !Expect(text, &pos, ':') ||
      !ReadDigits(text, &pos, 2, &second)) {
    return false;
  }
  int64_t fraction_ns = 0;
  if (pos < text.size()) {
    if (!Expect(text, &pos, '.')) return false;
    int digits = 0;
    while (pos < text.size() && digits < 9) {
      if (!std::isdigit(static_cast<unsigned char>(text[pos]))) return false;
      fraction_ns = fraction_ns * 10 + (text[pos] - '0');
      ++pos;
      ++digits;
    }
    if (digits == 0 || pos != text.size()) return false;
    for (; digits < 9; ++digits) fraction_ns *= 10;
  }
  // Nanoseconds since 1970 in an int64 reach 1677..2262; years outside 1900..2200 are typos.
  if (year < 1900 || year > 2200 || month < 1 || month > 12 || day < 1 ||
      day > DaysInMonth(year, month) || hour > 23 || minute > 59 || second > 60) {
    return false;
  }
  const int64_t seconds =
      DaysFromCivil(year, month, day) * kSecondsPerDay + hour * 3600 + minute * 60 + second;
  *stamp_ns = seconds * kNsPerSecond + fraction_ns;
  return true;
}

std::string FormatKittiTimestamp(StampNs stamp_ns) {
  int64_t seconds = stamp_ns / kNsPerSecond;
  int64_t fraction_ns = stamp_ns % kNsPerSecond;
  if (fraction_ns < 0) {
    fraction_ns += kNsPerSecond;
    --seconds;
  }
  int64_t days = seconds / kSecondsPerDay;
  int64_t second_of_day = seconds % kSecondsPerDay;
  if (second_of_day < 0) {
    second_of_day += kSecondsPerDay;
    --days;
  }
  int64_t year, month, day;
  CivilFromDays(days, &year, &month, &day);
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%04lld-%02lld-%02lld %02lld:%02lld:%02lld.%09lld",
                static_cast<long long>(year), static_cast<long long>(month),
                static_cast<long long>(day), static_cast<long long>(second_of_day / 3600),
                static_cast<long long>(second_of_day / 60 % 60),
                static_cast<long long>(second_of_day % 60), static_cast<long long>(fraction_ns));
  return buffer;
}

Status ReadTimestampsFile(const std::string& path, std::vector<StampNs>* stamps_ns) {
  stamps_ns->clear();
  std::vector<std::string> lines;
  STCALIB_RETURN_IF_ERROR(ReadLines(path, &lines));
  while (!lines.empty() && IsBlank(lines.back())) lines.pop_back();
  for (size_t i = 0; i < lines.size(); ++i) {
    StampNs stamp = 0;
    if (!ParseKittiTimestamp(lines[i], &stamp)) {
      return Status::Error(path + ":" + std::to_string(i + 1) + ": malformed timestamp '" +
                           lines[i] + "' (expected YYYY-MM-DD HH:MM:SS.nnnnnnnnn)");
    }
    stamps_ns->push_back(stamp);
  }
  if (stamps_ns->empty()) return Status::Error(path + ": no timestamps in file");
  return Status::Ok();
}

Status WriteTimestampsFile(const std::string& path, const std::vector<StampNs>& stamps_ns) {
  std::string contents;
  for (StampNs stamp : stamps_ns) contents += FormatKittiTimestamp(stamp) + "\n";
  return WriteTextFile(path, contents);
}

}  // namespace stcalib
