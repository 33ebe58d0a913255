#include "texel/coarse.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel {
namespace {

using detail::num;

void check_unit_interval(double v, const std::string& field) {
  if (!(v >= 0.0 && v <= 1.0)) throw InvalidArgument(field + " is " + num(v) + "; allowed: 0 … 1");
}

double interpolate_points(const std::vector<std::pair<double, double>>& pts, double x) {
  if (x <= pts.front().first) return pts.front().second;
  if (x >= pts.back().first) return pts.back().second;
  std::size_t lo = 0;
  std::size_t hi = pts.size() - 1;
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (pts[mid].first <= x ? lo : hi) = mid;
  }
  const double t = (x - pts[lo].first) / (pts[hi].first - pts[lo].first);
  return pts[lo].second + t * (pts[hi].second - pts[lo].second);
}

double interpolate_sampled(const SampledProfile& p, double x) {
  const double pos = x / p.spacing.value();
  if (pos <= 0.0) return p.values.front();
  const double last = static_cast<double>(p.values.size() - 1);
  if (pos >= last) return p.values.back();
  const double i = std::floor(pos);
  const auto k = static_cast<std::size_t>(i);
  const double t = pos - i;
  return p.values[k] + t * (p.values[k + 1] - p.values[k]);
}

struct Validator {
  void operator()(const ConstantProfile& p) const { check_unit_interval(p.value, "coarse.value"); }
  void operator()(const SineProfile& p) const {
    if (!(std::isfinite(p.period.value()) && p.period.value() > 0.0))
      throw InvalidArgument("coarse.period_mm is " + num(p.period.value()) + " mm; it must be a finite number > 0");
    if (!std::isfinite(p.phase_deg)) throw InvalidArgument("coarse.phase_deg is " + num(p.phase_deg) + "; it must be finite");
  }
  void operator()(const ValuesProfile& p) const {
    if (p.values.empty()) throw InvalidArgument("coarse.values is empty; give one value in 0 … 1 per texel");
    for (std::size_t i = 0; i < p.values.size(); ++i)
      check_unit_interval(p.values[i], "coarse.values[" + std::to_string(i) + "]");
  }
  void operator()(const PointsProfile& p) const {
    if (p.points.empty()) throw InvalidArgument("coarse.points is empty; give at least one [position_mm, value] pair");
    for (std::size_t i = 0; i < p.points.size(); ++i) {
      const auto& [x, v] = p.points[i];
      const std::string at = "coarse.points[" + std::to_string(i) + "]";
      if (!std::isfinite(x)) throw InvalidArgument(at + " position is " + num(x) + " mm; it must be finite");
      check_unit_interval(v, at + " value");
      if (i > 0 && !(x > p.points[i - 1].first))
        throw InvalidArgument(at + " position " + num(x) + " mm does not increase (previous " + num(p.points[i - 1].first) +
                              " mm); positions must be strictly increasing");
    }
  }
  void operator()(const SampledProfile& p) const {
    if (!(std::isfinite(p.spacing.value()) && p.spacing.value() > 0.0))
      throw InvalidArgument("coarse.spacing_mm is " + num(p.spacing.value()) + " mm; it must be a finite number > 0");
    if (p.values.empty()) throw InvalidArgument("coarse sampled profile has no values");
    for (std::size_t i = 0; i < p.values.size(); ++i)
      check_unit_interval(p.values[i], "coarse.samples[" + std::to_string(i) + "]");
  }
};

}  // namespace

void validate(const CoarseProfile& profile) { std::visit(Validator{}, profile); }

std::string kind_name(const CoarseProfile& profile) {
  struct Namer {
    std::string operator()(const ConstantProfile&) const { return "constant"; }
    std::string operator()(const SineProfile&) const { return "sine"; }
    std::string operator()(const ValuesProfile&) const { return "values"; }
    std::string operator()(const PointsProfile&) const { return "points"; }
    std::string operator()(const SampledProfile&) const { return "sampled"; }
  };
  return std::visit(Namer{}, profile);
}

void check_texel_values(const CoarseProfile& profile, std::size_t count) {
  if (const auto* v = std::get_if<ValuesProfile>(&profile); v != nullptr && v->values.size() < count)
    throw InvalidArgument("coarse.values has " + std::to_string(v->values.size()) + " values but the texture has " +
                          std::to_string(count) + " texels; give one value per texel");
}

std::vector<double> sample_at_texel_centres(const CoarseProfile& profile, Millimetres texel_length, std::size_t count) {
  validate(profile);
  check_texel_values(profile, count);
  std::vector<double> c(count);
  sample_at_texel_centres(profile, texel_length, 0, c);
  return c;
}

void sample_at_texel_centres(const CoarseProfile& profile, Millimetres texel_length, std::size_t first, std::span<double> c) {
  const double L = texel_length.value();
  const std::size_t count = c.size();
  auto centre = [L, first](std::size_t i) { return (static_cast<double>(first + i) + 0.5) * L; };
  if (const auto* k = std::get_if<ConstantProfile>(&profile)) {
    std::fill(c.begin(), c.end(), k->value);
  } else if (const auto* s = std::get_if<SineProfile>(&profile)) {
    for (std::size_t i = 0; i < count; ++i) {
      const double cycles = centre(i) / s->period.value() + s->phase_deg / 360.0;
      c[i] = 0.5 + 0.5 * detmath::sin_cycles(cycles);
    }
  } else if (const auto* v = std::get_if<ValuesProfile>(&profile)) {
    std::copy_n(v->values.begin() + static_cast<std::ptrdiff_t>(first), count, c.begin());
  } else if (const auto* p = std::get_if<PointsProfile>(&profile)) {
    for (std::size_t i = 0; i < count; ++i) c[i] = interpolate_points(p->points, centre(i));
  } else if (const auto* sp = std::get_if<SampledProfile>(&profile)) {
    for (std::size_t i = 0; i < count; ++i) c[i] = interpolate_sampled(*sp, centre(i));
  }
  // sin_cycles may overshoot 1 by an ulp; keep c in [0, 1] exactly.
  for (double& x : c) x = x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}

PointsProfile read_profile_csv(const std::string& path) {
  std::string text;
  try {
    text = read_file(path);
  } catch (const IoError& e) {
    throw IoError("cannot read coarse profile: " + std::string(e.what()));
  }
  PointsProfile profile;
  read_numeric_csv(text, path, 2, 2, "position_mm,value",
                   [&](std::size_t, std::span<const double> v) { profile.points.emplace_back(v[0], v[1]); });
  if (profile.points.empty()) throw FormatError(path + ": no position_mm,value rows");
  try {
    validate(CoarseProfile{profile});
  } catch (const InvalidArgument& e) {
    throw FormatError(path + ": " + e.what());
  }
  return profile;
}

}  // namespace texel
