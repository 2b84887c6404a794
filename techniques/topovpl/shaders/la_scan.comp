#version 460
// Exclusive prefix sum of the per-geometry-cluster entry counts (light assignment's compaction,
// notes 004 §7 point 7) in one workgroup, chunk by chunk; saturates at 0xFFFFFFFF so a total
// beyond 32 bits is an overflow, never a wrap. state[1] = the total.
layout(local_size_x = 256) in;
layout(set = 0, binding = 0, std430) readonly buffer Counts { uint counts[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 2, std430) buffer State { uint state[]; };

shared uint scan[256];

uint addSat(uint a, uint b) { return a + b < a ? 0xFFFFFFFFu : a + b; }

void main() {
    uint lid = gl_LocalInvocationIndex;
    uint count = state[0];
    uint running = 0u;
    for (uint base = 0u; base < count; base += 256u) {
        uint i = base + lid;
        uint mine = i < count ? counts[i] : 0u;
        scan[lid] = mine;
        barrier();
        for (uint d = 1u; d < 256u; d <<= 1u) {
            uint add = lid >= d ? scan[lid - d] : 0u;
            barrier();
            scan[lid] = addSat(scan[lid], add);
            barrier();
        }
        if (i < count) offsets[i] = addSat(running, scan[lid] - mine);
        running = addSat(running, scan[255]);
        barrier();
    }
    if (lid == 0u) state[1] = running;
}
