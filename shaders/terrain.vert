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
out vec3 world;
flat out vec3 wall_normal;


void main() {
    ivec2 s;
    wall_normal = vec3(0.0);
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
