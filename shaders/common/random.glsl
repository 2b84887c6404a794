// Integer hash for GPU-side random numbers (PCG output permutation, as in Jarzynski & Olano,
// "Hash Functions for GPU Rendering", JCGT 2020): a well-mixed 32-bit value from a counter.
#ifndef GILAB_RANDOM_GLSL
#define GILAB_RANDOM_GLSL

uint pcgHash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

#endif  // GILAB_RANDOM_GLSL
