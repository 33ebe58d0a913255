#include "texel/demo.hpp"

#include "texel/detail/format.hpp"

namespace texel {

std::vector<DemoTexture> demo_set() {
  TexelSpec base;
  base.central_pitch = Decibels(10.0);
  base.irregularity = Decibels(-5.0);
  base.texel_length = Millimetres(0.25);
  std::vector<DemoTexture> set;
  for (std::uint64_t seed : {1, 2}) {
    TexelSpec s = base;
    s.seed = seed;
    set.push_back({"fine-seed" + std::to_string(seed), s});
  }
  for (std::uint64_t seed : {1, 2}) {
    TexelSpec s = base;
    s.seed = seed;
    s.coarse = SineProfile{Millimetres(5.0), 0.0};
    s.coarse_strength = 1.0;
    s.fine_strength = 1.0;
    set.push_back({"coarse-sine5mm-seed" + std::to_string(seed), s});
  }
  for (double c : {0.0, 0.5, 1.0})
    for (double f : {0.0, 0.5, 1.0}) {
      TexelSpec s = base;
      s.seed = 1;
      s.coarse = SineProfile{Millimetres(5.0), 0.0};
      s.coarse_strength = c;
      s.fine_strength = f;
      set.push_back({"grid-C" + detail::num(c) + "-F" + detail::num(f), s});
    }
  return set;
}

}  // namespace texel
