#version 450 core
#include "common.glsl"
// The terrain's colour: the thesis's texture splatting (Listing 3.3: sand,
// grass, rock and snow by height in bands with a blend into each band, slope
// overriding grass and snow with rock, nested mix) with procedural textures,
// lit by the sun (shadow map) and the sky, then fogged.
in vec3 world;
flat in vec3 wall_normal;
uniform sampler2D heights;
uniform ivec2 grid;
uniform float cell;
uniform float exaggeration;
uniform vec3 eye;
// splatting (from orogen::terrain::SplatRules and the colour constants in terrain_mesh.hpp)
uniform float height_min, height_max;  // m, unexaggerated
uniform float band_start[4];           // fraction of the range where sand, grass, rock, snow start
uniform float blend_fraction;          // a band blends in from the one below over this part of it
uniform float slope_start, slope_full; // normal y where rock starts to, and fully, cover grass and snow
uniform vec3 material[4];              // linear albedo: sand, grass, rock, snow
uniform float jitter;                  // noise on the height bands, fraction of the range
uniform float texture_scale;           // m: size of the coarsest texture features
uniform int output_mode;               // 0 beauty, 1 albedo, 2 normal
// light
uniform sampler2DShadow shadow_map;
uniform mat4 light_view_projection;
uniform float shadow_texel;            // 1 / shadow map size
uniform vec3 ambient_colour;           // linear, from the sky
out vec4 colour;

float height_at(vec2 sample_pos) {  // bilinear, in samples
    return texture(heights, (sample_pos + 0.5) / vec2(grid)).r;
}

// Listing 3.3's chooser as weights (sum 1), the same rule as
// orogen::terrain::splat_weights on the CPU.
vec4 splat(float t, float normal_y) {
    int k = t >= band_start[3] ? 3 : t >= band_start[2] ? 2 : t >= band_start[1] ? 1 : 0;
    float band_end = k == 3 ? 1.0 : band_start[k + 1];
    float blend = blend_fraction * (band_end - band_start[k]);
    float into = t - band_start[k];
    vec4 w = vec4(0.0);
    if (k == 0 || into >= blend) {
        w[k] = 1.0;
    } else {
        float f = into / blend;
        w[k - 1] = 1.0 - f;
        w[k] = f;
    }
    float steep = clamp((slope_start - normal_y) / (slope_start - slope_full), 0.0, 1.0);
    float moved = steep * (w.y + w.w);
    w.y *= 1.0 - steep;
    w.w *= 1.0 - steep;
    w.z += moved;
    return w;
}

// How far the ground lies below (a hollow: > 0) or above (a ridge: < 0) the mean of a ring of eight points
// `r` samples around it, as a slope (m/m): the curvature at that scale, which ambient occlusion and the
// soil follow.
float below_ring(vec2 s, float h, float r) {
    const float d = 0.70710678;
    float sum = height_at(s + vec2(r, 0.0)) + height_at(s - vec2(r, 0.0)) + height_at(s + vec2(0.0, r)) +
                height_at(s - vec2(0.0, r)) + height_at(s + vec2(r * d, r * d)) + height_at(s - vec2(r * d, r * d)) +
                height_at(s + vec2(r * d, -r * d)) + height_at(s + vec2(-r * d, r * d));
    return (sum / 8.0 - h) / (r * cell);
}

// The renderer's own additions to Listing 3.3 (the exports keep the thesis's rule): steep faces are rock at
// every height (the thesis leaves sand on a cliff), sand keeps gentle ground (beaches, flats) and gives way
// to vegetation on slopes, hollows gather soil and water (vegetation on gentle concave ground), ridges are
// bare. `hollow` and `ridge` in [0, 1]; on a plane both are 0 and only the first two rules act.
vec4 exposure(vec4 w, float normal_y, float hollow, float ridge, float t, float patches) {
    float steep = clamp((slope_start - normal_y) / (slope_start - slope_full), 0.0, 1.0);
    w.z += w.x * steep;
    w.x *= 1.0 - steep;
    float sloped = 1.0 - smoothstep(0.90, 0.965, normal_y);  // 15° to 26°
    w.y += w.x * sloped;
    w.x *= 1.0 - sloped;
    // vegetation fades out of the hollows towards the snow line
    float lush = hollow * (1.0 - steep) * (1.0 - smoothstep(band_start[2], band_start[3], t));
    w.y += (w.x + w.z) * lush;
    w.x *= 1.0 - lush;
    w.z *= 1.0 - lush;
    // outcrops: from 28° on, rock shows through the vegetation in patches, more of it on ridges
    float bare = max(ridge * 0.7, smoothstep(0.88, 0.76, normal_y) * smoothstep(-0.2, 0.35, patches));
    w.z += w.y * bare;
    w.y *= 1.0 - bare;
    return w;
}

void main() {
    // texture_scale units per pixel, taken before any branch (derivatives need the whole 2 × 2 quad)
    float footprint = max(length(dFdx(world.xz)), length(dFdy(world.xz))) / texture_scale;
    if (wall_normal != vec3(0.0)) {
        // The skirt: layered earth and rock, lit like the rest.
        vec2 q = vec2(dot(world.xz, wall_normal.zx), world.y) / texture_scale;
        float layers = 0.5 + 0.5 * sin(world.y / exaggeration * 0.05 + 4.0 * fbm(q * vec2(1.0, 0.3), 3));
        vec3 earth = mix(material[2] * 0.42, material[0] * 0.45, 0.25 + 0.3 * layers) * (0.9 + 0.2 * fbm(q * 30.0, 2));
        if (output_mode == 1) { colour = vec4(earth, 1.0); return; }
        if (output_mode == 2) { colour = vec4(wall_normal * 0.5 + 0.5, 1.0); return; }
        vec3 wl = sun_colour * max(dot(wall_normal, sun_direction), 0.0) + ambient_colour * 0.5;
        colour = vec4(apply_fog(earth * wl, normalize(world - eye), distance(eye, world)), 1.0);
        return;
    }
    vec2 s = world.xz / cell;  // position in samples
    // Normals from the heights at full resolution (whatever the mesh's level of detail).
    float hl = height_at(s - vec2(1.0, 0.0)), hr = height_at(s + vec2(1.0, 0.0));
    float hu = height_at(s - vec2(0.0, 1.0)), hd = height_at(s + vec2(0.0, 1.0));
    vec2 gradient = vec2(hr - hl, hd - hu) / (2.0 * cell);  // m/m, true terrain
    vec3 true_normal = normalize(vec3(-gradient.x, 1.0, -gradient.y));
    vec3 n = normalize(vec3(-gradient.x * exaggeration, 1.0, -gradient.y * exaggeration));
    float h = world.y / exaggeration;

    vec2 p = world.xz / texture_scale;
    // Two noise fields serve every material: broad (texture_scale) and fine (1/40 of it).
    float broad = fbm_filtered(p, 4, footprint);
    float fine = fbm_filtered(p * 40.0, 2, footprint * 40.0);
    float range = max(height_max - height_min, 1e-6);
    // Exposure: curvature at two scales (3 and 9 samples), and how much the slope faces the sun (−1 away,
    // 1 towards: the sine of the slope times the cosine of the aspect to the sun).
    float concave = 0.5 * (below_ring(s, h, 3.0) + below_ring(s, h, 9.0));
    float hollow = smoothstep(0.015, 0.12, concave), ridge = smoothstep(0.015, 0.12, -concave);
    // (Below about 6° the aspect hardly changes the light a slope gets: not counted.)
    float sunward = dot(true_normal.xz, normalize(sun_direction.xz + vec2(1e-6, 0.0))) *
                    smoothstep(0.1, 0.5, length(true_normal.xz));
    // Sun-facing slopes are warmer (the bands climb), shaded ones colder (snow and rock come lower).
    float t = clamp((h - height_min) / range, 0.0, 1.0) + jitter * (broad + 0.5 * fine) - 0.06 * sunward;
    vec4 w = exposure(splat(t, true_normal.y), true_normal.y, hollow, ridge, t, broad + 0.5 * fine);

    // Procedural textures: no tiles, so nothing repeats.
    vec3 sand = material[0] * (0.92 + 0.12 * fine + 0.06 * broad);
    // Vegetation: denser and darker in hollows and on shaded slopes, drier and paler facing the sun and on
    // convex ground.
    float dry = clamp(0.45 + 0.35 * broad + 1.5 * sunward + 0.6 * ridge - 0.8 * hollow, 0.0, 1.0);
    vec3 grass = mix(material[1] * vec3(0.62, 0.74, 0.64), material[1] * vec3(1.28, 1.12, 0.84), dry);
    grass *= 0.9 + 0.12 * fine;
    float strata = 0.5 + 0.5 * sin(h * 0.04 + 5.0 * broad);  // layered rock, bent by the broad noise
    vec3 rock = material[2] * (0.78 + 0.28 * strata + 0.12 * fine);
    rock = mix(rock, rock * vec3(1.12, 0.98, 0.88), 0.5 + 0.5 * broad);
    vec3 snow = material[3] * (0.96 + 0.04 * fine);
    vec3 albedo = sand * w.x + grass * w.y + rock * w.z + snow * w.w;

    if (output_mode == 1) { colour = vec4(albedo, 1.0); return; }
    if (output_mode == 2) { colour = vec4(n * 0.5 + 0.5, 1.0); return; }

    // Sun: Lambert, shadowed by the map (5 PCF taps); sky: hemisphere light.
    vec4 ls = light_view_projection * vec4(world, 1.0);
    vec3 lp = ls.xyz / ls.w * 0.5 + 0.5;
    float lit = 0.0;
    float bias = 0.0015;
    lit += texture(shadow_map, vec3(lp.xy, lp.z - bias));
    lit += texture(shadow_map, vec3(lp.xy + vec2(shadow_texel, 0.0), lp.z - bias));
    lit += texture(shadow_map, vec3(lp.xy - vec2(shadow_texel, 0.0), lp.z - bias));
    lit += texture(shadow_map, vec3(lp.xy + vec2(0.0, shadow_texel), lp.z - bias));
    lit += texture(shadow_map, vec3(lp.xy - vec2(0.0, shadow_texel), lp.z - bias));
    lit /= 5.0;
    float lambert = max(dot(n, sun_direction), 0.0);
    // The sky's light reaches less of a hollow and more of a ridge (ambient occlusion from the curvature).
    float sky_seen = clamp(1.0 - 0.55 * hollow + 0.2 * ridge, 0.35, 1.2);
    vec3 light = sun_colour * lambert * lit * (1.0 - 0.3 * hollow) + ambient_colour * (0.55 + 0.45 * n.y) * sky_seen;
    // snow glints a little towards the sun
    vec3 v = normalize(eye - world);
    float spec = pow(max(dot(reflect(-sun_direction, n), v), 0.0), 24.0) * w.w * 0.25 * lit;
    vec3 c = albedo * light + sun_colour * spec;
    colour = vec4(apply_fog(c, -v, distance(eye, world)), 1.0);
}
