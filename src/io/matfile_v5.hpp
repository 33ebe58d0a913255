// The v5 pre-check of a .mat file (internal; matfile.cpp): every matrix of a
// level-5 file walked, at any depth, before libmatio allocates by its headers
// (matfile_v5.cpp says why).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace texel::mat::v5 {

/// Walks the top-level data elements of the level-5 file at `path`
/// (`file_size` bytes; tag: type, byte count), and every matrix inside them,
/// and returns how many elements there are. matio reads a truncated
/// element's data as zeros without an error, so every element must end
/// inside the file. Throws FormatError naming the element and what is wrong,
/// IoError if the file cannot be read.
std::size_t check_v5_elements(const std::string& path, std::uintmax_t file_size);

}  // namespace texel::mat::v5
