// Test helper for the schema tests (schema_conformance.py): writes every kind
// of .hjif Texel exports, and reports Texel's own verdicts on files, so a
// format-checking JSON-schema validator can be compared with them.
//
//   hjif_conformance_tool write DIR      the exports, one file per case
//   hjif_conformance_tool check FILE...  per file: name, schema verdict,
//                                        conformance verdict, first error
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "../support/specs.hpp"
#include "interchange_support.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"

using namespace texel;

namespace {

int write_cases(const std::string& dir) {
  const DeviceProfile tpad = load_device("tpad");
  auto fine = [](double p, double i, double l, std::uint64_t seed) { return test_support::fine_spec(p, i, l, seed); };
  std::vector<std::pair<std::string, Document>> docs;
  docs.emplace_back("fine", make_document(tpad, fine(10, -5, 0.25, 7)));
  TexelSpec coarse = fine(8, -8, 0.5, 3);
  coarse.coarse = SineProfile{Millimetres(5.0), 0.0};
  coarse.coarse_strength = 0.6;
  coarse.fine_strength = 0.4;
  docs.emplace_back("coarse", make_document(tpad, coarse));
  TexelSpec quantized = fine(12, -3, 0.25, 11);
  quantized.quantization_db = 3.0;
  docs.emplace_back("quantized", make_document(tpad, quantized));
  docs.emplace_back("two-regions", test_support::two_region_document(tpad));
  ReferenceSpec ref;
  ref.name = "4sin";
  docs.emplace_back("reference", make_reference_document(tpad, ref));
  docs.emplace_back("generic", make_document(load_device("generic"), fine(10, -5, 0.25, 7)));
  for (const auto& [name, doc] : docs) {
    hjif::ExportOptions o;
    o.date = "2026-11-26T14:06:29Z";
    write_file_atomic(dir + "/" + name + ".hjif", hjif::export_hjif(doc, o).json);
  }
  hjif::ExportOptions v;
  v.modality = hjif::Modality::vibrotactile_texture;
  write_file_atomic(dir + "/vibrotactile-texture.hjif", hjif::export_hjif(docs.front().second, v).json);
  return 0;
}

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\t') c = ' ';
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::vector<std::string> args(argv + 1, argv + argc);
    if (args.size() == 2 && args[0] == "write") return write_cases(args[1]);
    if (!args.empty() && args[0] == "check") {
      for (std::size_t i = 1; i < args.size(); ++i) {
        const std::string text = read_file(args[i]);
        const auto schema = hjif::schema_errors(text);
        const auto all = hjif::conformance_errors(text);
        std::cout << args[i] << "\t" << (schema.empty() ? "valid" : "invalid") << "\t"
                  << (all.empty() ? "conformant" : "not-conformant") << "\t"
                  << one_line(all.empty() ? std::string() : all.front()) << "\n";
      }
      return 0;
    }
    std::cerr << "usage: hjif_conformance_tool write DIR | check FILE...\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
}
