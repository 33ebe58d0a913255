// Strict, path-aware reading of JSON objects for Texel's file formats.
//
// Every accessor names the field by its JSON path in errors ("regions[1].
// texture.texel_length_mm is -1; ..."), and finish() reports keys that were
// never read, so a typo cannot silently fall back to a default.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::detail {

class JsonObject {
 public:
  JsonObject(const nlohmann::json& j, std::string path) : j_(j), path_(std::move(path)) {
    if (!j_.is_object()) throw FormatError(where() + " must be a JSON object, got " + type_of(j_));
  }

  [[nodiscard]] std::string field(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }
  [[nodiscard]] bool has(std::string_view key) const { return j_.contains(key) && !j_.at(std::string(key)).is_null(); }
  [[nodiscard]] const nlohmann::json& raw(std::string_view key) {
    seen_.insert(std::string(key));
    const auto it = j_.find(std::string(key));
    if (it == j_.end()) throw FormatError(field(key) + " is missing");
    return *it;
  }
  void skip(std::string_view key) { seen_.insert(std::string(key)); }

  double number(std::string_view key, double lo = -std::numeric_limits<double>::infinity(),
                double hi = std::numeric_limits<double>::infinity()) {
    const auto& v = raw(key);
    if (!v.is_number()) throw FormatError(field(key) + " must be a number, got " + type_of(v));
    const double d = v.get<double>();
    if (!(d >= lo && d <= hi)) throw FormatError(field(key) + " is " + num(d) + "; allowed: " + num(lo) + " … " + num(hi));
    return d;
  }
  double number_or(std::string_view key, double fallback, double lo = -std::numeric_limits<double>::infinity(),
                   double hi = std::numeric_limits<double>::infinity()) {
    if (!has(key)) {
      skip(key);
      return fallback;
    }
    return number(key, lo, hi);
  }
  std::optional<double> optional_number(std::string_view key, double lo, double hi) {
    if (!has(key)) {
      skip(key);
      return std::nullopt;
    }
    return number(key, lo, hi);
  }
  std::uint64_t uint64(std::string_view key) {
    const auto& v = raw(key);
    if (v.is_number_unsigned()) return v.get<std::uint64_t>();
    if (v.is_number_integer() && v.get<std::int64_t>() >= 0) return static_cast<std::uint64_t>(v.get<std::int64_t>());
    throw FormatError(field(key) + " must be a whole number 0 … 18446744073709551615, got " + v.dump());
  }
  std::uint64_t uint64_or(std::string_view key, std::uint64_t fallback) {
    if (!has(key)) {
      skip(key);
      return fallback;
    }
    return uint64(key);
  }
  std::int64_t integer(std::string_view key, std::int64_t lo, std::int64_t hi) {
    const auto& v = raw(key);
    if (!v.is_number_integer()) throw FormatError(field(key) + " must be a whole number, got " + v.dump());
    const auto i = v.get<std::int64_t>();
    if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(hi))
      throw FormatError(field(key) + " is " + v.dump() + "; allowed: " + std::to_string(lo) + " … " + std::to_string(hi));
    if (i < lo || i > hi)
      throw FormatError(field(key) + " is " + std::to_string(i) + "; allowed: " + std::to_string(lo) + " … " +
                        std::to_string(hi));
    return i;
  }
  std::string string(std::string_view key) {
    const auto& v = raw(key);
    if (!v.is_string()) throw FormatError(field(key) + " must be a string, got " + type_of(v));
    return v.get<std::string>();
  }
  std::string string_or(std::string_view key, std::string fallback) {
    if (!has(key)) {
      skip(key);
      return fallback;
    }
    return string(key);
  }
  bool boolean_or(std::string_view key, bool fallback) {
    if (!has(key)) {
      skip(key);
      return fallback;
    }
    const auto& v = raw(key);
    if (!v.is_boolean()) throw FormatError(field(key) + " must be true or false, got " + v.dump());
    return v.get<bool>();
  }

  /// Reports the first key that no accessor read.
  void finish() const {
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      if (!seen_.count(it.key())) {
        std::string known;
        for (const auto& s : seen_) known += (known.empty() ? "" : ", ") + s;
        throw FormatError(where() + " has unknown key '" + it.key() + "' (known keys here: " + known + ")");
      }
    }
  }

  [[nodiscard]] std::string where() const { return path_.empty() ? "the document" : path_; }
  [[nodiscard]] const std::string& path() const { return path_; }

  static std::string type_of(const nlohmann::json& v) {
    if (v.is_string()) return "the string " + v.dump();
    if (v.is_number()) return "the number " + v.dump();
    return std::string("a ") + v.type_name();
  }

 private:
  const nlohmann::json& j_;
  std::string path_;
  std::set<std::string> seen_;
};

/// Parses JSON text, turning syntax errors into FormatError naming `origin`.
inline nlohmann::json parse_json(std::string_view text, std::string_view origin) {
  try {
    return nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::exception& e) {
    // parse_error, and out_of_range for a number too large for a double ("1e999").
    std::string msg = e.what();
    // "[json.exception.parse_error.101] parse error at line 1, column 5: ..." -> keep the useful part
    auto pos = msg.find("parse error");
    if (pos == std::string::npos && (pos = msg.find("] ")) != std::string::npos) pos += 2;
    throw FormatError(std::string(origin) + ": malformed JSON: " + (pos == std::string::npos ? msg : msg.substr(pos)));
  }
}

}  // namespace texel::detail
