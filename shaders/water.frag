#version 450 core
#include "common.glsl"
// Water: sine waves plus simplex noise for the normal, Fresnel between a
// reflection (the sky, and the terrain mirrored in the water plane where a
// reflection map is given) and the water body, transparent where shallow
// (Beer–Lambert), then fogged. Blended over the terrain with
// glBlendFuncSeparate(ONE, SRC_ALPHA, ZERO, ONE): alpha is how much of the
// ground shows through (the frame's own alpha stays 1).
// Rivers and lakes (the `water` layer) are found per fragment from the layer
// at full resolution, smoothed by the cubic B-spline: the shore is a smooth
// curve where the smoothed wet field crosses one half, faded over a pixel, not
// the cells' or the mesh's edges.
in vec3 world;
uniform vec3 eye;
uniform float time;              // s, moves the waves
uniform float wave_height;       // m
uniform vec3 water_colour;       // linear, the colour of deep water in daylight
uniform float clarity;           // m: depth at which 1/e of the ground shows
uniform sampler2D reflection;    // the terrain mirrored in the water plane (linear RGBA, alpha = coverage)
uniform int has_reflection;
uniform vec2 viewport;           // pixels
uniform vec3 ambient_colour;
uniform int sea_plane;           // 1: depth = sea level − ground (heights), deep beyond the terrain
uniform float sea_level;
uniform sampler2D heights;
uniform sampler2D surface;       // RGBA32F per sample: water level (m), depth (m), wet (0/1), unused
uniform ivec2 grid;
uniform float cell;
uniform float turbidity;         // optical depth of the river's silt, added to depth / clarity
out vec4 colour;

const float shore = 0.3;         // the smoothed wet field at the shore: a diagonal river of single samples
                                 // stays above 0.46 along its middle, a one-sample puddle peaks at 0.44

float calm_waves = 1.0;  // rivers: a fraction of wave_height

// Height field of the waves (m) at xz: four directional sines and noise.
float waves(vec2 p) {
    float h = 0.0;
    h += 0.35 * sin(dot(p, vec2(0.80, 0.60)) * 0.090 + time * 1.1);
    h += 0.25 * sin(dot(p, vec2(-0.55, 0.83)) * 0.140 + time * 1.4);
    h += 0.18 * sin(dot(p, vec2(0.20, -0.98)) * 0.230 + time * 1.9);
    h += 0.12 * sin(dot(p, vec2(-0.93, -0.37)) * 0.370 + time * 2.3);
    h += 0.35 * simplex(p * 0.05 + vec2(time * 0.05, 0.0)) + 0.18 * simplex(p * 0.16 - vec2(0.0, time * 0.08));
    return h * wave_height * calm_waves;
}

void main() {
    float water_depth, edge = 1.0, silt = 0.0, calm = 1.0;
    if (sea_plane == 1) {
        vec2 s = world.xz / cell;
        bool inside = all(greaterThanEqual(s, vec2(0.0))) && all(lessThanEqual(s, vec2(grid - 1)));
        water_depth = inside ? sea_level - texture(heights, (s + 0.5) / vec2(grid)).r : 200.0;
    } else {
        vec4 layer = bspline(surface, world.xz / cell, vec2(grid));
        float soft = max(fwidth(layer.b), 1e-4);  // the wet field's change across a pixel: antialiased shore
        edge = smoothstep(shore - soft, shore + soft, layer.b);
        water_depth = edge > 0.0 ? max(layer.g, 1e-3) : 0.0;
        // Rivers carry silt (a film of rain in a hollow hardly any: it stays clear), and their ripples are
        // small: as deep as the water, at least 1/6 of the waves.
        silt = turbidity * smoothstep(0.1, 0.8, layer.g);
        calm = clamp(layer.g / 3.0, 1.0 / 6.0, 1.0);
    }
    if (water_depth <= 0.0) discard;
    calm_waves = calm;
    const float e = 0.5;  // m, finite-difference step
    float h0 = waves(world.xz);
    vec3 n = normalize(vec3(-(waves(world.xz + vec2(e, 0.0)) - h0) / e, 1.0,
                            -(waves(world.xz + vec2(0.0, e)) - h0) / e));
    // Waves finer than a pixel would sparkle: flatten them where a pixel spans metres.
    float footprint = length(fwidth(world.xz));
    n = normalize(mix(vec3(0.0, 1.0, 0.0), n, 1.0 / (1.0 + footprint * footprint * 0.02)));
    vec3 v = normalize(eye - world);
    float cos_theta = max(dot(n, v), 0.0);
    float fresnel = 0.02 + 0.98 * pow(1.0 - cos_theta, 5.0);
    vec3 r = reflect(-v, n);
    r.y = abs(r.y);
    vec3 reflected = sky_colour(r, 0.0);
    if (has_reflection == 1) {
        // planar reflection, nudged by the waves' normal
        vec2 uv = gl_FragCoord.xy / viewport + n.xz * 0.03;
        vec4 mirrored = texture(reflection, uv);
        reflected = mix(reflected, mirrored.rgb, mirrored.a);
    }
    float sun_glint = pow(max(dot(r, sun_direction), 0.0), 700.0) * 25.0;
    reflected += sun_colour * sun_glint;
    float lambert = max(sun_direction.y, 0.0);
    vec3 body = water_colour * (sun_colour * lambert + ambient_colour);
    float transmitted = exp(-water_depth / clarity - silt);  // of the ground's light
    vec3 c = fresnel * reflected + (1.0 - fresnel) * (1.0 - transmitted) * body;
    float alpha = (1.0 - fresnel) * transmitted;
    // fog: the water's own light and what shows through fade alike
    float f = 1.0 - exp(-fog_density * distance(eye, world));
    c = mix(c, sky_colour(-v, 0.0) * (1.0 - alpha), f);
    // at the shore the water fades out over a pixel: edge of it over the ground
    colour = sea_plane == 1 ? vec4(c, alpha * (1.0 - f)) : vec4(c * edge, 1.0 - edge * (1.0 - alpha * (1.0 - f)));
}
