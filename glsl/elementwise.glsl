// The elementwise kernels' interface: one element per invocation (64 to a workgroup), binding 0 the input vec4s,
// binding 1 the output vec4s, the push constant the element count (invocations past it do nothing).
#ifndef ELEMENTWISE_GLSL
#define ELEMENTWISE_GLSL
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, set = 0, binding = 1) buffer Outputs { vec4 outputs[]; };
layout(push_constant) uniform Push { uint count; } pc;
#endif
