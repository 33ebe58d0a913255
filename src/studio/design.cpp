// The designer's numbers (design.hpp): thin glue over the renderer, the
// texture's own draw, the spectrum and the codec.
#include "texel/studio/design.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>

#include "texel/bitstream.hpp"
#include "texel/detail/format.hpp"
#include "texel/detmath.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/plot.hpp"
#include "texel/spectrum.hpp"

namespace texel::studio {
namespace {

using detail::num;

std::string region_label(const Document& doc, std::size_t i) {
  const std::string& name = doc.regions[i].name;
  return "region " + std::to_string(i) + (name.empty() ? "" : " ('" + name + "')");
}

void check_region(const Document& doc, std::size_t i, std::string_view field) {
  if (i >= doc.regions.size())
    throw InvalidArgument(std::string(field) + " is " + std::to_string(i) + "; allowed: 0 … " +
                          std::to_string(doc.regions.size() - 1) + " (the document's regions)");
}

// The surface keeps its regions sorted by start; documents need not be.
const Region& surface_region(const Surface& surface, const RegionSpec& spec) {
  for (const Region& r : surface.regions())
    if (r.start == spec.start) return r;
  throw Error("internal: no surface region starts at " + num(spec.start.value()) + " mm");
}

// Samples [first, last) of the grid that belong to region r: the same
// membership rule as Surface::render (start <= position < end).
std::pair<std::size_t, std::size_t> region_samples(const Grid& grid, const Region& r) {
  const double start = r.start.value();
  const double end = start + r.length.value();
  auto first = static_cast<std::int64_t>(std::floor((start - grid.origin.value()) / grid.spacing.value()));
  first = std::clamp<std::int64_t>(first - 1, 0, grid.count);
  while (first < grid.count && grid.position(first).value() < start) ++first;
  std::int64_t last = first;
  while (last < grid.count && grid.position(last).value() < end) ++last;
  return {static_cast<std::size_t>(first), static_cast<std::size_t>(last)};
}

std::optional<std::size_t> last_texel_region(const Document& doc) {
  for (std::size_t i = doc.regions.size(); i-- > 0;)
    if (!doc.regions[i].reference) return i;
  return std::nullopt;
}

// Probability that the texture's distribution yields a frequency in [a, b)
// (cpm): lognormal(mu, sigma), either truncated to the band (redraw) or with
// the tails piled on the band edges (clamp).
double bin_probability(const PitchDistribution& d, double a, double b) {
  const double lo = d.config().band_min.value(), hi = d.config().band_max.value();
  auto cdf = [&](double f) {
    if (f <= 0) return 0.0;
    if (d.sigma() <= 0) return std::log(f) >= d.mu() ? 1.0 : 0.0;
    return detmath::normal_cdf((std::log(f) - d.mu()) / d.sigma());
  };
  if (d.config().out_of_band == OutOfBand::redraw) {
    const double x = std::max(a, lo), y = std::min(b, hi);
    return y > x && d.band_mass() > 0 ? (cdf(y) - cdf(x)) / d.band_mass() : 0.0;
  }
  double p = 0.0;
  const double x = std::max(a, lo), y = std::min(b, hi);
  if (y > x) p += cdf(y) - cdf(x);
  if (lo >= a && lo < b) p += cdf(lo);
  if (hi >= a && hi < b) p += 1.0 - cdf(hi);
  return p;
}

HistogramView histogram_of(const TexelTexture& t, std::size_t bins) {
  std::vector<double> f;
  f.reserve(t.texels().size());
  for (const Texel& k : t.texels()) f.push_back(k.frequency.value());
  const Histogram h = make_histogram(f, bins, AxisScale::log10);
  HistogramView v{h.edges, h.counts, {}};
  v.expected.reserve(h.counts.size());
  const double n = static_cast<double>(f.size());
  for (std::size_t i = 0; i + 1 < h.edges.size(); ++i) {
    // The last bin is closed on the right, like make_histogram's.
    const double b = i + 2 == h.edges.size() ? std::nextafter(h.edges[i + 1], 1e300) : h.edges[i + 1];
    v.expected.push_back(n * bin_probability(t.distribution(), h.edges[i], b));
  }
  return v;
}

// The region's spec as a bitstream (InvalidArgument when a field is not representable).
std::vector<std::byte> region_bitstream(const TexelTexture& t, const Region& r) {
  return codec::write_bitstream(codec::from_spec(t.spec(), r.length));
}

std::vector<double> render_region(const Surface& surface, const Region& r, std::vector<double>* whole = nullptr) {
  std::vector<double> map = surface.render();
  const auto [a, b] = region_samples(surface.grid(), r);
  std::vector<double> out(map.begin() + static_cast<std::ptrdiff_t>(a), map.begin() + static_cast<std::ptrdiff_t>(b));
  if (whole) *whole = std::move(map);
  return out;
}

std::string stem(std::string_view description, std::string_view fallback) {
  std::string s;
  for (const char c : description.substr(0, 40))
    s += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '-';
  return s.empty() ? std::string(fallback) : s;
}

}  // namespace

SpectrumView spectrum_view(std::span<const double> samples, Millimetres spacing, std::size_t points) {
  if (points < 16 || points > 2048)
    throw InvalidArgument("spectrum points is " + std::to_string(points) + "; allowed: 16 … 2048");
  const Spectrum s = magnitude_spectrum(samples, spacing);
  SpectrumView v;
  if (s.frequency_cpm.size() < 2) return v;
  // Log-spaced bands from the first non-DC bin to Nyquist; each point is the
  // band's strongest bin (at its own frequency), so narrow peaks survive.
  const double f0 = s.frequency_cpm[1], f1 = s.frequency_cpm.back();
  const double step = std::log(f1 / f0) / static_cast<double>(points);
  std::size_t k = 1;
  for (std::size_t p = 0; p < points && k < s.frequency_cpm.size(); ++p) {
    const double top =
        p + 1 == points ? std::numeric_limits<double>::infinity() : f0 * std::exp(step * static_cast<double>(p + 1));
    std::size_t best = k;
    bool any = false;
    for (; k < s.frequency_cpm.size() && s.frequency_cpm[k] < top; ++k) {
      if (!any || s.magnitude[k] > s.magnitude[best]) best = k;
      any = true;
    }
    if (!any) continue;
    v.frequency_cpm.push_back(s.frequency_cpm[best]);
    const double m = s.magnitude[best];
    v.magnitude_db.push_back(m > 0 ? 20.0 * std::log10(m) : -200.0);
  }
  return v;
}

DesignView design_view(const Document& doc, const DesignOptions& options) {
  if (options.histogram_bins > 1000)
    throw InvalidArgument("histogram bins is " + std::to_string(options.histogram_bins) + "; allowed: 0 (auto) … 1000");
  if (doc.regions.empty()) throw InvalidArgument("document has no regions");
  std::size_t analysed = options.region ? *options.region : last_texel_region(doc).value_or(doc.regions.size() - 1);
  check_region(doc, analysed, "region");

  const Surface surface = prepare_surface(doc);
  DesignView v;
  v.grid = surface.grid();
  v.analysed = analysed;
  std::vector<double> map;
  const Region& r = surface_region(surface, doc.regions[analysed]);
  const std::vector<double> samples = render_region(surface, r, &map);
  v.map.assign(map.begin(), map.end());
  for (const RegionSpec& spec : doc.regions) {
    const Region& sr = surface_region(surface, spec);
    v.regions.push_back({spec.name, spec.reference ? "reference" : "texel", sr.start, sr.length});
  }
  if (samples.size() >= 4) v.spectrum = spectrum_view(samples, v.grid.spacing, options.spectrum_points);

  if (const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get())) {
    v.texels = t->texel_count();
    const double L = t->spec().texel_length.value();
    if (t->spec().fill == Fill::whole_texels)
      v.uncovered_mm = std::max(0.0, r.length.value() - static_cast<double>(v.texels) * L);
    v.histogram = histogram_of(*t, options.histogram_bins);
    v.central_pitch = to_cpm(t->spec().central_pitch);
    v.irregularity = to_cpm(t->spec().irregularity);
    try {
      v.encoded = region_bitstream(*t, r);
    } catch (const InvalidArgument& e) {
      v.encoded_error = e.what();
    }
  }
  return v;
}

MatchView match_region(const Document& doc, const MatchOptions& options) {
  check_region(doc, options.region, "region");
  std::size_t into = options.region;
  if (options.into) {
    into = *options.into;
    check_region(doc, into, "into");
  } else {
    for (std::size_t i = doc.regions.size(); i-- > 0;)
      if (i != options.region) {
        into = i;
        break;
      }
  }
  const Surface surface = prepare_surface(doc);
  const std::vector<double> target = render_region(surface, surface_region(surface, doc.regions[options.region]));
  if (target.size() < 4)
    throw InvalidArgument(region_label(doc, options.region) + " holds " + std::to_string(target.size()) +
                          " samples; at least 4 are needed to encode it");
  codec::Signal signal{target, surface.grid().spacing, "studio " + region_label(doc, options.region)};

  MatchView m;
  codec::EncoderConfig encoder = options.encoder;  // the document's display in the model's loop unless given one
  if (encoder.model.display.flat()) encoder.model.display = doc.device.response;
  m.result = codec::encode(signal, encoder);
  m.into = into;
  m.document = doc;
  RegionSpec& dst = m.document.regions[into];
  dst.texel = m.result.spec;
  dst.reference.reset();
  dst.coarse_reference.reset();
  m.document.version = required_version(m.document);
  const Surface matched = prepare_surface(m.document);
  const std::vector<double> rendered = render_region(matched, surface_region(matched, dst));
  m.target = spectrum_view(target, signal.spacing, options.spectrum_points);
  if (rendered.size() >= 4) m.match = spectrum_view(rendered, signal.spacing, options.spectrum_points);
  return m;
}

std::string_view to_string(ImportKind k) {
  switch (k) {
    case ImportKind::document: return "document";
    case ImportKind::bitstream: return "bitstream";
    case ImportKind::signal: return "signal";
  }
  return "?";
}

ImportKind import_kind(std::string_view name) {
  const std::string ext = output_extension(std::string(name));
  if (ext == ".texel.json" || ext == ".json") return ImportKind::document;
  if (ext == ".texel") return ImportKind::bitstream;
  if (ext == ".bin" || ext == ".npy" || ext == ".csv" || ext == ".wav") return ImportKind::signal;
  throw InvalidArgument("file '" + std::string(name) + "' has extension '" + ext +
                        "'; allowed: .texel.json, .json, .texel, .bin, .npy, .csv, .wav");
}

ImportResult import_file(std::string_view name, std::span<const std::byte> bytes, const ImportOptions& options) {
  ImportResult out;
  out.kind = import_kind(name);
  const std::string origin(name);
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (out.kind == ImportKind::document) {
    out.document = parse_document(text, origin);
    return out;
  }
  if (out.kind == ImportKind::bitstream) {
    out.document = codec::decode_document(codec::parse_bitstream(bytes), options.device);
    return out;
  }
  // The one loader, from memory (texel/signal.hpp): the client's name only labels errors.
  SignalOptions lo;
  lo.device = options.device;
  lo.swipe_speed = options.swipe_speed;
  codec::Signal signal;
  try {
    signal = codec::encoder_signal(codec::decode_signal(std::as_bytes(bytes), signal_format_of(origin), lo, origin));
  } catch (const Error& e) {
    throw FormatError(e.what());  // the studio reports every bad upload as a format problem
  }
  codec::EncoderConfig encoder = options.encoder;  // the device's display in the model's loop unless given one
  if (encoder.model.display.flat()) encoder.model.display = options.device.response;
  out.encoded = codec::encode(signal, encoder);
  out.document = codec::decode_document(out.encoded->bitstream, options.device);
  return out;
}

std::string_view to_string(ExportFormat f) {
  switch (f) {
    case ExportFormat::document: return "document";
    case ExportFormat::bitstream: return "bitstream";
    case ExportFormat::device: return "device";
    case ExportFormat::npy: return "npy";
    case ExportFormat::csv: return "csv";
    case ExportFormat::hjif: return "hjif";
  }
  return "?";
}

ExportFormat parse_export_format(std::string_view text, std::string_view field) {
  for (const ExportFormat f : {ExportFormat::document, ExportFormat::bitstream, ExportFormat::device, ExportFormat::npy,
                               ExportFormat::csv, ExportFormat::hjif})
    if (text == to_string(f)) return f;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) +
                        "'; allowed: document, bitstream, device, npy, csv, hjif");
}

ExportFile export_file(const Document& doc, ExportFormat as, std::optional<std::size_t> region) {
  const std::string base = stem(doc.description, "texture");
  ExportFile f;
  if (as == ExportFormat::document) {
    f = {base + ".texel.json", "application/json", document_json(doc)};
    return f;
  }
  if (as == ExportFormat::hjif) {
    // The library's MPEG-I Haptics export, as `texel export a.texel.json -o a.hjif` writes it.
    f = {base + ".hjif", "application/json", hjif::export_hjif(doc).json};
    return f;
  }
  const Surface surface = prepare_surface(doc);
  if (as == ExportFormat::bitstream) {
    // A .texel holds one Texel texture over the whole device: writing one
    // region of several would silently drop the others.
    if (!region && doc.regions.size() > 1)
      throw InvalidArgument("a .texel bitstream holds one Texel texture; this document has " +
                            std::to_string(doc.regions.size()) +
                            " regions: export it as .texel.json to keep every region (or name the region to write)");
    const std::optional<std::size_t> i = region ? region : last_texel_region(doc);
    if (!i) throw InvalidArgument("the document has no Texel region to write as a bitstream");
    check_region(doc, *i, "region");
    const Region& r = surface_region(surface, doc.regions[*i]);
    const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get());
    if (!t) throw InvalidArgument(region_label(doc, *i) + " holds a reference texture; only Texel regions have a bitstream");
    const std::vector<std::byte> bytes = region_bitstream(*t, r);
    f = {base + ".texel", "application/octet-stream", std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size())};
  } else if (as == ExportFormat::device) {
    const std::vector<std::byte> bytes = surface.render_native(doc.device.format);
    f = {base + "." + doc.device.name + ".bin", "application/octet-stream",
         std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size())};
  } else if (as == ExportFormat::npy) {
    f = {base + ".npy", "application/octet-stream", npy_bytes(surface.render())};
  } else {
    const std::vector<double> map = surface.render();
    std::vector<double> x(map.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = surface.grid().position(static_cast<std::int64_t>(i)).value();
    f = {base + ".csv", "text/csv", csv_columns("position_mm", "amplitude", x, map)};
  }
  return f;
}

}  // namespace texel::studio
