// The 2-D encoder's inputs: PNG / .npy maps and scan bundles.
#include "texel/encode2d.hpp"
#include "texel/error.hpp"

namespace texel::codec {

Input2D load_input2d(const std::string&, const Raster2DLoadOptions&) {
  throw InvalidArgument("load_input2d: not implemented yet");
}
bool is_2d_input(const std::string&) { return false; }
ScanBundle load_scan_bundle(const std::string&, const SignalOptions&) {
  throw InvalidArgument("load_scan_bundle: not implemented yet");
}

}  // namespace texel::codec
