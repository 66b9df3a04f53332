// rmp_figures — the pictures in docs/rmp.md and docs/benchmarks.md, drawn
// with the kernel's PNG writer (matplotlib is not on the build machines).
//
//   rmp_figures plot TIMINGS.csv OUT.png     figure 4.13: seconds per 100 iterations vs regions
//   rmp_figures voronoi N SIZE OUT.png        a Voronoi diagram of N sites, the cell under the centre lit
//   rmp_figures shade IN.r32 W H OUT.png      a hillshaded heightmap (export:raw .r32)
//
// TIMINGS.csv lines: method,regions,seconds (method: graph | cones | voronoi),
// made from Google Benchmark's JSON by bench_to_csv.py.
#include <orogen/relief/voronoi.hpp>

#include <orogen/io.hpp>
#include <orogen/random.hpp>

#include <stb_easy_font.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace orogen;

namespace {

struct Rgb {
    std::uint8_t r, g, b;
};

struct Canvas {
    int w, h;
    std::vector<std::uint8_t> px;
    Canvas(int w_, int h_, Rgb bg) : w(w_), h(h_), px(std::size_t(w_) * h_ * 4) {
        for (std::size_t i = 0; i < px.size(); i += 4) {
            px[i] = bg.r;
            px[i + 1] = bg.g;
            px[i + 2] = bg.b;
            px[i + 3] = 255;
        }
    }
    void set(int x, int y, Rgb c, double a = 1.0) {
        if (x < 0 || y < 0 || x >= w || y >= h) return;
        std::uint8_t* p = &px[(std::size_t(y) * w + x) * 4];
        p[0] = std::uint8_t(p[0] + (c.r - p[0]) * a);
        p[1] = std::uint8_t(p[1] + (c.g - p[1]) * a);
        p[2] = std::uint8_t(p[2] + (c.b - p[2]) * a);
    }
    void rect(int x0, int y0, int x1, int y1, Rgb c) {
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) set(x, y, c);
    }
    // A line `width` pixels wide, antialiased by distance to the segment.
    void line(double x0, double y0, double x1, double y1, Rgb c, double width = 2.0, bool dashed = false) {
        const int bx0 = int(std::floor(std::min(x0, x1) - width)), bx1 = int(std::ceil(std::max(x0, x1) + width));
        const int by0 = int(std::floor(std::min(y0, y1) - width)), by1 = int(std::ceil(std::max(y0, y1) + width));
        const double dx = x1 - x0, dy = y1 - y0, len2 = std::max(dx * dx + dy * dy, 1e-12);
        for (int y = by0; y <= by1; ++y)
            for (int x = bx0; x <= bx1; ++x) {
                const double t = std::clamp(((x - x0) * dx + (y - y0) * dy) / len2, 0.0, 1.0);
                if (dashed && std::fmod(t * std::sqrt(len2), 12.0) > 7.0) continue;
                const double d = std::hypot(x - (x0 + t * dx), y - (y0 + t * dy));
                const double a = std::clamp(width / 2 + 0.5 - d, 0.0, 1.0);
                if (a > 0) set(x, y, c, a);
            }
    }
    void disc(double cx, double cy, double r, Rgb c, bool hollow = false) {
        for (int y = int(cy - r - 1); y <= int(cy + r + 1); ++y)
            for (int x = int(cx - r - 1); x <= int(cx + r + 1); ++x) {
                const double d = std::hypot(x - cx, y - cy);
                double a = std::clamp(r + 0.5 - d, 0.0, 1.0);
                if (hollow) a = std::min(a, std::clamp(d - (r - 2.5), 0.0, 1.0));
                if (a > 0) set(x, y, c, a);
            }
    }
    // Text with stb_easy_font, scaled by `s`; (x, y) is the top left.
    void text(double x, double y, const std::string& s, Rgb c, double scale = 2.0) {
        static char buffer[200000];
        const int quads = stb_easy_font_print(0, 0, const_cast<char*>(s.c_str()), nullptr, buffer, sizeof buffer);
        const float* v = reinterpret_cast<const float*>(buffer);
        for (int q = 0; q < quads; ++q) {
            const float* a = v + q * 16;  // 4 vertices × (x, y, z, colour)
            const int x0 = int(std::lround(x + a[0] * scale)), y0 = int(std::lround(y + a[1] * scale));
            const int x1 = int(std::lround(x + a[8] * scale)), y1 = int(std::lround(y + a[9] * scale));
            rect(x0, y0, x1, y1, c);
        }
    }
    static double text_width(const std::string& s, double scale = 2.0) {
        return stb_easy_font_width(const_cast<char*>(s.c_str())) * scale;
    }
    void save(const std::string& path) const {
        AtomicFile f(path);
        write_rgba_png(f.stream(), w, h, px);
        f.commit();
    }
};

int plot(const std::string& csv, const std::string& out) {
    // method → (regions, seconds per 100 iterations)
    std::map<std::string, std::vector<std::pair<double, double>>> series;
    std::ifstream in(csv);
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::stringstream ss(line);
        std::string method, regions, seconds;
        std::getline(ss, method, ',');
        std::getline(ss, regions, ',');
        std::getline(ss, seconds, ',');
        series[method].push_back({std::stod(regions), std::stod(seconds)});
    }
    for (auto& [_, pts] : series) std::sort(pts.begin(), pts.end());
    // The thesis's own figures (tables 4.1, 4.2), 256² tiles, a 2016 MacBook Pro.
    series["thesis graph (256^2)"] = {{7, 2.975}, {11, 46.729}, {16, 5937.348}};
    series["thesis cones (GPU, 256^2)"] = {{7, 1.989}, {11, 2.004}, {16, 2.025}};

    Canvas c(960, 636, {255, 255, 255});
    const double L = 100, R = 930, T = 76, B = 556;
    const double xmin = 0, xmax = 5, ymin = -3, ymax = 4;  // log10 of regions and of seconds
    auto X = [&](double regions) { return L + (std::log10(regions) - xmin) / (xmax - xmin) * (R - L); };
    auto Y = [&](double s) { return B - (std::log10(s) - ymin) / (ymax - ymin) * (B - T); };
    const Rgb grid{225, 225, 225}, ink{40, 40, 40};
    for (int k = int(xmin); k <= int(xmax); ++k) {
        c.line(X(std::pow(10, k)), T, X(std::pow(10, k)), B, grid, 1);
        const std::string label = k == 0 ? "1"
            : k <= 3                     ? std::to_string(int(std::pow(10, k)))
                                         : "1e" + std::to_string(k);
        c.text(X(std::pow(10, k)) - Canvas::text_width(label) / 2, B + 10, label, ink);
    }
    const char* ylabels[] = {"1 ms", "10 ms", "0.1 s", "1 s", "10 s", "100 s", "1000 s", "1e4 s"};
    for (int k = int(ymin); k <= int(ymax); ++k) {
        c.line(L, Y(std::pow(10, k)), R, Y(std::pow(10, k)), grid, 1);
        const std::string label = ylabels[k - int(ymin)];
        c.text(L - 10 - Canvas::text_width(label), Y(std::pow(10, k)) - 7, label, ink);
    }
    c.line(L, B, R, B, ink, 1.5);
    c.line(L, T, L, B, ink, 1.5);
    const std::string xl = "regions (cones or polygons) per iteration";
    c.text((L + R) / 2 - Canvas::text_width(xl) / 2, B + 40, xl, ink);
    c.text(L - 90, T - 32, "seconds per 100 iterations", ink);
    const std::string title = "RMP on a 1025^2 grid, 100 iterations (cf. thesis fig. 4.13)";
    c.text((L + R) / 2 - Canvas::text_width(title) / 2, 8, title, ink);

    struct Style {
        Rgb colour;
        bool dashed, hollow;
    };
    const std::map<std::string, Style> styles{
        {"voronoi", {{30, 140, 60}, false, false}},
        {"cones", {{40, 90, 200}, false, false}},
        {"graph", {{220, 110, 20}, false, false}},
        {"thesis graph (256^2)", {{220, 110, 20}, true, true}},
        {"thesis cones (GPU, 256^2)", {{40, 90, 200}, true, true}},
    };
    double ly = T + 14;
    for (const char* name : {"voronoi", "cones", "graph", "thesis cones (GPU, 256^2)", "thesis graph (256^2)"}) {
        auto it = series.find(name);
        if (it == series.end()) continue;
        const Style& st = styles.at(name);
        const auto& pts = it->second;
        for (std::size_t i = 1; i < pts.size(); ++i)
            c.line(X(pts[i - 1].first), Y(pts[i - 1].second), X(pts[i].first), Y(pts[i].second), st.colour, 2.5,
                   st.dashed);
        for (const auto& [r, s] : pts) c.disc(X(r), Y(s), 5, st.colour, st.hollow);
        // Legend, top left.
        c.line(L + 20, ly, L + 60, ly, st.colour, 2.5, st.dashed);
        c.disc(L + 40, ly, 5, st.colour, st.hollow);
        c.text(L + 70, ly - 7, name, ink);
        ly += 24;
    }
    c.save(out);
    return 0;
}

Rgb cell_colour(int id) {
    const std::uint64_t h = random::hash(0xC0105ull, std::uint64_t(id));
    return {std::uint8_t(90 + (h & 127)), std::uint8_t(90 + ((h >> 8) & 127)), std::uint8_t(90 + ((h >> 16) & 127))};
}

int voronoi(int count, int size, const std::string& out) {
    const auto sites = relief::random_sites(count, size, size, 1);
    const relief::SiteIndex index(sites, size, size);
    const auto labels = relief::label_grid(index);
    const int lit = index.nearest(0.5 * (size - 1), 0.5 * (size - 1));
    Canvas c(size, size, {0, 0, 0});
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const int id = labels[std::size_t(y) * size + x];
            const bool border = (x + 1 < size && labels[std::size_t(y) * size + x + 1] != id) ||
                (y + 1 < size && labels[std::size_t(y + 1) * size + x] != id);
            c.set(x, y, border ? Rgb{30, 30, 30} : id == lit ? Rgb{255, 255, 255} : cell_colour(id));
        }
    for (const Point2& s : sites) c.disc(s.x, s.y, size > 400 && count > 500 ? 1.0 : 2.0, {20, 20, 20});
    c.save(out);
    return 0;
}

int shade(const std::string& in, int w, int h, const std::string& out) {
    const auto bytes = read_file(in);
    if (bytes.size() != std::size_t(w) * h * 4) {
        std::cerr << "rmp_figures: " << in << " holds " << bytes.size() << " bytes, not " << w << " x " << h
                  << " floats\n";
        return 2;
    }
    std::vector<float> z(std::size_t(w) * h);
    std::memcpy(z.data(), bytes.data(), bytes.size());
    const auto [lo, hi] = std::minmax_element(z.begin(), z.end());
    const double range = std::max(double(*hi - *lo), 1e-6);
    // Light from the north-west, 45° up; the relief drawn as 6 % of the map's width.
    const double scale = 0.06 * w / range;
    const double lx = -0.5, ly = -0.5, lz = std::sqrt(0.5);
    Canvas c(w, h, {0, 0, 0});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            auto at = [&](int xx, int yy) {
                return double(z[std::size_t(std::clamp(yy, 0, h - 1)) * w + std::clamp(xx, 0, w - 1)]) * scale;
            };
            const double gx = (at(x + 1, y) - at(x - 1, y)) / 2, gy = (at(x, y + 1) - at(x, y - 1)) / 2;
            const double n = std::sqrt(gx * gx + gy * gy + 1);
            const double lambert = std::max(0.0, (-gx * lx - gy * ly + lz) / n);
            const double t = (z[std::size_t(y) * w + x] - *lo) / range;  // green lowlands to pale peaks
            const Rgb base{std::uint8_t(90 + 150 * t), std::uint8_t(130 + 110 * t), std::uint8_t(80 + 160 * t)};
            const double k = 0.35 + 0.65 * lambert;
            c.set(x, y, {std::uint8_t(base.r * k), std::uint8_t(base.g * k), std::uint8_t(base.b * k)});
        }
    c.save(out);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> a(argv + 1, argv + argc);
    try {
        if (a.size() == 3 && a[0] == "plot") return plot(a[1], a[2]);
        if (a.size() == 4 && a[0] == "voronoi") return voronoi(std::stoi(a[1]), std::stoi(a[2]), a[3]);
        if (a.size() == 5 && a[0] == "shade") return shade(a[1], std::stoi(a[2]), std::stoi(a[3]), a[4]);
    } catch (const std::exception& e) {
        std::cerr << "rmp_figures: " << e.what() << "\n";
        return 1;
    }
    std::cerr << "usage: rmp_figures plot TIMINGS.csv OUT.png | voronoi N SIZE OUT.png | shade IN.r32 W H OUT.png\n";
    return 2;
}
