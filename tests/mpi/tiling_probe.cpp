// A unit test of the kernel's MPI tiling itself (NodeTiling over mpi_comm), not of a whole run: under
// `mpirun -n R*C tiling_probe W H R C`, every rank fills its owned tile with a known function of the
// global coordinates, and checks what the primitives give back against that function:
//   - exchange() of int64, double and float grids (several at once), ghost widths 1-3: every ghost
//     vertex, corners (diagonal neighbours) included, holds the function at its global position, the
//     owned part is unchanged, and the ghosted rectangle stops at the grid's edges;
//   - reduce() sum / min / max over every rank;
//   - carry() east with gather_rows(): each row's sum over the whole grid, carried tile to tile.
// The first wrong value is printed (rank, what, x, y, got, want) and the rank exits 1, so mpirun fails.
// Plain main rather than GoogleTest: every rank checks its own part, and the ranks agree on the outcome.
#include "tiles/mpi_comm.hpp"
#include "tiles/tiles.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

namespace {

using namespace orogen;

/// A value no neighbour could send by accident: distinct for every vertex of grids up to 100003 rows.
std::int64_t f(int x, int y) { return std::int64_t(x) * 100003 + y; }

struct Probe {
    int rank;
    int failures = 0;
    template <typename T>
    void expect(bool ok, const char* what, int x, int y, T got, std::int64_t want) {
        if (ok) return;
        if (failures++ < 5)
            std::fprintf(stderr, "tiling_probe: rank %d, %s at (%d, %d): got %.17g, want %lld\n", rank, what, x, y,
                         double(got), (long long)want);
    }
};

template <typename T>
std::vector<T> filled(const Tiling& t, std::int64_t scale, std::int64_t offset, T ghost) {
    const TileRect g = t.ghosted(), o = t.owned();
    std::vector<T> v(std::size_t(g.width) * std::size_t(g.height), ghost);
    for (int y = o.y0; y < o.y1(); ++y)
        for (int x = o.x0; x < o.x1(); ++x)
            v[std::size_t(y - g.y0) * std::size_t(g.width) + std::size_t(x - g.x0)] = T(f(x, y) * scale + offset);
    return v;
}

template <typename T>
void check_grid(Probe& p, const Tiling& t, const std::vector<T>& v, std::int64_t scale, std::int64_t offset,
                const char* what) {
    const TileRect g = t.ghosted();
    for (int y = g.y0; y < g.y1(); ++y)
        for (int x = g.x0; x < g.x1(); ++x) {
            const T got = v[std::size_t(y - g.y0) * std::size_t(g.width) + std::size_t(x - g.x0)];
            const std::int64_t want = f(x, y) * scale + offset;
            p.expect(got == T(want), what, x, y, got, want);
        }
}

void check_ghosted_rect(Probe& p, const Tiling& t) {
    const TileRect o = t.owned(), g = t.ghosted();
    const int h = t.halo();
    const int want_x0 = std::max(0, o.x0 - h), want_y0 = std::max(0, o.y0 - h);
    const int want_x1 = std::min(t.grid_width(), o.x1() + h), want_y1 = std::min(t.grid_height(), o.y1() + h);
    p.expect(g.x0 == want_x0 && g.y0 == want_y0, "ghosted corner", g.x0, g.y0, 0, std::int64_t(want_x0));
    p.expect(g.x1() == want_x1 && g.y1() == want_y1, "ghosted far corner", g.x1(), g.y1(), 0, std::int64_t(want_x1));
}

void exchanges(Probe& p, TiledRun& run) {
    for (int halo = 1; halo <= 3; ++halo) {
        NodeTiling t(run, halo);
        check_ghosted_rect(p, t);
        // Two int64 grids in one exchange, then a double grid, then two float views.
        auto a = filled<std::int64_t>(t, 1, 0, -1), b = filled<std::int64_t>(t, 3, 7, -1);
        std::int64_t* ints[2] = {a.data(), b.data()};
        t.exchange(std::span<std::int64_t* const>(ints, 2));
        check_grid(p, t, a, 1, 0, "int64 grid 1");
        check_grid(p, t, b, 3, 7, "int64 grid 2");
        auto d = filled<double>(t, 1, -5, std::numeric_limits<double>::quiet_NaN());
        double* doubles[1] = {d.data()};
        t.exchange(std::span<double* const>(doubles, 1));
        check_grid(p, t, d, 1, -5, "double grid");
        // Floats hold whole numbers exactly below 2^24: a smaller function of the coordinates.
        const TileRect g = t.ghosted(), o = t.owned();
        std::vector<float> u(std::size_t(g.width) * std::size_t(g.height), -1.0f), w = u;
        for (int y = o.y0; y < o.y1(); ++y)
            for (int x = o.x0; x < o.x1(); ++x) {
                u[std::size_t(y - g.y0) * std::size_t(g.width) + std::size_t(x - g.x0)] = float(x * 1000 + y);
                w[std::size_t(y - g.y0) * std::size_t(g.width) + std::size_t(x - g.x0)] = float(-(x * 1000 + y));
            }
        const GridView views[2] = {{u.data(), g.width, g.height, 1.0}, {w.data(), g.width, g.height, 1.0}};
        t.exchange(std::span<const GridView>(views, 2));
        for (int y = g.y0; y < g.y1(); ++y)
            for (int x = g.x0; x < g.x1(); ++x) {
                const std::size_t i = std::size_t(y - g.y0) * std::size_t(g.width) + std::size_t(x - g.x0);
                p.expect(u[i] == float(x * 1000 + y), "float view 1", x, y, u[i], x * 1000 + y);
                p.expect(w[i] == float(-(x * 1000 + y)), "float view 2", x, y, w[i], -(x * 1000 + y));
            }
    }
}

void reductions(Probe& p, TiledRun& run) {
    NodeTiling t(run, 1);
    const int R = t.ranks(), r = t.rank();
    std::int64_t v[3] = {r + 1, 10 - r, 3 * r};
    t.reduce(std::span<std::int64_t>(v, 3), Tiling::Reduce::sum);
    p.expect(v[0] == std::int64_t(R) * (R + 1) / 2, "reduce sum", 0, 0, v[0], std::int64_t(R) * (R + 1) / 2);
    p.expect(v[1] == 10LL * R - std::int64_t(R) * (R - 1) / 2, "reduce sum", 1, 0, v[1],
             10LL * R - std::int64_t(R) * (R - 1) / 2);
    const double lo = t.reduce(double(r) - 0.5, Tiling::Reduce::min),
                 hi = t.reduce(double(r) + 0.25, Tiling::Reduce::max);
    p.expect(lo == -0.5, "reduce min", 0, 0, lo, 0);
    p.expect(hi == R - 1 + 0.25, "reduce max", 0, 0, hi, R - 1);
}

void carried_row_sums(Probe& p, TiledRun& run) {
    NodeTiling t(run, 1);
    const TileRect o = t.owned();
    std::vector<double> sums(std::size_t(o.height), 0.0);
    t.carry(Tiling::Toward::east, sums, 1, [&](int first, int count) {
        for (int line = first; line < first + count; ++line)
            for (int x = o.x0; x < o.x1(); ++x) sums[std::size_t(line)] += double(f(x, o.y0 + line));
    });
    const std::vector<double> rows = t.gather_rows(sums, 1);
    const int W = t.grid_width();
    for (int y = 0; y < t.grid_height(); ++y) {
        // Σ_x (100003 x + y) over the whole row.
        const std::int64_t want = 100003LL * W * (W - 1) / 2 + std::int64_t(W) * y;
        p.expect(rows.size() == std::size_t(t.grid_height()) && rows[std::size_t(y)] == double(want), "carried row sum",
                 W, y, rows.size() > std::size_t(y) ? rows[std::size_t(y)] : -1.0, want);
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 5) {
        std::fprintf(stderr, "usage: mpirun -n R*C tiling_probe WIDTH HEIGHT R C\n");
        return 2;
    }
    mpi::Session session(argc, argv);
    const int W = std::atoi(argv[1]), H = std::atoi(argv[2]), R = std::atoi(argv[3]), C = std::atoi(argv[4]);
    const TileSplit split = split_grid(W, H, R, C);
    if (split.count() != session.size()) {
        std::fprintf(stderr, "tiling_probe: %dx%d tiles need %d ranks, mpirun gave %d\n", R, C, split.count(),
                     session.size());
        return 2;
    }
    TiledRun run(split, session.rank());
    Probe p{session.rank()};
    exchanges(p, run);
    reductions(p, run);
    carried_row_sums(p, run);
    // Every rank learns whether any failed, so all exit alike.
    int worst = p.failures > 0 ? 1 : 0;
    mpi::max_all(&worst, 1);
    if (session.rank() == 0)
        std::printf("tiling_probe: %dx%d tiles of a %dx%d grid: %s\n", R, C, W, H,
                    worst ? "FAILED" : "all checks pass");
    return worst;
}
