// erosion_figures — a debugging and figure tool for the grid eroders (not a
// test): builds a terrain (Diamond-Square, Fault, or a 16-bit PNG), runs
// thermal and pipe erosion on it with the cores directly, prints artefact
// metrics and writes hillshaded PNGs of the terrain and colour maps of the
// pipe model's layers.
//
//   erosion_figures key=value...
//     terrain=ds|fault|png   n=513 cell=10 amplitude=400 roughness=0.5 seed=7
//     in=FILE.png low=0 high=1000  (terrain=png: 16-bit gray, heights low..high m)
//     thermal=20 talus=40 nb=moore       (thermal steps before the pipe model)
//     steps=1500 dt=1 rain=0.0005 evaporation=0.001 capacity=0.5 ...  (pipe::Settings names)
//     out=/tmp/ef prefix=ds
// Writes OUT/PREFIX-{before,after}.png (hillshade), -water.png, -flow.png,
// -eroded.png; prints checkerboard energy, pits and the flow network size.
#include "pipe.hpp"
#include "thermal.hpp"
#include "diamond_square.hpp"
#include "fault.hpp"

#include <orogen/io.hpp>
#include <orogen/parallel.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

using namespace orogen;

namespace {

std::map<std::string, std::string> args;
double num(const std::string& k, double def) { return args.count(k) ? std::stod(args[k]) : def; }
std::string str(const std::string& k, const std::string& def) { return args.count(k) ? args[k] : def; }

struct Rgb {
    float r, g, b;
};

/// Every picture also goes into one side-by-side panel (OUT/PREFIX-panel.png).
std::vector<std::vector<Rgb>> panels;

void write_rgb(const std::string& path, int w, int h, const std::vector<Rgb>& px, bool panel = true) {
    if (panel) panels.push_back(px);
    std::vector<std::uint8_t> rgba(std::size_t(w) * h * 4);
    for (std::size_t i = 0; i < px.size(); ++i) {
        rgba[4 * i] = std::uint8_t(std::clamp(px[i].r, 0.0f, 1.0f) * 255.0f + 0.5f);
        rgba[4 * i + 1] = std::uint8_t(std::clamp(px[i].g, 0.0f, 1.0f) * 255.0f + 0.5f);
        rgba[4 * i + 2] = std::uint8_t(std::clamp(px[i].b, 0.0f, 1.0f) * 255.0f + 0.5f);
        rgba[4 * i + 3] = 255;
    }
    std::ofstream f(path, std::ios::binary);
    write_rgba_png(f, w, h, rgba);
    std::printf("wrote %s\n", path.c_str());
}

/// Lambertian shade (light from the north-west, 45° up), 0..1.
std::vector<float> hillshade(const std::vector<float>& hgt, int w, int h, double cell) {
    std::vector<float> s(hgt.size());
    const double lx = -1.0, ly = -1.0, lz = std::sqrt(2.0);
    const double ln = std::sqrt(lx * lx + ly * ly + lz * lz);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            auto at = [&](int xx, int yy) {
                return double(hgt[std::size_t(std::clamp(yy, 0, h - 1)) * w + std::clamp(xx, 0, w - 1)]);
            };
            const double gx = (at(x + 1, y) - at(x - 1, y)) / (2 * cell);
            const double gy = (at(x, y + 1) - at(x, y - 1)) / (2 * cell);
            const double nx = -gx, ny = -gy, nz = 1.0;
            const double d = (nx * lx + ny * ly + nz * lz) / (std::sqrt(nx * nx + ny * ny + 1.0) * ln);
            s[std::size_t(y) * w + x] = float(std::max(0.0, d));
        }
    return s;
}

void write_shade(const std::string& path, const std::vector<float>& hgt, int w, int h, double cell,
                 const std::vector<float>* water = nullptr) {
    const auto s = hillshade(hgt, w, h, cell);
    const auto [lo, hi] = std::minmax_element(hgt.begin(), hgt.end());
    std::vector<Rgb> px(hgt.size());
    for (std::size_t i = 0; i < px.size(); ++i) {
        const float t = (hgt[i] - *lo) / std::max(*hi - *lo, 1e-6f);
        // a faint hypsometric tint under the shade: green lowlands, brown-white tops
        const Rgb tint{0.55f + 0.4f * t, 0.6f + 0.3f * t, 0.45f + 0.5f * t};
        const float v = 0.25f + 0.75f * s[i];
        Rgb c{tint.r * v, tint.g * v, tint.b * v};
        if (water && (*water)[i] > 0.02f) {
            const float a = std::min(1.0f, (*water)[i] / 1.0f) * 0.8f + 0.2f;
            c = {c.r * (1 - a) + 0.1f * a, c.g * (1 - a) + 0.3f * a, c.b * (1 - a) + 0.8f * a};
        }
        px[i] = c;
    }
    write_rgb(path, w, h, px);
}

/// A sequential colour ramp (black → purple → orange → yellow) of v / vmax.
Rgb ramp(float t) {
    t = std::clamp(t, 0.0f, 1.0f);
    return {std::min(1.0f, 2.0f * t), std::max(0.0f, 2.0f * t - 0.7f), 0.4f * std::sin(3.14159f * t) + 0.2f * t};
}

void write_layer(const std::string& path, const std::vector<float>& v, int w, int h, float vmax) {
    std::vector<Rgb> px(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) px[i] = ramp(std::sqrt(std::max(v[i], 0.0f) / vmax));
    write_rgb(path, w, h, px);
}

/// Red where terrain was removed, blue where deposited, white unchanged; ± scale metres saturate.
void write_diverging(const std::string& path, const std::vector<float>& v, int w, int h, float scale) {
    std::vector<Rgb> px(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        const float t = std::clamp(v[i] / scale, -1.0f, 1.0f);
        px[i] = t < 0 ? Rgb{1.0f, 1.0f + t, 1.0f + t} : Rgb{1.0f - t, 1.0f - t, 1.0f};
    }
    write_rgb(path, w, h, px);
}

struct Metrics {
    double checker_global = 0, checker_block = 0, laplace_rms = 0;
    int pits = 0, peaks = 0;
};

/// checker_block: RMS over 8×8 blocks of the block-mean of (−1)^(x+y)·(h − mean of 4 axis neighbours).
Metrics metrics(const std::vector<float>& hgt, int w, int h) {
    Metrics m;
    const int B = 8;
    std::vector<double> block(std::size_t((w / B + 1) * (h / B + 1)), 0.0);
    std::vector<int> count(block.size(), 0);
    double sum = 0, l2 = 0;
    std::size_t n = 0;
    for (int y = 1; y < h - 1; ++y)
        for (int x = 1; x < w - 1; ++x) {
            auto at = [&](int xx, int yy) { return double(hgt[std::size_t(yy) * w + xx]); };
            const double c = at(x, y);
            const double lap = c - 0.25 * (at(x - 1, y) + at(x + 1, y) + at(x, y - 1) + at(x, y + 1));
            const double sgn = ((x + y) & 1) ? -1.0 : 1.0;
            sum += sgn * lap;
            l2 += lap * lap;
            ++n;
            const std::size_t b = std::size_t(y / B) * (w / B + 1) + std::size_t(x / B);
            block[b] += sgn * lap;
            ++count[b];
            bool pit = true, peak = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    if (!dx && !dy) continue;
                    pit = pit && c < at(x + dx, y + dy);
                    peak = peak && c > at(x + dx, y + dy);
                }
            m.pits += pit;
            m.peaks += peak;
        }
    m.checker_global = std::abs(sum / double(n));
    double bs = 0;
    int nb = 0;
    for (std::size_t b = 0; b < block.size(); ++b)
        if (count[b]) {
            const double v = block[b] / count[b];
            bs += v * v;
            ++nb;
        }
    m.checker_block = std::sqrt(bs / std::max(nb, 1));
    m.laplace_rms = std::sqrt(l2 / double(n));
    return m;
}

void print(const char* what, const std::vector<float>& hgt, int w, int h) {
    const Metrics m = metrics(hgt, w, h);
    std::printf("%-8s checker(global) %.4g m  checker(8x8 RMS) %.4g m  laplacian RMS %.4g m  pits %d  peaks %d\n", what,
                m.checker_global, m.checker_block, m.laplace_rms, m.pits, m.peaks);
}

}  // namespace

int main(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        const auto eq = a.find('=');
        if (eq == std::string::npos) {
            std::fprintf(stderr, "arguments are key=value\n");
            return 2;
        }
        args[a.substr(0, eq)] = a.substr(eq + 1);
    }
    int n = int(num("n", 513));
    const double cell = num("cell", 10);
    const std::string kind = str("terrain", "ds");
    const std::string out = str("out", "/tmp/ef"), prefix = str("prefix", kind);
    std::vector<float> hgt;
    int w = n, h = n;
    if (kind == "png") {
        const GrayImage img = read_gray_png(str("in", ""));
        w = img.width;
        h = img.height;
        const double low = num("low", 0), high = num("high", 1000), full = img.bits == 16 ? 65535.0 : 255.0;
        hgt.resize(img.samples.size());
        for (std::size_t i = 0; i < hgt.size(); ++i) hgt[i] = float(low + (high - low) * img.samples[i] / full);
    } else {
        hgt.assign(std::size_t(n) * n, 0.0f);
        GridView g{hgt.data(), n, n, cell};
        if (kind == "fault") {
            fault::apply(g, int(num("lines", 1024)), num("displacement", 0.5), std::uint64_t(num("seed", 7)));
        } else {
            diamond_square::Params p;
            p.amplitude = num("amplitude", 400);
            p.roughness = num("roughness", 0.5);
            diamond_square::generate(g, p, std::uint64_t(num("seed", 7)));
        }
    }
    std::filesystem::create_directories(out);
    const std::vector<float> start = hgt;
    write_shade(out + "/" + prefix + "-before.png", hgt, w, h, cell);
    print("input", hgt, w, h);

    GridView g{hgt.data(), w, h, cell};
    if (num("thermal", 0) > 0) {
        thermal::Settings ts;
        ts.neighbourhood = thermal::parse_neighbourhood(str("nb", "moore"));
        ts.talus_slope = std::tan(num("talus", 40) * 3.14159265358979 / 180.0);
        ts.rate = num("trate", 0.5);
        thermal::erode(g, std::int64_t(num("thermal", 0)), ts);
        print("thermal", hgt, w, h);
        write_shade(out + "/" + prefix + "-thermal.png", hgt, w, h, cell);
    }
    const std::vector<float> mid = hgt;
    const int steps = int(num("steps", 0));
    if (steps > 0) {
        const std::size_t size = hgt.size();
        std::vector<float> water(size), sed(size), fw(size), fe(size), fn(size), fs(size), speed(size);
        auto v = [&](std::vector<float>& a) { return GridView{a.data(), w, h, cell}; };
        pipe::State st{g, v(water), v(sed), v(fw), v(fe), v(fn), v(fs), v(speed)};
        pipe::Settings s;
        s.rain = num("rain", s.rain);
        s.evaporation = num("evaporation", s.evaporation);
        s.capacity = num("capacity", s.capacity);
        s.dissolve = num("dissolve", s.dissolve);
        s.deposit = num("deposit", s.deposit);
        s.gravity = num("gravity", s.gravity);
        s.pipe_area = num("pipe_area", s.pipe_area);
        s.min_slope = num("min_slope", s.min_slope);
        s.erosion_depth = num("erosion_depth", s.erosion_depth);
        s.creep = num("creep", s.creep);
        s.boundary = str("boundary", "closed") == "open" ? pipe::Boundary::open : pipe::Boundary::closed;
        const auto t0 = std::chrono::steady_clock::now();
        std::int64_t subs = 0;
        {
            pipe::Solver solver(st, s);
            const double dt = num("dt", 1);
            for (int i = 1; i <= steps; ++i) solver.advance(dt, i);
            solver.finish();
            subs = solver.substeps();
        }
        const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::printf("pipe: %d steps, %lld sub-steps, %.2f s\n", steps, (long long)subs, secs);
        print("pipe", hgt, w, h);
        std::vector<float> eroded(size);
        for (std::size_t i = 0; i < size; ++i) eroded[i] = hgt[i] - mid[i];
        float smax = 0, wmax = 0;
        std::vector<float> sorted = speed;
        std::sort(sorted.begin(), sorted.end());
        smax = std::max(sorted[std::size_t(0.995 * double(size))], 1e-6f);
        sorted = water;
        std::sort(sorted.begin(), sorted.end());
        wmax = std::max(sorted[std::size_t(0.995 * double(size))], 1e-6f);
        std::vector<float> er = eroded;
        for (float& e : er) e = std::abs(e);
        std::sort(er.begin(), er.end());
        const float emax = std::max(er[std::size_t(0.99 * double(size))], 1e-6f);
        {
            // connectivity of the fastest 5% of cells (8-neighbours): a network or a speckle?
            std::vector<float> srt = speed;
            std::sort(srt.begin(), srt.end());
            const float thr = srt[std::size_t(0.95 * double(size))];
            std::vector<int> label(size, -1);
            std::vector<std::size_t> stack;
            std::size_t biggest = 0, total = 0, comps = 0;
            for (std::size_t i = 0; i < size; ++i) {
                if (speed[i] <= thr || label[i] >= 0) continue;
                std::size_t count = 0;
                stack.push_back(i);
                label[i] = int(comps);
                while (!stack.empty()) {
                    const std::size_t j = stack.back();
                    stack.pop_back();
                    ++count;
                    const int x = int(j % w), y = int(j / w);
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            const int nx = x + dx, ny = y + dy;
                            if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                            const std::size_t q = std::size_t(ny) * w + nx;
                            if (speed[q] > thr && label[q] < 0) {
                                label[q] = int(comps);
                                stack.push_back(q);
                            }
                        }
                }
                ++comps;
                total += count;
                biggest = std::max(biggest, count);
            }
            std::printf("fast 5%%: %zu cells in %zu components, largest %zu (%.0f%%), mean size %.1f\n", total, comps,
                        biggest, 100.0 * double(biggest) / double(std::max<std::size_t>(total, 1)),
                        double(total) / double(std::max<std::size_t>(comps, 1)));
        }
        std::printf("flow p99.5 %.3g m/s, water p99.5 %.3g m, |eroded| p99 %.3g m\n", smax, wmax, emax);
        write_layer(out + "/" + prefix + "-flow.png", speed, w, h, smax);
        write_layer(out + "/" + prefix + "-water.png", water, w, h, wmax);
        write_diverging(out + "/" + prefix + "-eroded.png", eroded, w, h, emax);
        write_shade(out + "/" + prefix + "-after.png", hgt, w, h, cell);
        write_shade(out + "/" + prefix + "-after-water.png", hgt, w, h, cell, &water);
    }
    // the panel: every picture side by side, 4 per row
    const int cols = std::min<int>(4, int(panels.size())), rows_n = (int(panels.size()) + cols - 1) / cols;
    std::vector<Rgb> all(std::size_t(w) * cols * h * rows_n, Rgb{1, 1, 1});
    for (std::size_t k = 0; k < panels.size(); ++k) {
        const int ox = int(k % cols) * w, oy = int(k / cols) * h;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                all[std::size_t(oy + y) * (w * cols) + ox + x] = panels[k][std::size_t(y) * w + x];
    }
    write_rgb(out + "/" + prefix + "-panel.png", w * cols, h * rows_n, all, false);
    return 0;
}
