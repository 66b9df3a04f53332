// plates_figures — the pictures in docs/tectonics.md.
//
//   plates_figures shade IN.r32 W H CELL OUT.png [X0 Y0 CW CH ZOOM]
//       a hillshaded heightmap (export:raw .r32, CELL metres apart), true
//       vertical scale, optionally a crop (CW × CH samples at X0, Y0) zoomed
//       ZOOM times (nearest sample)
//   plates_figures features OUT.png
//       the three kinds of boundary relief alone (profiles.hpp), side by
//       side: a collision range, a subduction zone (trench and arc), a rift;
//       each boundary hit 40 times along slightly different segments
#include "profiles.hpp"

#include <orogen/io.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using namespace orogen;

namespace {

struct Image {
    int w, h;
    std::vector<std::uint8_t> px;
    Image(int w_, int h_) : w(w_), h(h_), px(std::size_t(w_) * h_ * 4, 255) {}
    void set(int x, int y, double r, double g, double b) {
        std::uint8_t* p = &px[(std::size_t(y) * w + x) * 4];
        p[0] = std::uint8_t(std::clamp(r, 0.0, 255.0));
        p[1] = std::uint8_t(std::clamp(g, 0.0, 255.0));
        p[2] = std::uint8_t(std::clamp(b, 0.0, 255.0));
    }
    void save(const std::string& path) const {
        std::ofstream f(path, std::ios::binary);
        write_rgba_png(f, w, h, px);
    }
};

// Colour by height within the picture's range: t = 0 lowest … 1 highest,
// dark green through tan to pale grey.
void colour(double t, double& r, double& g, double& b) {
    t = std::clamp(t, 0.0, 1.0);
    if (t < 0.5) {
        const double u = t / 0.5;
        r = 70 + 110 * u, g = 110 + 50 * u, b = 70 + 40 * u;
    } else {
        const double u = (t - 0.5) / 0.5;
        r = 180 + 60 * u, g = 160 + 75 * u, b = 110 + 125 * u;
    }
}

// A heightmap: w × h samples `cell` metres apart.
struct Heights {
    const std::vector<float>& z;
    int w, h;
    double cell;
};

// The part of a heightmap to draw: cw × ch samples from (x0, y0), each zoom × zoom pixels.
struct Crop {
    int x0, y0, cw, ch, zoom;
};

// Light from the north-west, 45° up, true vertical scale; drawn at (ox, oy) of img, coloured over [lo, hi]
// (hi < lo: the heightmap's own range).
void shade_into(Image& img, int ox, int oy, const Heights& heights, Crop crop, double lo = 0.0, double hi = -1.0) {
    const std::vector<float>& z = heights.z;
    const int w = heights.w, h = heights.h;
    const double cell = heights.cell;
    const int x0 = crop.x0, y0 = crop.y0, cw = crop.cw, ch = crop.ch, zoom = crop.zoom;
    auto at = [&](int x, int y) {
        return double(z[std::size_t(std::clamp(y, 0, h - 1)) * w + std::clamp(x, 0, w - 1)]);
    };
    const double lx = -0.5, ly = -0.5, lz = std::sqrt(0.5);
    if (hi < lo) {  // the picture's own range
        const auto [lo_it, hi_it] = std::minmax_element(z.begin(), z.end());
        lo = *lo_it, hi = *hi_it;
    }
    const double span = std::max(hi - lo, 1e-6);
    for (int y = 0; y < ch * zoom; ++y)
        for (int x = 0; x < cw * zoom; ++x) {
            const int sx = x0 + x / zoom, sy = y0 + y / zoom;
            const double gx = (at(sx + 1, sy) - at(sx - 1, sy)) / (2 * cell);
            const double gy = (at(sx, sy + 1) - at(sx, sy - 1)) / (2 * cell);
            const double n = std::sqrt(gx * gx + gy * gy + 1);
            const double lambert = std::max(0.0, (-gx * lx - gy * ly + lz) / n);
            double r, g, b;
            colour((at(sx, sy) - lo) / span, r, g, b);
            const double k = 0.3 + 0.85 * lambert;
            img.set(ox + x, oy + y, r * k, g * k, b * k);
        }
}

int shade(const std::vector<std::string>& a) {
    const int w = std::stoi(a[2]), h = std::stoi(a[3]);
    const double cell = std::stod(a[4]);
    std::ifstream f(a[1], std::ios::binary);
    std::vector<float> z(std::size_t(w) * h);
    f.read(reinterpret_cast<char*>(z.data()), std::streamsize(z.size() * 4));
    if (!f) {
        std::cerr << "plates_figures: " << a[1] << " is not " << w << " x " << h << " floats\n";
        return 2;
    }
    int x0 = 0, y0 = 0, cw = w, ch = h, zoom = 1;
    if (a.size() == 11)
        x0 = std::stoi(a[6]), y0 = std::stoi(a[7]), cw = std::stoi(a[8]), ch = std::stoi(a[9]), zoom = std::stoi(a[10]);
    Image img(cw * zoom, ch * zoom);
    shade_into(img, 0, 0, {z, w, h, cell}, {x0, y0, cw, ch, zoom});
    img.save(a[5]);
    return 0;
}

int features(const std::string& out) {
    const int n = 257, gap = 6;
    const double cell_m = 30.0;
    plates::ReliefShape shape;
    shape.cell = 120.0;  // samples: the Voronoi cell size of cones ≈ 4.6 on this grid, so the features fill it
    Image img(3 * n + 2 * gap, n);
    std::vector<std::vector<float>> panels;
    for (int panel = 0; panel < 3; ++panel) {
        plates::BoundaryRelief relief(n, n, shape, 7);
        for (int k = 0; k < 40; ++k) {
            // A boundary hit again and again, each contact a little shifted and shorter or longer.
            const double dx = random::uniform_in(-6.0, 6.0, 5, k, 1), dy = random::uniform_in(-20.0, 20.0, 5, k, 2);
            const Point2 a{128 + dx - 12, 30 + dy}, b{128 + dx + 12, 226 + dy};
            if (panel == 0) relief.add_range(a, b);
            if (panel == 1) relief.add_subduction(a, b, {1, 0});  // dense plate west, light east
            if (panel == 2) relief.add_rift(a, b);
        }
        panels.push_back(relief.relief());
    }
    double lo = 0.0, hi = 0.0;  // one colour scale for all three
    for (const auto& z : panels)
        for (float v : z) lo = std::min(lo, double(v)), hi = std::max(hi, double(v));
    for (int panel = 0; panel < 3; ++panel)
        shade_into(img, panel * (n + gap), 0, {panels[std::size_t(panel)], n, n, cell_m}, {0, 0, n, n, 1}, lo, hi);
    img.save(out);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> a(argv + 1, argv + argc);
    try {
        if ((a.size() == 6 || a.size() == 11) && a[0] == "shade") return shade(a);
        if (a.size() == 2 && a[0] == "features") return features(a[1]);
    } catch (const std::exception& e) {
        std::cerr << "plates_figures: " << e.what() << "\n";
        return 1;
    }
    std::cerr << "usage: plates_figures shade IN.r32 W H CELL OUT.png [X0 Y0 CW CH ZOOM] | features OUT.png\n";
    return 2;
}
