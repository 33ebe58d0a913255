// An anonymous scratch file for data that must not live in memory: what
// lets the reference synthesis run in bounded memory at any length
// (detfft.hpp's out-of-core chirp-z, the ReferenceTexture's samples).
// Internal to Texel.
//
// The file is created in $TMPDIR (else /tmp) already unlinked (O_TMPFILE,
// or mkstemp + unlink where the file system lacks it), so it vanishes with
// the object or the process, whatever way the process ends. Reads and writes
// are pread/pwrite of doubles at element offsets: no shared file position,
// so concurrent readers of a const ScratchFile are safe. Its pages live in
// the kernel's page cache, not in the process's memory: the system may write
// them to disk.
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace texel::detail {

class ScratchFile {
 public:
  /// Opens a new empty scratch file; `purpose` names it in errors (e.g.
  /// "reference synthesis"). Throws IoError.
  explicit ScratchFile(std::string purpose);
  ~ScratchFile();
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  /// Allocates room for `elements` doubles up front where the file system
  /// can (Linux fallocate; the first writes of a page then cost about half
  /// as much); best effort: a file system that cannot simply grows as
  /// written, and a full disk is still reported by write().
  void reserve(std::uint64_t elements);
  /// Writes `data` at element `offset` (doubles), growing the file as
  /// needed. Throws IoError (e.g. the disk is full).
  void write(std::uint64_t offset, std::span<const double> data);
  /// Reads data.size() doubles at element `offset`; all of them must have
  /// been written. Throws IoError.
  void read(std::uint64_t offset, std::span<double> data) const;
  /// The directory the file lives in (for messages and documentation).
  [[nodiscard]] const std::string& directory() const { return directory_; }

 private:
  int fd_ = -1;
  std::string purpose_;
  std::string directory_;
};

}  // namespace texel::detail
