// The 2-D encoder (docs/encoder.md "2-D inputs"): split, scans, design correction.
#include "texel/encode2d.hpp"
#include "texel/error.hpp"

namespace texel::codec {

Encode2DResult encode_surface2d(const Raster2D&, const Encode2DConfig&) {
  throw InvalidArgument("encode_surface2d: not implemented yet");
}
Encode2DResult encode_scans(const ScanBundle&, const Encode2DConfig&) {
  throw InvalidArgument("encode_scans: not implemented yet");
}
void write_encoding2d(const Encode2DResult&, const std::string&) {
  throw InvalidArgument("write_encoding2d: not implemented yet");
}
std::string to_json(const Encode2DResult&) { throw InvalidArgument("to_json: not implemented yet"); }

}  // namespace texel::codec
