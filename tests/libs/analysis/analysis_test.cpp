// orogen_analysis on surfaces whose figures are known: a plane's slope, a cone's hypsometric integral
// of 1/3, spectral surfaces of prescribed β, rivers at stream-power steady state (θ = m/n,
// k_s = (U/K)^(1/n)), pits, local relief, valleys of known sections, nodata and terrains too small for a
// figure; the FFT
// against the naive DFT; the same bits for any thread count.
#include <orogen/analysis/compare.hpp>
#include <orogen/analysis/fft.hpp>
#include <orogen/analysis/figures.hpp>

#ifdef OROGEN_HAVE_LANDSCAPE
#include <orogen/landscape/stream_power.hpp>
#endif

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <complex>
#include <cstdint>
#include <numbers>
#include <vector>

namespace {

using namespace orogen::analysis;
using enum FigureId;

/// A uniform number in [0, 1) from a counter (splitmix64): the same sequence everywhere.
double uniform(std::uint64_t i) {
    std::uint64_t z = i * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E5Bull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * 0x1.0p-53;
}

std::vector<float> field(int w, int h, auto&& f) {
    std::vector<float> z(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) z[std::size_t(y) * std::size_t(w) + std::size_t(x)] = float(f(x, y));
    return z;
}

constexpr double degrees = 180.0 / std::numbers::pi;

// ------------------------------------------------------------------ FFT

std::vector<std::complex<double>> naive_dft(const std::vector<std::complex<double>>& x, bool inverse) {
    const std::size_t n = x.size();
    std::vector<std::complex<double>> out(n);
    for (std::size_t k = 0; k < n; ++k) {
        std::complex<double> sum = 0.0;
        for (std::size_t j = 0; j < n; ++j)
            sum += x[j] * std::polar(1.0, (inverse ? 2.0 : -2.0) * std::numbers::pi * double((j * k) % n) / double(n));
        out[k] = inverse ? sum / double(n) : sum;
    }
    return out;
}

TEST(Fft, EveryLengthMatchesTheNaiveDftBothWays) {
    // Powers of two (radix-2), primes, and composites (Bluestein), including the reference DEMs' odd sides.
    for (std::size_t n : {1, 2, 3, 4, 5, 7, 8, 12, 17, 31, 64, 100, 127, 250, 647}) {
        std::vector<std::complex<double>> x(n);
        for (std::size_t j = 0; j < n; ++j) x[j] = {uniform(2 * j + n) - 0.5, uniform(2 * j + 1 + n) - 0.5};
        const Fft fft(n);
        for (bool inverse : {false, true}) {
            auto y = x;
            fft.transform(y, inverse);
            const auto expected = naive_dft(x, inverse);
            double worst = 0.0, scale = 0.0;
            for (std::size_t k = 0; k < n; ++k)
                worst = std::max(worst, std::abs(y[k] - expected[k])), scale = std::max(scale, std::abs(expected[k]));
            EXPECT_LT(worst, 1e-11 * std::max(scale, 1.0)) << "n = " << n << (inverse ? " inverse" : " forward");
        }
        auto round_trip = x;
        fft.transform(round_trip);
        fft.transform(round_trip, true);
        for (std::size_t j = 0; j < n; ++j) EXPECT_NEAR(std::abs(round_trip[j] - x[j]), 0.0, 1e-12) << "n = " << n;
    }
}

TEST(Fft, TwoDimensionalOfAProductIsTheProductOfTransforms) {
    // x[y][x] = a[x]·b[y] transforms to A[u]·B[v]: rows and columns both done, neither twice.
    const std::size_t w = 12, h = 9;
    std::vector<std::complex<double>> a(w), b(h), grid(w * h);
    for (std::size_t i = 0; i < w; ++i) a[i] = uniform(100 + i);
    for (std::size_t i = 0; i < h; ++i) b[i] = uniform(200 + i);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) grid[y * w + x] = a[x] * b[y];
    fft2(grid, w, h);
    const auto fa = naive_dft(a, false), fb = naive_dft(b, false);
    for (std::size_t v = 0; v < h; ++v)
        for (std::size_t u = 0; u < w; ++u) EXPECT_NEAR(std::abs(grid[v * w + u] - fa[u] * fb[v]), 0.0, 1e-10);
}

// --------------------------------------------------------- slopes, hypsometry

TEST(Figures, APlaneHasOneSlopeEverywhereEdgesIncluded) {
    // z = 0.3 x + 0.4 y (in metres): |grad z| = 0.5, slope atan(0.5) = 26.565° at every sample, the
    // edges' one-sided differences included; half the relief lies above the mean height.
    const int w = 40, h = 30;
    const double cell = 25.0;
    const auto z = field(w, h, [&](int x, int y) { return 0.3 * x * cell + 0.4 * y * cell; });
    const Figures f = measure({z.data(), w, h, cell});
    const double expected = std::atan(0.5) * degrees;
    EXPECT_NEAR(f[slope_mean].value, expected, 1e-4);
    EXPECT_NEAR(f[slope_median].value, expected, 1e-4);
    EXPECT_NEAR(f[slope_p90].value, expected, 1e-4);
    EXPECT_EQ(f[steeper_30].value, 0.0);
    EXPECT_EQ(f[steeper_40].value, 0.0);
    EXPECT_NEAR(f.slope_histogram[26], 1.0, 1e-12) << "every sample in the [26°, 27°) bin";
    EXPECT_NEAR(f[hypsometric_integral].value, 0.5, 1e-6);
    EXPECT_EQ(f[pits].value, 0.0);
    EXPECT_NEAR(f[curvature_spread].value, 0.0, 1e-6);
    EXPECT_EQ(f.samples, std::size_t(w * h));
    EXPECT_EQ(f.nodata, 0u);
}

TEST(Figures, ASteepPlaneIsAllAboveFortyDegrees) {
    const int w = 20, h = 20;
    const auto z = field(w, h, [](int x, int) { return 1.5 * x * 10.0; });  // 56.3°
    const Figures f = measure({z.data(), w, h, 10.0});
    EXPECT_EQ(f[steeper_30].value, 100.0);
    EXPECT_EQ(f[steeper_40].value, 100.0);
    EXPECT_NEAR(f[slope_p90].value, std::atan(1.5) * degrees, 1e-4);
}

TEST(Figures, SlopePercentilesInterpolateAsNumpy) {
    // Two rows of z = 0, 1, 11, 21 m, 10 m apart: gx = 0.1 (one-sided), 0.55, 1.0 (central), 1.0
    // (one-sided), gy = 0. Of the 8 sorted slopes numpy.percentile(s, 50) interpolates halfway
    // between the 4th and 5th, percentile 90 at rank 0.9·7 = 6.3.
    const std::vector<float> z = {0, 1, 11, 21, 0, 1, 11, 21};
    const Figures f = measure({z.data(), 4, 2, 10.0});
    const double s0 = std::atan(0.1) * degrees, s1 = std::atan(0.55) * degrees, s2 = 45.0;
    EXPECT_NEAR(f[slope_median].value, 0.5 * (s1 + s2), 1e-9);
    EXPECT_NEAR(f[slope_p90].value, s2, 1e-9);
    EXPECT_NEAR(f[slope_mean].value, (s0 + s1 + 2.0 * s2) / 4.0, 1e-9);
    EXPECT_EQ(f[steeper_40].value, 50.0);
}

TEST(Figures, AConeHasAHypsometricIntegralOfOneThird) {
    // z = H (1 − r/R) over the disc r ≤ R (the rest masked as nodata): mean height H/3.
    const int n = 401;
    const double R = 200.0;
    std::vector<std::uint8_t> valid(std::size_t(n) * n);
    const auto z = field(n, n, [&](int x, int y) {
        const double r = std::hypot(x - 200.0, y - 200.0);
        valid[std::size_t(y) * n + std::size_t(x)] = r <= R;
        return 1000.0 * (1.0 - r / R);
    });
    const Figures f = measure({z.data(), n, n, 10.0, valid.data()});
    EXPECT_NEAR(f[hypsometric_integral].value, 1.0 / 3.0, 0.005);
    EXPECT_GT(f.nodata, std::size_t(n) * n / 5) << "the corners outside the disc are nodata";
    EXPECT_EQ(f.samples + f.nodata, std::size_t(n) * n);
    // The curve: share of the area above relative height h is (1 − h)² on a cone.
    ASSERT_EQ(f.hypsometric_area.size(), 101u);
    EXPECT_NEAR(f.hypsometric_area[50], 0.25, 0.01);
    EXPECT_NEAR(f.hypsometric_area[0], 1.0, 1e-12);
    // Slopes are 1000 m / 2000 m = 0.5 everywhere inside (the apex and the rim aside).
    EXPECT_NEAR(f[slope_median].value, std::atan(0.5) * degrees, 0.05);
}

// -------------------------------------------------------------- spectrum

/// A surface whose power spectrum is k^(−β): random phases, amplitude k^(−β/2), the real part of the
/// inverse transform.
std::vector<float> spectral_surface(int n, double beta, std::uint64_t seed) {
    std::vector<std::complex<double>> s(std::size_t(n) * std::size_t(n));
    for (int v = 0; v < n; ++v)
        for (int u = 0; u < n; ++u) {
            const int fu = u < (n + 1) / 2 ? u : u - n, fv = v < (n + 1) / 2 ? v : v - n;
            const double k = std::hypot(double(fu), double(fv));
            if (k == 0.0) continue;
            const double phase = 2.0 * std::numbers::pi * uniform(seed * 1'000'003 + std::uint64_t(v) * n + u);
            s[std::size_t(v) * n + std::size_t(u)] = std::polar(std::pow(k, -beta / 2.0), phase);
        }
    fft2(s, std::size_t(n), std::size_t(n), true);
    double peak = 0.0;
    for (const auto& c : s) peak = std::max(peak, std::abs(c.real()));
    std::vector<float> z(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) z[i] = float(1000.0 * s[i].real() / peak);
    return z;
}

TEST(Figures, ASpectralSurfaceHasItsPrescribedBeta) {
    for (const auto& [n, beta] : {std::pair{256, 2.0}, std::pair{250, 3.0}, std::pair{200, 4.0}}) {
        const auto z = spectral_surface(n, beta, std::uint64_t(n));
        const Figures f = measure({z.data(), n, n, 30.0});
        EXPECT_NEAR(f[spectral_exponent].value, beta, 0.15) << n << "² with β = " << beta;
        EXPECT_EQ(f.spectrum_side, n);
        EXPECT_EQ(f.spectrum_k.size(), std::size_t(n / 2));
        EXPECT_EQ(f.spectrum_fit.points, std::size_t(n / 4 - 3));
    }
}

TEST(Figures, WhiteNoiseHasAFlatSpectrum) {
    const int n = 128;
    const auto z = field(n, n, [](int x, int y) { return 100.0 * uniform(std::uint64_t(y) * 128 + x); });
    EXPECT_NEAR(measure({z.data(), n, n, 30.0})[spectral_exponent].value, 0.0, 0.3);
}

// --------------------------------------------------------------- drainage

TEST(Figures, ParallelRiversAtSteadyStateGiveTheirConcavityAndSteepness) {
    // Rivers down every column to the south edge: the cell in row y drains the y + 1 cells above and
    // itself, A = (y + 1)·cell², and its height is built from the south edge up so that its slope to
    // the cell below is exactly k_s A^(−θ) (stream power's steady state, θ = m/n).
    const int w = 5, h = 120;
    const double cell = 200.0, ks = 50.0, theta = 0.45;
    std::vector<double> column(h, 0.0);
    for (int y = h - 2; y >= 0; --y)
        column[std::size_t(y)] = column[std::size_t(y + 1)] + ks * std::pow((y + 1) * cell * cell, -theta) * cell;
    const auto z = field(w, h, [&](int, int y) { return column[std::size_t(y)]; });
    const Figures f = measure({z.data(), w, h, cell});
    EXPECT_NEAR(f[concavity].value, theta, 2e-3);  // float heights: ~1e-7 relative
    EXPECT_NEAR(f[steepness].value, ks, 0.01 * ks);
    // A channel that never widens has length ∝ area: Hack's exponent 1.
    EXPECT_NEAR(f[hack_exponent].value, 1.0, 0.05);
    // Network (A > 0.1 km²): rows 2 … 118 of each column, each 200 m to its receiver, over 120 rows.
    EXPECT_NEAR(f[drainage_density].value, 117.0 * cell / (120.0 * cell * cell) * 1000.0, 1e-9);
    EXPECT_NEAR(f[network_share].value, 100.0 * 118.0 / 120.0, 1e-9);
    // Off the network: rows 0 (400 m to row 2) and 1 (200 m).
    EXPECT_NEAR(f[hillslope_length].value, 300.0, 1e-9);
    // Every 1 km reach of these channels is straight.
    EXPECT_NEAR(f[channel_sinuosity].value, 1.0, 1e-12);
    ASSERT_FALSE(f.slope_area.x.empty());
    for (std::size_t b = 0; b < f.slope_area.x.size(); ++b) EXPECT_GT(f.slope_area.y[b], 0.0);
}

TEST(Figures, FilledFlatsAreLeftOutOfTheSlopeAreaFits) {
    // One river down the middle column between walls 1000 m high that drain into it (the cell in row y
    // drains 3(y + 1) cells), at stream power's steady state, with a lake dug into rows 60–69 5 m below its
    // outlet. The priority flood fills the lake to a surface sloping 1e-4 (ε = 1e-4·cell a cell), which the
    // test S > 1e-4 takes or not by rounding. Without the filled cells the fit is the least-squares line
    // over the others exactly, the drop into the lake included.
    const int w = 3, h = 120;
    const double cell = 200.0, ks = 50.0, theta = 0.45;
    std::vector<double> column(h, 0.0);
    for (int y = h - 2; y >= 0; --y)
        column[std::size_t(y)] = column[std::size_t(y + 1)] + ks * std::pow(3.0 * (y + 1) * cell * cell, -theta) * cell;
    for (int y = 60; y < 70; ++y) column[std::size_t(y)] = column[70] - 5.0;
    const auto z = field(w, h, [&](int x, int y) { return column[std::size_t(y)] + (x == 1 ? 0.0 : 1000.0); });
    // That is the default; fit_filled_cells = true is terrain_stats.py's.
    const Figures f = measure({z.data(), w, h, cell});
    ASSERT_TRUE(f[concavity].ok()) << f[concavity].why_not;
    EXPECT_FALSE(Options{}.fit_filled_cells);

    // The channel cells (A > 1 km²) of the river, but the lake's: S to the cell below, on the filled heights.
    const double eps = 1e-4 * cell;
    auto filled = [&](int y) {
        return y >= 60 && y < 70 ? double(z[std::size_t(70 * w + 1)]) + (70 - y) * eps
                                 : double(z[std::size_t(y * w + 1)]);
    };
    std::vector<double> la, ls;
    for (int y = 0; y + 1 < h; ++y) {
        const double area = 3.0 * (y + 1) * cell * cell;
        if (area <= 1e6 || (y >= 60 && y < 70)) continue;
        la.push_back(std::log(area));
        ls.push_back(std::log((filled(y) - filled(y + 1)) / cell));
    }
    double ma = 0.0, ms = 0.0, sas = 0.0, saa = 0.0;
    for (std::size_t k = 0; k < la.size(); ++k) ma += la[k] / double(la.size()), ms += ls[k] / double(la.size());
    for (std::size_t k = 0; k < la.size(); ++k) sas += (la[k] - ma) * (ls[k] - ms), saa += (la[k] - ma) * (la[k] - ma);
    EXPECT_EQ(f.slope_area_fit.points, la.size());
    EXPECT_NEAR(f[concavity].value, -sas / saa, 1e-9);
    // The lake's cells are in the other fit only as far as rounding lets them (0 … 10 of them), and nothing
    // else changes.
    Options o;
    o.fit_filled_cells = true;
    const Figures all = measure({z.data(), w, h, cell}, o);
    EXPECT_GE(all.slope_area_fit.points, la.size());
    EXPECT_LE(all.slope_area_fit.points, la.size() + 10);
    EXPECT_EQ(f[slope_p90].value, all[slope_p90].value);
    EXPECT_EQ(f[drainage_density].value, all[drainage_density].value);
}
TEST(Figures, AWindingChannelIsSinuousAndAStraightOneIsNot) {
    // One channel winding down a maze: east along row 1, down at the east end, west along row 3, down at
    // the west end, ... (the rows between are walls 5 km high), falling 1 m a cell, out at the bottom right
    // corner. D8 cuts each bend's corners with diagonals, but a 1 km reach over a bend still doubles back.
    const int w = 41, h = 21;
    std::vector<float> z(std::size_t(w) * h, 5000.0f);
    std::vector<std::pair<int, int>> path;
    for (int row = 1; row < h; row += 2) {
        const bool east = (row / 2) % 2 == 0;
        for (int k = 0; k < w - 2; ++k) path.emplace_back(east ? 1 + k : w - 2 - k, row);
        if (row + 2 < h) path.emplace_back(east ? w - 2 : 1, row + 1);
    }
    path.emplace_back(w - 1, path.back().second);  // the outlet, on the east edge
    for (std::size_t k = 0; k < path.size(); ++k)
        z[std::size_t(path[k].second) * w + std::size_t(path[k].first)] = float(2000.0 - double(k));
    const Figures winding = measure({z.data(), w, h, 100.0});
    ASSERT_TRUE(winding[channel_sinuosity].ok()) << winding[channel_sinuosity].why_not;
    EXPECT_GT(winding[channel_sinuosity].value, 1.2);
    EXPECT_LT(winding[channel_sinuosity].value, 3.0);
    // The same channel's last row alone, straight: sinuosity 1.
    std::vector<float> straight(std::size_t(w) * h, 5000.0f);
    for (int x = 0; x < w; ++x) straight[std::size_t(h / 2) * w + std::size_t(x)] = float(1000.0 - 20.0 * x);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (y != h / 2)
                straight[std::size_t(y) * w + std::size_t(x)] = float(1000.0 - 20.0 * x + 300.0 * std::abs(y - h / 2));
    const Figures line = measure({straight.data(), w, h, 100.0});
    ASSERT_TRUE(line[channel_sinuosity].ok()) << line[channel_sinuosity].why_not;
    EXPECT_NEAR(line[channel_sinuosity].value, 1.0, 1e-12);
}

// ----------------------------------------------------------------- valleys

/// A straight valley running south down the middle column of a w × h grid (30 m cells), falling `fall` m/m
/// (steeper than 6°, so its cells count), its cross-section `rise(d, y)` metres d ≥ 0 cells from the river.
/// Its sides drain straight across into the river: the river at row y drains rows 0 … y.
std::vector<float> valley(int w, int h, double fall, auto&& rise) {
    return field(w, h, [&](int x, int y) { return 4000.0 - 30.0 * fall * y + rise(std::abs(x - w / 2), y); });
}

TEST(Figures, AVValleyHasTheWidthAndCurvatureOfItsWalls) {
    // Walls at 30°: 10 m above the river at 10 / tan 30° = 17.3 m to either side (34.6 m across), the
    // Laplacian at the river 2·tan 30° / 30 m (38.5 /km), the same width at every drainage area.
    const int w = 201, h = 401;
    const double wall = std::tan(30.0 / degrees);
    const auto z = valley(w, h, 0.15, [&](int d, int) { return 30.0 * wall * d; });
    const Figures f = measure({z.data(), w, h, 30.0});
    ASSERT_TRUE(f[channel_curvature].ok()) << f[channel_curvature].why_not;
    EXPECT_NEAR(f[channel_curvature].value, 2.0 * wall / 30.0 * 1000.0, 0.01);
    ASSERT_TRUE(f[valley_width].ok()) << f[valley_width].why_not;
    EXPECT_NEAR(f[valley_width].value, 2.0 * 10.0 / wall, 1e-3);
    ASSERT_EQ(f.valley_section.size(), 9u);
    EXPECT_NEAR(f.valley_section[4], 4 * 30.0 * wall, 1e-3);
    ASSERT_TRUE(f[valley_widening].ok()) << f[valley_widening].why_not;
    EXPECT_NEAR(f[valley_widening].value, 0.0, 1e-6);
    EXPECT_GE(f.valley_widths.x.size(), 3u);
}

TEST(Figures, AValleyWidthInterpolatesBetweenSamplesAtTheRiseAsked) {
    // Lower walls at 20° to 3 cells out, then 40°: 50 m above the river (Options::valley_rise) at
    // 3 + (50 − 32.8) / 25.2 cells, linear between the samples as the section is.
    const int w = 201, h = 401;
    const double lower = 30.0 * std::tan(20.0 / degrees), upper = 30.0 * std::tan(40.0 / degrees);
    const auto z = valley(w, h, 0.11, [&](int d, int) { return d <= 3 ? lower * d : 3 * lower + upper * (d - 3); });
    Options o;
    o.valley_rise = 50.0;
    const Figures f = measure({z.data(), w, h, 30.0}, o);
    ASSERT_TRUE(f[valley_width].ok()) << f[valley_width].why_not;
    EXPECT_NEAR(f[valley_width].value, 2.0 * 30.0 * (3.0 + (50.0 - 3.0 * lower) / upper), 1e-3);
    // The default rise (10 m) falls on the lower walls.
    EXPECT_NEAR(measure({z.data(), w, h, 30.0})[valley_width].value, 2.0 * 30.0 * 10.0 / lower, 1e-3);
}

TEST(Figures, AValleyWideningDownstreamAsAPowerOfAreaGivesItsExponent) {
    // Walls gentler downstream, tan α ∝ A^−0.2 with A = (y + 1)·w·cell² the river's drainage area at
    // row y: the width 2·10 m / tan α grows as A^0.2. A narrow grid, so that the walls, gentler a row
    // down, drain straight across (A is the rows' count) rather than down-valley first.
    const int w = 41, h = 2001;
    const double b = 0.2, a0 = 1e6;
    auto tan_wall = [&](int y) { return std::min(1.0, std::pow((y + 1) * w * 900.0 / a0, -b)); };
    const auto z = valley(w, h, 0.15, [&](int d, int y) { return 30.0 * tan_wall(y) * d; });
    const Figures f = measure({z.data(), w, h, 30.0});
    ASSERT_TRUE(f[valley_widening].ok()) << f[valley_widening].why_not;
    EXPECT_NEAR(f[valley_widening].value, b, 0.02);
    ASSERT_GE(f.valley_widths.x.size(), 3u);
    for (std::size_t k = 1; k < f.valley_widths.y.size(); ++k)
        EXPECT_GT(f.valley_widths.y[k], f.valley_widths.y[k - 1]) << "wider downstream";
}

TEST(Figures, ValleyFiguresSayWhyTheyCannotBeMeasured) {
    // A valley falling 5 % (under 6°): no channel cell for the curvature, but its width is measured (a
    // floodplain's counts), 10 m up at 10 / 3 cells from the river.
    const int w = 201, h = 401;
    const auto gentle = valley(w, h, 0.05, [](int d, int) { return 3.0 * d; });
    const Figures f = measure({gentle.data(), w, h, 30.0});
    EXPECT_EQ(f[channel_curvature].why_not, "no channel cell (draining more than 1 km²) slopes more than 6°");
    ASSERT_TRUE(f[valley_width].ok()) << f[valley_width].why_not;
    EXPECT_NEAR(f[valley_width].value, 2.0 * 30.0 * 10.0 / 3.0, 1e-3);
    // 8 cells out the walls stand 160 m above the river: asked for the width 200 m up, wider than the reach.
    const auto broad = valley(w, h, 0.15, [](int d, int) { return 20.0 * d; });
    Options high;
    high.valley_rise = 200.0;
    const Figures g = measure({broad.data(), w, h, 30.0}, high);
    EXPECT_TRUE(g[channel_curvature].ok());
    EXPECT_EQ(g[valley_width].why_not,
              "the valleys are wider than 480 m: 240 m from the river they stand 160.0 m above it");
    // A valley too short to have three quarter decades of area with 30 channel cells each.
    // (And one narrower than its reach: no section at all.)
    const auto narrow = valley(15, 401, 0.15, [](int d, int) { return 20.0 * d; });
    EXPECT_EQ(measure({narrow.data(), 15, 401, 30.0})[valley_width].why_not,
              "no channel cell (draining more than 1 km²) has 8 measured samples on both sides across it");
    const auto short_valley = valley(201, 40, 0.15, [](int d, int) { return 20.0 * d; });
    const Figures s = measure({short_valley.data(), 201, 40, 30.0});
    EXPECT_TRUE(s[valley_width].ok()) << s[valley_width].why_not;
    EXPECT_NE(s[valley_widening].why_not.find("the fit needs 3"), std::string::npos) << s[valley_widening].why_not;
}

#ifdef OROGEN_HAVE_LANDSCAPE
TEST(Figures, AStreamPowerSteadyStateGivesThetaMOverNAndKsUOverK) {
    // erode:stream-power's model run to steady state with uniform uplift: channels obey
    // S = (U/K)^(1/n) A^(−m/n), so θ = m/n and k_sn (reference concavity m/n) = (U/K)^(1/n).
    namespace sp = orogen::landscape;
    const int w = 81, h = 61;
    const double cell = 100.0, U = 1e-3;
    sp::Settings s;
    s.erodibility = 1e-5;
    s.area_exponent = 0.5;
    s.slope_exponent = 1.0;
    s.diffusivity = 0.0;
    s.open = {true, false, true, false};  // rivers run north and south
    std::vector<double> start(std::size_t(w) * h);
    // The north and south rows are the base level, all at 0 m: outlets at different heights would pass
    // water along the edge, which the model does not.
    for (std::size_t i = std::size_t(w); i + std::size_t(w) < start.size(); ++i) start[i] = 10.0 * uniform(i);
    sp::Model model(w, h, cell, start, std::vector<double>(start.size(), U), s);
    model.run(3e7, 2e5);
    std::vector<float> z(model.heights().begin(), model.heights().end());
    Options o;
    o.reference_concavity = 0.5;
    const Figures f = measure({z.data(), w, h, cell}, o);
    ASSERT_TRUE(f[concavity].ok()) << f[concavity].why_not;
    EXPECT_NEAR(f[concavity].value, 0.5, 0.005);
    EXPECT_NEAR(f[steepness].value, U / s.erodibility, 0.01 * U / s.erodibility);
}
#endif

// ------------------------------------------------------- pits, relief

TEST(Figures, PitsAreInteriorSamplesBelowAllEightNeighbours) {
    const int w = 12, h = 10;
    auto z = field(w, h, [](int x, int y) { return 10.0 * x + 3.0 * y; });
    z[std::size_t(3 * w + 4)] -= 100.0f;  // two pits
    z[std::size_t(7 * w + 8)] -= 100.0f;
    z[std::size_t(0 * w + 5)] -= 100.0f;  // on the edge: not a sample pits are counted over
    const Figures f = measure({z.data(), w, h, 10.0});
    EXPECT_NEAR(f[pits].value, 100.0 * 2.0 / double((w - 2) * (h - 2)), 1e-12);
}

TEST(Figures, LocalReliefOfAPlaneIsItsSlopeTimesTheClippedWindow) {
    // z = 0.1·x metres a metre; window ±1 km = ±10 cells of 100 m, clipped at the edges: the relief at
    // column c is 0.1·100·(min(c + 10, w − 1) − max(c − 10, 0)).
    const int w = 50, h = 30;
    const auto z = field(w, h, [](int x, int) { return 10.0 * x; });
    const Figures f = measure({z.data(), w, h, 100.0});
    double expected = 0.0;
    for (int c = 0; c < w; ++c) expected += 10.0 * (std::min(c + 10, w - 1) - std::max(c - 10, 0));
    EXPECT_NEAR(f[local_relief].value, expected / w, 1e-9);
}

// ------------------------------------------------------------ bad input

TEST(Figures, HolesAreMaskedAndCounted) {
    // A plane with a hole of NaN and one masked sample: the slopes stay exact (one-sided beside the
    // hole), the hole is counted, and no figure reads it.
    const int w = 40, h = 40;
    auto z = field(w, h, [](int x, int y) { return 3.0 * x + 4.0 * y; });
    std::vector<std::uint8_t> valid(z.size(), 1);
    for (int y = 10; y < 15; ++y)
        for (int x = 10; x < 15; ++x) z[std::size_t(y * w + x)] = std::numeric_limits<float>::quiet_NaN();
    valid[std::size_t(30 * w + 30)] = 0;
    z[std::size_t(30 * w + 30)] = -1e30f;  // a nodata value: must not be read
    const Figures f = measure({z.data(), w, h, 10.0, valid.data()});
    EXPECT_EQ(f.nodata, 26u);
    EXPECT_EQ(f.samples, std::size_t(w * h - 26));
    EXPECT_NEAR(f[slope_p90].value, std::atan(0.5) * degrees, 1e-4);
    EXPECT_NEAR(f[slope_mean].value, std::atan(0.5) * degrees, 1e-4);
    EXPECT_EQ(f.minimum, 0.0);
    for (const auto& m : f.values)
        if (m.ok()) EXPECT_TRUE(std::isfinite(m.value));
}

TEST(Figures, ATerrainTooSmallForAFigureSaysWhichAndWhyAndMeasuresTheRest) {
    const int w = 10, h = 8;
    const auto z = field(w, h, [](int x, int y) { return 5.0 * x + 2.0 * y * y; });
    const Figures f = measure({z.data(), w, h, 30.0});
    EXPECT_TRUE(f[slope_median].ok());
    EXPECT_TRUE(f[hypsometric_integral].ok());
    EXPECT_EQ(f[spectral_exponent].why_not,
              "the terrain (10x8) is narrower than 32 samples: too few wavenumbers in 4 … n/4 to fit");
    EXPECT_EQ(f[concavity].why_not,
              "only 0 channel cells (draining more than 1 km², slope above 0.0001, not filled); the fit needs 51: "
              "the terrain's rivers are too short");
    EXPECT_EQ(f[local_relief].why_not, "the terrain (10x8) is 0.21 km across, less than the 2.00 km window");
    EXPECT_EQ(f[drainage_density].why_not, "no cell drains more than 0.1 km² (the terrain covers 0.072 km²)");
    EXPECT_TRUE(std::isnan(f[concavity].value));
}

TEST(Figures, NoMeasuredSampleLeavesEveryFigureUnmeasured) {
    const std::vector<float> z(16, std::numeric_limits<float>::quiet_NaN());
    const Figures f = measure({z.data(), 4, 4, 1.0});
    for (const auto& m : f.values) EXPECT_EQ(m.why_not, "the terrain has no measured sample (all nodata)");
    EXPECT_EQ(f.nodata, 16u);
}

TEST(Figures, AMalformedGridIsRefused) {
    const std::vector<float> z(4, 0.0f);
    EXPECT_THROW(measure({nullptr, 2, 2, 1.0}), std::invalid_argument);
    EXPECT_THROW(measure({z.data(), 0, 2, 1.0}), std::invalid_argument);
    EXPECT_THROW(measure({z.data(), 2, 2, 0.0}), std::invalid_argument);
    EXPECT_THROW(measure({z.data(), 2, 2, std::numeric_limits<double>::infinity()}), std::invalid_argument);
}

TEST(Figures, TheTableDescribesEveryFigureOnce) {
    ASSERT_EQ(figure_table().size(), figure_count);
    for (std::size_t i = 0; i < figure_count; ++i) {
        const auto& row = figure_table()[i];
        EXPECT_EQ(std::size_t(row.id), i);
        EXPECT_FALSE(row.definition.empty()) << row.key;
        EXPECT_FALSE(row.source.empty()) << row.key;
        EXPECT_EQ(find_figure(row.key), row.id);
    }
    EXPECT_FALSE(find_figure("slope"));
}

// ------------------------------------------------------------ references

Figures figures_with(double first, double second) {
    Figures f;
    for (auto& m : f.values) m.why_not = "not measured here";
    f.values[0] = {first, ""};
    f.values[1] = {second, ""};
    return f;
}

TEST(Compare, BandsSpanTheReferencesAndTheDistanceIsInTheirSpread) {
    // Figure 0 over the references 1, 2, 3 (sd √(2/3)); figure 1 over 5, 5, 5 (no spread, left out of
    // distances); the others measured by none.
    const Figures a = figures_with(1, 5), b = figures_with(2, 5), c = figures_with(3, 5);
    const std::vector<const Figures*> refs = {&a, &b, &c};
    const Bands bands = reference_bands(refs);
    EXPECT_TRUE(bands[0].known);
    EXPECT_EQ(bands[0].low, 1.0);
    EXPECT_EQ(bands[0].high, 3.0);
    EXPECT_NEAR(bands[0].spread, std::sqrt(2.0 / 3.0), 1e-15);
    EXPECT_EQ(bands[1].spread, 0.0);
    EXPECT_FALSE(bands[2].known);
    EXPECT_TRUE(bands[0].contains(3.0));
    EXPECT_FALSE(bands[0].contains(3.5));
    EXPECT_FALSE(bands[0].contains(std::nan("")));
    EXPECT_FALSE(bands[2].contains(0.0)) << "no reference measured it";
    const Figures mine = figures_with(4, 9);
    const Distance d = distance(mine, a, bands);
    EXPECT_EQ(d.used, 1u) << "only figure 0 has a spread";
    EXPECT_NEAR(d.value, 3.0 / std::sqrt(2.0 / 3.0), 1e-12);
    EXPECT_EQ(distance(mine, b, bands).value < d.value, true) << "nearer to 2 than to 1";
    Figures unmeasured = figures_with(0, 0);
    unmeasured.values[0] = {std::nan(""), "too small"};
    EXPECT_EQ(distance(unmeasured, a, bands).used, 0u);
}

// ---------------------------------------------------------- determinism

TEST(Figures, TheSameBitsWithOneThreadOrTwo) {
    const int n = 150;
    const auto z = spectral_surface(n, 3.5, 9);
    auto run = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        return measure({z.data(), n, n, 30.0});
    };
    const Figures one = run(1), two = run(2);
    for (std::size_t i = 0; i < figure_count; ++i) {
        if (one.values[i].ok()) EXPECT_EQ(one.values[i].value, two.values[i].value) << figure_table()[i].key;
        EXPECT_EQ(one.values[i].why_not, two.values[i].why_not);
    }
    EXPECT_EQ(one.spectrum_power, two.spectrum_power);
}

}  // namespace
