#include "texel/surface.hpp"

#include <algorithm>
#include <cmath>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel {

using detail::num;

Surface::Surface(Grid grid, std::vector<Region> regions) : grid_(grid), regions_(std::move(regions)) {
  if (!(grid_.spacing.value() > 0.0) || grid_.count < 0)
    throw InvalidArgument("surface grid must have spacing > 0 and count >= 0");
  const double total = grid_.length().value();
  std::sort(regions_.begin(), regions_.end(), [](const Region& a, const Region& b) { return a.start.value() < b.start.value(); });
  for (std::size_t i = 0; i < regions_.size(); ++i) {
    const Region& r = regions_[i];
    const std::string name = "region '" + (r.name.empty() ? std::to_string(i) : r.name) + "'";
    if (!r.texture) throw InvalidArgument(name + " has no texture");
    if (!(std::isfinite(r.start.value()) && r.start.value() >= 0.0))
      throw InvalidArgument(name + " start_mm is " + num(r.start.value()) + " mm; allowed: 0 … " + num(total) + " mm");
    if (!(std::isfinite(r.length.value()) && r.length.value() > 0.0))
      throw InvalidArgument(name + " length_mm is " + num(r.length.value()) + " mm; it must be > 0");
    // 1 µm of slack: layouts written with rounded decimals (50.88 + 50.88).
    if (r.start.value() + r.length.value() > total + 1e-3)
      throw InvalidArgument(name + " ends at " + num(r.start.value() + r.length.value()) +
                            " mm, past the device's active length " + num(total) + " mm");
    if (i > 0 && r.start.value() < regions_[i - 1].start.value() + regions_[i - 1].length.value() - 1e-9)
      throw InvalidArgument(name + " starts at " + num(r.start.value()) + " mm, inside the previous region (which ends at " +
                            num(regions_[i - 1].start.value() + regions_[i - 1].length.value()) +
                            " mm); regions must not overlap");
  }
}

void Surface::render(std::int64_t first, std::span<double> out) const {
  const auto n = static_cast<std::int64_t>(out.size());
  // Samples in no region are at rest: zero the gaps between the regions'
  // windows only (a texture's render writes every sample of its window).
  std::int64_t rest = first;  // samples [first, rest) are written
  for (const Region& r : regions_) {
    // Samples i with start <= position(i) < start + length belong to r.
    const double end_mm = r.start.value() + r.length.value();
    auto inside = [&](std::int64_t i) {
      const double x = grid_.position(i).value();
      return x >= r.start.value() && x < end_mm;
    };
    std::int64_t a = std::max<std::int64_t>(
        first, static_cast<std::int64_t>(std::floor((r.start.value() - grid_.origin.value()) / grid_.spacing.value())) - 1);
    while (a < first + n && !inside(a)) ++a;
    if (a >= first + n) continue;
    std::int64_t b = a;
    const auto est = static_cast<std::int64_t>(std::ceil((end_mm - grid_.origin.value()) / grid_.spacing.value())) + 1;
    b = std::clamp(est, a, first + n);
    while (b > a && !inside(b - 1)) --b;
    while (b < first + n && inside(b)) ++b;
    // The region's texture sees positions from its own origin.
    const Grid local{grid_.origin - r.start, grid_.spacing, grid_.count};
    if (a > rest) std::fill(out.begin() + (rest - first), out.begin() + (a - first), 0.0);
    r.texture->render(local, a, out.subspan(static_cast<std::size_t>(a - first), static_cast<std::size_t>(b - a)));
    rest = std::max(rest, b);  // regions may share a sample within their 1e-9 mm tolerance
  }
  std::fill(out.begin() + (rest - first), out.end(), 0.0);
}

std::vector<double> Surface::render() const {
  std::vector<double> map(static_cast<std::size_t>(grid_.count));
  render(0, map);
  return map;
}

std::vector<std::byte> Surface::render_native(SampleFormat format) const {
  const auto count = static_cast<std::size_t>(grid_.count);
  const std::size_t width = bytes_per_sample(format);
  std::vector<std::byte> bytes(count * width);
  constexpr std::size_t chunk = 1024;  // 8 KiB of doubles: stays in L1 between render and encode
  std::vector<double> scratch(chunk);
  for (std::size_t i = 0; i < count; i += chunk) {
    const std::size_t len = std::min(chunk, count - i);
    std::span<double> s(scratch.data(), len);
    render(static_cast<std::int64_t>(i), s);
    encode_samples(format, s, std::span<std::byte>(bytes.data() + i * width, len * width));
  }
  return bytes;
}

}  // namespace texel
