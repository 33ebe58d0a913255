#include "render_output.hpp"

#include <cstdio>
#include <numeric>

#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/map_file.hpp"
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
      for (const auto& texel : t->texels()) f.push_back(texel.frequency.value());
  return f;
}

bool is_mat_output(const std::string& path) { return output_extension(path) == ".mat"; }

void check_render_output(const std::string& path) {
  if (!is_mat_output(path)) output_kind(path);
  check_writable(path);
}

std::vector<mat::Variable> map_variables(const Document& doc, const Surface& surface, const std::vector<double>& map) {
  using mat::Matrix;
  using mat::Text;
  const Grid& g = surface.grid();
  std::vector<double> x(map.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = g.position(static_cast<std::int64_t>(i)).value();

  mat::Struct params;
  params.add("device", Text{doc.device.name})
      .add("format", Text{std::string(to_string(doc.device.format))})
      .add("samples", Matrix::scalar(static_cast<double>(g.count)))
      .add("spacing_mm", Matrix::scalar(g.spacing.value()))
      .add("length_mm", Matrix::scalar(g.length().value()))
      .add("regions", Matrix::scalar(static_cast<double>(surface.regions().size())));
  // The first Texel region's parameters (a one-region document's texture);
  // every region's full description is in `document`.
  for (const auto& r : surface.regions()) {
    const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get());
    if (!t) continue;
    const TexelSpec& s = t->spec();
    params.add("central_pitch_db", Matrix::scalar(s.central_pitch.value()))
        .add("irregularity_db", Matrix::scalar(s.irregularity.value()))
        .add("texel_length_mm", Matrix::scalar(s.texel_length.value()))
        .add("seed", Matrix::scalar(static_cast<double>(s.seed)))  // exact below 2^53; `document` has every digit
        .add("parameterization", Text{std::string(to_string(s.parameterization))})
        .add("out_of_band", Text{std::string(to_string(s.out_of_band))})
        .add("band_min_cpm", Matrix::scalar(s.band_min.value()))
        .add("band_max_cpm", Matrix::scalar(s.band_max.value()))
        .add("quantization_db", Matrix::scalar(s.quantization_db))
        .add("phase", Text{std::string(to_string(s.phase))})
        .add("fill", Text{std::string(to_string(s.fill))})
        .add("coarse_strength", Matrix::scalar(s.coarse_strength))
        .add("fine_strength", Matrix::scalar(s.fine_strength));
    break;
  }
  std::string textures;
  for (const auto& r : surface.regions()) textures += (textures.empty() ? "" : "; ") + r.texture->describe();
  params.add("texture", Text{textures});
  params.add("description", Text{doc.description});

  std::vector<mat::Variable> vars;
  vars.push_back({"amplitude", Matrix::column(map)});
  vars.push_back({"position_mm", Matrix::column(std::move(x))});
  vars.push_back({"params", std::move(params)});

  // One row per texel, as columns (struct2table(texels) gives a MATLAB table).
  std::vector<double> index, start, freq, amp, region;
  for (std::size_t r = 0; r < surface.regions().size(); ++r) {
    const auto& reg = surface.regions()[r];
    const auto* t = dynamic_cast<const TexelTexture*>(reg.texture.get());
    if (!t) continue;
    for (std::size_t k = 0; k < t->texels().size(); ++k) {
      const Texel& tx = t->texels()[k];
      index.push_back(static_cast<double>(k));
      start.push_back(reg.start.value() + tx.start.value());
      freq.push_back(tx.frequency.value());
      amp.push_back(tx.envelope);
      region.push_back(static_cast<double>(r + 1));  // MATLAB counts from 1
    }
  }
  if (!index.empty()) {
    mat::Struct texels;
    texels.add("index", Matrix::column(std::move(index)))
        .add("start_mm", Matrix::column(std::move(start)))
        .add("frequency_cpm", Matrix::column(std::move(freq)))
        .add("amplitude", Matrix::column(std::move(amp)))
        .add("region", Matrix::column(std::move(region)));
    vars.push_back({"texels", std::move(texels)});
  }
  vars.push_back({"document", Text{document_json(doc)}});
  return vars;
}

namespace {
// The main file `path` was already written atomically by its own writer
// (matio, Cairo): commit the extra files, and take the main one back if that
// fails, so a failed command leaves no partial output.
void commit_extras_after(const std::string& path, const std::vector<PendingFile>& extra) {
  try {
    commit_files(extra);
  } catch (...) {
    std::remove(path.c_str());
    throw;
  }
}
}  // namespace

double write_surface(const std::string& path, const Document& doc, const Surface& surface, std::vector<PendingFile> extra,
                     mat::MatVersion mat_version) {
  check_render_output(path);
  for (const auto& f : extra) check_writable(f.path);
  if (map_file_kind(path)) {
    const auto n = static_cast<std::size_t>(surface.grid().count);
    Progress progress("rendering " + std::to_string(n) + " samples");
    MapFileOptions o;
    if (n > (std::size_t{1} << 22)) o.progress = [&](double f) { progress.update(f); };
    const MapFileStats stats = write_map(path, surface, doc.device.format, o);
    commit_extras_after(path, extra);
    return stats.mean_amplitude;
  }
  const std::vector<double> map = render_map(surface);
  write_rendered(path, doc, surface, map, texel_frequencies(surface), std::move(extra), mat_version);
  return map.empty() ? 0.0 : std::accumulate(map.begin(), map.end(), 0.0) / static_cast<double>(map.size());
}

void write_rendered(const std::string& path, const Document& doc, const Surface& surface, const std::vector<double>& map,
                    const std::vector<double>& frequencies_cpm, std::vector<PendingFile> extra, mat::MatVersion mat_version) {
  check_render_output(path);
  for (const auto& f : extra) check_writable(f.path);
  if (is_mat_output(path)) {
    mat::write_mat(path, map_variables(doc, surface, map), {.version = mat_version});  // atomic on its own
    commit_extras_after(path, extra);
    return;
  }
  const OutputKind kind = output_kind(path);
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
      for (std::size_t i = 0; i < x.size(); ++i) x[i] = g.position(static_cast<std::int64_t>(i)).value();
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
      for (std::size_t i = 0; i < map.size(); ++i) plot.positions_mm[i] = g.position(static_cast<std::int64_t>(i)).value();
      plot.amplitudes = map;
      plot.frequencies_cpm = frequencies_cpm;
      plot.excerpt = Millimetres(std::min(6.0, g.length().value()));
      plot_map(plot, path);  // atomic on its own
      commit_extras_after(path, extra);
      return;
    }
  }
  extra.insert(extra.begin(), std::move(main));
  commit_files(extra);
}

}  // namespace texel::cli
