// libsndfile, opened on first use (dlopen) instead of linked: it brings FLAC,
// Vorbis, Opus and MP3 decoders, which every texel command would otherwise
// load at start-up whether or not it reads or writes audio. The signal loader
// (src/io/signal.cpp) and the WAV writer (src/player/sinks.cpp) share this
// one table. <sndfile.h> still gives the types and constants. Internal to
// Texel.
#pragma once

#include <sndfile.h>

#include "texel/detail/shared_object.hpp"

#ifndef TEXEL_SNDFILE_SONAME
#error "TEXEL_SNDFILE_SONAME (libsndfile's shared object name) is set by src/CMakeLists.txt"
#endif

namespace texel::detail {

// clang-format off
#define TEXEL_SNDFILE_FUNCTIONS(X) \
  X(sf_close) \
  X(sf_command) \
  X(sf_open) \
  X(sf_open_virtual) \
  X(sf_readf_double) \
  X(sf_strerror) \
  X(sf_writef_float)
// clang-format on

/// libsndfile, opened on the first audio file read or written (`sndfile()`);
/// without it the rest of Texel works and audio files are an IoError naming
/// the library. Never called from a real-time thread (WAV files are written
/// from whole buffers on the caller's thread).
TEXEL_SHARED_LIBRARY(SndFile, sndfile, TEXEL_SNDFILE_SONAME, "audio files (.wav)", TEXEL_SNDFILE_FUNCTIONS)

}  // namespace texel::detail
