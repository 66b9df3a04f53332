#version 450 core
// The water surface as the terrain's grid: each vertex at the water's level
// (sea level, or the ground plus the `water` layer). Where the ground is dry
// the vertex lies on the ground, so the grid drapes the terrain and the
// fragment shader decides, from the layer at full resolution, where water is.
uniform sampler2D surface;    // RGBA32F: water level (m), depth (m), wet (0/1), unused
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
void main() {
    if (sea_plane == 1) {
        vec2 f = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
        world = vec3(mix(plane_extent.x, plane_extent.z, f.x), sea_level * exaggeration, mix(plane_extent.y, plane_extent.w, f.y));
        gl_Position = view_projection * vec4(world, 1.0);
        return;
    }
    ivec2 s = min(ivec2(gl_VertexID % kept.x, gl_VertexID / kept.x) * stride, grid - 1);
    world = vec3(float(s.x) * cell, texelFetch(surface, s, 0).r * exaggeration, float(s.y) * cell);
    gl_Position = view_projection * vec4(world, 1.0);
}
