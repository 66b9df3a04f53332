// A figure tool (not a test): rain as SPH particles on a Diamond-Square
// terrain, drawn top-down over the hillshade — particles as dots coloured by
// speed (blue slow → white fast), the terrain by the hillshade tinted by
// height. Used for docs/erosion.md when ParaView is not at hand:
//   build/tests/sph_figure out.png [n=257] [cell=2] [steps=200] [rain=150]
#include "diamond_square.hpp"
#include <orogen/formats/heightmap_png.hpp>
#include "sph.hpp"

#include <orogen/io.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace orogen;

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: sph_figure out.png [n=257] [cell=2] [steps=200] [rain=150]\n");
        return 2;
    }
    int n = 257, steps = 200, rain = 150;
    double cell = 2.0;
    for (int a = 2; a < argc; ++a) {
        const std::string s = argv[a];
        const auto eq = s.find('=');
        const std::string k = s.substr(0, eq), v = s.substr(eq + 1);
        if (k == "n") n = std::stoi(v);
        else if (k == "cell") cell = std::stod(v);
        else if (k == "steps") steps = std::stoi(v);
        else if (k == "rain") rain = std::stoi(v);
    }
    std::vector<float> h(std::size_t(n) * n);
    diamond_square::Params p;
    p.amplitude = 60;
    p.roughness = 0.5;
    diamond_square::generate(GridView{h.data(), n, n, cell}, p, 7);
    sph::Settings s;
    s.radius = 1.0;
    s.boundary = sph::Boundary::open;
    sph::Simulation sim(ConstGridView(h.data(), n, n, cell), s, 100000);
    for (int step = 1; step <= steps; ++step) {
        sim.rain(rain, 2.0, 7, step, 2.0f, 300);
        sim.advance(0.05, step);
        sim.end_step();
    }
    std::vector<float> eroded(h.size());
    sim.write_terrain(GridView{eroded.data(), n, n, cell});
    const auto shade = formats::png::hillshade(ConstGridView(eroded.data(), n, n, cell), 8, 315, 45);
    const auto range = formats::png::range_of(ConstGridView(eroded.data(), n, n, cell));
    const int scale = 4;  // pixels per cell
    const int W = (n - 1) * scale + 1;
    std::vector<std::uint8_t> rgba(std::size_t(W) * W * 4);
    for (int y = 0; y < W; ++y)
        for (int x = 0; x < W; ++x) {
            const int gx = std::min(n - 1, x / scale), gy = std::min(n - 1, y / scale);
            const std::size_t g = std::size_t(gy) * n + gx;
            const double t = (eroded[g] - range.low) / std::max(1e-6f, range.high - range.low);
            const double sh = shade[g] / 255.0;
            // green lowlands → brown → grey heights, times the hillshade
            const double r = (0.35 + 0.45 * t) * (0.3 + 0.7 * sh), gr = (0.45 + 0.2 * t) * (0.3 + 0.7 * sh),
                         b = (0.25 + 0.4 * t) * (0.3 + 0.7 * sh);
            std::uint8_t* px = &rgba[(std::size_t(y) * W + x) * 4];
            px[0] = std::uint8_t(255 * std::clamp(r, 0.0, 1.0));
            px[1] = std::uint8_t(255 * std::clamp(gr, 0.0, 1.0));
            px[2] = std::uint8_t(255 * std::clamp(b, 0.0, 1.0));
            px[3] = 255;
        }
    const auto pos = sim.positions();
    const auto vel = sim.velocities();
    for (std::size_t i = 0; i < pos.size(); ++i) {
        const double speed = std::sqrt(vel[i].x * vel[i].x + vel[i].y * vel[i].y + vel[i].z * vel[i].z);
        const double t = std::clamp(speed / 6.0, 0.0, 1.0);
        const int cx = int(pos[i].x / cell * scale), cy = int(pos[i].z / cell * scale);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int x = cx + dx, y = cy + dy;
                if (x < 0 || y < 0 || x >= W || y >= W) continue;
                std::uint8_t* px = &rgba[(std::size_t(y) * W + x) * 4];
                px[0] = std::uint8_t(30 + 225 * t);
                px[1] = std::uint8_t(90 + 165 * t);
                px[2] = 255;
            }
    }
    std::ofstream out(argv[1], std::ios::binary);
    write_rgba_png(out, W, W, rgba);
    std::printf("%zu particles alive after %d steps (%lld sub-steps)\n", pos.size(), steps, (long long)sim.substeps());
    return 0;
}
