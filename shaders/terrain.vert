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
out vec3 world;
void main() {
    ivec2 s = min(ivec2(gl_VertexID % kept.x, gl_VertexID / kept.x) * stride, grid - 1);
    float h = texelFetch(heights, s, 0).r;
    world = vec3(float(s.x) * cell, h * exaggeration, float(s.y) * cell);
    gl_Position = view_projection * vec4(world, 1.0);
}
