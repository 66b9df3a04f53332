#version 450 core
#include "common.glsl"
in vec2 uv;
uniform mat4 inverse_view_projection;
out vec4 colour;
void main() {
    vec4 far_point = inverse_view_projection * vec4(uv * 2.0 - 1.0, 1.0, 1.0);
    vec4 near_point = inverse_view_projection * vec4(uv * 2.0 - 1.0, -1.0, 1.0);
    vec3 dir = normalize(far_point.xyz / far_point.w - near_point.xyz / near_point.w);
    colour = vec4(sky_colour(dir, sun_disc), 1.0);
}
