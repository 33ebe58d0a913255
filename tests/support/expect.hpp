// The one way tests check an error: the exception's type and a fragment of
// its message, and on failure the message that was actually thrown (or that
// nothing was, or that another type was).
//
//   EXPECT_THROW_MSG(parse_npy("junk", "x.npy"), texel::FormatError, "x.npy: not a .npy file");
//   const std::string m = message_of<texel::FieldError>([&] { load_signal(path); });
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <string>
#include <string_view>

#include "texel/error.hpp"

namespace texel::test_support {

/// The message of the `E` that `f()` throws; "(no exception)" when it
/// returns, "wrong type: <message>" when it throws anything else.
template <class E = texel::Error, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("wrong type: ") + e.what();
  }
  return "(no exception)";
}

/// EXPECT_THROW_MSG's check: `f()` throws an `E` whose message contains
/// `fragment`.
template <class E, class F>
::testing::AssertionResult throws_with(F&& f, std::string_view fragment, const char* statement, const char* type) {
  try {
    f();
  } catch (const E& e) {
    if (std::string_view(e.what()).find(fragment) != std::string_view::npos) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << statement << " threw " << type << " \"" << e.what() << "\", which does not contain \""
                                         << fragment << '"';
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << statement << " threw another type than " << type << ": \"" << e.what() << '"';
  }
  return ::testing::AssertionFailure() << statement << " threw nothing (expected " << type << " with \"" << fragment << "\")";
}

}  // namespace texel::test_support

/// EXPECT_THROW_MSG(statement, type, fragment): `statement` throws `type`
/// (or a class derived from it) whose what() contains `fragment`.
#define EXPECT_THROW_MSG(statement, type, fragment) \
  EXPECT_TRUE((::texel::test_support::throws_with<type>([&] { statement; }, fragment, #statement, #type)))
