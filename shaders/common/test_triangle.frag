#version 460
// Test shader: flat colour from push constants.
layout(push_constant) uniform Push { vec4 color; };
layout(location = 0) out vec4 outColor;
void main() { outColor = color; }
