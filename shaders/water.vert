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
uniform int sea_plane;        // 1: a sea, one quad at sea_level out to plane_extent (x0, z0, x1, z1), m
uniform float sea_level;      // m
uniform vec4 plane_extent;
out vec3 world;
out float depth;
void main() {
    if (sea_plane == 1) {
        vec2 f = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
        world = vec3(mix(plane_extent.x, plane_extent.z, f.x), sea_level * exaggeration, mix(plane_extent.y, plane_extent.w, f.y));
        depth = 1.0;  // the fragment shader measures it against the ground
        gl_Position = view_projection * vec4(world, 1.0);
        return;
    }
    ivec2 s = min(ivec2(gl_VertexID % kept.x, gl_VertexID / kept.x) * stride, grid - 1);
    vec2 sd = texelFetch(surface, s, 0).rg;
    world = vec3(float(s.x) * cell, sd.x * exaggeration, float(s.y) * cell);
    depth = sd.y;
    gl_Position = view_projection * vec4(world, 1.0);
}
