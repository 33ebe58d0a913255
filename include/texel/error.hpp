// One project error type and its families (fmt's format_error pattern).
// Every error a user can cause carries a message that names the field, the
// value and what was allowed; front doors print it on one line and exit 2.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace texel {

/// Base of every exception Texel throws on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A parameter outside its allowed range or set (library or CLI input).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// An InvalidArgument about one named library option field ("spacing",
/// "swipe_speed", "region" ...): what() is "<field> <detail>". Front doors
/// that spell the field differently (the CLI's --spacing) rewrite the field
/// name in one place and keep the detail.
class FieldError : public InvalidArgument {
 public:
  FieldError(std::string field, std::string detail)
      : InvalidArgument(field + " " + detail), field_(std::move(field)), detail_(std::move(detail)) {}
  [[nodiscard]] const std::string& field() const { return field_; }
  [[nodiscard]] const std::string& detail() const { return detail_; }

 private:
  std::string field_;
  std::string detail_;
};

/// A file or byte string that does not parse or validate.
class FormatError : public Error {
 public:
  using Error::Error;
};

/// An operating-system level failure: unreadable input, unwritable output.
class IoError : public Error {
 public:
  using Error::Error;
};

}  // namespace texel
