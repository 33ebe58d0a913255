// The anonymous scratch file (src/internal/texel/detail/scratch_file.hpp).
#include "texel/detail/scratch_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "texel/error.hpp"

namespace texel::detail {

namespace {

std::string scratch_directory() {
  const char* t = std::getenv("TMPDIR");
  return t != nullptr && *t != '\0' ? std::string(t) : std::string("/tmp");
}

}  // namespace

ScratchFile::ScratchFile(std::string purpose) : purpose_(std::move(purpose)), directory_(scratch_directory()) {
#ifdef O_TMPFILE
  fd_ = ::open(directory_.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
  if (fd_ < 0) {  // no O_TMPFILE here (or on this file system): create, then unlink at once
    std::string name = directory_ + "/texel-scratch-XXXXXX";
    fd_ = ::mkostemp(name.data(), O_CLOEXEC);
    if (fd_ >= 0) ::unlink(name.c_str());
  }
  if (fd_ < 0)
    throw IoError("cannot create a scratch file in '" + directory_ + "' for the " + purpose_ + ": " + std::strerror(errno) +
                  " (set TMPDIR to a writable directory)");
}

ScratchFile::~ScratchFile() {
  if (fd_ >= 0) ::close(fd_);
}

void ScratchFile::reserve(std::uint64_t elements) {
#ifdef __linux__
  if (elements > 0) (void)::fallocate(fd_, 0, 0, static_cast<off_t>(elements * sizeof(double)));
#else
  (void)elements;
#endif
}

void ScratchFile::write(std::uint64_t offset, std::span<const double> data) {
  const auto* p = reinterpret_cast<const char*>(data.data());
  std::size_t left = data.size_bytes();
  auto at = static_cast<off_t>(offset * sizeof(double));
  while (left > 0) {
    const ssize_t w = ::pwrite(fd_, p, left, at);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0)
      throw IoError("cannot write the " + purpose_ + "'s scratch file in '" + directory_ +
                    "': " + (w < 0 ? std::strerror(errno) : "no space written") + " (set TMPDIR to a directory with room)");
    p += w;
    at += w;
    left -= static_cast<std::size_t>(w);
  }
}

void ScratchFile::read(std::uint64_t offset, std::span<double> data) const {
  auto* p = reinterpret_cast<char*>(data.data());
  std::size_t left = data.size_bytes();
  auto at = static_cast<off_t>(offset * sizeof(double));
  while (left > 0) {
    const ssize_t r = ::pread(fd_, p, left, at);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0)
      throw IoError("cannot read the " + purpose_ + "'s scratch file in '" + directory_ +
                    "': " + (r < 0 ? std::strerror(errno) : "it ended early"));
    p += r;
    at += r;
    left -= static_cast<std::size_t>(r);
  }
}

}  // namespace texel::detail
