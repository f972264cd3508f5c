#pragma once

#include <string>
#include <utility>

namespace stcalib {

// Outcome of an operation on user input (files, flags, data). Programmer errors use CHECK;
// everything a user can get wrong comes back as a Status whose message names the file, the line
// where there is one, and the problem.
class Status {
 public:
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return ok_; }
  const std::string& message() const { return message_; }

  // Prefixes the message with context, e.g. "while opening drive X: ".
  Status WithContext(const std::string& context) const {
    return ok_ ? *this : Status(context + message_);
  }

 private:
  Status() = default;
  explicit Status(std::string message) : ok_(false), message_(std::move(message)) {}

  bool ok_ = true;
  std::string message_;
};

}  // namespace stcalib

// Returns from the enclosing function when `expr` yields a non-ok Status.
#define STCALIB_RETURN_IF_ERROR(expr)                  \
  do {                                                 \
    ::stcalib::Status _stcalib_status = (expr);        \
    if (!_stcalib_status.ok()) return _stcalib_status; \
  } while (0)
