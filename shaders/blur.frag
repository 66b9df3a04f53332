#version 450 core
// One axis of a separable Gaussian (thesis Listings 3.4/3.5): every tap of the
// kernel, weights summing to 1, the image mirrored at its edges (half-sample
// symmetric), which keeps the image's sum exactly: a symmetric kernel reads
// each pixel once too often on one side as often as too rarely on the other.
uniform sampler2D image;
uniform ivec2 direction;   // (1, 0) or (0, 1)
uniform int radius;        // taps each side
uniform float weights[257]; // weights[k] for offset k = 0..radius
out vec4 colour;
int mirror(int i, int n) {
    // half-sample symmetric: ... 1 0 | 0 1 2 ... n-1 | n-1 n-2 ... (GLSL's % is undefined for
    // negative operands, so no modulo; a kernel wider than the image clamps at the far edge)
    if (i < 0) i = -1 - i;
    if (i >= n) i = 2 * n - 1 - i;
    return clamp(i, 0, n - 1);
}
void main() {
    ivec2 size = textureSize(image, 0);
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 sum = texelFetch(image, p, 0) * weights[0];
    int n = direction.x == 1 ? size.x : size.y;
    int c = direction.x == 1 ? p.x : p.y;
    ivec2 step = direction;
    if (c - radius >= 0 && c + radius < n) {
        // Away from the edges (nearly every pixel): no mirroring, the same taps in the same order.
        for (int k = 1; k <= radius; ++k)
            sum += (texelFetch(image, p - k * step, 0) + texelFetch(image, p + k * step, 0)) * weights[k];
        colour = sum;
        return;
    }
    for (int k = 1; k <= radius; ++k) {
        int a = mirror(c - k, n), b = mirror(c + k, n);
        ivec2 pa = direction.x == 1 ? ivec2(a, p.y) : ivec2(p.x, a);
        ivec2 pb = direction.x == 1 ? ivec2(b, p.y) : ivec2(p.x, b);
        sum += (texelFetch(image, pa, 0) + texelFetch(image, pb, 0)) * weights[k];
    }
    colour = sum;
}
