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
    colour = vec4(original.rgb + strength * texture(bloom, uv).rgb, original.a);
}
