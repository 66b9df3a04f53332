// The spectral exponent β (Perron, Kirchner & Dietrich 2008), computed as terrain_stats.py does:
// the top-left square crop, mean removed, a Hann window (numpy.hanning) on both axes, |FFT|², power
// averaged over integer radial bins k = ⌊|(kx, ky)|⌋, and the least-squares slope of ln P against
// ln k over k = 4 … n/4.
#include "detail.hpp"

#include <orogen/analysis/fft.hpp>

#include <orogen/parallel.hpp>

#include <cmath>
#include <complex>
#include <numbers>

namespace orogen::analysis::detail {

namespace {

/// The smallest crop the fit has points for: k = 4 … n/4 gives n/4 − 3 wavenumbers, 5 at n = 32.
constexpr int minimum_side = 32;

/// numpy.hanning(n): the symmetric Hann window 0.5 − 0.5 cos(2πi/(n − 1)).
std::vector<double> hann(int n) {
    std::vector<double> w(std::size_t(n), 1.0);
    if (n == 1) return w;
    for (int i = 0; i < n; ++i) w[std::size_t(i)] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * i / double(n - 1));
    return w;
}

/// The signed frequency of unshifted FFT index u (numpy.fft.fftfreq · n): what fftshift puts at u.
int frequency(int u, int n) { return u < (n + 1) / 2 ? u : u - n; }

/// |F(u, v)|² of the 2-D transform of the real n × n `data` for the columns u = 0 … n/2 (row-major, n/2 + 1
/// a row); the other columns mirror them (F(n − u, n − v) = conj F(u, v)). Real input halves the work: two
/// rows go through one complex transform (z = a + ib, then A = (Z[k] + conj Z[n−k])/2 and
/// B = (Z[k] − conj Z[n−k])/2i), and only the n/2 + 1 columns are transformed.
std::vector<double> half_power_spectrum(const std::vector<double>& data, int n) {
    const std::size_t side = std::size_t(n), columns = side / 2 + 1;
    std::vector<std::complex<double>> half(side * columns);
    const Fft fft(side);
    // Each pair of rows, then each column, is one iteration's alone: the same bits for any thread count.
    orogen::parallel_for(0, std::int64_t((side + 1) / 2), 8, [&](std::int64_t begin, std::int64_t end) {
        std::vector<std::complex<double>> z(side);
        for (auto pair = std::size_t(begin); pair < std::size_t(end); ++pair) {
            const std::size_t y0 = 2 * pair, y1 = y0 + 1;
            for (std::size_t x = 0; x < side; ++x) z[x] = {data[y0 * side + x], y1 < side ? data[y1 * side + x] : 0.0};
            fft.transform(z);
            for (std::size_t u = 0; u < columns; ++u) {
                const std::complex<double> zk = z[u], zm = std::conj(z[(side - u) % side]);
                half[y0 * columns + u] = 0.5 * (zk + zm);
                if (y1 < side) half[y1 * columns + u] = std::complex<double>(0.0, -0.5) * (zk - zm);
            }
        }
    });
    std::vector<double> power(side * columns);
    orogen::parallel_for(0, std::int64_t(columns), 8, [&](std::int64_t begin, std::int64_t end) {
        std::vector<std::complex<double>> column(side);
        for (auto u = std::size_t(begin); u < std::size_t(end); ++u) {
            for (std::size_t v = 0; v < side; ++v) column[v] = half[v * columns + u];
            fft.transform(column);
            for (std::size_t v = 0; v < side; ++v) power[v * columns + u] = std::norm(column[v]);
        }
    });
    return power;
}

}  // namespace

void measure_spectrum(const Terrain& t, Figures& f) {
    const int n = std::min(t.width, t.height);
    f.spectrum_side = n;
    if (n < minimum_side) {
        f[FigureId::spectral_exponent].why_not = "the terrain (" + std::to_string(t.width) + "x" +
            std::to_string(t.height) + ") is narrower than " + std::to_string(minimum_side) +
            " samples: too few wavenumbers in 4 … n/4 to fit";
        return;
    }
    // Mean of the crop's measured samples; holes take it, so they add no power (after the mean is removed).
    double sum = 0.0;
    std::size_t count = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            if (t.valid[t.at(x, y)]) sum += t.z[t.at(x, y)], ++count;
    if (count == 0) {
        f[FigureId::spectral_exponent].why_not = "the square crop it is measured on has no measured sample";
        return;
    }
    const double mean = sum / double(count);
    const auto window = hann(n);
    std::vector<double> data(std::size_t(n) * std::size_t(n));
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const std::size_t i = t.at(x, y);
            const double v = t.valid[i] ? t.z[i] - mean : 0.0;
            data[std::size_t(y) * std::size_t(n) + std::size_t(x)] =
                v * window[std::size_t(y)] * window[std::size_t(x)];
        }
    const std::vector<double> half = half_power_spectrum(data, n);

    // Radial bins as numpy.bincount of int(hypot(kx, ky)); the largest bin is ⌊√2·n/2⌋. Column u of the
    // half spectrum stands for itself and, unless it is its own mirror (u = 0, or n/2 for even n), for
    // column n − u, whose power is the same at the mirrored row and falls in the same bin.
    const std::size_t bins = std::size_t(std::hypot(double(n / 2), double(n / 2))) + 1;
    const std::size_t columns = std::size_t(n / 2 + 1);
    std::vector<double> power(bins, 0.0);
    std::vector<std::size_t> members(bins, 0);
    for (int v = 0; v < n; ++v)
        for (int u = 0; u <= n / 2; ++u) {
            const std::size_t weight = u == 0 || 2 * u == n ? 1 : 2;
            const std::size_t k = std::size_t(std::hypot(double(frequency(u, n)), double(frequency(v, n))));
            power[k] += double(weight) * half[std::size_t(v) * columns + std::size_t(u)];
            members[k] += weight;
        }
    for (std::size_t k = 0; k < bins; ++k) power[k] /= double(std::max<std::size_t>(members[k], 1));

    std::vector<double> lk, lp;
    for (int k = 1; k <= n / 2; ++k) {
        f.spectrum_k.push_back(double(k));
        f.spectrum_power.push_back(power[std::size_t(k)]);
        if (k >= 4 && k <= n / 4 && power[std::size_t(k)] > 0.0) {
            lk.push_back(std::log(double(k)));
            lp.push_back(std::log(power[std::size_t(k)]));
        }
    }
    f.spectrum_fit = fit_line(lk, lp);
    if (lk.size() < 2 || std::isnan(f.spectrum_fit.slope)) {
        f[FigureId::spectral_exponent].why_not = "the spectrum has no power at wavenumbers 4 … n/4 (a flat terrain?)";
        return;
    }
    f[FigureId::spectral_exponent].value = -f.spectrum_fit.slope;
}

}  // namespace orogen::analysis::detail
