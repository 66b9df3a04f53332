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

// The sky and the air: single scattering by the air (Rayleigh), its aerosols (Mie) and ozone, over a
// spherical Earth. The sky's radiance per direction is looked up in a table the CPU integrates once per sun
// and camera altitude (atmosphere.cpp; Nishita et al. 1993, Hillaire 2020's sky-view table); the air in
// front of the terrain and the sea is the same scattering along the view ray, in closed form for layers of
// air thinning exponentially with altitude (Hoffman and Preetham 2002, with height). `dir` is a unit view
// ray, y up.
uniform vec3 sun_direction;   // unit, towards the sun
uniform vec3 sun_colour;      // linear: the sunlight reaching the terrain, per π (a white surface facing it)
uniform vec3 ambient_colour;  // linear: the sky's light on a horizontal surface, per π
uniform float sun_disc;       // 1 draws the disc, 0 only its glow (reflections, fog)
uniform sampler2D sky_table;  // RGB radiance per unit sun irradiance; u azimuth from north, v sqrt-mapped elevation
uniform vec3 sky_scale;       // the sun's irradiance above the air (the table's unit)
uniform vec3 eye;             // world position of the camera
uniform float air_sea_y;      // world y of the sea level (altitude 0 for the air's density)
uniform float air_exaggeration;
uniform vec3 rayleigh_scattering;  // 1/m at sea level (also its extinction)
uniform float mie_scattering, mie_extinction;  // 1/m at sea level, times the haze
uniform float rayleigh_height, mie_height;     // m, scale heights
uniform float mie_g;

const float PI = 3.14159265;

float rayleigh_phase(float c) { return 3.0 / (16.0 * PI) * (1.0 + c * c); }
float mie_phase(float c) {  // Cornette–Shanks
    float g2 = mie_g * mie_g;
    return 3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + c * c) / ((2.0 + g2) * pow(1.0 + g2 - 2.0 * mie_g * c, 1.5));
}

vec3 sky_colour(vec3 dir, float with_disc) {
    // Below the horizon a ray ends on the ground past the drawn world (the table's value there is the air's
    // glow over a black ground): the horizon's colour, which the far air in front of the ground tends to.
    float elevation = asin(clamp(dir.y, 0.0, 1.0));
    float v = 0.5 + 0.5 * sign(elevation) * sqrt(abs(elevation) / (0.5 * PI));
    float u = atan(dir.x, -dir.z) / (2.0 * PI);  // clockwise from north; the table wraps around
    vec3 sky = texture(sky_table, vec2(u, v)).rgb * sky_scale;
    float mu = dot(dir, sun_direction);
    // the sun's disc (0.27° across), limb-darkened a little; HDR so the bloom makes it glow
    vec3 disc = sun_colour * 40.0 * smoothstep(0.99996, 0.99999, mu) * with_disc;
    return sky + disc;
}

// Mean density (relative to sea level) of an exponential layer of scale height `H` between altitudes a, b.
float mean_density(float a, float b, float H) {
    float d = b - a;
    return abs(d) > 1.0 ? H * (exp(-a / H) - exp(-b / H)) / d : exp(-0.5 * (a + b) / H);
}

// Aerial perspective: what the air between the eye and a surface `distance` away along `view_dir` lets
// through (transmittance, per channel) and what it scatters in (the sunlight and the sky's light).
void air(vec3 view_dir, float distance, out vec3 transmit, out vec3 inscatter) {
    vec3 p = eye + view_dir * distance;
    float a = max((eye.y - air_sea_y) / air_exaggeration, 0.0), b = max((p.y - air_sea_y) / air_exaggeration, 0.0);
    float r = mean_density(a, b, rayleigh_height), m = mean_density(a, b, mie_height);
    vec3 extinction = rayleigh_scattering * r + mie_extinction * m;
    transmit = exp(-extinction * distance);
    float c = dot(view_dir, sun_direction);
    vec3 scatter_sun = rayleigh_scattering * r * rayleigh_phase(c) + mie_scattering * m * mie_phase(c);
    vec3 scatter_all = rayleigh_scattering * r + mie_scattering * m;
    vec3 share = (1.0 - transmit) / max(extinction, vec3(1e-12));
    // sunlight: π·sun_colour is its irradiance; the sky's light, isotropic: π·ambient / 4π
    inscatter = share * (PI * sun_colour * scatter_sun + 0.25 * ambient_colour * scatter_all);
}

vec3 apply_fog(vec3 colour, vec3 view_dir, float distance) {
    vec3 transmit, inscatter;
    air(view_dir, distance, transmit, inscatter);
    return colour * transmit + inscatter;
}
