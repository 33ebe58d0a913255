// Exact transcoding: a document or bitstream that already holds Texel
// parameters becomes a bitstream without estimation (docs/encoder.md,
// "Transcoding").
//
// Estimation (encode()) is for sample data: it measures what a signal feels
// like and fits parameters to it, so a Texel document sent through it comes
// back as a near neighbour with another seed. A document already *is* the
// parameters, so its bitstream is those parameters at the bitstream's
// resolution (0.01 dB, 1 µm, 0.1 dB, n/255, 2^bits levels) with the same
// seed and options. Exactness is then decided, not hoped for: the decoded
// spec is prepared on the document's own grid beside the original and their
// texels (start, frequency, phase, envelope) and fine strength are compared
// bit for bit — the render kernel is a pure function of those, so equal
// texels mean equal bytes. Fine fields equal to the bit make the texture the
// same on every device; a coarse profile is stored per texel of the
// document's device, so its equality is stated for that device.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <variant>

#include "texel/coarse.hpp"
#include "texel/codec.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/matfile.hpp"
#include "texel/surface.hpp"

namespace texel::codec {
namespace {

using detail::num;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The bits per level that store every value of `v` exactly (level / top gives
// the same double), smallest first; 0 when none does.
unsigned exact_bits(const std::vector<double>& v) {
  for (unsigned bits = 1; bits <= 16; ++bits) {
    const double top = static_cast<double>((1u << bits) - 1u);
    const bool all = std::all_of(v.begin(), v.end(), [&](double x) {
      const double level = std::round(x * top);
      return level >= 0.0 && level <= top && same_bits(level / top, x);
    });
    if (all) return bits;
  }
  return 0;
}

void compare(std::vector<std::string>& losses, const char* field, double given, double stored, const std::string& how) {
  if (!same_bits(given, stored))
    losses.push_back(std::string(field) + " " + num(given) + " is stored as " + num(stored) + " (" + how + ")");
}

// Texels of `spec` prepared over the region on the document's grid.
std::vector<Texel> texels_of(const TexelSpec& spec, const Document& doc) {
  const Grid grid = doc.device.grid();
  const TexelTexture t(spec, grid.length(), Sampling{grid, doc.device.band_top()});
  return t.texels();
}

bool same_texels(const std::vector<Texel>& a, const std::vector<Texel>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (!same_bits(a[k].start.value(), b[k].start.value()) || !same_bits(a[k].frequency.value(), b[k].frequency.value()) ||
        !same_bits(a[k].phase_cycles, b[k].phase_cycles) || !same_bits(a[k].envelope, b[k].envelope))
      return false;
  return true;
}

}  // namespace

std::optional<std::string> not_transcodable(const Document& doc) {
  if (doc.regions.size() != 1)
    return "it has " + std::to_string(doc.regions.size()) + " regions; a bitstream holds one texture over the whole device";
  const RegionSpec& r = doc.regions.front();
  if (r.reference) return "its region holds the reference '" + r.reference->name + "', not Texel parameters";
  if (r.coarse_reference) return "its coarse profile is the reference '" + r.coarse_reference->name + "'";
  if (r.start.value() != 0.0) return "its region starts at " + num(r.start.value()) + " mm, not at the device's start";
  if (r.length && !same_bits(r.length->value(), doc.device.grid().length().value()))
    return "its region is " + num(r.length->value()) + " mm long, not the device's " + num(doc.device.grid().length().value()) +
           " mm";
  return std::nullopt;
}

Transcoded transcode(const Document& doc, const TranscodeOptions& options) {
  if (const auto why = not_transcodable(doc)) throw InvalidArgument("the document cannot be transcoded: " + *why);
  const TexelSpec& given = doc.regions.front().texel;
  validate(given);
  if (options.coarse_bits && (*options.coarse_bits < 1 || *options.coarse_bits > 16))
    throw FieldError("coarse_bits", "is " + std::to_string(*options.coarse_bits) + "; allowed: 1 … 16");

  // Levels [choice]: the fewest bits that hold the profile's values exactly;
  // else, when the coarse strength itself is stored exactly (n/255), 16 bits
  // (the finest the format has); else 8 bits, whose level error (≤ C/510 of
  // the envelope) is no larger than the strength's own rounding (≤ 1/510):
  // more bits would buy size, not fidelity. The caller may choose instead.
  unsigned bits = 16;
  if (options.coarse_bits) {
    bits = *options.coarse_bits;
  } else if (given.coarse_strength != 0.0 && !std::holds_alternative<ConstantProfile>(given.coarse)) {
    const std::size_t n = std::max<std::size_t>(1, texel_count(doc.device.grid().length(), given.texel_length, given.fill));
    const bool strength_exact = same_bits(std::round(given.coarse_strength * 255.0) / 255.0, given.coarse_strength);
    if (const unsigned b = exact_bits(sample_at_texel_centres(given.coarse, given.texel_length, n)))
      bits = b;
    else if (!strength_exact)
      bits = 8;
  }

  Transcoded t;
  t.bitstream = from_spec(given, doc.device.grid().length(), bits);
  t.bytes = write_bitstream(t.bitstream);
  t.spec = to_spec(t.bitstream);
  const TexelSpec& s = t.spec;

  std::vector<std::string>& losses = t.losses;
  compare(losses, "central_pitch_db", given.central_pitch.value(), s.central_pitch.value(), "0.01 dB steps");
  compare(losses, "irregularity_db", given.irregularity.value(), s.irregularity.value(), "0.01 dB steps");
  compare(losses, "texel_length_mm", given.texel_length.value(), s.texel_length.value(), "1 µm steps");
  compare(losses, "quantization_db", given.quantization_db, s.quantization_db, "0.1 dB steps");
  compare(losses, "band_min_cpm", given.band_min.value(), s.band_min.value(), "0.01 dB steps");
  compare(losses, "band_max_cpm", given.band_max.value(), s.band_max.value(), "0.01 dB steps, rounded down");
  const bool fine_equal = losses.empty();

  // Coarse: what rendering sees is each texel's envelope and F.
  bool coarse_equal = same_bits(given.fine_strength, s.fine_strength);
  if (!coarse_equal) compare(losses, "fine_strength", given.fine_strength, s.fine_strength, "n/255 steps");
  if (fine_equal) {
    const std::vector<Texel> a = texels_of(given, doc);
    const std::vector<Texel> b = texels_of(s, doc);
    if (!same_texels(a, b)) {
      coarse_equal = false;
      double worst = 0.0;
      for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k)
        worst = std::max(worst, std::fabs(a[k].envelope - b[k].envelope));
      losses.push_back("coarse envelope (C " + num(given.coarse_strength) + " stored as " + num(s.coarse_strength) + ", " +
                       std::to_string(bits) + "-bit levels): texel envelopes differ by up to " + num(worst));
    }
  }
  t.exact = fine_equal && coarse_equal;
  if (options.max_bytes && t.bytes.size() > *options.max_bytes)
    throw FieldError("max_bytes", std::to_string(*options.max_bytes) + " is too small for this document: its bitstream is " +
                                      std::to_string(t.bytes.size()) + " bytes");
  return t;
}

Transcoded transcode(const Bitstream& b) {
  Transcoded t;
  t.bitstream = b;
  t.bytes = write_bitstream(b);
  t.spec = to_spec(b);
  t.exact = true;
  return t;
}

}  // namespace texel::codec

namespace texel::codec {

std::optional<Transcoded> transcode_file(const std::string& path, const SignalOptions& signal, const TranscodeOptions& options,
                                         std::string* why_not) {
  auto no = [&](std::string why) -> std::optional<Transcoded> {
    if (why_not) *why_not = std::move(why);
    return std::nullopt;
  };
  const SignalFormat format = signal_format_of(path);
  if (format != SignalFormat::document && format != SignalFormat::bitstream && format != SignalFormat::hjif &&
      format != SignalFormat::mat)
    return no("it holds samples, not Texel parameters");
  if (signal.region) return no("a region of it was asked for");
  if (signal.spacing) return no("another sample spacing was asked for");
  if (format == SignalFormat::bitstream) return transcode(read_bitstream(path));
  Document doc;
  if (format == SignalFormat::hjif) {
    // An MPEG-I Haptics file Texel exported carries its document: the same
    // parameters, hence the same bitstream, as the document itself.
    hjif::Experience e = hjif::load_hjif(path);
    if (!e.carried) return no(e.carried_rejected.empty() ? "it carries no Texel document, only samples" : e.carried_rejected);
    doc = std::move(*e.carried);
  } else if (format == SignalFormat::mat) {
    // A map Texel rendered to .mat carries its document in the char variable
    // `document` (docs/format.md "MATLAB .mat"): the same parameters as the
    // document itself. A .mat without one is a recording to estimate.
    std::optional<std::string> text = mat::read_text(path, "document");
    if (!text) return no("it carries no Texel document, only samples");
    try {
      doc = parse_document(*text, path + ": variable 'document'");
    } catch (const FormatError& e) {
      return no(std::string("its variable 'document' is not a Texel document: ") + e.what());
    }
  } else {
    doc = load_document(path);
  }
  if (signal.device) doc.device = *signal.device;  // re-targeted, as `texel render DOC --device X`
  if (auto why = not_transcodable(doc)) return no(std::move(*why));
  return transcode(doc, options);
}

}  // namespace texel::codec
