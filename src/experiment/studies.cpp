// The study table (studies.hpp).
#include "studies.hpp"

namespace texel::experiment {

namespace {

constexpr Study table[] = {
    {"texel-length", "Texel length", StudyDesign::staircase, "texel length (mm)", false, true, false},
    {"parameter-mapping", "Parameter mapping", StudyDesign::matching, {}, false, false, true},
    {"free-exploration", "Free exploration", StudyDesign::matching},
    {"quantization", "Quantization", StudyDesign::quantization},
    {"guided-exploration", "Guided exploration", StudyDesign::guided},
    {"coarse-features", "Coarse strength", StudyDesign::staircase, "coarse strength (0 … 1)", true, false, false},
    {"working-memory", "Working memory", StudyDesign::memory},
    {"working-memory-components", "Working-memory components", StudyDesign::memory},
    {"direction-independence", "Direction independence", StudyDesign::oddity, {}, false, false, false, true},
    {"rendering-2d", "2-D rendering against the 1-D original", StudyDesign::oddity},
    {"distributed-irregularity", "Distributed irregularity", StudyDesign::playback},
};

}  // namespace

std::span<const Study> studies() { return table; }

const Study* find_study(std::string_view name) {
  for (const Study& s : table)
    if (s.name == name) return &s;
  return nullptr;
}

}  // namespace texel::experiment
