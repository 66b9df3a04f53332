// Fault algorithm (Krten; thesis section 3.2).
//
// Each iteration draws a random line through the grid; every vertex p with
// sgn((p − a) × (b − a)) ≥ 0 is raised by `displacement`, every other vertex
// lowered by it. Lines are a random point in the grid and a random direction,
// so which side rises is itself uniformly random and the mean height stays
// where it started (in expectation).
//
// A straight line crosses each row once, so per row a line only changes the
// running sign at one column: a per-row difference array makes the whole run
// O(lines · rows + cells) instead of O(lines · cells).
#pragma once

#include <orogen/grid.hpp>

#include <cstdint>
#include <vector>

namespace orogen::fault {

struct Line {
    double ax, ay;  ///< a point on the line, sample coordinates
    double dx, dy;  ///< direction (b − a)
};

/// The `count` lines a run with `seed` uses (in sample coordinates of a width × height grid).
std::vector<Line> random_lines(int width, int height, int count, std::uint64_t seed);

/// The thesis's side test: true if (p − a) × (b − a) ≥ 0 (the vertex is raised).
inline bool raised(const Line& l, double px, double py) { return (px - l.ax) * l.dy - (py - l.ay) * l.dx >= 0.0; }

/// Per vertex, the number of lines that raise it minus the number that lower it.
/// Exactly what applying raised() to every vertex for every line gives.
void count_sides(std::vector<std::int32_t>& counts, int width, int height, const std::vector<Line>& lines);

/// Add displacement × count_sides(...) to `terrain` (metres).
void apply(GridView terrain, int iterations, double displacement, std::uint64_t seed);

/// apply() on one tile of a grid_width × grid_height grid: `tile` holds the
/// vertices from column x0 and row y0 on. The lines are the whole grid's, so
/// every vertex gets the very bits apply() gives it on the whole grid.
void apply_tile(GridView tile, int grid_width, int grid_height, int x0, int y0, int iterations, double displacement,
                std::uint64_t seed);

}  // namespace orogen::fault
