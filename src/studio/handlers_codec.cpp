// Codec messages on the FIFO lane: match (encode a region's rendering, put the
// decoded texture into another region), import and export of files. The
// work is design.hpp's match_region / import_file / export_file.
#include "base64.hpp"
#include "messages.hpp"
#include "texel/device.hpp"

namespace texel::studio::detail {

namespace {

// The encoder's result: the fields the studio has always sent (model_distance
// kept readable for a release beside distance_jnd; docs/format.md "Result field
// names") and, under "result", the library's one serialisation of it
// (codec::to_json, the same text as `texel encode --json`).
ojson encode_json(const codec::EncodeResult& r) {
  return ojson{{"bytes", r.bytes.size()},
               {"hex", hex(r.bytes)},
               {"distance_jnd", r.model_distance},
               {"model_distance", r.model_distance},
               {"central_pitch_db", r.spec.central_pitch.value()},
               {"irregularity_db", r.spec.irregularity.value()},
               {"texel_length_mm", r.spec.texel_length.value()},
               {"coarse", r.coarse},
               {"texel_recovered", r.texel_recovered},
               {"seconds", r.seconds},
               {"result", ojson::parse(codec::to_json(r))}};
}

}  // namespace

void on_match(State& s, Client& c, const Job& job) {
  const auto t0 = Clock::now();
  const Fields f(job.msg, job.type);
  MatchOptions o;
  o.region = static_cast<std::size_t>(f.integer("region", 0, 1023));
  o.into = region_field(f, "into");
  const MatchView m = match_region(document_of(s, f.object("document"), "document"), o);
  ojson r = reply("match", job.id);
  const ojson doc = ojson::parse(document_json(m.document));
  r["into"] = m.into;
  r["region"] = doc["regions"][m.into];
  r["document"] = doc;
  r["encoded"] = encode_json(m.result);
  r["distance_jnd"] = m.result.model_distance;
  r["model_distance"] = m.result.model_distance;
  r["target_spectrum"] = spectrum_json(m.target);
  r["match_spectrum"] = spectrum_json(m.match);
  r["elapsed_ms"] = ms_since(t0);
  send(c, r);
}

void on_import(State& s, Client& c, const Job& job) {
  const auto t0 = Clock::now();
  const Fields f(job.msg, job.type);
  const std::string name = f.string("name", max_name_chars);
  const auto bytes = base64_decode(f.string("data_base64", s.options.max_message_bytes));
  if (!bytes) throw Reject{"invalid", "import: data_base64 is not valid base64 (RFC 4648, padded)"};
  ImportOptions o;
  if (f.has("device")) {
    const std::string dev = f.string("device", max_name_chars);
    require_builtin_device(dev, "import: device is " + clipped(dev) + "; allowed: a built-in device");
    o.device = load_device(dev);
  }
  ImportResult res = import_file(name, std::as_bytes(std::span(*bytes)), o);
  // A document's inline device may be anything: apply the service's caps.
  const json doc = json::parse(document_json(res.document));
  (void)document_of(s, doc, "document");
  ojson r = reply("import", job.id);
  r["kind"] = to_string(res.kind);
  r["document"] = ojson::parse(doc.dump());
  r["encoded"] = res.encoded ? encode_json(*res.encoded) : ojson(nullptr);
  r["elapsed_ms"] = ms_since(t0);
  send(c, r);
}

void on_export(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const ExportFormat as = parse_export_format(f.string("as", 32));
  const ExportFile file = export_file(document_of(s, f.object("document"), "document"), as, region_field(f, "region"));
  ojson r = reply("export", job.id);
  r["name"] = file.name;
  r["mime"] = file.mime;
  r["bytes"] = file.data.size();
  r["data_base64"] = base64_encode(file.data);
  send(c, r);
}

}  // namespace texel::studio::detail
