// texel reference: one reference texture (docs/references.md) on a device, in any
// output format `render` writes; --list names every generator and its
// parameters.
// texel atlas: every reference with its spectrum plot, and the overview of
// the second study's nine references (excerpt plus spectrum, three families
// in three rows). `make demo` runs it into out/demo/references.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "render_output.hpp"
#include "spectrum_common.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/plot.hpp"
#include "texel/reference.hpp"

namespace texel::cli {
namespace {

using ordered = nlohmann::ordered_json;

std::string kind_text(const ReferenceParam& p) {
  switch (p.kind) {
    case ReferenceParamKind::number: return "number";
    case ReferenceParamKind::integer: return "integer";
    case ReferenceParamKind::list: return "list";
    case ReferenceParamKind::choice: return "choice";
  }
  return "?";
}

std::string allowed_text(const ReferenceParam& p) {
  if (p.kind == ReferenceParamKind::choice) {
    std::string s;
    for (const auto& c : p.choices) s += (s.empty() ? "" : " | ") + c;
    return s;
  }
  std::string s = detail::num(p.min) + " … " + detail::num(p.max);
  if (p.kind == ReferenceParamKind::list)
    s = std::to_string(p.min_count) + " … " + std::to_string(p.max_count) + " values, each " + s;
  return s;
}

ordered value_json(const ReferenceValue& v) {
  if (const auto* d = std::get_if<double>(&v)) return *d;
  if (const auto* l = std::get_if<std::vector<double>>(&v)) return *l;
  return std::get<std::string>(v);
}

void print_list(bool json) {
  if (json) {
    ordered all = ordered::array();
    for (const auto& info : reference_catalogue()) {
      ordered j{{"name", info.name}, {"family", info.family}, {"description", info.description}, {"uses_seed", info.uses_seed}};
      j["params"] = ordered::array();
      for (const auto& p : info.params) {
        ordered pj{{"key", p.key}, {"kind", kind_text(p)}, {"unit", p.unit}, {"default", value_json(p.default_value)}};
        if (p.kind == ReferenceParamKind::choice)
          pj["choices"] = p.choices;
        else {
          pj["min"] = p.min;
          pj["max"] = p.max;
        }
        if (p.kind == ReferenceParamKind::list) {
          pj["min_count"] = p.min_count;
          pj["max_count"] = p.max_count;
        }
        pj["description"] = p.description;
        j["params"].push_back(pj);
      }
      all.push_back(j);
    }
    print_json(all);
    return;
  }
  std::string family;
  for (const auto& info : reference_catalogue()) {
    if (info.family != family) {
      family = info.family;
      std::cout << (family.empty() ? "" : "\n") << "== " << family << " ==\n";
    }
    std::cout << info.name << (info.uses_seed ? " [seeded]" : "") << ": " << info.description << "\n";
    for (const auto& p : info.params) {
      std::cout << "    " << std::left << std::setw(20) << p.key << std::right << " default "
                << format_reference_value(p.default_value) << (p.unit.empty() ? "" : " " + p.unit) << "; " << allowed_text(p)
                << "\n        " << p.description << "\n";
    }
  }
}

}  // namespace

void register_reference(CLI::App& app) {
  struct Args {
    std::optional<std::string> name;
    std::vector<std::string> params;
    std::optional<std::uint64_t> seed;
    DeviceOptions device;
    std::optional<std::string> output;
    bool list = false;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "reference",
      "Generate a reference texture (band-pass noise, sums of sinusoids, noise colours, waveforms, patches, pulses)");
  cmd->add_option("name", a->name, "Reference name (texel reference --list shows them all)");
  cmd->add_option("--param", a->params, "KEY=VALUE override of a generator parameter (repeatable; lists comma-separated)");
  cmd->add_option("--seed", a->seed, "Random seed, 0 … 2^64-1 [1]");
  add_device_options(*cmd, a->device);
  cmd->add_option("-o,--output", a->output, "Output: .bin (device native), .csv, .npy, .texel.json, .png or .svg");
  cmd->add_flag("--list", a->list, "List every reference with its parameters, defaults and ranges");
  cmd->add_flag("--json", a->json, "With --list: as JSON; otherwise print a JSON summary");
  cmd->callback([a] {
    if (a->list) {
      if (a->name || a->output) throw InvalidArgument("--list takes no reference name and no --output");
      print_list(a->json);
      return;
    }
    if (!a->name) throw InvalidArgument("reference: give a reference NAME (see texel reference --list)");
    if (!a->output)
      throw InvalidArgument("reference: give an output file with -o (.bin, .csv, .npy, .mat, .texel.json, .png, .svg)");
    check_render_output(*a->output);  // reject a bad extension before any work
    ReferenceSpec spec;
    spec.name = *a->name;
    (void)reference_info(spec.name);
    for (const auto& p : a->params) set_reference_param(spec, p);
    if (a->seed) spec.seed = *a->seed;
    validate(spec);
    Document doc = make_reference_document(resolve_device(a->device, nullptr), spec);
    doc.description = "Texel reference " + spec.name;
    const Surface surface = prepare_surface(doc);
    write_surface(*a->output, doc, surface);
    if (a->json) {
      ordered j{{"output", *a->output},
                {"reference", spec.name},
                {"texture", surface.regions()[0].texture->describe()},
                {"device", doc.device.name},
                {"samples", surface.grid().count},
                {"spacing_mm", surface.grid().spacing.value()},
                {"device_bytes", doc.device.native_bytes()}};
      print_json(j);
    }
  });
}

void register_atlas(CLI::App& app) {
  struct Args {
    OutputSetArgs set{"out/demo/references"};
    std::uint64_t seed = 1;
  };
  auto a = std::make_shared<Args>();
  auto* cmd =
      app.add_subcommand("atlas", "Write every reference, its spectrum plot and the second study's overview into a directory");
  add_output_set_options(*cmd, a->set);
  cmd->add_option("--seed", a->seed, "Seed of the seeded references [1]");
  cmd->callback([a] {
    namespace fs = std::filesystem;
    const DeviceProfile device = prepare_output_set(a->set);
    const std::vector<std::string> overview_names = second_study_names();
    std::vector<Figure> cells(overview_names.size());
    std::cout << std::left << std::setw(20) << "reference" << std::right << std::setw(10) << "bytes" << std::setw(14)
              << "centroid cpm" << std::setw(16) << "log centroid dB"
              << "  peaks (cpm)\n";
    for (const auto& info : reference_catalogue()) {
      ReferenceSpec spec;
      spec.name = info.name;
      spec.seed = a->seed;
      Document doc = make_reference_document(device, spec);
      doc.description = "Texel reference " + info.name + ": " + info.description;
      const Surface surface = prepare_surface(doc);
      const std::vector<double> map = render_map(surface);
      const std::string stem = (fs::path(a->set.out) / info.name).string();
      write_rendered(stem + ".bin", doc, surface, map, {});
      write_rendered(stem + ".texel.json", doc, surface, map, {});
      Signal sig;
      sig.samples = map;
      sig.spacing = surface.grid().spacing;
      sig.description = "device " + device.name;
      AnalysisOptions opt;
      opt.peaks.max_peaks = 12;
      const SpectralReport r = analyse_spectrum(sig.samples, sig.spacing, opt);
      const SpectrumPlot plot = make_spectrum_plot(info.name + ": " + info.description, sig, r, std::nullopt);
      plot_spectrum(plot, stem + "-spectrum.png");
      for (std::size_t i = 0; i < overview_names.size(); ++i)
        if (overview_names[i] == info.name) {
          SpectrumPlot cell = plot;
          cell.title = info.name;
          cells[i] = spectrum_cell_figure(cell, 460, 400);
        }
      std::string peaks;
      for (std::size_t i = 0; i < r.peaks.size() && i < 5; ++i)
        peaks += (i ? " " : "") + detail::fixed(r.peaks[i].frequency.value(), 2);
      if (r.peaks.size() > 5) peaks += " …";
      std::cout << std::left << std::setw(20) << info.name << std::right << std::setw(10) << fs::file_size(stem + ".bin")
                << std::setw(14) << detail::fixed(r.summary.centroid.value(), 3) << std::setw(16)
                << detail::fixed(r.summary.log_centroid.value(), 2) << "  " << peaks << "\n";
    }
    FigureGrid grid;
    grid.title = "Second-study references on " + device.name + ": sums of sinusoids, colours of noise, shaped waveforms";
    grid.columns = 3;
    grid.cells = std::move(cells);
    save_figure_grid(grid, (fs::path(a->set.out) / "overview.png").string());
    std::cout << "overview: " << (fs::path(a->set.out) / "overview.png").string() << "\n";
  });
}

}  // namespace texel::cli
