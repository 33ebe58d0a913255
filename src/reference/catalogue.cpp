// The registry of reference generators: names, families, parameters with
// units, defaults and ranges (docs/references.md gives the defaults), and the
// validation / parsing every front door shares.
#include <algorithm>
#include <charconv>
#include <cmath>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/reference.hpp"

namespace texel {
namespace {

using detail::num;
using Kind = ReferenceParamKind;

constexpr double big = 1e6;

ReferenceParam number(std::string key, std::string unit, double def, double lo, double hi, std::string text) {
  ReferenceParam p;
  p.key = std::move(key);
  p.kind = Kind::number;
  p.unit = std::move(unit);
  p.default_value = def;
  p.min = lo;
  p.max = hi;
  p.description = std::move(text);
  return p;
}

ReferenceParam integer(std::string key, double def, double lo, double hi, std::string text) {
  ReferenceParam p = number(std::move(key), "", def, lo, hi, std::move(text));
  p.kind = Kind::integer;
  return p;
}

ReferenceParam list(std::string key, std::string unit, std::vector<double> def, double lo, double hi, std::size_t min_count,
                    std::size_t max_count, std::string text) {
  ReferenceParam p;
  p.key = std::move(key);
  p.kind = Kind::list;
  p.unit = std::move(unit);
  p.default_value = std::move(def);
  p.min = lo;
  p.max = hi;
  p.min_count = min_count;
  p.max_count = max_count;
  p.description = std::move(text);
  return p;
}

ReferenceParam choice(std::string key, std::string def, std::vector<std::string> choices, std::string text) {
  ReferenceParam p;
  p.key = std::move(key);
  p.kind = Kind::choice;
  p.default_value = std::move(def);
  p.choices = std::move(choices);
  p.description = std::move(text);
  return p;
}

ReferenceInfo sines(const std::string& name, std::vector<double> freqs) {
  const std::string list_text = [&] {
    std::string s;
    for (double f : freqs) s += (s.empty() ? "" : " + ") + num(f);
    return s;
  }();
  return {name,
          "sum of sinusoids",
          "equally weighted sinusoids at " + list_text + " cpm (second study)",
          true,
          {list("frequencies_cpm", "cpm", std::move(freqs), 1e-6, big, 1, 256,
                "component frequencies; each must lie below the grid's Nyquist frequency"),
           list("weights", "", {}, 0.0, big, 0, 256, "relative amplitude of each component; empty = equal weights"),
           choice("phase", "zero", {"zero", "random"}, "zero: every component sin(2πfx); random: uniform phases from the seed")}};
}

ReferenceInfo colour(const std::string& name, double slope, const std::string& what) {
  return {name,
          "colour of noise",
          what + " Gaussian noise over the band (second study)",
          true,
          {number("band_min_cpm", "cpm", 0.5, 1e-6, big, "lowest frequency of the band"),
           number("band_max_cpm", "cpm", 0.0, 0.0, big,
                  "highest frequency of the band; 0 (or above Nyquist) = the grid's Nyquist frequency"),
           number("slope_db_per_decade", "dB/decade", slope, -60.0, 60.0, "PSD slope: 0 white, -10 pink (1/f), +10 blue (f)")}};
}

ReferenceInfo waveform(const std::string& name, const std::string& what) {
  return {name,
          "shaped waveform",
          what + ", band-limited to the grid's Nyquist frequency (second study)",
          false,
          {number("fundamental_cpm", "cpm", 1.0, 1e-6, big, "fundamental frequency"),
           number("band_max_cpm", "cpm", 0.0, 0.0, big,
                  "highest harmonic frequency; 0 (or above Nyquist) = the grid's Nyquist frequency"),
           number("phase_deg", "deg", 0.0, -big, big, "phase of the fundamental")}};
}

ReferenceInfo bandpass(const std::string& name, double fc, double zeta, const std::string& what) {
  return {
      name,
      "band-pass noise",
      what,
      true,
      {number("centre_cpm", "cpm", fc, 1e-6, big, "centre frequency f_c of the second-order band-pass"),
       number("zeta", "", zeta, 1e-4, 1e3, "irregularity ζ = 1/(2Q); -3 dB width 2ζ·f_c"),
       number("band_min_cpm", "cpm", 0.0, 0.0, big, "lowest synthesised frequency; 0 = the texture's lowest harmonic 1/length"),
       number("band_max_cpm", "cpm", 0.0, 0.0, big,
              "highest synthesised frequency; 0 (or above Nyquist) = the grid's Nyquist frequency")}};
}

ReferenceInfo patch(const std::string& name, double spacing) {
  return {name,
          "patch texture",
          "2.6 mm patches (a = 1) separated by whole-mm gaps (a = 0) drawn uniformly from {0 … 2c}, c = " + num(spacing) +
              " mm (working-memory study)",
          true,
          {number("patch_mm", "mm", 2.6, 1e-3, 1e4, "length of each patch"),
           number("spacing_mm", "mm", spacing, 0.0, 1e4, "average gap c: gaps are whole mm drawn from {0 … round(2c)}"),
           list("gaps_mm", "mm", {}, 0.0, 1e4, 0, 1000000,
                "explicit gaps in order (cycled if the texture is longer); empty = draw from the seed"),
           integer("shuffle", 0, 0, 2147483647, "0 = gaps in drawn order; n >= 1 = the n-th shuffle of the same gaps"),
           number("start_mm", "mm", 0.0, 0.0, 1e6, "position of the first patch")}};
}

ReferenceInfo pulse(const std::string& name, bool mirrored) {
  return {name,
          "coarse pulse pair",
          std::string("5 mm sinusoidal pulses (0.2 cpm, -7 dB) separated by varying gaps") +
              (mirrored ? "; mirror image of pulse-a (coarse-feature study)" : " (coarse-feature study)"),
          false,
          {number("pulse_mm", "mm", 5.0, 1e-3, 1e4, "length of one pulse (one period of 0.5 − 0.5·cos)"),
           list("gaps_mm", "mm", {3, 8, 1, 12, 5, 2, 10, 6}, 0.0, 1e4, 1, 1000000,
                "gaps between consecutive pulses, cycled to fill the texture"),
           number("start_mm", "mm", 0.0, 0.0, 1e6, "position of the first pulse (before mirroring)"),
           choice("mirror", mirrored ? "yes" : "no", {"no", "yes"}, "yes: the texture reflected about its centre, a(L − x)")}};
}

std::vector<ReferenceInfo> build_catalogue() {
  std::vector<ReferenceInfo> c;
  c.push_back(bandpass("bandpass", 4.0, 0.5, "Friesen band-pass noise, |H| = 1/sqrt(1 + Q²(f/f_c − f_c/f)²), any f_c and ζ"));
  for (double fc : {1.0, 4.0, 20.0})
    for (double z : {0.05, 0.5, 5.0})
      c.push_back(bandpass("bandpass-f" + num(fc) + "-z" + num(z), fc, z,
                           "Friesen band-pass noise f_c = " + num(fc) + " cpm, ζ = " + num(z) + " (first study)"));
  c.push_back(sines("2sin", {2.5, 6.0}));
  c.push_back(sines("3sin", {2.5, 6.0, 8.5}));
  c.push_back(sines("4sin", {2.5, 6.0, 8.5, 11.0}));
  c.push_back(colour("white", 0.0, "white (flat PSD)"));
  c.push_back(colour("pink", -10.0, "pink (PSD ∝ 1/f)"));
  c.push_back(colour("blue", 10.0, "blue (PSD ∝ f)"));
  c.push_back(waveform("square", "square wave: odd harmonics ∝ 1/n"));
  c.push_back(waveform("tri", "triangle wave: odd harmonics ∝ 1/n², alternating sign"));
  c.push_back(waveform("saw", "sawtooth wave: all harmonics ∝ 1/n"));
  c.push_back(patch("patch-2.5", 2.5));
  c.push_back(patch("patch-4.6", 4.6));
  c.push_back(patch("patch-13.5", 13.5));
  c.push_back(pulse("pulse-a", false));
  c.push_back(pulse("pulse-b", true));
  return c;
}

const ReferenceParam* find_param(const ReferenceInfo& info, std::string_view key) {
  for (const auto& p : info.params)
    if (p.key == key) return &p;
  return nullptr;
}

std::string known_keys(const ReferenceInfo& info) {
  std::string s;
  for (const auto& p : info.params) s += (s.empty() ? "" : ", ") + p.key;
  return s;
}

std::string range_text(const ReferenceParam& p) {
  std::string r = num(p.min) + " … " + num(p.max);
  if (!p.unit.empty()) r += " " + p.unit;
  return r;
}

void check_value(const ReferenceInfo& info, const ReferenceParam& p, const ReferenceValue& v) {
  const std::string field = "reference '" + info.name + "' parameter " + p.key;
  switch (p.kind) {
    case Kind::number:
    case Kind::integer: {
      const auto* d = std::get_if<double>(&v);
      if (!d) throw InvalidArgument(field + " must be a number");
      if (!(std::isfinite(*d) && *d >= p.min && *d <= p.max))
        throw InvalidArgument(field + " is " + num(*d) + "; allowed: " + range_text(p));
      if (p.kind == Kind::integer && std::floor(*d) != *d)
        throw InvalidArgument(field + " is " + num(*d) + "; it must be a whole number " + range_text(p));
      break;
    }
    case Kind::list: {
      const auto* l = std::get_if<std::vector<double>>(&v);
      if (!l) throw InvalidArgument(field + " must be a list of numbers");
      if (l->size() < p.min_count || l->size() > p.max_count)
        throw InvalidArgument(field + " has " + std::to_string(l->size()) + " values; allowed: " + std::to_string(p.min_count) +
                              " … " + std::to_string(p.max_count));
      for (std::size_t i = 0; i < l->size(); ++i)
        if (!(std::isfinite((*l)[i]) && (*l)[i] >= p.min && (*l)[i] <= p.max))
          throw InvalidArgument(field + "[" + std::to_string(i) + "] is " + num((*l)[i]) + "; allowed: " + range_text(p));
      break;
    }
    case Kind::choice: {
      const auto* s = std::get_if<std::string>(&v);
      if (!s) throw InvalidArgument(field + " must be one of the words listed");
      if (std::find(p.choices.begin(), p.choices.end(), *s) == p.choices.end()) {
        std::string allowed;
        for (const auto& c : p.choices) allowed += (allowed.empty() ? "" : ", ") + c;
        throw InvalidArgument(field + " is '" + *s + "'; allowed: " + allowed);
      }
      break;
    }
  }
}

double parse_number(std::string_view text, const std::string& field) {
  // Trim spaces; accept a leading '+'.
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double v = 0.0;
  const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || res.ec != std::errc() || res.ptr != text.data() + text.size())
    throw InvalidArgument(field + ": '" + std::string(text) + "' is not a number");
  return v;
}

}  // namespace

const std::vector<ReferenceInfo>& reference_catalogue() {
  static const std::vector<ReferenceInfo> catalogue = build_catalogue();
  return catalogue;
}

const ReferenceInfo& reference_info(std::string_view name) {
  for (const auto& info : reference_catalogue())
    if (info.name == name) return info;
  std::string names;
  for (const auto& info : reference_catalogue()) names += (names.empty() ? "" : ", ") + info.name;
  throw InvalidArgument("unknown reference '" + std::string(name) + "'; known: " + names);
}

std::vector<std::string> second_study_names() {
  return {"2sin", "3sin", "4sin", "white", "pink", "blue", "square", "tri", "saw"};
}

void validate(const ReferenceSpec& spec) {
  const ReferenceInfo& info = reference_info(spec.name);
  for (const auto& [key, value] : spec.params) {
    const ReferenceParam* p = find_param(info, key);
    if (!p)
      throw InvalidArgument("reference '" + info.name + "' has no parameter '" + key + "'; its parameters: " + known_keys(info));
    check_value(info, *p, value);
  }
  // Cross-parameter rules that do not depend on the grid.
  if (info.family == "sum of sinusoids") {
    const auto f = std::get<std::vector<double>>(reference_value(spec, "frequencies_cpm"));
    const auto w = std::get<std::vector<double>>(reference_value(spec, "weights"));
    if (!w.empty() && w.size() != f.size())
      throw InvalidArgument("reference '" + info.name + "' parameter weights has " + std::to_string(w.size()) +
                            " values but frequencies_cpm has " + std::to_string(f.size()) +
                            "; give one weight per frequency or none");
  }
}

ReferenceValue reference_value(const ReferenceSpec& spec, std::string_view key) {
  const auto it = spec.params.find(std::string(key));
  if (it != spec.params.end()) return it->second;
  const ReferenceInfo& info = reference_info(spec.name);
  const ReferenceParam* p = find_param(info, key);
  if (!p) throw InvalidArgument("reference '" + info.name + "' has no parameter '" + std::string(key) + "'");
  return p->default_value;
}

ReferenceValue parse_reference_value(const ReferenceInfo& info, std::string_view key, std::string_view text) {
  const ReferenceParam* p = find_param(info, key);
  if (!p)
    throw InvalidArgument("reference '" + info.name + "' has no parameter '" + std::string(key) +
                          "'; its parameters: " + known_keys(info));
  const std::string field = "reference '" + info.name + "' parameter " + p->key;
  ReferenceValue v;
  switch (p->kind) {
    case Kind::number:
    case Kind::integer: v = parse_number(text, field); break;
    case Kind::list: {
      std::vector<double> values;
      std::string_view rest = text;
      while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
      if (!rest.empty() && rest != "none" && rest != "[]") {
        while (true) {
          const auto comma = rest.find(',');
          values.push_back(parse_number(rest.substr(0, comma), field));
          if (comma == std::string_view::npos) break;
          rest.remove_prefix(comma + 1);
        }
      }
      v = std::move(values);
      break;
    }
    case Kind::choice: v = std::string(text); break;
  }
  check_value(info, *p, v);
  return v;
}

void set_reference_param(ReferenceSpec& spec, std::string_view assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string_view::npos || eq == 0)
    throw InvalidArgument("--param '" + std::string(assignment) +
                          "' must be KEY=VALUE (lists comma-separated, e.g. frequencies_cpm=2.5,6)");
  const std::string key(assignment.substr(0, eq));
  spec.params[key] = parse_reference_value(reference_info(spec.name), key, assignment.substr(eq + 1));
}

std::string format_reference_value(const ReferenceValue& value) {
  if (const auto* d = std::get_if<double>(&value)) return num(*d);
  if (const auto* s = std::get_if<std::string>(&value)) return *s;
  const auto& l = std::get<std::vector<double>>(value);
  if (l.empty()) return "none";
  std::string out;
  for (double x : l) out += (out.empty() ? "" : ",") + num(x);
  return out;
}

}  // namespace texel
