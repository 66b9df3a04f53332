// common.glsl — shared by the scene shaders (pasted in by embed.cmake where a
// shader says #include "common.glsl"): noise, sky and fog.

// 2-D simplex noise, after Ashima Arts / Stefan Gustavson's webgl-noise (MIT):
// about in [-1, 1], no lattice artefacts, no tiling.
vec3 mod289(vec3 x) { return x - floor(x * (1.0 / 289.0)) * 289.0; }
vec2 mod289(vec2 x) { return x - floor(x * (1.0 / 289.0)) * 289.0; }
vec3 permute(vec3 x) { return mod289(((x * 34.0) + 10.0) * x); }
float simplex(vec2 v) {
    const vec4 C = vec4(0.211324865405187, 0.366025403784439, -0.577350269189626, 0.024390243902439);
    vec2 i = floor(v + dot(v, C.yy));
    vec2 x0 = v - i + dot(i, C.xx);
    vec2 i1 = (x0.x > x0.y) ? vec2(1.0, 0.0) : vec2(0.0, 1.0);
    vec4 x12 = x0.xyxy + C.xxzz;
    x12.xy -= i1;
    i = mod289(i);
    vec3 p = permute(permute(i.y + vec3(0.0, i1.y, 1.0)) + i.x + vec3(0.0, i1.x, 1.0));
    vec3 m = max(0.5 - vec3(dot(x0, x0), dot(x12.xy, x12.xy), dot(x12.zw, x12.zw)), 0.0);
    m = m * m;
    m = m * m;
    vec3 x = 2.0 * fract(p * C.www) - 1.0;
    vec3 h = abs(x) - 0.5;
    vec3 ox = floor(x + 0.5);
    vec3 a0 = x - ox;
    m *= 1.79284291400159 - 0.85373472095314 * (a0 * a0 + h * h);
    vec3 g;
    g.x = a0.x * x0.x + h.x * x0.y;
    g.yz = a0.yz * x12.xz + h.yz * x12.yw;
    return 130.0 * dot(m, g);
}

// Fractal sum of `octaves` simplex octaves, each twice as fine and half as
// strong, rotated so the lattices never line up: about in [-1, 1].
float fbm(vec2 p, int octaves) {
    const mat2 turn = mat2(1.6, 1.2, -1.2, 1.6);  // ×2 scale and a 37° turn
    float sum = 0.0, amplitude = 0.5;
    for (int i = 0; i < octaves; ++i) {
        sum += amplitude * simplex(p);
        p = turn * p + vec2(17.1, 9.7);
        amplitude *= 0.5;
    }
    return sum * 1.07;
}

// fbm() with each octave faded out as it nears the pixel's footprint
// (`footprint`: how far p moves across one pixel, from dFdx/dFdy), and the
// finer ones not evaluated at all: detail finer than half a pixel cannot be
// drawn, only aliased (it shimmers from frame to frame in a turntable), and on
// llvmpipe skipping it is most of what the far terrain costs. Equal to
// fbm(p, octaves) where every octave is coarser than 4 pixels.
float fbm_filtered(vec2 p, int octaves, float footprint) {
    const mat2 turn = mat2(1.6, 1.2, -1.2, 1.6);
    float sum = 0.0, amplitude = 0.5, frequency = 1.0;
    for (int i = 0; i < octaves; ++i) {
        // a simplex octave's features are about one lattice cell (1/frequency) wide: keep it whole while a cell
        // spans 4+ pixels, fade it out until a cell spans 2 pixels
        float keep = clamp((0.5 - footprint * frequency) * 4.0, 0.0, 1.0);
        if (keep <= 0.0) break;
        sum += amplitude * keep * simplex(p);
        p = turn * p + vec2(17.1, 9.7);
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    return sum * 1.07;
}

// A texture sampled with the cubic B-spline (C2: its level sets have no corners) at `s`, in samples
// (sample (x, y) at integer s, texel centres), from four bilinear taps (GPU Gems 2, ch. 20); the texture
// must filter linearly and clamp to its edge. The B-spline approximates: it smooths a field over about a
// sample, so a one-sample spike keeps 4/9 of its height.
vec4 bspline(sampler2D tex, vec2 s, vec2 size) {
    vec2 i = floor(s), f = s - i;
    vec2 f2 = f * f, f3 = f2 * f;
    vec2 w0 = (1.0 - 3.0 * f + 3.0 * f2 - f3) / 6.0;
    vec2 w1 = (4.0 - 6.0 * f2 + 3.0 * f3) / 6.0;
    vec2 w2 = (1.0 + 3.0 * f + 3.0 * f2 - 3.0 * f3) / 6.0;
    vec2 w3 = f3 / 6.0;
    vec2 g0 = w0 + w1, g1 = w2 + w3;
    vec2 t0 = (i - 1.0 + w1 / g0 + 0.5) / size, t1 = (i + 1.0 + w3 / g1 + 0.5) / size;
    return g0.y * (g0.x * texture(tex, vec2(t0.x, t0.y)) + g1.x * texture(tex, vec2(t1.x, t0.y))) +
           g1.y * (g0.x * texture(tex, vec2(t0.x, t1.y)) + g1.x * texture(tex, vec2(t1.x, t1.y)));
}

// The sky: a gradient from a hazy horizon to a deeper zenith, brighter and
// warmer towards the sun (single-scattering look), and the sun's disc (HDR,
// so the bloom makes it glow). `dir` is a unit view ray, y up.
uniform vec3 sun_direction;   // unit, towards the sun
uniform vec3 sun_colour;      // linear, times intensity
uniform vec3 sky_zenith;      // linear
uniform vec3 sky_horizon;     // linear
uniform float sun_disc;       // 1 draws the disc, 0 only its glow (reflections, fog)

vec3 sky_colour(vec3 dir, float with_disc) {
    float up = max(dir.y, 0.0);
    vec3 sky = mix(sky_horizon, sky_zenith, pow(up, 0.35));
    // Below the horizon the haze lies over the ground or the sea, not the bright sky: darker and a little
    // bluer from the horizon down (over a tenth of a degree, so the horizon is a line, not a step of pixels),
    // so that a far sea reads as sea under the sky rather than melting into it.
    if (dir.y < 0.0) {
        vec3 below = sky_horizon * vec3(0.70, 0.76, 0.84) * (1.0 - 0.2 * min(-dir.y * 3.0, 1.0));
        sky = mix(sky_horizon, below, smoothstep(0.0, 0.002, -dir.y));
    }
    float mu = max(dot(dir, sun_direction), 0.0);
    vec3 glow = sun_colour * (0.25 * pow(mu, 8.0) + 0.6 * pow(mu, 64.0) + 0.3 * pow(mu, 600.0));
    vec3 disc = sun_colour * 40.0 * smoothstep(0.99996, 0.99999, mu) * with_disc;
    return sky + glow * 0.5 + disc;
}

// Aerial perspective: the farther a surface, the more of the sky's colour in
// the view direction replaces it (optical depth = fog_density × distance).
uniform float fog_density;  // 1/m
vec3 apply_fog(vec3 colour, vec3 view_dir, float distance) {
    float f = 1.0 - exp(-fog_density * distance);
    return mix(colour, sky_colour(view_dir, 0.0), f);
}
