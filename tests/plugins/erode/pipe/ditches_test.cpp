// Experiment 4.1 of the thesis, as a test: rain on the crooked, pyramid and
// hemispheric surfaces. The thesis reports that Olsen's automaton cut
// uniform ditches there; the pipe model must cut differing ones — ditches of
// unequal depth at unequal spacing where the water gathers — while Olsen's
// automaton (ours, as in the thesis) lowers the slopes evenly.
#include "hydraulic.hpp"
#include "pipe.hpp"
#include "shape.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace {

using namespace orogen;

constexpr int kSize = 129;  // the pipeline uses 257²; half the size keeps the test short

std::vector<float> make(shape::Kind kind) {
    std::vector<float> h(std::size_t(kSize) * kSize);
    shape::ShapeParams p;
    p.kind = kind;
    p.height = 30.0;  // the pipeline's 60 m on 257 cells of 1 m, at half the size
    shape::make_shape(GridView{h.data(), kSize, kSize, 1.0}, p);
    return h;
}

/// Net change of the terrain (m; negative = eroded) after the pipe model with
/// the pipeline's settings.
std::vector<float> pipe_change(const std::vector<float>& start) {
    const std::size_t n = start.size();
    std::vector<float> height = start, water(n), sediment(n), fw(n), fe(n), fn(n), fs(n), speed(n);
    auto g = [](std::vector<float>& v) { return GridView{v.data(), kSize, kSize, 1.0}; };
    pipe::Settings s;
    s.rain = 0.004;
    s.evaporation = 0.0;
    s.capacity = 1.0;
    s.creep = 0.1;
    {
        pipe::Solver solver({g(height), g(water), g(sediment), g(fw), g(fe), g(fn), g(fs), g(speed)}, s);
        for (int i = 1; i <= 600; ++i) solver.advance(0.1, i);
        solver.finish();
    }
    std::vector<float> change(n);
    for (std::size_t i = 0; i < n; ++i) change[i] = height[i] - start[i];
    return change;
}

/// The same for Olsen's automaton (the pipeline's 300 iterations, defaults).
std::vector<float> olsen_change(const std::vector<float>& start) {
    const std::size_t n = start.size();
    std::vector<float> height = start, water(n), sediment(n);
    auto g = [](std::vector<float>& v) { return GridView{v.data(), kSize, kSize, 1.0}; };
    hydraulic::erode({g(height), g(water), g(sediment)}, 300, hydraulic::Settings{});
    std::vector<float> change(n);
    for (std::size_t i = 0; i < n; ++i) change[i] = height[i] - start[i];
    return change;
}

/// Ditches met along a path across the slope: troughs of the change that
/// are local minima over ±2 samples and cut at least 20 % of the path's deepest.
struct Ditches {
    std::vector<double> depth;  // m below the path's median change
    std::vector<double> spacing;  // samples between neighbouring ditches
    double profile_spread = 0.0;  // (max − min) of the change along the path, m
};

double cv(const std::vector<double>& v) {  // coefficient of variation
    if (v.size() < 2) return 0.0;
    double m = 0.0, q = 0.0;
    for (double x : v) m += x / double(v.size());
    for (double x : v) q += (x - m) * (x - m) / double(v.size() - 1);
    return std::sqrt(q) / std::max(std::fabs(m), 1e-12);
}

Ditches ditches_along(const std::vector<float>& change, const std::vector<std::pair<double, double>>& path) {
    std::vector<double> c;
    for (auto [x, y] : path) {
        const int xi = std::clamp(int(std::lround(x)), 0, kSize - 1),
                  yi = std::clamp(int(std::lround(y)), 0, kSize - 1);
        c.push_back(change[std::size_t(yi) * kSize + xi]);
    }
    std::vector<double> sorted = c;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[sorted.size() / 2], deepest = sorted.front();
    Ditches d;
    d.profile_spread = sorted.back() - sorted.front();
    int last = -1;
    for (int i = 2; i + 2 < int(c.size()); ++i) {
        bool trough = true;
        for (int j = i - 2; j <= i + 2; ++j) trough = trough && (j == i || c[i] < c[j]);
        if (!trough || median - c[i] < 0.2 * (median - deepest) || median - c[i] <= 1e-4) continue;
        d.depth.push_back(median - c[i]);
        if (last >= 0) d.spacing.push_back(double(i - last));
        last = i;
    }
    return d;
}

/// A path across the lower slope of each surface, along the contour.
std::vector<std::pair<double, double>> path_for(shape::Kind kind) {
    std::vector<std::pair<double, double>> p;
    const double c = 0.5 * (kSize - 1);
    switch (kind) {
        case shape::Kind::pyramid:  // the south face, 80 % of the way from the apex to its foot
            for (double x = c - 0.7 * c; x <= c + 0.7 * c; x += 1.0) p.emplace_back(x, c + 0.8 * c);
            break;
        case shape::Kind::hemisphere:  // a circle at 85 % of the radius
            for (int i = 0; i < 720; ++i) {
                const double a = 2.0 * std::numbers::pi * i / 720.0;
                p.emplace_back(c + 0.85 * c * std::cos(a), c + 0.85 * c * std::sin(a));
            }
            break;
        default:  // crooked: a row across its southern part, where the ridges end
            for (double x = 2.0; x <= kSize - 3.0; x += 1.0) p.emplace_back(x, 0.75 * (kSize - 1));
            break;
    }
    return p;
}

TEST(Experiment41, PipeModelCutsDifferingDitchesWhereOlsenLowersEvenly) {
    const std::pair<shape::Kind, const char*> shapes[] = {
        {shape::Kind::crooked, "crooked"}, {shape::Kind::pyramid, "pyramid"}, {shape::Kind::hemisphere, "hemisphere"}};
    for (auto [kind, name] : shapes) {
        const auto start = make(kind);
        const Ditches pipe = ditches_along(pipe_change(start), path_for(kind));
        const Ditches olsen = ditches_along(olsen_change(start), path_for(kind));
        ASSERT_FALSE(pipe.depth.empty()) << name << ": the pipe model cut no ditch across the slope";
        const double shallow = *std::min_element(pipe.depth.begin(), pipe.depth.end());
        const double deep = *std::max_element(pipe.depth.begin(), pipe.depth.end());
        std::printf(
            "%-10s pipe: %zu ditches %.3f..%.3f m deep, spacing cv %.2f, profile spread %.3f m | "
            "olsen: %zu ditches, profile spread %.5f m\n",
            name, pipe.depth.size(), shallow, deep, cv(pipe.spacing), pipe.profile_spread, olsen.depth.size(),
            olsen.profile_spread);
        EXPECT_GE(pipe.depth.size(), 3u) << name;
        // Differing: unequal depths, or unequal spacing (uniform ditches would
        // have a depth ratio near 1 and a spacing cv near 0).
        EXPECT_TRUE(deep >= 1.5 * shallow || cv(pipe.spacing) >= 0.5)
            << name << ": ditches " << shallow << ".." << deep << " m deep, spacing cv " << cv(pipe.spacing);
        // Olsen's automaton lowers the same path evenly: no ditch, and a
        // profile flatter than a twentieth of the pipe model's.
        EXPECT_TRUE(olsen.depth.empty()) << name;
        EXPECT_LT(olsen.profile_spread, 0.05 * pipe.profile_spread) << name;
    }
}

}  // namespace
