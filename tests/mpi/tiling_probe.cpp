// A unit test of the kernel's MPI tiling (NodeTiling, kernel/src/tiles), run
// under mpiexec on one split: `tiling_probe ROWSxCOLS WIDTH HEIGHT`. Each rank
// fills its owned tile with a known function of GLOBAL coordinates, then the
// halo exchange (ghost widths 1-3, several grids at once, float, double and
// int64), reduce, carry, fetch_samples, scatter, gather, ranks_meeting and
// send_to_ranks must give every cell exactly that function (or its known
// sum). The first wrong cell is printed (rank, x, y, got, want) and the probe exits 1; a usage error exits 2.
#include "tiles/mpi_comm.hpp"
#include "tiles/tiles.hpp"

#include <orogen/tiles.hpp>
#include <orogen/values.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace {

using orogen::TileRect;
using orogen::Tiling;

/// The value every rank agrees is at global vertex (x, y); exact in float
/// (below 2^24 for grids under 160 columns) and in double and int64.
template <typename T>
T value_at(int x, int y, int salt) {
    return T(std::int64_t(x) * 100003 % 16381 * 1000 + std::int64_t(y) * 7 + salt);
}
template <>
std::int64_t value_at<std::int64_t>(int x, int y, int salt) {
    return std::int64_t(x) * 100003 + y + std::int64_t(salt) * 1000000007;
}

int failures = 0;

template <typename T>
void expect_cell(int rank, const char* what, int x, int y, T got, T want) {
    if (got == want) return;
    if (failures++ == 0)  // the first wrong cell says most; the count comes at the end
        std::fprintf(stderr, "FAIL rank %d %s: cell (x=%d, y=%d) got %.17g want %.17g\n", rank, what, x, y, double(got),
                     double(want));
}

void expect_true(int rank, const char* what, bool ok) {
    if (!ok && failures++ == 0) std::fprintf(stderr, "FAIL rank %d: %s\n", rank, what);
}

/// One exchange of three grids of type T: every cell of each ghosted grid,
/// owned part and ghosts (corners from the diagonal neighbours included),
/// must then hold value_at() of its global coordinate.
template <typename T>
void check_exchange(Tiling& tiling, const char* what) {
    const TileRect own = tiling.owned(), g = tiling.ghosted();
    const int h = tiling.halo();
    // The ghosted rectangle: owned grown by the halo, clipped to the grid (no ghosts past its edge).
    const TileRect want_g{std::max(0, own.x0 - h), std::max(0, own.y0 - h), 0, 0};
    expect_true(tiling.rank(), "ghosted() starts at owned() - halo, clipped at 0",
                g.x0 == want_g.x0 && g.y0 == want_g.y0);
    expect_true(tiling.rank(), "ghosted() ends at owned() + halo, clipped at the grid's edge",
                g.x1() == std::min(tiling.grid_width(), own.x1() + h) &&
                    g.y1() == std::min(tiling.grid_height(), own.y1() + h));
    constexpr int kGrids = 3;
    std::vector<std::vector<T>> grids;
    for (int k = 0; k < kGrids; ++k) {
        std::vector<T> tile(std::size_t(own.width) * std::size_t(own.height));
        for (int y = 0; y < own.height; ++y)
            for (int x = 0; x < own.width; ++x)
                tile[std::size_t(y) * std::size_t(own.width) + std::size_t(x)] = value_at<T>(own.x0 + x, own.y0 + y, k);
        grids.push_back(tiling.ghosted_copy(tile.data()));
    }
    std::vector<T*> pointers;
    for (auto& grid : grids) pointers.push_back(grid.data());
    tiling.exchange(std::span<T* const>(pointers));
    for (int k = 0; k < kGrids; ++k)
        for (int y = 0; y < g.height; ++y)
            for (int x = 0; x < g.width; ++x)
                expect_cell(tiling.rank(), what, g.x0 + x, g.y0 + y,
                            grids[std::size_t(k)][std::size_t(y) * std::size_t(g.width) + std::size_t(x)],
                            value_at<T>(g.x0 + x, g.y0 + y, k));
}

/// reduce(): sums, minima and maxima of every rank's index and tile size.
void check_reduce(Tiling& tiling) {
    const int n = tiling.ranks(), r = tiling.rank();
    const TileRect own = tiling.owned();
    expect_cell(r, "reduce sum of tile areas", 0, 0,
                tiling.reduce<std::int64_t>(std::int64_t(own.width) * own.height, Tiling::Reduce::sum),
                std::int64_t(tiling.grid_width()) * tiling.grid_height());
    expect_cell(r, "reduce sum (double)", 0, 0, tiling.reduce<double>(r + 0.5, Tiling::Reduce::sum),
                n * (n - 1) / 2.0 + 0.5 * n);
    std::vector<float> span_values{float(r), float(-r)};
    tiling.reduce(std::span<float>(span_values), Tiling::Reduce::max);
    expect_cell(r, "reduce max", 0, 0, span_values[0], float(n - 1));
    expect_cell(r, "reduce max", 1, 0, span_values[1], 0.0f);
    expect_cell(r, "reduce min", 0, 0, tiling.reduce<std::int64_t>(r - 7, Tiling::Reduce::min), std::int64_t(-7));
}

/// carry() east and south: a running sum along each whole row (column) of the
/// grid, which each tile continues from its upstream neighbour's.
void check_carry(Tiling& tiling) {
    const TileRect own = tiling.owned();
    const int r = tiling.rank();
    std::vector<double> rows(std::size_t(own.height), 0.0);
    tiling.carry(Tiling::Toward::east, rows, 1, [&](int first, int count) {
        for (int y = first; y < first + count; ++y)
            for (int x = own.x0; x < own.x1(); ++x) rows[std::size_t(y)] += value_at<double>(x, own.y0 + y, 0);
    });
    for (int y = 0; y < own.height; ++y) {
        double want = 0.0;  // the sum of the row up to this tile's east edge, in the same order
        for (int x = 0; x < own.x1(); ++x) want += value_at<double>(x, own.y0 + y, 0);
        expect_cell(r, "carry east", own.x1() - 1, own.y0 + y, rows[std::size_t(y)], want);
    }
    std::vector<double> columns(std::size_t(own.width), 0.0);
    tiling.carry(Tiling::Toward::north, columns, 1, [&](int first, int count) {
        for (int x = first; x < first + count; ++x)
            for (int y = own.y1() - 1; y >= own.y0; --y) columns[std::size_t(x)] += value_at<double>(own.x0 + x, y, 1);
    });
    for (int x = 0; x < own.width; ++x) {
        double want = 0.0;  // from the grid's south edge up to this tile's north edge
        for (int y = tiling.grid_height() - 1; y >= own.y0; --y) want += value_at<double>(own.x0 + x, y, 1);
        expect_cell(r, "carry north", own.x0 + x, own.y0, columns[std::size_t(x)], want);
    }
}

/// fetch_samples(), scatter_from_rank0() and the run's gather(): whole-grid
/// values read back through the tiles.
void check_moving(Tiling& tiling, orogen::TiledRun& run) {
    const TileRect own = tiling.owned();
    const int r = tiling.rank(), w = tiling.grid_width(), h = tiling.grid_height();
    std::vector<float> mine(std::size_t(own.width) * std::size_t(own.height));
    for (int y = 0; y < own.height; ++y)
        for (int x = 0; x < own.width; ++x)
            mine[std::size_t(y) * std::size_t(own.width) + std::size_t(x)] = value_at<float>(own.x0 + x, own.y0 + y, 2);
    // A lattice every 3rd column from rank-dependent starts, keeping the far edges.
    const orogen::AxisSamples columns{r % 3, 3, (w - 1 - r % 3) / 3, w - 1}, rows{0, 2, (h - 1) / 2, h - 1};
    const std::vector<float> got = tiling.fetch_samples(mine.data(), columns, rows);
    expect_true(r, "fetch_samples size", got.size() == std::size_t(columns.size()) * std::size_t(rows.size()));
    for (int j = 0; j < rows.size() && failures == 0; ++j)
        for (int i = 0; i < columns.size(); ++i)
            expect_cell(r, "fetch_samples", columns.at(i), rows.at(j),
                        got[std::size_t(j) * std::size_t(columns.size()) + std::size_t(i)],
                        value_at<float>(columns.at(i), rows.at(j), 2));
    std::unique_ptr<orogen::Heightmap> whole;
    if (r == 0) {
        whole = std::make_unique<orogen::Heightmap>(w, h, 1.0);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                whole->heights()[std::size_t(y) * std::size_t(w) + std::size_t(x)] = value_at<float>(x, y, 3);
    }
    const auto tile = tiling.scatter_from_rank0(whole.get());
    expect_true(r, "scatter_from_rank0 tile size", tile->width() == own.width && tile->height() == own.height);
    for (int y = 0; y < own.height && failures == 0; ++y)
        for (int x = 0; x < own.width; ++x)
            expect_cell(r, "scatter_from_rank0", own.x0 + x, own.y0 + y,
                        tile->heights()[std::size_t(y) * std::size_t(own.width) + std::size_t(x)],
                        value_at<float>(own.x0 + x, own.y0 + y, 3));
    const orogen::Heightmap mine_map(own.width, own.height, 1.0, mine);
    const auto gathered = run.gather(&mine_map);
    if (r != 0) return;
    expect_true(r, "gather size on rank 0", gathered && gathered->width() == w && gathered->height() == h);
    for (int y = 0; y < h && failures == 0; ++y)
        for (int x = 0; x < w; ++x)
            expect_cell(r, "gather", x, y, gathered->heights()[std::size_t(y) * std::size_t(w) + std::size_t(x)],
                        value_at<float>(x, y, 2));
}

/// ranks_meeting() against every tile's rectangle, and send_to_ranks(): rank s sends rank d a message of
/// (s·7 + d) % 5 values (none at all for some pairs, so only some travel), each a known function of (s, d, i),
/// and every rank must get exactly those, from every rank, in rank order (its own message to itself included).
void check_routing(Tiling& tiling) {
    const int r = tiling.rank(), n = tiling.ranks(), w = tiling.grid_width(), h = tiling.grid_height();
    for (const TileRect probe :
         {TileRect{-3, -3, 5, 5}, TileRect{w / 2 - 2, h / 2 - 3, 4, 7}, TileRect{0, 0, w, h},
          TileRect{w - 1, h - 1, 9, 9}, TileRect{w, 0, 4, 4}, TileRect{3, 2, 0, 5}, TileRect{r, r, 2 * r + 1, 3}}) {
        std::vector<int> want;
        for (int k = 0; k < n; ++k) {
            const TileRect t = tiling.tile(k);
            const int x0 = std::max({probe.x0, t.x0, 0}), x1 = std::min({probe.x1(), t.x1(), w});
            const int y0 = std::max({probe.y0, t.y0, 0}), y1 = std::min({probe.y1(), t.y1(), h});
            if (x0 < x1 && y0 < y1) want.push_back(k);
        }
        expect_true(r, "ranks_meeting lists the tiles a rectangle meets", tiling.ranks_meeting(probe) == want);
    }
    auto count = [](int from, int to) { return (from * 7 + to) % 5; };
    auto value = [](int from, int to, int i) { return std::int64_t(from) * 1000003 + to * 1009 + i; };
    std::vector<std::string> out(static_cast<std::size_t>(n));
    for (int d = 0; d < n; ++d)
        for (int i = 0; i < count(r, d); ++i) {
            const std::int64_t v = value(r, d, i);
            out[std::size_t(d)].append(reinterpret_cast<const char*>(&v), sizeof v);
        }
    const std::vector<std::string> in = tiling.send_to_ranks(out);
    expect_true(r, "send_to_ranks returns one message per rank", in.size() == std::size_t(n));
    for (int s = 0; s < n && failures == 0 && in.size() == std::size_t(n); ++s) {
        const std::string& got = in[std::size_t(s)];
        expect_true(r, "send_to_ranks message size", got.size() == std::size_t(count(s, r)) * sizeof(std::int64_t));
        for (int i = 0; i < count(s, r) && failures == 0; ++i) {
            std::int64_t v = 0;
            std::memcpy(&v, got.data() + std::size_t(i) * sizeof v, sizeof v);
            expect_cell(r, "send_to_ranks (x = sender, y = value index)", s, i, v, value(s, r, i));
        }
    }
}

int probe(int rows, int cols, int width, int height, int rank) {
    orogen::TiledRun run(orogen::split_grid(width, height, rows, cols), rank);
    for (int halo = 1; halo <= 3; ++halo) {
        orogen::NodeTiling tiling(run, halo);
        const std::string what = "exchange halo " + std::to_string(halo);
        check_exchange<float>(tiling, (what + " float").c_str());
        check_exchange<double>(tiling, (what + " double").c_str());
        check_exchange<std::int64_t>(tiling, (what + " int64").c_str());
    }
    orogen::NodeTiling tiling(run, 1);
    check_reduce(tiling);
    check_carry(tiling);
    check_moving(tiling, run);
    check_routing(tiling);
    // Every rank learns whether any failed, so the exit codes agree.
    return run.agree(failures ? 1 : 0);
}

}  // namespace

int main(int argc, char** argv) {
    int rows = 0, cols = 0, width = 0, height = 0;
    if (argc != 4 || std::sscanf(argv[1], "%dx%d", &rows, &cols) != 2 || (width = std::atoi(argv[2])) < 1 ||
        (height = std::atoi(argv[3])) < 1) {
        std::fprintf(stderr, "usage: mpiexec -n R*C tiling_probe RxC WIDTH HEIGHT\n");
        return 2;
    }
    try {
        orogen::mpi::Session session(argc, argv);
        if (session.size() != rows * cols) {
            std::fprintf(stderr, "tiling_probe: %d ranks for a %dx%d split\n", session.size(), rows, cols);
            return 2;
        }
        const int code = probe(rows, cols, width, height, session.rank());
        if (code == 0 && session.rank() == 0)
            std::printf("tiling_probe %dx%d on %dx%d: every cell as expected\n", rows, cols, width, height);
        if (failures) std::fprintf(stderr, "rank %d: %d wrong cells or checks\n", session.rank(), failures);
        return code;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "tiling_probe: %s\n", e.what());
        orogen::mpi::abort_all(1);
    }
}
