// orogen/grid.hpp — plain views over a grid of float samples.
//
// Every algorithm core in orogen works on these views, never on kernel types,
// so it can be tested and benchmarked without the loader. A view does not own
// its memory. Samples are stored row-major: sample (x, y) is data[y * width + x],
// x grows east, y grows south (image order), as the thesis's heightmap does.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <span>

namespace orogen {

/// A mutable view of `width` × `height` float samples, `cell` metres apart.
struct GridView {
    float* data = nullptr;
    int width = 0;  ///< samples per row (vertices, not tiles)
    int height = 0;  ///< rows
    double cell = 1.0;  ///< distance between neighbouring samples, metres

    std::size_t size() const { return std::size_t(width) * std::size_t(height); }
    float& at(int x, int y) const {
        assert(x >= 0 && x < width && y >= 0 && y < height);
        return data[std::size_t(y) * std::size_t(width) + std::size_t(x)];
    }
    float* row(int y) const { return data + std::size_t(y) * std::size_t(width); }
    std::span<float> span() const { return {data, size()}; }
};

/// A read-only view of `width` × `height` float samples, `cell` metres apart.
struct ConstGridView {
    const float* data = nullptr;
    int width = 0;
    int height = 0;
    double cell = 1.0;

    ConstGridView() = default;
    ConstGridView(const float* d, int w, int h, double c) : data(d), width(w), height(h), cell(c) {}
    ConstGridView(const GridView& v) : data(v.data), width(v.width), height(v.height), cell(v.cell) {}

    std::size_t size() const { return std::size_t(width) * std::size_t(height); }
    float at(int x, int y) const {
        assert(x >= 0 && x < width && y >= 0 && y < height);
        return data[std::size_t(y) * std::size_t(width) + std::size_t(x)];
    }
    const float* row(int y) const { return data + std::size_t(y) * std::size_t(width); }
    std::span<const float> span() const { return {data, size()}; }
};

/// A point in the plane. Meaning of the unit depends on use: grid-relative
/// (0..1 across the grid), sample index, or metres; each API says which.
struct Point2 {
    double x = 0.0;
    double y = 0.0;
    friend bool operator==(const Point2&, const Point2&) = default;
};

}  // namespace orogen
