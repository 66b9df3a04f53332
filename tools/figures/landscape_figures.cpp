// landscape_figures — docs/landscape.md's drainage maps and statistics (not a test).
//
//   build/bin/landscape_figures TERRAIN.r32 WIDTH HEIGHT CELL [DRAINAGE.png]
//
// Reads float32 heights (export:raw's .r32), prints the statistics of
// landscape_stats.hpp, and optionally writes a drainage map: a grey hillshade
// with the channels (drainage area ≥ 0.05 km², D8 on the pit-filled surface)
// drawn in blue, darker and wider-looking the larger their area (log scale).
#include "landscape_stats.hpp"

#include <orogen/io.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    if (argc < 5) {
        std::fprintf(stderr, "usage: %s TERRAIN.r32 WIDTH HEIGHT CELL [DRAINAGE.png [MFD_EXPONENT]]\n", argv[0]);
        return 2;
    }
    const int w = std::stoi(argv[2]), h = std::stoi(argv[3]);
    const double cell = std::stod(argv[4]);
    std::vector<float> z(std::size_t(w) * std::size_t(h));
    std::ifstream in(argv[1], std::ios::binary);
    in.read(reinterpret_cast<char*>(z.data()), std::streamsize(z.size() * sizeof(float)));
    if (!in) {
        std::fprintf(stderr, "cannot read %zu floats from %s\n", z.size(), argv[1]);
        return 2;
    }
    const auto s = orogen::landscape::measure(z.data(), w, h, cell);
    std::printf(
        "median slope %.1f deg | steeper than 40 deg %.1f %% | pits %.3f %% | concavity %.2f (%d bins) | "
        "Hack %.2f (%d bins) | relief %.0f m\n",
        s.median_slope_deg, 100 * s.steeper_than_40, 100 * s.pit_share, s.concavity, s.concavity_bins, s.hack,
        s.hack_bins, s.relief);
    if (argc < 6) return 0;

    std::vector<double> filled(z.begin(), z.end());
    orogen::landscape::FlowRouter flow(w, h, cell, orogen::landscape::OpenSides{});
    flow.route(filled.data(), orogen::landscape::Depressions::fill);
    if (argc > 6)  // multiple flow directions (Freeman 1991) with this exponent
        flow.accumulate_multiple(filled.data(), std::stod(argv[6]));
    else flow.accumulate();
    const auto& area = flow.area();
    double amax = 0.0;
    for (double a : area) amax = std::max(amax, a);
    const double a_min = 5e4;
    std::vector<std::uint8_t> rgba(std::size_t(w) * std::size_t(h) * 4);
    auto at = [&](int x, int y) {
        x = std::clamp(x, 0, w - 1), y = std::clamp(y, 0, h - 1);
        return double(z[std::size_t(y) * std::size_t(w) + std::size_t(x)]);
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // Hillshade, light from the north-west, 45° up.
            const double dx = (at(x + 1, y) - at(x - 1, y)) / (2 * cell),
                         dy = (at(x, y + 1) - at(x, y - 1)) / (2 * cell);
            const double nx = -dx, ny = -dy, nz = 1.0, len = std::sqrt(nx * nx + ny * ny + nz * nz);
            const double lx = -0.5, ly = -0.5, lz = std::sqrt(0.5);
            const double shade = std::clamp((nx * lx + ny * ly + nz * lz) / len, 0.0, 1.0);
            double r = 90 + 150 * shade, g = r, b = r;
            const double a = area[std::size_t(y) * std::size_t(w) + std::size_t(x)];
            if (a >= a_min) {
                const double t =
                    std::log(a / a_min) / std::log(amax / a_min);  // 0 at the channel head, 1 at the outlet
                const double k = 0.55 + 0.45 * t;
                r = r * (1 - k) + 20 * k, g = g * (1 - k) + (90 - 50 * t) * k, b = b * (1 - k) + (220 - 60 * t) * k;
            }
            std::uint8_t* p = &rgba[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4];
            p[0] = std::uint8_t(r), p[1] = std::uint8_t(g), p[2] = std::uint8_t(b), p[3] = 255;
        }
    std::ostringstream png;
    orogen::write_rgba_png(png, w, h, rgba);
    const std::string bytes = png.str();
    orogen::write_file_atomically(argv[5], {reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()});
    return 0;
}
