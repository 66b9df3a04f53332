// Shared by the exporter benchmarks (tests/bench/export_*.cpp): a 4097² test
// terrain and a scratch folder on the same disk as the build.
#pragma once

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <vector>

namespace orogen::bench {

/// Ridged hills, 0..~2500 m, n × n samples (made once per process).
inline const std::vector<float>& terrain(int n) {
    static std::vector<float> h;
    static int made = 0;
    if (made != n) {
        h.assign(std::size_t(n) * std::size_t(n), 0.0f);
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double u = double(x) / (n - 1), v = double(y) / (n - 1);
                h[std::size_t(y) * std::size_t(n) + std::size_t(x)] =
                    float(1200.0 + 900.0 * std::sin(7.0 * u) * std::cos(5.0 * v) +
                          300.0 * std::abs(std::sin(37.0 * u + 11.0 * v)));
            }
        made = n;
    }
    return h;
}

inline std::filesystem::path scratch() {
    const auto p = std::filesystem::temp_directory_path() / "orogen-bench-export";
    std::filesystem::create_directories(p);
    return p;
}

}  // namespace orogen::bench
