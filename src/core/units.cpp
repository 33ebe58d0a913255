#include "texel/units.hpp"

#include "texel/detmath.hpp"

namespace texel {

CyclesPerMm to_cpm(Decibels db) { return CyclesPerMm(detmath::pow10(db.value() / 10.0)); }

Decibels to_db(CyclesPerMm f) {
  constexpr double ten_over_ln10 = 4.34294481903251827651;
  return Decibels(ten_over_ln10 * detmath::log(f.value()));
}

}  // namespace texel
