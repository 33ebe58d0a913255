// The C ABI: 1-D surfaces, a document or parameters on a device rendered
// window by window (texel_c_internal.hpp).
#include "texel_c_internal.hpp"

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

using namespace capi_detail;

namespace {

// Checks a window [first, first + count) against the map's size.
void check_window(const texel_surface& s, std::int64_t first, std::size_t count) {
  const auto size = static_cast<std::uint64_t>(s.surface.grid().count);
  if (first < 0 || static_cast<std::uint64_t>(first) > size || count > size - static_cast<std::uint64_t>(first))
    throw InvalidArgument("window first=" + std::to_string(first) + " count=" + std::to_string(count) + " is outside the map's " +
                          std::to_string(size) + " samples");
}

// Renders a window chunk by chunk (bounded scratch memory), handing each
// chunk's amplitudes and its offset in the window to `emit`.
template <class Emit>
void render_chunks(const texel_surface& s, std::int64_t first, std::size_t count, Emit&& emit) {
  constexpr std::size_t chunk = std::size_t{1} << 16;
  std::vector<double> scratch(std::min(count, chunk));
  for (std::size_t done = 0; done < count; done += chunk) {
    const std::size_t len = std::min(chunk, count - done);
    std::span<double> part(scratch.data(), len);
    s.surface.render(first + static_cast<std::int64_t>(done), part);
    emit(std::span<const double>(part), done);
  }
}

}  // namespace

extern "C" {

// --------------------------------------------------------------- surfaces

texel_status texel_surface_create(const texel_document* doc, texel_surface** out) {
  return create(out, [&] {
    const texel::Document& d = need(doc, "doc").doc;
    return std::make_unique<texel_surface>(texel_surface{d.device, texel::prepare_surface(d)});
  });
}

texel_status texel_surface_from_params(const char* device, const texel_params* params, texel_surface** out) {
  return create(out, [&] {
    const texel::TexelSpec spec = spec_of(need(params, "params"));
    const texel::Document d = texel::make_document(device_named(device), spec);
    return std::make_unique<texel_surface>(texel_surface{d.device, texel::prepare_surface(d)});
  });
}

texel_status texel_surface_device(const texel_surface* surface, texel_device_info* out) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    need(out, "out") = info_of(s.device);
  });
}

texel_status texel_surface_size(const texel_surface* surface, std::size_t* samples) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    need(samples, "samples") = static_cast<std::size_t>(s.surface.grid().count);
  });
}

texel_status texel_surface_render(const texel_surface* surface, std::int64_t first, double* out, std::size_t count) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    check_window(s, first, count);
    if (count == 0) return;
    need(out, "out");
    s.surface.render(first, std::span<double>(out, count));
  });
}

texel_status texel_surface_render_u16(const texel_surface* surface, std::int64_t first, std::uint16_t* out, std::size_t count) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    check_window(s, first, count);
    if (count == 0) return;
    need(out, "out");
    render_chunks(s, first, count, [&](std::span<const double> a, std::size_t at) {
      texel::encode_u16(a, std::span<std::uint16_t>(out + at, a.size()));
    });
  });
}

texel_status texel_surface_render_native(const texel_surface* surface, std::int64_t first, std::size_t count, void* buffer,
                                         std::size_t capacity, std::size_t* needed) {
  return guarded([&] {
    const texel_surface& s = need(surface, "surface");
    check_window(s, first, count);
    const std::size_t bps = texel::bytes_per_sample(s.device.format);
    if (!check_buffer(count * bps, buffer, capacity, needed)) return;  // count <= samples: no overflow
    auto* bytes = static_cast<std::byte*>(buffer);
    render_chunks(s, first, count, [&](std::span<const double> a, std::size_t at) {
      texel::encode_samples(s.device.format, a, std::span<std::byte>(bytes + at * bps, a.size() * bps));
    });
  });
}

void texel_surface_destroy(texel_surface* surface) { delete surface; }

}  // extern "C"
