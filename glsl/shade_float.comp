#version 450
// The profiling kernel over a 48-byte float G-buffer (`profile --gbuffer float`): shade.glsl.
#extension GL_GOOGLE_include_directive : require
#include "shade.glsl"
