// texel demo: renders the set that shows what the method does (issue #2):
// fine texture from two seeds; the same with a 5 mm sinusoidal coarse
// profile from two seeds; a 3 × 3 grid of coarse strength × fine strength.
// All at Central Pitch 10 dB, Irregularity −5 dB, texel length 0.25 mm on the
// reference device. Each texture is written as device file, document and plot.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "render_output.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::cli {
namespace {

struct DemoTexture {
  std::string name;
  TexelSpec spec;
};

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

}  // namespace

void register_demo(CLI::App& app) {
  struct Args {
    std::string out = "out/demo";
    std::string device = "tpad";
    bool plots = true;
  };
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("demo", "Render the demonstration set into a directory");
  cmd->add_option("--out", args->out, "Output directory [out/demo]");
  cmd->add_option("--device", args->device, "Device profile [tpad]");
  cmd->add_flag("!--no-plots", args->plots, "Skip the PNG plots");
  cmd->callback([args] {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(args->out, ec);
    if (ec) throw IoError("cannot create '" + args->out + "': " + ec.message());
    const DeviceProfile device = load_device(args->device);
    std::cout << std::left << std::setw(28) << "texture" << std::right << std::setw(8) << "texels" << std::setw(18)
              << "raw device bytes" << std::setw(16) << "document bytes" << "\n";
    for (const auto& t : demo_set()) {
      Document doc = make_document(device, t.spec);
      doc.description = "Texel demo: " + t.name;
      const Surface surface = prepare_surface(doc);
      const std::vector<double> map = render_map(surface);
      const std::vector<double> freqs = texel_frequencies(surface);
      const std::string stem = (fs::path(args->out) / t.name).string();
      write_rendered(stem + ".bin", doc, surface, map, freqs);
      write_rendered(stem + ".texel.json", doc, surface, map, freqs);
      if (args->plots) write_rendered(stem + ".png", doc, surface, map, freqs);
      std::cout << std::left << std::setw(28) << t.name << std::right << std::setw(8) << freqs.size() << std::setw(18)
                << fs::file_size(stem + ".bin") << std::setw(16) << fs::file_size(stem + ".texel.json") << "\n";
    }
  });
}

}  // namespace texel::cli
