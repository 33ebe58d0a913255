// Base64 (RFC 4648 §4, with padding) for the studio's binary payloads: the
// float32 map, imported and exported files. Beast has one, but only as an
// internal detail, and the service must not depend on Beast.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace texel::studio::detail {

std::string base64_encode(std::span<const unsigned char> bytes);
inline std::string base64_encode(std::string_view bytes) {
  return base64_encode(std::span(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()));
}
/// Strict decoding: length a multiple of 4, only the alphabet, '=' only as
/// the final one or two characters, zero pad bits. Anything else: nothing.
std::optional<std::vector<unsigned char>> base64_decode(std::string_view text);

}  // namespace texel::studio::detail
