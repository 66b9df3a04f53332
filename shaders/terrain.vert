#version 450 core
// The heightmap as a grid of vertices made from gl_VertexID: no vertex
// buffer, only the heights as a float texture. World space: X east = x·cell,
// Y up = height·exaggeration, Z south = y·cell (as the glTF export).
uniform sampler2D heights;    // R32F, texel (x, y) = sample (x, y), metres
uniform ivec2 grid;           // samples
uniform int stride;           // keep every stride-th sample (level of detail)
uniform ivec2 kept;           // vertices drawn per row and column
uniform float cell;           // m
uniform float exaggeration;
uniform mat4 view_projection;
// The skirt: walls from each edge of the terrain down to floor_height, so the
// block reads as solid from the side. skirt_edge 0..3 = north, east, south,
// west (one strip each, two vertices per kept edge sample); −1: the surface.
uniform int skirt_edge;
uniform float floor_height;   // m, exaggerated
uniform vec4 clip_plane;      // world-space plane (a, b, c, d): kept where a·x + b·y + c·z + d ≥ 0
// The world past the map's edge: 0 the map itself (surface or skirt); 1 sea (the ground falls below the sea
// over a coast a twelfth of the map wide), 2 plain (the edge's heights fade to their mean over a quarter of the
// map), 3 mirror (the map mirrored at its edges, fading to the mean from one to four maps away). Drawn as a
// grid of beyond_cells² quads (six vertices each, no buffer) reaching beyond_reach m from the map's middle,
// denser near the map (x ∝ u³), in four draws (beyond_side 0..3: north, south, west, east of the map) each
// clipped to its side by gl_ClipDistance[1..3], so nothing is drawn over the map (a `discard` in the terrain's
// shader would cost the map its early depth test on llvmpipe).
uniform int beyond;
uniform int beyond_side;
uniform int beyond_cells;
uniform float beyond_reach;   // m
uniform float edge_height;    // m: mean height of the map's edge
uniform float sea_floor;      // m: where the ground past a coast settles, below the sea
out vec3 world;
flat out vec3 wall_normal;

vec2 beyond_xz(ivec2 ij, vec2 extent) {
    vec2 u = vec2(ij) / float(beyond_cells) * 2.0 - 1.0;
    return 0.5 * extent + sign(u) * abs(u * u * u) * beyond_reach;
}

vec3 beyond_vertex() {
    const ivec2 corner[6] = ivec2[6](ivec2(0, 0), ivec2(0, 1), ivec2(1, 0), ivec2(1, 0), ivec2(0, 1), ivec2(1, 1));
    int q = gl_VertexID / 6;
    ivec2 ij = ivec2(q % beyond_cells, q / beyond_cells) + corner[gl_VertexID % 6];
    vec2 extent = vec2(grid - 1) * cell;
    vec2 xz = beyond_xz(ij, extent);
    // A quad wholly over the map is dropped here (all its vertices outside the clip volume), so that its
    // fragments never run only to be discarded.
    ivec2 first = ivec2(q % beyond_cells, q / beyond_cells);
    vec2 a = beyond_xz(first, extent), b = beyond_xz(first + 1, extent);
    if (all(greaterThan(a, vec2(0.0))) && all(lessThan(b, extent))) return vec3(-1e30);
    float d = length(max(max(-xz, xz - extent), vec2(0.0)));  // m outside the map
    float size = max(extent.x, extent.y);
    float h = textureLod(heights, (xz / cell + 0.5) / vec2(grid), 0.0).r;  // clamped, or mirrored (mirror)
    if (beyond == 1) h = mix(h, sea_floor, smoothstep(0.0, size / 12.0, d));
    else if (beyond == 2) h = mix(h, edge_height, smoothstep(0.0, 0.25 * size, d));
    else h = mix(h, edge_height, smoothstep(size, 4.0 * size, d));
    return vec3(xz.x, h * exaggeration, xz.y);
}


void main() {
    ivec2 s;
    wall_normal = vec3(0.0);
    if (beyond > 0) {
        world = beyond_vertex();
        gl_Position = world.x == -1e30 ? vec4(2.0, 2.0, 2.0, 1.0) : view_projection * vec4(world, 1.0);
        gl_ClipDistance[0] = dot(vec4(world, 1.0), clip_plane);
        vec2 extent = vec2(grid - 1) * cell;
        bool across = beyond_side >= 2;  // west and east: between the north and south sides' strips
        gl_ClipDistance[1] = beyond_side == 0 ? -world.z : beyond_side == 1 ? world.z - extent.y
                           : beyond_side == 2 ? -world.x : world.x - extent.x;
        gl_ClipDistance[2] = across ? world.z : 1.0;
        gl_ClipDistance[3] = across ? extent.y - world.z : 1.0;
        return;
    }
    if (skirt_edge < 0) {
        s = min(ivec2(gl_VertexID % kept.x, gl_VertexID / kept.x) * stride, grid - 1);
    } else {
        int i = gl_VertexID / 2;
        int along = skirt_edge == 0 || skirt_edge == 2 ? grid.x : grid.y;
        int k = min(i * stride, along - 1);
        if (skirt_edge == 0) { s = ivec2(k, 0); wall_normal = vec3(0.0, 0.0, -1.0); }
        else if (skirt_edge == 1) { s = ivec2(grid.x - 1, k); wall_normal = vec3(1.0, 0.0, 0.0); }
        else if (skirt_edge == 2) { s = ivec2(grid.x - 1 - k, grid.y - 1); wall_normal = vec3(0.0, 0.0, 1.0); }
        else { s = ivec2(0, grid.y - 1 - k); wall_normal = vec3(-1.0, 0.0, 0.0); }
    }
    float h = texelFetch(heights, s, 0).r * exaggeration;
    if (skirt_edge >= 0 && (gl_VertexID & 1) == 1) h = floor_height;
    world = vec3(float(s.x) * cell, h, float(s.y) * cell);
    gl_Position = view_projection * vec4(world, 1.0);
    // Only used (GL_CLIP_DISTANCE0) by the sea's reflection pass, which keeps what lies above the water.
    gl_ClipDistance[0] = dot(vec4(world, 1.0), clip_plane);
}
