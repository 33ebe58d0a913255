// Optional third-party libraries opened on first use (dlopen) instead of
// linked: a library that only a few commands need (libmatio for .mat files,
// PortAudio for live playback) would otherwise be loaded, with everything it
// links, by every texel command at start-up. Internal to Texel.
#pragma once

#include <string_view>

namespace texel::detail {

/// The shared object `soname`, opened once per process (RTLD_NOW | RTLD_LOCAL)
/// and never closed; `needed_for` names what needs it in the IoError thrown
/// when it cannot be opened (e.g. "MATLAB .mat files").
void* open_shared_object(const char* soname, std::string_view needed_for);

/// The symbol `name` of a handle from open_shared_object; an IoError naming
/// both if it is missing.
void* shared_object_symbol(void* handle, const char* soname, const char* name);

/// The symbol as a function pointer of type F, e.g.
/// `shared_function<decltype(&Mat_Open)>(h, so, "Mat_Open")` (decltype, not
/// the address itself: that would make the linker look for the library).
template <class F>
F shared_function(void* handle, const char* soname, const char* name) {
  return reinterpret_cast<F>(shared_object_symbol(handle, soname, name));
}

}  // namespace texel::detail
