// The demonstration set (issue #2): what the method does, in thirteen
// textures. Fine texture from two seeds; the same with a 5 mm sinusoidal
// coarse profile (coarse strength 1) from two seeds; a 3 × 3 grid of coarse
// strength × fine strength (0, 0.5, 1) over that profile. All at Central Pitch
// 10 dB, Irregularity −5 dB, texel length 0.25 mm. Shared by `texel demo`,
// the golden-digest test and the cross-build determinism check, so all three
// always mean the same set.
#pragma once

#include <string>
#include <vector>

#include "texel/texture.hpp"

namespace texel {

struct DemoTexture {
  std::string name;  ///< file stem, e.g. "grid-C0.5-F1"
  TexelSpec spec;
};

std::vector<DemoTexture> demo_set();

}  // namespace texel
