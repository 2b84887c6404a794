#version 460
// Test shader: one triangle from gl_VertexIndex (no vertex buffer), covering the centre.
void main() {
    vec2 positions[3] = vec2[](vec2(-0.5, -0.5), vec2(0.5, -0.5), vec2(0.0, 0.5));
    gl_Position = vec4(positions[gl_VertexIndex], 0.5, 1.0);
}
