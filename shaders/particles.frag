#version 450 core
#include "common.glsl"
in vec3 centre;
uniform vec3 eye;
uniform vec3 particle_colour;  // linear albedo
uniform vec3 ambient_colour;
out vec4 colour;
void main() {
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    float r2 = dot(d, d);
    if (r2 > 1.0) discard;
    // a sphere's normal in view-aligned axes is close enough for small points
    vec3 v = normalize(eye - centre);
    vec3 right = normalize(cross(vec3(0.0, 1.0, 0.0), v));
    vec3 up = cross(v, right);
    vec3 n = normalize(d.x * right - d.y * up + sqrt(1.0 - r2) * v);
    float lambert = max(dot(n, sun_direction), 0.0);
    vec3 c = particle_colour * (sun_colour * lambert + ambient_colour * (0.6 + 0.4 * n.y));
    colour = vec4(apply_fog(c, -v, distance(eye, centre)), 1.0);
}
