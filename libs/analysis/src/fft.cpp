// Radix-2 Cooley–Tukey and Bluestein's chirp-z transform (fft.hpp).
#include <orogen/analysis/fft.hpp>

#include <orogen/parallel.hpp>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace orogen::analysis {

namespace {

std::size_t next_power_of_two(std::size_t n) {
    std::size_t p = 1;
    while (p < n) p <<= 1;
    return p;
}

bool is_power_of_two(std::size_t n) { return n != 0 && (n & (n - 1)) == 0; }

}  // namespace

Fft::Fft(std::size_t n) : n_(n) {
    if (n == 0) throw std::invalid_argument("Fft: length 0");
    m_ = is_power_of_two(n) ? n : next_power_of_two(2 * n - 1);
    // Each stage's twiddles in a row of their own, e^{−2πi k/len} = e^{−2πi k·(m/len)/m} for k < len/2 at
    // offset len/2 − 1: the values a stage reads, read one after another rather than m/len apart.
    std::vector<std::complex<double>> full(m_ / 2);
    for (std::size_t k = 0; k < m_ / 2; ++k)
        full[k] = std::polar(1.0, -2.0 * std::numbers::pi * double(k) / double(m_));
    twiddles_.resize(m_ > 1 ? m_ - 1 : 0);
    for (std::size_t len = 2; len <= m_; len <<= 1)
        for (std::size_t k = 0; k < len / 2; ++k) twiddles_[len / 2 - 1 + k] = full[k * (m_ / len)];
    if (m_ == n_) return;
    // Bluestein: jk = (j² + k² − (k − j)²)/2, so X[k] = c[k] Σ_j (x[j] c[j]) conj(c[k − j]) with
    // c[k] = e^{−πi k²/n}: a convolution, done at the power-of-two length m. k² is taken mod 2n
    // before the angle so large k lose no precision.
    chirp_.resize(n_);
    for (std::size_t k = 0; k < n_; ++k) {
        const std::size_t k2 = (k * k) % (2 * n_);
        chirp_[k] = std::polar(1.0, -std::numbers::pi * double(k2) / double(n_));
    }
    kernel_.assign(m_, {0.0, 0.0});
    kernel_[0] = std::conj(chirp_[0]);
    for (std::size_t k = 1; k < n_; ++k) kernel_[k] = kernel_[m_ - k] = std::conj(chirp_[k]);
    radix2(kernel_, false);
}

void Fft::radix2(std::span<std::complex<double>> a, bool inverse) const {
    const std::size_t m = a.size();
    // Bit-reversal permutation.
    for (std::size_t i = 1, j = 0; i < m; ++i) {
        std::size_t bit = m >> 1;
        for (; j & bit; bit >>= 1) j ^= bit;
        j ^= bit;
        if (i < j) std::swap(a[i], a[j]);
    }
    // The butterflies in real arithmetic, v·w = (vr·wr − vi·wi, vr·wi + vi·wr): the products and sums
    // std::complex's operator* forms for finite values (no FMA contraction on this target), so the same
    // bits, without its NaN branch, which kept the loop from being vectorised. The heights that reach a
    // transform are finite.
    double* p = reinterpret_cast<double*>(a.data());
    const double sign = inverse ? -1.0 : 1.0;
    for (std::size_t len = 2; len <= m; len <<= 1) {
        const std::size_t half = len / 2;
        const double* tw = reinterpret_cast<const double*>(twiddles_.data() + (half - 1));
        for (std::size_t i = 0; i < m; i += len) {
            double* lo = p + 2 * i;
            double* hi = lo + 2 * half;
            for (std::size_t k = 0; k < half; ++k) {
                const double wr = tw[2 * k], wi = sign * tw[2 * k + 1];
                const double vr = hi[2 * k] * wr - hi[2 * k + 1] * wi, vi = hi[2 * k] * wi + hi[2 * k + 1] * wr;
                const double ur = lo[2 * k], ui = lo[2 * k + 1];
                lo[2 * k] = ur + vr, lo[2 * k + 1] = ui + vi;
                hi[2 * k] = ur - vr, hi[2 * k + 1] = ui - vi;
            }
        }
    }
}

void Fft::transform(std::span<std::complex<double>> data, bool inverse) const {
    if (data.size() != n_) throw std::invalid_argument("Fft::transform: wrong length");
    if (m_ == n_) {
        radix2(data, inverse);
    } else {
        // The inverse is the conjugate of the forward transform of the conjugate.
        std::vector<std::complex<double>> a(m_, {0.0, 0.0});
        for (std::size_t j = 0; j < n_; ++j) a[j] = (inverse ? std::conj(data[j]) : data[j]) * chirp_[j];
        radix2(a, false);
        for (std::size_t k = 0; k < m_; ++k) a[k] *= kernel_[k];
        radix2(a, true);
        const double scale = 1.0 / double(m_);
        for (std::size_t k = 0; k < n_; ++k) {
            const std::complex<double> x = a[k] * scale * chirp_[k];
            data[k] = inverse ? std::conj(x) : x;
        }
    }
    if (inverse) {
        const double scale = 1.0 / double(n_);
        for (auto& x : data) x *= scale;
    }
}

void fft2(std::vector<std::complex<double>>& data, std::size_t width, std::size_t height, bool inverse) {
    if (data.size() != width * height) throw std::invalid_argument("fft2: data is not width × height");
    // Each row and each column is transformed by one iteration alone: the same bits for any thread count.
    const Fft rows(width);
    orogen::parallel_for(0, std::int64_t(height), 16, [&](std::int64_t begin, std::int64_t end) {
        for (auto y = std::size_t(begin); y < std::size_t(end); ++y)
            rows.transform(std::span(data).subspan(y * width, width), inverse);
    });
    const Fft columns(height);
    orogen::parallel_for(0, std::int64_t(width), 16, [&](std::int64_t begin, std::int64_t end) {
        std::vector<std::complex<double>> column(height);
        for (auto x = std::size_t(begin); x < std::size_t(end); ++x) {
            for (std::size_t y = 0; y < height; ++y) column[y] = data[y * width + x];
            columns.transform(column, inverse);
            for (std::size_t y = 0; y < height; ++y) data[y * width + x] = column[y];
        }
    });
}

}  // namespace orogen::analysis
