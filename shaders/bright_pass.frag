#version 450 core
// The bloom's bright pass (thesis §3.7.2): each pixel's luminance, scaled to
// the middle grey, mapped with Reinhard's formula
//   Ld = L (1 + L / Lwhite²) / (1 + L),
// less the threshold; what remains (≥ 0) keeps the pixel's colour.
uniform sampler2D image;        // linear RGBA
uniform int scale;              // box-average scale × scale input pixels per output pixel
uniform float average_luminance;
uniform float middle_grey;
uniform float white;            // luminance mapped to 1
uniform float threshold;
out vec4 colour;
void main() {
    ivec2 o = ivec2(gl_FragCoord.xy) * scale;
    ivec2 size = textureSize(image, 0);
    vec3 c = vec3(0.0);
    for (int j = 0; j < scale; ++j)
        for (int i = 0; i < scale; ++i) c += texelFetch(image, min(o + ivec2(i, j), size - 1), 0).rgb;
    c /= float(scale * scale);
    float luminance = dot(c, vec3(0.2126, 0.7152, 0.0722));
    float l = luminance * middle_grey / average_luminance;
    float mapped = l * (1.0 + l / (white * white)) / (1.0 + l);
    float bright = max(mapped - threshold, 0.0);
    colour = vec4(luminance > 0.0 ? c * (bright / mapped) : vec3(0.0), 1.0);
}
