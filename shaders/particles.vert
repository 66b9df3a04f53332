#version 450 core
// Particles as points that the fragment shader shades as spheres.
layout(location = 0) in vec3 position;  // m, x east, y up, z south
uniform mat4 view_projection;
uniform float exaggeration;
uniform float radius;          // m
uniform float pixels_per_metre_at_unit_distance;  // viewport height / (2 tan(fov/2))
uniform vec3 eye;
out vec3 centre;
void main() {
    centre = vec3(position.x, position.y * exaggeration, position.z);
    gl_Position = view_projection * vec4(centre, 1.0);
    gl_PointSize = max(2.0 * radius * pixels_per_metre_at_unit_distance / max(distance(eye, centre), 1e-3), 1.0);
}
