// One project error type and its families (fmt's format_error pattern).
// Every error a user can cause carries a message that names the field, the
// value and what was allowed; front doors print it on one line and exit 2.
#pragma once

#include <stdexcept>
#include <string>

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
