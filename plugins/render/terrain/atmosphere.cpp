// Single scattering in a spherical atmosphere: the sky table and the sun's transmittance.
#include "atmosphere.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace orogen::render {

namespace {

constexpr double kPi = std::numbers::pi;

/// Densities (relative to sea level) of the air, the aerosols and the ozone at `altitude` m.
struct Densities {
    double rayleigh, mie, ozone;
};
Densities densities(const Atmosphere& a, double altitude) {
    const double h = std::max(altitude, 0.0);
    return {std::exp(-h / a.rayleigh_height), std::exp(-h / a.mie_height),
            std::max(0.0, 1.0 - std::abs(h - 25e3) / 15e3)};  // ozone: a tent 30 km wide around 25 km
}

std::array<double, 3> extinction(const Atmosphere& a, const Densities& d) {
    std::array<double, 3> e{};
    for (int c = 0; c < 3; ++c)
        e[c] = a.rayleigh[c] * d.rayleigh + a.mie_extinction * a.haze * d.mie + a.ozone[c] * d.ozone;
    return e;
}

/// Distance along a ray from radius r (sine of elevation mu) to the sphere of radius R; −1 if none ahead.
double to_sphere(double r, double mu, double R) {
    const double b = r * mu, c = r * r - R * R, disc = b * b - c;
    if (disc < 0) return -1;
    const double s = std::sqrt(disc);
    if (-b - s > 0) return -b - s;
    return -b + s > 0 ? -b + s : -1;
}

}  // namespace

double rayleigh_phase(double c) { return 3.0 / (16.0 * kPi) * (1.0 + c * c); }

double mie_phase(double c, double g) {
    const double g2 = g * g;
    return 3.0 / (8.0 * kPi) * (1.0 - g2) * (1.0 + c * c) / ((2.0 + g2) * std::pow(1.0 + g2 - 2.0 * g * c, 1.5));
}

std::array<double, 3> transmittance(const Atmosphere& a, double altitude, double mu) {
    const double r = a.planet_radius + std::max(altitude, 0.0);
    const double ground = to_sphere(r, mu, a.planet_radius);
    // Rays that graze below the horizon from a height still reach space if they miss the planet.
    if (ground > 0 && mu < 0) return {0, 0, 0};
    const double length = to_sphere(r, mu, a.top_radius);
    std::array<double, 3> depth{};
    constexpr int kSteps = 40;
    for (int i = 0; i < kSteps; ++i) {
        const double t = (i + 0.5) / kSteps * length;
        const double ri = std::sqrt(r * r + t * t + 2 * r * t * mu);
        const auto e = extinction(a, densities(a, ri - a.planet_radius));
        for (int c = 0; c < 3; ++c) depth[c] += e[c] * length / kSteps;
    }
    return {std::exp(-depth[0]), std::exp(-depth[1]), std::exp(-depth[2])};
}

SkyTable sky_table(const Atmosphere& a, const std::array<double, 3>& sun, double altitude, int width, int height) {
    SkyTable t;
    t.width = width;
    t.height = height;
    t.rgb.assign(std::size_t(width) * std::size_t(height) * 3, 0.0f);
    const double r0 = a.planet_radius + std::max(altitude, 1.0);
    // The sun's transmittance by altitude along the sun's direction (the planet curves under a long ray,
    // so the sun's elevation seen from a sample differs; a table over altitude is within a percent of that
    // for rays shorter than a few hundred km, which is all that scatters light).
    constexpr int kLevels = 96;
    const double top = a.top_radius - a.planet_radius;
    std::array<std::array<double, 3>, kLevels> sun_through{};
    for (int k = 0; k < kLevels; ++k) sun_through[k] = transmittance(a, top * k / (kLevels - 1), sun[1]);
    auto sun_at = [&](double h) {
        const double f = std::clamp(h / top, 0.0, 1.0) * (kLevels - 1);
        const int k = std::min(int(f), kLevels - 2);
        std::array<double, 3> s{};
        for (int c = 0; c < 3; ++c) s[c] = sun_through[k][c] + (f - k) * (sun_through[k + 1][c] - sun_through[k][c]);
        return s;
    };
    const auto at_eye = transmittance(a, altitude, sun[1]);
    for (int c = 0; c < 3; ++c) t.sun_transmittance[c] = float(at_eye[c]);
    constexpr int kSteps = 48;
    std::array<double, 3> irradiance{};
    for (int j = 0; j < height; ++j) {
        const double v = (j + 0.5) / height * 2.0 - 1.0;
        const double elevation = (v < 0 ? -1.0 : 1.0) * v * v * kPi / 2;
        const double mu = std::sin(elevation), ce = std::cos(elevation);
        for (int i = 0; i < width; ++i) {
            const double azimuth = (i + 0.5) / width * 2 * kPi;
            const std::array<double, 3> dir{std::sin(azimuth) * ce, mu, -std::cos(azimuth) * ce};
            const double cos_theta = dir[0] * sun[0] + dir[1] * sun[1] + dir[2] * sun[2];
            const double pr = rayleigh_phase(cos_theta), pm = mie_phase(cos_theta, a.mie_g);
            double length = to_sphere(r0, mu, a.top_radius);
            const double ground = to_sphere(r0, mu, a.planet_radius);
            if (ground > 0) length = ground;
            std::array<double, 3> radiance{}, depth{};
            // Steps grow quadratically: most of the light scatters in the dense air near the start.
            double t0 = 0;
            for (int s = 0; s < kSteps; ++s) {
                const double t1 = length * double((s + 1) * (s + 1)) / double(kSteps * kSteps);
                const double tm = 0.5 * (t0 + t1), dt = t1 - t0;
                t0 = t1;
                const double ri = std::sqrt(r0 * r0 + tm * tm + 2 * r0 * tm * mu);
                const Densities d = densities(a, ri - a.planet_radius);
                const auto e = extinction(a, d);
                const auto lit = sun_at(ri - a.planet_radius);
                for (int c = 0; c < 3; ++c) {
                    const double view = std::exp(-(depth[c] + 0.5 * e[c] * dt));
                    const double scatter = a.rayleigh[c] * d.rayleigh * pr + a.mie_scattering * a.haze * d.mie * pm;
                    radiance[c] += view * lit[c] * scatter * dt;
                    depth[c] += e[c] * dt;
                }
            }
            float* out = &t.rgb[3 * (std::size_t(j) * std::size_t(width) + std::size_t(i))];
            for (int c = 0; c < 3; ++c) out[c] = float(radiance[c]);
            if (mu > 0) {  // the sky's light on a horizontal surface: ∫ L cos dω over this texel
                const double v0 = double(j) / height * 2 - 1, v1 = double(j + 1) / height * 2 - 1;
                const double mu0 = std::sin(v0 * v0 * kPi / 2), mu1 = std::sin(v1 * v1 * kPi / 2);
                const double solid_cos = 0.5 * (mu1 * mu1 - mu0 * mu0) * 2 * kPi / width;
                for (int c = 0; c < 3; ++c) irradiance[c] += radiance[c] * solid_cos;
            }
        }
    }
    for (int c = 0; c < 3; ++c) t.irradiance[c] = float(irradiance[c]);
    return t;
}

}  // namespace orogen::render
