#version 450 core
// The bloom pass: the original frame plus strength × the blurred bright pass
// (sampled bilinearly when the bright pass is smaller).
in vec2 uv;
uniform sampler2D image;
uniform sampler2D bloom;
uniform float strength;
out vec4 colour;
void main() {
    vec4 original = texelFetch(image, ivec2(gl_FragCoord.xy), 0);
    // the pixel's centre as a fraction of the frame, from the window position (exact: the interpolated uv is
    // off by rounding, which blends in a neighbour of a bloom the frame's own size)
    vec2 at = gl_FragCoord.xy / vec2(textureSize(image, 0));
    colour = vec4(original.rgb + strength * texture(bloom, at).rgb, original.a);
}
