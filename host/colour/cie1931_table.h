// cie1931_table.h: the CIE 1931 2° standard observer (x̄, ȳ, z̄) every nanometre from 360 to 830 nm.
#pragma once

namespace narval {

constexpr int kCie1931FirstNm = 360;
constexpr int kCie1931Count = 471;  // 360..830 nm
extern const float kCie1931[kCie1931Count][3];

}  // namespace narval
