#version 450 core
// The water surface as the terrain's grid: each vertex at the water's level
// (sea level, or the ground plus the `water` layer), with the water depth
// beside it; the fragment shader drops what lies above the water.
uniform sampler2D surface;    // RG32F: water surface height (m), water depth (m)
uniform ivec2 grid;
uniform int stride;
uniform ivec2 kept;
uniform float cell;
uniform float exaggeration;
uniform mat4 view_projection;
out vec3 world;
out float depth;
void main() {
    ivec2 s = min(ivec2(gl_VertexID % kept.x, gl_VertexID / kept.x) * stride, grid - 1);
    vec2 sd = texelFetch(surface, s, 0).rg;
    world = vec3(float(s.x) * cell, sd.x * exaggeration, float(s.y) * cell);
    depth = sd.y;
    gl_Position = view_projection * vec4(world, 1.0);
}
