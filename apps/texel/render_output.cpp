#include "render_output.hpp"

#include <cstdio>

#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/plot.hpp"

namespace texel::cli {

std::vector<double> render_map(const Surface& surface) {
  const auto n = static_cast<std::size_t>(surface.grid().count);
  std::vector<double> map(n);
  Progress progress("rendering " + std::to_string(n) + " samples");
  constexpr std::size_t chunk = std::size_t{1} << 20;
  for (std::size_t i = 0; i < n; i += chunk) {
    const std::size_t len = std::min(chunk, n - i);
    surface.render(static_cast<std::int64_t>(i), std::span<double>(map.data() + i, len));
    if (n > 4 * chunk) progress.update(static_cast<double>(i + len) / static_cast<double>(n));
  }
  return map;
}

std::vector<double> texel_frequencies(const Surface& surface) {
  std::vector<double> f;
  for (const auto& r : surface.regions())
    if (const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get()))
      for (const auto& texel : t->texels()) f.push_back(texel.frequency_cpm);
  return f;
}

void write_rendered(const std::string& path, const Document& doc, const Surface& surface, const std::vector<double>& map,
                    const std::vector<double>& frequencies_cpm, std::vector<PendingFile> extra) {
  const OutputKind kind = output_kind(path);
  check_writable(path);
  for (const auto& f : extra) check_writable(f.path);
  const Grid& g = surface.grid();
  PendingFile main{path, {}};
  switch (kind) {
    case OutputKind::bin: {
      std::vector<std::byte> bytes(map.size() * bytes_per_sample(doc.device.format));
      encode_samples(doc.device.format, map, bytes);
      main.bytes.assign(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      break;
    }
    case OutputKind::csv: {
      std::vector<double> x(map.size());
      for (std::size_t i = 0; i < x.size(); ++i) x[i] = g.position(static_cast<std::int64_t>(i));
      main.bytes = csv_columns("position_mm", "amplitude", x, map);
      break;
    }
    case OutputKind::npy: main.bytes = npy_bytes(map); break;
    case OutputKind::document: main.bytes = document_json(doc); break;
    case OutputKind::png:
    case OutputKind::svg: {
      MapPlot plot;
      plot.title = doc.device.name + ": " +
                   (surface.regions().size() == 1 ? surface.regions()[0].texture->describe()
                                                  : std::to_string(surface.regions().size()) + " regions");
      plot.positions_mm.resize(map.size());
      for (std::size_t i = 0; i < map.size(); ++i) plot.positions_mm[i] = g.position(static_cast<std::int64_t>(i));
      plot.amplitudes = map;
      plot.frequencies_cpm = frequencies_cpm;
      plot.excerpt_mm = std::min(6.0, g.length_mm());
      plot_map(plot, path);  // atomic on its own
      try {
        commit_files(extra);
      } catch (...) {
        std::remove(path.c_str());
        throw;
      }
      return;
    }
  }
  extra.insert(extra.begin(), std::move(main));
  commit_files(extra);
}

}  // namespace texel::cli
