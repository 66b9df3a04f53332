// onset.hpp — 1 − e^(−x), the smooth onset of channels and of bank erosion with drainage area, fast.
//
// Rain-weighted drainage areas (rain=orographic) are not whole numbers of
// cells, so the whole-cell tables of the incision's A^m·(1 − e^(−A/A_c)) and
// of the banks' 1 − e^(−A/A_b) miss nearly every cell, and an expm1 per cell
// and step took 4–5 % of a rainy run (perf, the Kahurangi preset at 1025²).
// Here 1 − e^(−x) is linear between the exact values 2^−12 apart below 38:
// within h²/8 = 7.5·10⁻⁹ of it (the curvature is at most 1), and from
// 38 on it is 1 exactly (e^(−38) is less than half an ulp of 1). The table
// (1.2 MB, the first 32 kB of it for areas under A_c: most cells) is built
// once per process, the same values on every thread and run.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

namespace orogen::landscape {

/// 1 − e^(−x) for x ≥ 0 to within 7.5·10⁻⁹ (above); NaN stays NaN.
inline double onset(double x) {
    constexpr int kPerUnit = 4096;
    constexpr double kReach = 38.0;
    static const std::vector<double> table = [] {
        std::vector<double> t(std::size_t(kReach * kPerUnit) + 2);
        for (std::size_t i = 0; i < t.size(); ++i) t[i] = -std::expm1(-double(i) / kPerUnit);
        return t;
    }();
    if (!(x < kReach)) return x >= kReach ? 1.0 : x;
    if (!(x > 0.0)) return x < 0.0 ? -std::expm1(-x) : 0.0;
    const double u = x * kPerUnit;
    const auto i = std::size_t(u);
    return table[i] + (u - double(i)) * (table[i + 1] - table[i]);
}

}  // namespace orogen::landscape
