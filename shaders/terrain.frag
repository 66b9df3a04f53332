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
// splatting by altitude above the sea (never by the map's height range), slope and aspect
uniform float sea_altitude;            // m: the sea's level (sea_level), altitudes are counted from it
uniform int has_sea;                   // 1: beaches of sand at the shore
uniform float beach_height;            // m above the sea: sand on gentle ground below it
uniform float tree_line;               // m: vegetation thins out to bare ground over ±250 m around it
uniform float snow_line;               // m: lying snow on gentle slopes facing the sun (lower facing away)
uniform float slope_start, slope_full; // normal y where rock starts to, and fully, covers grass and snow
uniform vec3 material[4];              // linear albedo: sand, grass, rock, snow
uniform float jitter;                  // m: noise on the altitude lines, so they do not follow contours
uniform float texture_scale;           // m: size of the coarsest texture features
uniform int output_mode;               // 0 beauty, 1 albedo, 2 normal
// the simulation's layers, per sample (RGBA32F): river cover (0..1, drawn as wide as the drained area asks),
// wetness (0..1, log of the drained area), deposit (0..1, sediment and landslide debris), unused
uniform sampler2D layers;
uniform int has_layers;
uniform int beyond;                    // > 0: the world past the map's edge (terrain.vert), not over the map
// light
uniform sampler2DShadow shadow_map;
uniform mat4 light_view_projection;
uniform float shadow_texel;            // 1 / shadow map size
out vec4 colour;

float height_at(vec2 sample_pos) {  // bilinear, in samples
    return texture(heights, (sample_pos + 0.5) / vec2(grid)).r;
}

// Weights (sum 1) of sand, vegetation, rock and snow from the altitude above the sea `z` (m, jittered for
// the tree and snow lines; `shore` unjittered, as the beach is metres high),
// the normal's y, how much the slope faces the sun (`sunward`, −1..1) and the north (`north`, −1..1).
// Sun-facing slopes hold vegetation higher and lose their snow (the snow line climbs 250 m on them and
// falls 250 m facing away, and another 150 m on north faces, which the sun reaches least over a day); snow lies on gentle ground and slides off steep faces (above ~45°, a little
// steeper the higher it is); steep faces are rock at every altitude; sand only on gentle shores.
vec4 splat(float z, float shore, float normal_y, float sunward, float north) {
    float steep = clamp((slope_start - normal_y) / (slope_start - slope_full), 0.0, 1.0);
    float sloped = 1.0 - smoothstep(0.90, 0.965, normal_y);  // 15° to 26°: no beach
    float beach = has_sea == 1 ? (1.0 - smoothstep(beach_height, beach_height + 4.0, shore)) * (1.0 - sloped) : 0.0;
    float tree = tree_line + 150.0 * sunward;
    float vegetation = 1.0 - smoothstep(tree - 250.0, tree + 250.0, z);
    vec4 w = vec4(beach, (1.0 - beach) * vegetation, (1.0 - beach) * (1.0 - vegetation), 0.0);
    w.z += (w.x + w.y) * steep;
    w.xy *= 1.0 - steep;
    float line = snow_line + 250.0 * sunward - 150.0 * north;
    float above = clamp((z - line) / 1000.0, 0.0, 1.0);
    float snow = smoothstep(line - 120.0, line + 120.0, z) * smoothstep(0.62 - 0.12 * above, 0.78 - 0.12 * above, normal_y);
    return vec4(w.xyz * (1.0 - snow), snow);
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

// Hollows gather soil and water (vegetation on gentle concave ground below the tree line), ridges are
// bare; from 28° on, rock shows through the vegetation in patches. `hollow`, `ridge`, `wet` in [0, 1].
vec4 exposure(vec4 w, float normal_y, float hollow, float ridge, float wet, float z, float patches) {
    float steep = clamp((slope_start - normal_y) / (slope_start - slope_full), 0.0, 1.0);
    float below_trees = 1.0 - smoothstep(tree_line, tree_line + 400.0, z);
    float lush = max(hollow, wet) * (1.0 - steep) * below_trees;
    w.y += (w.x + w.z) * lush;
    w.x *= 1.0 - lush;
    w.z *= 1.0 - lush;
    float bare = max(ridge * 0.7, smoothstep(0.88, 0.76, normal_y) * smoothstep(-0.2, 0.35, patches)) * (1.0 - wet);
    w.z += w.y * bare;
    w.y *= 1.0 - bare;
    return w;
}

void main() {
    // texture_scale units per pixel, taken before any branch (derivatives need the whole 2 × 2 quad)
    float footprint = max(length(dFdx(world.xz)), length(dFdy(world.xz))) / texture_scale;
    vec3 facet = normalize(cross(dFdy(world), dFdx(world)));  // the drawn triangle's normal (exaggerated)
    facet *= sign(facet.y + 1e-9);
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
    // A sea's coast and a plain past the edge fade away from the clamped edge heights: their slope is the
    // drawn surface's (the clamped texture's would stripe them); a mirrored map keeps the texture's.
    if (beyond == 1 || beyond == 2) gradient = -facet.xz / max(facet.y, 1e-3) / exaggeration;
    vec3 true_normal = normalize(vec3(-gradient.x, 1.0, -gradient.y));
    vec3 n = normalize(vec3(-gradient.x * exaggeration, 1.0, -gradient.y * exaggeration));
    float h = world.y / exaggeration;

    vec2 p = world.xz / texture_scale;
    // Two noise fields serve every material: broad (texture_scale) and fine (1/40 of it).
    float broad = fbm_filtered(p, 4, footprint);
    float fine = fbm_filtered(p * 40.0, 2, footprint * 40.0);
    // Exposure: curvature at two scales (3 and 9 samples), and how much the slope faces the sun and the
    // north (−1 away, 1 towards: the sine of the slope times the cosine of the aspect).
    // (Past the edge the ground is coarse and far: no curvature, and no shadow from the map.)
    float concave = 0.0;
    if (beyond == 0) concave = 0.5 * (below_ring(s, h, 3.0) + below_ring(s, h, 9.0));
    float hollow = smoothstep(0.015, 0.12, concave), ridge = smoothstep(0.015, 0.12, -concave);
    // (Below about 6° the aspect hardly changes the light a slope gets: not counted.)
    float tilted = smoothstep(0.1, 0.5, length(true_normal.xz));
    float sunward = dot(true_normal.xz, normalize(sun_direction.xz + vec2(1e-6, 0.0))) * tilted;
    float north = -true_normal.z / max(length(true_normal.xz), 1e-6) * tilted;
    // The simulation's layers: rivers, wetness (drained area), deposits (sediment, landslide debris). The
    // B-spline keeps 4/9 of a one-sample river: its cover is scaled back up (and wide rivers' edges sharpen).
    vec4 sim = vec4(0.0);
#ifdef SIMULATION_LAYERS  // a second program for heightmaps with layers: llvmpipe runs both sides of a branch
    if (has_layers == 1) sim = bspline(layers, s, vec2(grid));
#endif
    float river = clamp(sim.r * 2.25, 0.0, 1.0), wet = clamp(sim.g, 0.0, 1.0), deposit = clamp(sim.b, 0.0, 1.0);
    float shore = h - sea_altitude, z = shore + jitter * (broad + 0.5 * fine);  // m above the sea
    vec4 w = exposure(splat(z, shore, true_normal.y, sunward, north), true_normal.y, hollow, ridge, wet, z,
                      broad + 0.5 * fine);

    // Procedural textures: no tiles, so nothing repeats.
    vec3 sand = material[0] * (0.92 + 0.12 * fine + 0.06 * broad);
    // Vegetation: denser and darker in hollows, along wet ground (large drained areas) and on shaded slopes, drier and paler facing the sun and on
    // convex ground.
    float dry = clamp(0.45 + 0.35 * broad + 1.5 * sunward + 0.6 * ridge - 0.8 * max(hollow, wet), 0.0, 1.0);
    vec3 grass = mix(material[1] * vec3(0.62, 0.74, 0.64), material[1] * vec3(1.28, 1.12, 0.84), dry);
    grass *= 0.9 + 0.12 * fine;
    float strata = 0.5 + 0.5 * sin(h * 0.04 + 5.0 * broad);  // layered rock, bent by the broad noise
    vec3 rock = material[2] * (0.78 + 0.28 * strata + 0.12 * fine);
    rock = mix(rock, rock * vec3(1.12, 0.98, 0.88), 0.5 + 0.5 * broad);
    // Scree and talus where the simulation deposited debris on a slope (from ~15°): paler, warmer, grained
    // broken rock over the vegetation and the bedrock; on gentle ground the deposit is soil (left as it is).
    float talus = deposit * smoothstep(0.97, 0.9, true_normal.y) * (1.0 - w.w);
    vec3 scree = material[2] * vec3(1.25, 1.18, 1.08) * (0.85 + 0.3 * fine);
    w.z += w.y * talus;
    w.y *= 1.0 - talus;
    rock = mix(rock, scree, talus);
    vec3 snow = material[3] * (0.96 + 0.04 * fine);
    vec3 albedo = sand * w.x + grass * w.y + rock * w.z + snow * w.w;
    // Rivers (the drainage layer's, as wide as their drained area asks): a dark, silty water body over
    // the bed; the sky's reflection is added once lit.
    albedo = mix(albedo, vec3(0.035, 0.06, 0.065), river);

    if (output_mode == 1) { colour = vec4(albedo, 1.0); return; }
    if (output_mode == 2) { colour = vec4(n * 0.5 + 0.5, 1.0); return; }

    // Sun: Lambert, shadowed by the map (5 PCF taps); sky: hemisphere light.
    vec4 ls = light_view_projection * vec4(world, 1.0);
    vec3 lp = ls.xyz / ls.w * 0.5 + 0.5;
    float lit = 0.0;
    float bias = 0.0015;
    if (beyond == 0) {  // the world beyond lies outside the shadow map's box: lit
        lit += texture(shadow_map, vec3(lp.xy, lp.z - bias));
        lit += texture(shadow_map, vec3(lp.xy + vec2(shadow_texel, 0.0), lp.z - bias));
        lit += texture(shadow_map, vec3(lp.xy - vec2(shadow_texel, 0.0), lp.z - bias));
        lit += texture(shadow_map, vec3(lp.xy + vec2(0.0, shadow_texel), lp.z - bias));
        lit += texture(shadow_map, vec3(lp.xy - vec2(0.0, shadow_texel), lp.z - bias));
        lit /= 5.0;
    }
    // Past the shadow map's box (the world beyond the edge) nothing of the map casts a shadow.
    if (beyond > 0 || any(lessThan(lp, vec3(0.0))) || any(greaterThan(lp, vec3(1.0)))) lit = 1.0;
    float lambert = max(dot(n, sun_direction), 0.0);
    // The sky's light reaches less of a hollow and more of a ridge (ambient occlusion from the curvature).
    float sky_seen = clamp(1.0 - 0.55 * hollow + 0.2 * ridge, 0.35, 1.2);
    vec3 light = sun_colour * lambert * lit * (1.0 - 0.3 * hollow) + ambient_colour * (0.55 + 0.45 * n.y) * sky_seen;
    // snow glints a little towards the sun
    vec3 v = normalize(eye - world);
    float spec = pow(max(dot(reflect(-sun_direction, n), v), 0.0), 24.0) * w.w * 0.25 * lit;
    vec3 c = albedo * light + sun_colour * spec;
#ifdef SIMULATION_LAYERS
    if (river > 0.0) {  // calm water mirrors the sky (Schlick's Fresnel, n = 1.33)
        vec3 r = reflect(-v, vec3(0.0, 1.0, 0.0));
        float fresnel = 0.02 + 0.98 * pow(1.0 - max(v.y, 0.0), 5.0);
        c += river * fresnel * sky_colour(r, 0.0);
    }
#endif
    colour = vec4(apply_fog(c, -v, distance(eye, world)), 1.0);
}
