// orogen/analysis/fft.hpp — discrete Fourier transforms of any length.
//
// Radix-2 Cooley–Tukey for powers of two; every other length through
// Bluestein's chirp-z algorithm (Bluestein 1970) over a power-of-two
// convolution, so a 1000- or 647-sample DEM needs no padding or cropping.
// Double precision; the error against the naive DFT is ~1e-12 relative.
// Sign convention as numpy.fft: forward X[k] = Σ x[j] e^{−2πi jk/n}, the
// inverse has +2πi and divides by n.
#pragma once

#include <complex>
#include <cstddef>
#include <span>
#include <vector>

namespace orogen::analysis {

/// A transform of one length, planned once (twiddles, Bluestein's chirp and its transform) and applied
/// to many rows. Immutable after construction: `transform` may run on several threads at once.
class Fft {
public:
    explicit Fft(std::size_t n);
    std::size_t size() const { return n_; }
    /// In place: forward (inverse = false) or inverse (divided by n).
    void transform(std::span<std::complex<double>> data, bool inverse = false) const;

private:
    void radix2(std::span<std::complex<double>> data, bool inverse) const;
    std::size_t n_;
    std::size_t m_;  ///< the power-of-two length the radix-2 kernel runs at (n itself, or ≥ 2n − 1 for Bluestein)
    std::vector<std::complex<double>> twiddles_;  ///< stage len's e^{−2πi k/len}, k < len/2, at len/2 − 1
    std::vector<std::complex<double>> chirp_;  ///< Bluestein: e^{−πi k²/n}, k < n
    std::vector<std::complex<double>> kernel_;  ///< Bluestein: the forward transform of the conjugate chirp, length m
};

/// The 2-D forward transform of a row-major width × height array, in place (rows, then columns).
void fft2(std::vector<std::complex<double>>& data, std::size_t width, std::size_t height, bool inverse = false);

}  // namespace orogen::analysis
