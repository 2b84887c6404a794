#version 460
// The indirect dispatch of light assignment (techniques/topovpl/gate_lighting.h): one workgroup
// per geometry cluster, laid out as x + 32768 y (the count can exceed the 65535 groups a
// dimension guarantees).
layout(local_size_x = 1) in;
layout(set = 0, binding = 0, std430) buffer State { uint state[]; };  // [0] clusters, [4..6] args

void main() {
    uint count = state[0];
    state[4] = min(count, 32768u);
    state[5] = (count + 32767u) / 32768u;
    state[6] = 1u;
}
