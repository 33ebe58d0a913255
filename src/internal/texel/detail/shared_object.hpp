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

/// Defines `struct Type` with one pointer per function in LIST (an X-macro
/// over the names the library's header declares) and `const Type& accessor()`,
/// which opens SONAME and resolves them on its first call (thread-safe, once;
/// a failure throws and the next call tries again). Use inside an unnamed
/// namespace of the one file that calls the library, or in an internal header
/// when several files of Texel call it (the accessor is inline: one table per
/// process, e.g. texel/detail/sndfile.hpp):
///   #define TEXEL_MATIO_FUNCTIONS(X) X(Mat_Open) X(Mat_Close)
///   TEXEL_SHARED_LIBRARY(Matio, matio, "libmatio.so.11", "MATLAB .mat files", TEXEL_MATIO_FUNCTIONS)
///   ... matio().Mat_Open(path, MAT_ACC_RDONLY) ...
#define TEXEL_SHARED_LIBRARY_POINTER(name) decltype(&::name) name = nullptr;
#define TEXEL_SHARED_LIBRARY_RESOLVE(name) \
  loaded_.name = ::texel::detail::shared_function<decltype(&::name)>(handle_, soname_, #name);
#define TEXEL_SHARED_LIBRARY(Type, accessor, SONAME, NEEDED_FOR, LIST)          \
  struct Type {                                                                 \
    LIST(TEXEL_SHARED_LIBRARY_POINTER)                                          \
  };                                                                            \
  inline const Type& accessor() {                                               \
    static const Type loaded = [] {                                             \
      const char* soname_ = SONAME;                                             \
      void* handle_ = ::texel::detail::open_shared_object(soname_, NEEDED_FOR); \
      Type loaded_;                                                             \
      LIST(TEXEL_SHARED_LIBRARY_RESOLVE)                                        \
      return loaded_;                                                           \
    }();                                                                        \
    return loaded;                                                              \
  }
