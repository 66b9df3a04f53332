// atmosphere.hpp — the sky and the air by single scattering in Earth's atmosphere (Rayleigh, Mie and
// ozone absorption over a spherical planet; Nishita et al. 1993, with Bruneton 2017's and Hillaire 2020's
// constants), precomputed on the CPU into a small table of sky radiance per direction once per sun and
// camera altitude, which the shaders look up (Hillaire's "sky-view" table). The aerial perspective in
// front of the terrain is the same scattering along the view ray, in closed form for exponential layers
// of air (shaders/common.glsl, apply_fog).
#pragma once

#include <array>
#include <vector>

namespace orogen::render {

/// Earth's clear air, metres and 1/m at sea level.
struct Atmosphere {
    double planet_radius = 6360e3, top_radius = 6460e3;
    std::array<double, 3> rayleigh{5.802e-6, 13.558e-6, 33.1e-6};  ///< scattering, red green blue
    double rayleigh_height = 8000.0;  ///< m, scale height
    double mie_scattering = 3.996e-6, mie_extinction = 4.440e-6;  ///< aerosols (times `haze`)
    double mie_height = 1200.0;  ///< m
    double mie_g = 0.8;  ///< Cornette–Shanks asymmetry: the glow around the sun
    std::array<double, 3> ozone{0.650e-6, 1.881e-6, 0.085e-6};  ///< absorption at its peak (25 km)
    double haze = 1.0;  ///< multiplies the aerosols (1: a clear day, ~40 km visibility)
};

/// Radiance of the sky per unit of the sun's irradiance (1/sr), per direction, for an observer at one
/// altitude: `width` × `height` texels of RGB; u = the azimuth (0 north, clockwise, a full turn),
/// v = 0.5 + 0.5·sign(e)·sqrt(|e| / 90°) for an elevation e (finer near the horizon).
struct SkyTable {
    int width = 0, height = 0;
    std::vector<float> rgb;
    std::array<float, 3> sun_transmittance{};  ///< of the sunlight reaching the observer's altitude
    std::array<float, 3> irradiance{};  ///< the sky's light on a horizontal surface, per unit sun irradiance
};

/// `sun` is a unit vector (x east, y up, z south) towards the sun; `altitude` m above the sea.
SkyTable sky_table(const Atmosphere& air, const std::array<double, 3>& sun, double altitude, int width = 128,
                   int height = 64);

/// Transmittance of the air from `altitude` (m) to space along a ray whose sine of elevation is `mu`
/// (1 up, 0 horizontal); 0 where the ray meets the planet.
std::array<double, 3> transmittance(const Atmosphere& air, double altitude, double mu);

/// The phase functions (1/sr): Rayleigh's, and Cornette–Shanks' for the aerosols.
double rayleigh_phase(double cos_theta);
double mie_phase(double cos_theta, double g);

}  // namespace orogen::render
