// Shared by the .hjif reader, writer, conformance checker and the .hmpg
// codec (src/io/hjif_*.cpp, src/io/hmpg.cpp); not installed.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "texel/interchange.hpp"

namespace texel::hjif::detail {

/// How strictly a text is walked.
enum class Mode {
  /// The reader: refuses what the published schema refuses (dates excepted:
  /// every form real writers use is read) and what Texel cannot sample.
  read,
  /// The published schemas word for word (date-time is RFC 3339), nothing else.
  schema,
  /// The checker: the schema word for word (date-time is RFC 3339), plus the
  /// field dependencies of the schema's descriptions and the reference
  /// software's loader rules.
  check,
};

/// The schema's body parts (channel body_part_target), in the order of their binary codes.
inline constexpr std::string_view kBodyParts[] = {
    "Unknown",        "All",           "Upper", "Lower",  "Right",     "Left",       "Front",    "Back",      "Arm",
    "Head",           "Chest",         "Waist", "Leg",    "Upper-arm", "Forearm",    "Hand",     "Crane",     "Neck",
    "Thigh",          "Calf",          "Foot",  "Palm",   "Finger",    "Sole",       "Toe",      "Thumb",     "Index",
    "Middle",         "Ring",          "Pinky", "Hallux", "Index-Toe", "Middle-Toe", "Ring-Toe", "Pinky-Toe", "First Phalanx",
    "Second Phalanx", "Third Phalanx", "Minus", "Plus"};

/// Base signals, in the order of their binary codes.
inline constexpr std::string_view kBaseSignals[] = {"Sine", "Square", "Triangle", "SawToothUp", "SawToothDown"};

/// A reference device's optional numbers (all ≥ 0), in the order of the binary
/// syntax's presence mask (which adds `custom`, then `type`).
inline constexpr std::string_view kDeviceNumbers[] = {"maximum_frequency",
                                                      "minimum_frequency",
                                                      "resonance_frequency",
                                                      "maximum_amplitude",
                                                      "impedance",
                                                      "maximum_voltage",
                                                      "maximum_current",
                                                      "maximum_displacement",
                                                      "weight",
                                                      "size"};

/// Every violation found (read: the reader's subset), and what was read.
struct Walked {
  std::vector<std::string> errors;
  Experience experience;
};

/// Validates a text; throws FormatError only for what stops the walk (size,
/// nesting, JSON syntax).
Walked walk_text(std::string_view text, std::string_view origin, const ImportLimits& limits, Mode mode);

/// A value quoted for a one-line message: control characters escaped, at most 40 characters.
std::string quote_value(std::string_view v);

/// RFC 3339 date-time (the schema's `format: date-time`): YYYY-MM-DDTHH:MM:SS[.frac](Z|±HH:MM),
/// T and Z in either case, real calendar dates, seconds 00–59.
bool rfc3339_date_time(std::string_view s);

/// The dates the reader accepts besides RFC 3339: ISO 8601 calendar dates
/// with or without a time, "T" or a space between them, with or without a
/// zone ("2026-11-26", "2026-11-26 14:06:29", "2026-11-26T14:06").
bool liberal_date(std::string_view s);

/// JSON nesting depth of a text (brackets outside strings), counted up to just past `limit`.
std::size_t nesting_depth(std::string_view text, std::size_t limit);

/// A Linear curve at tick u: linear between keyframes, 0 outside [first, last]
/// (a millionth of a tick of slack at the ends).
double curve_at(const CurveEffect& c, double u);

/// 10^k for small k.
double pow10i(int k);

/// The modalities whose positions are spatial (Texel reads them as positions in mm).
bool is_spatial(std::string_view modality);

}  // namespace texel::hjif::detail
