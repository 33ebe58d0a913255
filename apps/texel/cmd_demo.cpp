// texel demo: renders the demonstration set (include/texel/demo.hpp) on the
// reference device; each texture as device file, document and plot.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "render_output.hpp"
#include "texel/demo.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel::cli {
void register_demo(CLI::App& app) {
  struct Args {
    OutputSetArgs set{"out/demo"};
    bool plots = true;
  };
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("demo", "Render the demonstration set into a directory");
  add_output_set_options(*cmd, args->set);
  cmd->add_flag("!--no-plots", args->plots, "Skip the PNG plots");
  cmd->callback([args] {
    namespace fs = std::filesystem;
    const DeviceProfile device = prepare_output_set(args->set);
    std::cout << std::left << std::setw(28) << "texture" << std::right << std::setw(8) << "texels" << std::setw(18)
              << "raw device bytes" << std::setw(16) << "document bytes"
              << "\n";
    for (const auto& t : demo_set()) {
      Document doc = make_document(device, t.spec);
      doc.description = "Texel demo: " + t.name;
      const Surface surface = prepare_surface(doc);
      const std::vector<double> map = render_map(surface);
      const std::vector<double> freqs = texel_frequencies(surface);
      const std::string stem = (fs::path(args->set.out) / t.name).string();
      write_rendered(stem + ".bin", doc, surface, map, freqs);
      write_rendered(stem + ".texel.json", doc, surface, map, freqs);
      if (args->plots) write_rendered(stem + ".png", doc, surface, map, freqs);
      std::cout << std::left << std::setw(28) << t.name << std::right << std::setw(8) << freqs.size() << std::setw(18)
                << fs::file_size(stem + ".bin") << std::setw(16) << fs::file_size(stem + ".texel.json") << "\n";
    }
  });
}

}  // namespace texel::cli
