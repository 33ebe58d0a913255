// Units as types: millimetres, cycles per millimetre, decibels re 1 cycle/mm,
// hertz and seconds are distinct, so a pitch in dB can never be passed where
// cycles/mm are expected.
//
// A Quantity is a double with a tag. Same-unit arithmetic is allowed;
// conversions between units are explicit functions (to_cpm, to_db, ...).
// The dB scale is the spec's power form: X_dB = 10·log10(X / 1 cpm)
// (docs/algorithm.md §2), so 10 cpm = 10 dB and 0.1 cpm = -10 dB.
#pragma once

#include <compare>
#include <optional>

namespace texel {

template <class Tag>
class Quantity {
 public:
  constexpr Quantity() = default;
  constexpr explicit Quantity(double value) : value_(value) {}
  [[nodiscard]] constexpr double value() const { return value_; }

  constexpr Quantity operator+(Quantity o) const { return Quantity(value_ + o.value_); }
  constexpr Quantity operator-(Quantity o) const { return Quantity(value_ - o.value_); }
  constexpr Quantity operator-() const { return Quantity(-value_); }
  constexpr Quantity operator*(double k) const { return Quantity(value_ * k); }
  constexpr Quantity operator/(double k) const { return Quantity(value_ / k); }
  constexpr double operator/(Quantity o) const { return value_ / o.value_; }
  constexpr Quantity& operator+=(Quantity o) {
    value_ += o.value_;
    return *this;
  }
  constexpr Quantity& operator-=(Quantity o) {
    value_ -= o.value_;
    return *this;
  }
  constexpr auto operator<=>(const Quantity&) const = default;

 private:
  double value_ = 0.0;
};

template <class Tag>
constexpr Quantity<Tag> operator*(double k, Quantity<Tag> q) {
  return q * k;
}

struct MillimetreTag {};
struct CyclesPerMmTag {};
struct DecibelTag {};
struct HertzTag {};
struct SecondTag {};
struct MmPerSecondTag {};

using Millimetres = Quantity<MillimetreTag>;   ///< position or length along the swipe axis
using CyclesPerMm = Quantity<CyclesPerMmTag>;  ///< spatial frequency
using Decibels = Quantity<DecibelTag>;         ///< spatial frequency in dB re 1 cycle/mm
using Hertz = Quantity<HertzTag>;              ///< temporal frequency
using Seconds = Quantity<SecondTag>;           ///< time
using MmPerSecond = Quantity<MmPerSecondTag>;  ///< finger speed

/// dB re 1 cpm -> cycles/mm (10^(dB/10)). Deterministic: uses Texel's own exp.
CyclesPerMm to_cpm(Decibels db);
/// cycles/mm -> dB re 1 cpm (10·log10(f)). Requires f > 0.
Decibels to_db(CyclesPerMm f);
/// Temporal frequency felt by a finger moving at speed v over spatial frequency f.
constexpr Hertz temporal(CyclesPerMm f, MmPerSecond v) { return Hertz(f.value() * v.value()); }
/// Spatial position reached after time t at speed v.
constexpr Millimetres travelled(MmPerSecond v, Seconds t) { return Millimetres(v.value() * t.value()); }

/// An optional plain number as an optional quantity (for parsed, optional fields).
inline std::optional<Millimetres> millimetres(std::optional<double> v) {
  return v ? std::optional<Millimetres>(Millimetres(*v)) : std::nullopt;
}

namespace literals {
constexpr Millimetres operator""_mm(long double v) { return Millimetres(static_cast<double>(v)); }
constexpr Millimetres operator""_mm(unsigned long long v) { return Millimetres(static_cast<double>(v)); }
constexpr CyclesPerMm operator""_cpm(long double v) { return CyclesPerMm(static_cast<double>(v)); }
constexpr CyclesPerMm operator""_cpm(unsigned long long v) { return CyclesPerMm(static_cast<double>(v)); }
constexpr Decibels operator""_dB(long double v) { return Decibels(static_cast<double>(v)); }
constexpr Decibels operator""_dB(unsigned long long v) { return Decibels(static_cast<double>(v)); }
constexpr Hertz operator""_Hz(long double v) { return Hertz(static_cast<double>(v)); }
constexpr Hertz operator""_Hz(unsigned long long v) { return Hertz(static_cast<double>(v)); }
constexpr Seconds operator""_s(long double v) { return Seconds(static_cast<double>(v)); }
constexpr Seconds operator""_s(unsigned long long v) { return Seconds(static_cast<double>(v)); }
constexpr MmPerSecond operator""_mm_per_s(long double v) { return MmPerSecond(static_cast<double>(v)); }
constexpr MmPerSecond operator""_mm_per_s(unsigned long long v) { return MmPerSecond(static_cast<double>(v)); }
}  // namespace literals

}  // namespace texel
