#include "fault.hpp"

#include <orogen/parallel.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace orogen::fault {

std::vector<Line> random_lines(int width, int height, int count, std::uint64_t seed) {
    std::vector<Line> lines(std::size_t(std::max(0, count)));
    for (int i = 0; i < count; ++i) {
        const double angle = 2.0 * std::numbers::pi * random::uniform(seed, i, 2);
        lines[std::size_t(i)] = {random::uniform(seed, i, 0) * (width - 1), random::uniform(seed, i, 1) * (height - 1),
                                 std::cos(angle), std::sin(angle)};
    }
    return lines;
}

namespace {

/// First column x in [0, width] from which raised() holds along row y, for a
/// line with dy > 0 (raised() is then increasing in x). Exact: the estimate is
/// corrected with the very test raised() applies.
int first_raised(const Line& l, double y, int width) {
    const double x0 = l.ax + (y - l.ay) * l.dx / l.dy;
    double c = std::ceil(x0);
    c = std::clamp(c, 0.0, double(width));
    int x = int(c);
    while (x > 0 && raised(l, x - 1, y)) --x;
    while (x < width && !raised(l, x, y)) ++x;
    return x;
}

/// For dy < 0: first column from which raised() fails (it holds on [0, x)).
int first_lowered(const Line& l, double y, int width) {
    const double x0 = l.ax + (y - l.ay) * l.dx / l.dy;
    double c = std::floor(x0) + 1.0;
    c = std::clamp(c, 0.0, double(width));
    int x = int(c);
    while (x > 0 && !raised(l, x - 1, y)) --x;
    while (x < width && raised(l, x, y)) ++x;
    return x;
}

/// The counts of row y at columns x0 .. x0+count−1 of a `width`-wide grid,
/// into out[0..count): the sign at column x0 summed over the lines, then a
/// difference array over the columns after it. O(lines + count) a row, so a
/// tile pays only for its own columns.
void count_row(std::int32_t* out, std::vector<std::int32_t>& diff, int width, int x0, int count, int y,
               const std::vector<Line>& lines) {
    std::fill(diff.begin(), diff.begin() + std::ptrdiff_t(count) + 1, 0);
    std::int32_t start = 0;  // sign at column x0, summed over lines
    const int x1 = x0 + count;
    for (const Line& l : lines) {
        if (l.dy > 0.0) {  // lowered on [0, x), raised on [x, width)
            const int x = first_raised(l, y, width);
            start += x > x0 ? -1 : 1;
            if (x > x0 && x < x1) diff[std::size_t(x - x0)] += 2;
        } else if (l.dy < 0.0) {  // raised on [0, x), lowered after
            const int x = first_lowered(l, y, width);
            start += x > x0 ? 1 : -1;
            if (x > x0 && x < x1) diff[std::size_t(x - x0)] -= 2;
        } else {
            start += raised(l, 0, y) ? 1 : -1;  // horizontal: the whole row on one side
        }
    }
    std::int32_t running = start;
    for (int i = 0; i < count; ++i) {
        running += diff[std::size_t(i)];
        out[i] = running;
    }
}

}  // namespace

void count_sides(std::vector<std::int32_t>& counts, int width, int height, const std::vector<Line>& lines) {
    counts.assign(std::size_t(width) * std::size_t(height), 0);
    parallel_for(0, height, 16, [&](std::int64_t y0, std::int64_t y1) {
        std::vector<std::int32_t> diff(std::size_t(width) + 1);
        for (std::int64_t y = y0; y < y1; ++y)
            count_row(counts.data() + std::size_t(y) * std::size_t(width), diff, width, 0, width, int(y), lines);
    });
}

void apply(GridView terrain, int iterations, double displacement, std::uint64_t seed) {
    apply_tile(terrain, terrain.width, terrain.height, 0, 0, iterations, displacement, seed);
}

void apply_tile(GridView tile, int grid_width, int grid_height, int x0, int y0, int iterations, double displacement,
                std::uint64_t seed) {
    const std::vector<Line> lines = random_lines(grid_width, grid_height, iterations, seed);
    const float d = float(displacement);
    parallel_for(0, tile.height, 16, [&](std::int64_t t0, std::int64_t t1) {
        std::vector<std::int32_t> diff(std::size_t(tile.width) + 1), row(static_cast<std::size_t>(tile.width));
        for (std::int64_t t = t0; t < t1; ++t) {
            count_row(row.data(), diff, grid_width, x0, tile.width, y0 + int(t), lines);
            float* out = tile.row(int(t));
            for (int x = 0; x < tile.width; ++x) out[x] += d * float(row[std::size_t(x)]);
        }
    });
}

}  // namespace orogen::fault
