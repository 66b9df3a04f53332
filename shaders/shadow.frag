#version 450 core
// Depth only: the shadow map pass writes nothing but depth.
void main() {}
