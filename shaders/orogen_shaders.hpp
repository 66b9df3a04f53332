// orogen_shaders.hpp — the GLSL 4.50 core sources in shaders/, embedded at
// build time (embed.cmake): each file foo.frag is orogen::shaders::foo_frag.
// Files that say #include "common.glsl" have it pasted in.
#pragma once

namespace orogen::shaders {
extern const char* const fullscreen_vert;
extern const char* const sky_frag;
extern const char* const terrain_vert;
extern const char* const terrain_frag;
extern const char* const shadow_frag;
extern const char* const water_vert;
extern const char* const water_frag;
extern const char* const particles_vert;
extern const char* const particles_frag;
extern const char* const bright_pass_frag;
extern const char* const blur_frag;
extern const char* const combine_frag;
}  // namespace orogen::shaders
