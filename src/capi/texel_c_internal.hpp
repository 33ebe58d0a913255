// What the C ABI's sources share (internal, not installed; texel_c.cpp):
// the opaque handles' definitions, the thread's error slot and `guarded`,
// which turns the project's exception families into status codes, the checks
// of what a C caller supplies (NULL pointers, enum values, non-finite
// numbers, buffers) and the conversions between texel.h's structs and the
// library's. One API area per source: texel_c.cpp (version, status, devices,
// documents), texel_c_surface.cpp, texel_c_encode.cpp, texel_c_spectrum.cpp,
// texel_c_player.cpp, texel_c_2d.cpp.
#pragma once

#include "texel.h"

#include <cstring>
#include <initializer_list>
#include <memory>
#include <new>
#include <string>
#include <type_traits>

#include "texel/codec.hpp"
#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/encode2d.hpp"
#include "texel/error.hpp"
#include "texel/player.hpp"
#include "texel/signal.hpp"
#include "texel/spectrum.hpp"
#include "texel/surface.hpp"
#include "texel/surface2d.hpp"
#include "texel/texture.hpp"

struct texel_document {
  texel::Document doc;
};

struct texel_surface {
  texel::DeviceProfile device;
  texel::Surface surface;
};

struct texel_encode_result {
  texel::codec::EncodeResult result;
};

struct texel_spectrum {
  texel::SpectralReport report;
  std::size_t samples = 0;
  double spacing_mm = 0.0;
};

struct texel_surface2d {
  texel::Surface2D surface;
};

struct texel_encode2d_result {
  texel::codec::Encode2DResult result;
};

struct texel_player {
  texel::Player player;
  explicit texel_player(const texel::PlayerConfig& c) : player(c) {}
};

// Not in texel::, so that unqualified names inside resolve as they would at
// global scope (the sources use `using namespace capi_detail;`).
namespace capi_detail {

using texel::InvalidArgument;

// The last error of this thread (texel_c.cpp). `fixed` points at static text
// when building a message could itself fail (out of memory).
extern thread_local std::string t_message;
extern thread_local const char* t_fixed;

texel_status fail(texel_status status, const char* what) noexcept;

// Thrown (and caught by `guarded`) when a caller buffer or the player's event
// queue has no room: not an error of the library, so not a texel::Error.
struct BufferTooSmall {
  std::string message;
};

template <class F>
texel_status guarded(F&& body) noexcept {
  t_message.clear();  // keeps its capacity: never allocates
  t_fixed = nullptr;
  try {
    body();
    return TEXEL_OK;
  } catch (const BufferTooSmall& e) {
    return fail(TEXEL_BUFFER_TOO_SMALL, e.message.c_str());
  } catch (const texel::InvalidArgument& e) {
    return fail(TEXEL_INVALID_ARGUMENT, e.what());
  } catch (const texel::FormatError& e) {
    return fail(TEXEL_FORMAT_ERROR, e.what());
  } catch (const texel::IoError& e) {
    return fail(TEXEL_IO_ERROR, e.what());
  } catch (const std::bad_alloc&) {
    t_fixed = "out of memory";
    return TEXEL_OUT_OF_MEMORY;
  } catch (const std::exception& e) {
    return fail(TEXEL_INTERNAL, e.what());
  } catch (...) {
    t_fixed = "unknown exception inside Texel";
    return TEXEL_INTERNAL;
  }
}

template <class T>
T& need(T* p, const char* name) {
  if (!p) throw InvalidArgument(std::string(name) + " is NULL");
  return *p;
}

const char* need_text(const char* p, const char* name);

// The integer a C caller stored in an enum. C allows any int there; in C++ a
// load of an enum object outside its range is undefined (and UBSan's `enum`
// check stops on it), so the bytes are copied instead of loaded as the enum.
template <class E>
long long enum_value(const E& e) {
  std::underlying_type_t<E> v;
  static_assert(sizeof v == sizeof e);
  std::memcpy(&v, &e, sizeof v);
  return static_cast<long long>(static_cast<int>(v));
}

// The library value of a C enum field: one row per C value (value, library
// value, C name); any other value is refused, naming the field and listing
// what is allowed ("mode is 5; allowed: TEXEL_MAP2D_PATH (0), ...").
template <class To>
struct Choice {
  long long c;
  To value;
  const char* name;
};
template <class To, class E>
To choose(const E& e, const char* field, std::initializer_list<Choice<To>> choices) {
  const long long v = enum_value(e);
  std::string allowed;
  for (const Choice<To>& c : choices) {
    if (c.c == v) return c.value;
    allowed += (allowed.empty() ? "" : ", ") + std::string(c.name) + " (" + std::to_string(c.c) + ")";
  }
  throw InvalidArgument(std::string(field) + " is " + std::to_string(v) + "; allowed: " + allowed);
}

void need_finite(double v, const char* name);
std::string num(double v);

// The buffer rule of check_buffer for a result of `size` elements (`unit`)
// in the buffer the caller names `name`.
bool check_count(std::size_t size, const void* buffer, std::size_t capacity, std::size_t* needed, const char* name,
                 const char* unit);
// The (buffer, capacity, needed) rule of texel.h for a result of `size`
// bytes: true when the caller gave a buffer with room for it.
bool check_buffer(std::size_t size, const void* buffer, std::size_t capacity, std::size_t* needed);
void copy_out(const void* data, std::size_t size, void* buffer, std::size_t capacity, std::size_t* needed);

texel_device_info info_of(const texel::DeviceProfile& d);
// A C parameterization value (any int a C caller stored) as the library's.
texel::Parameterization parameterization_of(const texel_parameterization& p);
// texel_params -> TexelSpec, checking what the C caller can get wrong with
// the C field names (the CLI checks the same values under its flag names).
texel::TexelSpec spec_of(const texel_params& p);
texel_params params_of(const texel::TexelSpec& s, int* has_profile);
texel::DeviceProfile device_named(const char* name);

// texel_encode_options -> EncoderConfig with the C field names
// (texel_c_encode.cpp).
texel::codec::EncoderConfig config_of(const texel_encode_options& o);
// A map in memory, read by the library's one rule (texel_c_encode.cpp).
texel::Signal map_signal(const double* amplitudes, std::size_t count, double spacing_mm);
// texel_player_config -> PlayerConfig (validated), with the C field names
// (texel_c_player.cpp).
texel::PlayerConfig player_config_of(const texel_player_config& c);

template <class Handle, class Make>
texel_status create(Handle** out, Make&& make) {
  if (out) *out = nullptr;
  return guarded([&] {
    need(out, "out");
    *out = make().release();
  });
}

}  // namespace capi_detail
