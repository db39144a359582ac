#version 450
// The profiling kernel over an engine-style packed G-buffer (the default of `brdfprof profile`): shade.glsl.
#define GBUFFER_PACKED
#extension GL_GOOGLE_include_directive : require
#include "shade.glsl"
